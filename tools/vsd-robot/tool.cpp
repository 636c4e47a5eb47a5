// vsd-robot (see tool.hpp).
#include "tool.hpp"

#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/robotics/ik.hpp"
#include "vsd/robotics/kinematic_tree.hpp"
#include "vsd/robotics/module.hpp"
#include "vsd/scene/scene.hpp"
#include "vsd_tool/arguments.hpp"
#include "vsd_tool/input.hpp"
#include "vsd_tool/models.hpp"
#include "vsd_tool/runner.hpp"
#include "vsd_tool/scene_input.hpp"
#include "vsd_tool/text.hpp"

namespace vsd::tool::vsd_robot {

namespace {

using robotics::DofInfo;
using robotics::KinematicJointType;
using robotics::Model;

constexpr std::string_view usage = R"(vsd-robot: kinematics of a robot description (URDF)

Usage:
  vsd-robot chain    ROBOT.urdf --base LINK --tip LINK [--json]
      the joints from LINK to LINK in the order the other commands take their values: name, type,
      limits and speed limit
  vsd-robot fk       ROBOT.urdf --base LINK --tip LINK --q v1,v2,...
      {"position": [x, y, z], "quaternion": [x, y, z, w]}: the tip in the base frame (w >= 0)
  vsd-robot jacobian ROBOT.urdf --base LINK --tip LINK --q v1,v2,...
      {"jacobian": [[...], ...]}: 6 rows (linear velocity first, then angular), one column per value,
      in the base frame, of the tip's origin
  vsd-robot ik       ROBOT.urdf --base LINK --tip LINK --target x,y,z,qx,qy,qz,qw [--seed v1,...]
                     [--timeout SECONDS]
      joint values that put the tip at the target (position in metres, unit quaternion) in the base
      frame: {"success": true, "q": [...], "position_error": ..., ...}, the errors those values have;
      the seed defaults to the middle of the limits; --timeout 0 to 60 s (default 1)
  vsd-robot --help

Values are metres and radians, separated by commas (--q "" for a chain without joints). ROBOT.urdf may be
"-" (standard input). What the kinematics cannot use as written (a floating or planar joint becomes
fixed, ...) is a warning on the error stream; vsd-scene shows the file's other warnings.
Exit status: 0 done; 1 a bad file, an unknown link, a wrong number of values, a result that is not finite
or no IK solution (the reason on stderr); 2 a usage error (a malformed number included).
)";

const Tool tool{"vsd-robot", usage, true};

std::string num(double v) {
  if (v == 0.0) v = 0.0;  // no "-0"
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string list(const double* v, std::size_t n) {
  std::string s = "[";
  for (std::size_t i = 0; i < n; ++i) s += (i ? ", " : "") + num(v[i]);
  return s + "]";
}

bool finite(const double* v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

// Joint values: empty text is no value (a chain without joints).
std::vector<double> values_of(std::string_view text, std::string_view what) {
  return text.empty() ? std::vector<double>{} : parse_reals(text, what);
}

const char* type_name(KinematicJointType t) {
  switch (t) {
    case KinematicJointType::Rotary:
      return "rotary";
    case KinematicJointType::Prismatic:
      return "prismatic";
    case KinematicJointType::Universal:
      return "universal";
    default:
      return "fixed";
  }
}

int body(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  if (args.empty()) throw UsageError("no command (chain, fk, jacobian or ik)");
  const std::string_view cmd = args[0];
  if (cmd != "chain" && cmd != "fk" && cmd != "jacobian" && cmd != "ik")
    throw UsageError("unknown command '" + printable(cmd) + "'");
  const Arguments a(args.subspan(1), {flag("--json"), with_value("--base"), with_value("--tip"), with_value("--q"),
                                      with_value("--target"), with_value("--seed"), with_value("--timeout")});
  a.expect_positional(1, 1, "one robot file");
  if (!a.has("--base") || !a.has("--tip")) throw UsageError("--base and --tip are required");
  if ((cmd == "fk" || cmd == "jacobian") && !a.has("--q"))
    throw UsageError(std::string(cmd) + " needs --q (--q \"\" for a chain without joints)");
  if (cmd == "ik" && !a.has("--target")) throw UsageError("ik needs --target");
  // Numbers are checked before the file is read: a malformed one is a usage error.
  const std::vector<double> q_given = a.has("--q") ? values_of(*a.value("--q"), "--q") : std::vector<double>{};
  const std::vector<double> target_given = a.has("--target") ? parse_reals(*a.value("--target"), "--target")
                                                             : std::vector<double>{};
  const std::vector<double> seed_given = a.has("--seed") ? values_of(*a.value("--seed"), "--seed")
                                                         : std::vector<double>{};
  const double timeout = a.real("--timeout", 1.0, 0.0, 60.0);
  const std::string_view file = a.positional()[0];

  Workspace ws;
  ws.env().use<robotics::Module>();
  scene::UrdfOptions uo;
  uo.load_meshes = false;
  scene::Scene& scene = *load_urdf_input(ws.state(), file, uo).scene;
  // What the kinematics could not use as written (a floating or planar joint made fixed, ...); the URDF's
  // other warnings (unsupported tags, missing meshes) are vsd-scene's to show.
  std::vector<std::string> warnings;
  (void)robotics::build_kinematics(scene, &warnings);
  print_warnings(warnings, err);
  auto link = [&](std::string_view which) -> scene::Node3D& {
    const std::string_view name = *a.value(which);
    if (scene.name() == name) return scene;
    scene::Link* l = scene.find_link(name);
    if (l == nullptr) throw Error("unknown link '" + printable(name) + "' in " + input_name(file));
    return *l;
  };
  scene::Node3D& base = link("--base");
  scene::Node3D& tip = link("--tip");
  const Model model = Model::compile(base, &tip);
  const auto n = static_cast<std::size_t>(model.dof());
  const std::string chain_name = printable(base.name()) + " -> " + printable(tip.name());

  if (cmd == "chain") {
    if (a.has("--json")) {
      out << "{\"base\": " << json_string(base.name()) << ", \"tip\": " << json_string(tip.name())
          << ", \"joints\": [";
      for (std::size_t i = 0; i < n; ++i) {
        const DofInfo& d = model.layout()[i];
        out << (i ? ", " : "") << "{\"name\": " << json_string(d.name) << ", \"type\": \"" << type_name(d.type)
            << "\"";
        if (d.has_limits && std::isfinite(d.lower) && std::isfinite(d.upper))
          out << ", \"lower\": " << num(d.lower) << ", \"upper\": " << num(d.upper);
        if (d.velocity_limit > 0 && std::isfinite(d.velocity_limit)) out << ", \"velocity\": " << num(d.velocity_limit);
        out << "}";
      }
      out << "]}\n";
      return exit_ok;
    }
    out << "chain " << chain_name << ": " << n << " joint value" << (n == 1 ? "" : "s") << "\n";
    for (std::size_t i = 0; i < n; ++i) {
      const DofInfo& d = model.layout()[i];
      const char* unit = d.type == KinematicJointType::Prismatic ? "m" : "rad";
      out << "  " << i + 1 << " " << printable(d.name) << " " << type_name(d.type);
      if (d.has_limits) {
        out << " [" << num(d.lower) << ", " << num(d.upper) << "] " << unit;
      } else {
        out << " unlimited";
      }
      if (d.velocity_limit > 0) out << ", velocity " << num(d.velocity_limit) << " " << unit << "/s";
      out << "\n";
    }
    return exit_ok;
  }
  auto check_count = [&](const std::vector<double>& v, std::string_view what) {
    if (v.size() != n)
      throw Error(std::string(what) + " has " + std::to_string(v.size()) + " values; the chain " + chain_name +
                  " has " + std::to_string(n) + " (see vsd-robot chain)");
  };
  // A pose that is not finite (a huge prismatic value, a model with huge numbers) is an error, never output.
  auto check_finite = [&](const double* v, std::size_t count, std::string_view what) {
    if (!finite(v, count))
      throw Error(std::string(what) + " of " + chain_name +
                  " is not finite (a joint value or a number of the model is too large)");
  };
  Model::Data data = model.make_data();
  if (cmd == "fk" || cmd == "jacobian") {
    check_count(q_given, "--q");
    model.forward(q_given.data(), data);
    if (cmd == "fk") {
      const robotics::Frame& f = model.pose(data, model.tip());
      check_finite(f.translation.data(), 3, "the position");
      check_finite(f.rotation.data(), 9, "the orientation");
      Eigen::Quaterniond r(f.rotation);
      r.normalize();
      if (r.w() < 0) r.coeffs() = -r.coeffs();
      const double quat[4] = {r.x(), r.y(), r.z(), r.w()};
      check_finite(quat, 4, "the orientation");
      out << "{\"position\": " << list(f.translation.data(), 3) << ", \"quaternion\": " << list(quat, 4) << "}\n";
    } else {
      Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, static_cast<Eigen::Index>(n));
      model.jacobian(data, model.tip(), j);
      check_finite(j.data(), static_cast<std::size_t>(j.size()), "the Jacobian");
      out << "{\"jacobian\": [";
      for (int r = 0; r < 6; ++r) {
        std::vector<double> row(n);
        for (std::size_t c = 0; c < n; ++c) row[c] = j(r, static_cast<Eigen::Index>(c));
        out << (r ? ", " : "") << list(row.data(), n);
      }
      out << "]}\n";
    }
    return exit_ok;
  }
  // ik
  const std::vector<double>& t = target_given;
  if (t.size() != 7)
    throw Error("--target has " + std::to_string(t.size()) + " values; 7 expected (x,y,z,qx,qy,qz,qw)");
  const Eigen::Quaterniond rot(t[6], t[3], t[4], t[5]);
  if (std::abs(rot.norm() - 1.0) > 1e-3)
    throw Error("--target: the quaternion has norm " + num(rot.norm()) + "; a unit quaternion is expected");
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.linear() = rot.normalized().toRotationMatrix();
  target.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  std::vector<double> seed(n, 0.0);
  if (a.has("--seed")) {
    check_count(seed_given, "--seed");
    seed = seed_given;
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      const DofInfo& d = model.layout()[i];
      if (d.has_limits) seed[i] = 0.5 * d.lower + 0.5 * d.upper;  // halves first: no overflow to inf
    }
  }
  check_finite(seed.data(), seed.size(), "the seed");
  robotics::IkOptions io;
  io.time_budget = timeout;
  robotics::IkSolver solver(model, model.tip(), io);
  const robotics::IkResult r = solver.solve(target, seed);
  // The errors of the joint values printed, measured here: what the solver reports of its best attempt
  // is not always of these values (an attempt whose error is not a number reports none).
  check_finite(r.q.data(), r.q.size(), "the IK solution");
  model.forward(r.q.data(), data);
  const Eigen::Isometry3d reached = model.pose(data, model.tip()).isometry();
  const double position_error = (reached.translation() - target.translation()).norm();
  const double orientation_error = Eigen::AngleAxisd(target.linear().transpose() * reached.linear()).angle();
  const double errors[2] = {position_error, orientation_error};
  check_finite(errors, 2, "the IK error");
  out << "{\"success\": " << (r.success ? "true" : "false") << ", \"q\": " << list(r.q.data(), r.q.size())
      << ", \"position_error\": " << num(position_error) << ", \"orientation_error\": " << num(orientation_error)
      << ", \"iterations\": " << r.iterations << ", \"restarts\": " << r.restarts << "}\n";
  if (!r.success) {
    err << "vsd-robot: ik: no solution within " << num(io.time_budget) << " s (best: position error "
        << num(position_error) << " m, orientation error " << num(orientation_error) << " rad)\n";
    return exit_failure;
  }
  return exit_ok;
}

}  // namespace

int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  return tool::run(tool, args, out, err, body);
}

}  // namespace vsd::tool::vsd_robot
