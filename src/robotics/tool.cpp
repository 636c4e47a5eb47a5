// The vsd-robot command-line tool (see vsd/robotics/tool.hpp).
#include "vsd/robotics/tool.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/robotics/ik.hpp"
#include "vsd/robotics/kinematic_tree.hpp"
#include "vsd/robotics/module.hpp"
#include "vsd/scene/scene.hpp"
#include "vsd/scene/urdf_loader.hpp"

namespace vsd::robotics {

namespace {

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
      frame: {"success": true, "q": [...], ...}; the seed defaults to the middle of the limits
  vsd-robot --help

Values are metres and radians, separated by commas.
Exit status: 0 done; 1 a bad file, an unknown link, a wrong number of values or no IK solution (the
reason on stderr); 2 a usage error.
)";

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

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

std::vector<double> parse_values(std::string_view text, std::string_view what) {
  std::vector<double> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    const std::string item(text.substr(pos, comma - pos));
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    while (used < item.size() && std::isspace(static_cast<unsigned char>(item[used]))) ++used;
    if (item.empty() || used != item.size() || !std::isfinite(v))
      throw vsd::Error(std::string(what) + ": '" + item + "' is not a number");
    out.push_back(v);
    pos = comma + 1;
  }
  return out;
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

int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  if (args.empty()) throw UsageError("no command");
  const std::string_view cmd = args[0];
  if (cmd == "--help" || cmd == "-h") {
    out << usage;
    return 0;
  }
  if (cmd != "chain" && cmd != "fk" && cmd != "jacobian" && cmd != "ik")
    throw UsageError("unknown command '" + std::string(cmd) + "'");
  std::optional<std::string_view> file;
  std::map<std::string, std::string_view, std::less<>> opt;
  bool json = false;
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string_view a = args[i];
    if (a == "--json") {
      json = true;
    } else if (a == "--base" || a == "--tip" || a == "--q" || a == "--target" || a == "--seed" ||
               a == "--timeout") {
      if (i + 1 >= args.size()) throw UsageError(std::string(a) + " needs a value");
      opt[std::string(a.substr(2))] = args[++i];
    } else if (a.starts_with("--")) {
      throw UsageError("unknown option '" + std::string(a) + "'");
    } else if (!file) {
      file = a;
    } else {
      throw UsageError("more than one file: '" + std::string(*file) + "' and '" + std::string(a) + "'");
    }
  }
  if (!file) throw UsageError("no robot file");
  if (!opt.contains("base") || !opt.contains("tip")) throw UsageError("--base and --tip are required");
  if ((cmd == "fk" || cmd == "jacobian") && !opt.contains("q"))
    throw UsageError(std::string(cmd) + " needs --q");
  if (cmd == "ik" && !opt.contains("target")) throw UsageError("ik needs --target");

  vsd::Environment env;
  env.use<Module>();
  scene::UrdfOptions uo;
  uo.load_meshes = false;
  const auto report = scene::load_urdf(env.main_state().database(), std::string(*file), uo);
  (void)build_kinematics(*report.scene);
  auto link = [&](std::string_view which) -> scene::Node3D& {
    const std::string_view name = opt.find(which)->second;
    if (report.scene->name() == name) return *report.scene;
    scene::Link* l = report.scene->find_link(name);
    if (l == nullptr) throw vsd::Error("unknown link '" + std::string(name) + "' in " + std::string(*file));
    return *l;
  };
  scene::Node3D& base = link("base");
  scene::Node3D& tip = link("tip");
  const Model model = Model::compile(base, &tip);
  const auto n = static_cast<std::size_t>(model.dof());

  if (cmd == "chain") {
    if (json) {
      out << "{\"base\": \"" << base.name() << "\", \"tip\": \"" << tip.name() << "\", \"joints\": [";
      for (std::size_t i = 0; i < n; ++i) {
        const DofInfo& d = model.layout()[i];
        out << (i ? ", " : "") << "{\"name\": \"" << d.name << "\", \"type\": \"" << type_name(d.type)
            << "\"";
        if (d.has_limits) out << ", \"lower\": " << num(d.lower) << ", \"upper\": " << num(d.upper);
        if (d.velocity_limit > 0) out << ", \"velocity\": " << num(d.velocity_limit);
        out << "}";
      }
      out << "]}\n";
      return 0;
    }
    out << "chain " << base.name() << " -> " << tip.name() << ": " << n << " joint value"
        << (n == 1 ? "" : "s") << "\n";
    for (std::size_t i = 0; i < n; ++i) {
      const DofInfo& d = model.layout()[i];
      const char* unit = d.type == KinematicJointType::Prismatic ? "m" : "rad";
      out << "  " << i + 1 << " " << d.name << " " << type_name(d.type);
      if (d.has_limits) {
        out << " [" << num(d.lower) << ", " << num(d.upper) << "] " << unit;
      } else {
        out << " unlimited";
      }
      if (d.velocity_limit > 0) out << ", velocity " << num(d.velocity_limit) << " " << unit << "/s";
      out << "\n";
    }
    return 0;
  }
  auto values = [&](std::string_view key) {
    std::vector<double> q = parse_values(opt.find(key)->second, "--" + std::string(key));
    if (q.size() != n)
      throw vsd::Error("--" + std::string(key) + " has " + std::to_string(q.size()) + " values; the chain " +
                       base.name() + " -> " + tip.name() + " has " + std::to_string(n) +
                       " (see vsd-robot chain)");
    return q;
  };
  Model::Data data = model.make_data();
  if (cmd == "fk" || cmd == "jacobian") {
    const std::vector<double> q = values("q");
    model.forward(q, data);
    if (cmd == "fk") {
      const Frame& f = model.pose(data, model.tip());
      Eigen::Quaterniond r(f.rotation);
      r.normalize();
      if (r.w() < 0) r.coeffs() = -r.coeffs();
      const double quat[4] = {r.x(), r.y(), r.z(), r.w()};
      out << "{\"position\": " << list(f.translation.data(), 3) << ", \"quaternion\": " << list(quat, 4)
          << "}\n";
    } else {
      Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, static_cast<Eigen::Index>(n));
      model.jacobian(data, model.tip(), j);
      out << "{\"jacobian\": [";
      for (int r = 0; r < 6; ++r) {
        std::vector<double> row(n);
        for (std::size_t c = 0; c < n; ++c) row[c] = j(r, static_cast<Eigen::Index>(c));
        out << (r ? ", " : "") << list(row.data(), n);
      }
      out << "]}\n";
    }
    return 0;
  }
  // ik
  const std::vector<double> t = parse_values(opt.find("target")->second, "--target");
  if (t.size() != 7)
    throw vsd::Error("--target has " + std::to_string(t.size()) + " values; 7 expected (x,y,z,qx,qy,qz,qw)");
  const Eigen::Quaterniond rot(t[6], t[3], t[4], t[5]);
  if (std::abs(rot.norm() - 1.0) > 1e-3)
    throw vsd::Error("--target: the quaternion has norm " + num(rot.norm()) +
                     "; a unit quaternion is expected");
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.linear() = rot.normalized().toRotationMatrix();
  target.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  std::vector<double> seed(n, 0.0);
  if (opt.contains("seed")) {
    seed = values("seed");
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      const DofInfo& d = model.layout()[i];
      if (d.has_limits) seed[i] = 0.5 * (d.lower + d.upper);
    }
  }
  IkOptions io;
  if (opt.contains("timeout")) {
    const auto v = parse_values(opt.find("timeout")->second, "--timeout");
    if (v.size() != 1 || v[0] < 0) throw vsd::Error("--timeout: one number of seconds >= 0 expected");
    io.time_budget = v[0];
  } else {
    io.time_budget = 1.0;
  }
  IkSolver solver(model, model.tip(), io);
  const IkResult r = solver.solve(target, seed);
  out << "{\"success\": " << (r.success ? "true" : "false") << ", \"q\": " << list(r.q.data(), r.q.size())
      << ", \"position_error\": " << num(r.position_error)
      << ", \"orientation_error\": " << num(r.orientation_error) << ", \"iterations\": " << r.iterations
      << ", \"restarts\": " << r.restarts << "}\n";
  if (!r.success) {
    err << "vsd-robot: ik: no solution within " << num(io.time_budget) << " s (best: position error "
        << num(r.position_error) << " m, orientation error " << num(r.orientation_error) << " rad)\n";
    return 1;
  }
  return 0;
}

}  // namespace

int run_tool(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  try {
    return run(args, out, err);
  } catch (const UsageError& e) {
    err << "vsd-robot: " << e.what() << "\n" << usage;
    return 2;
  } catch (const std::exception& e) {
    err << "vsd-robot: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace vsd::robotics
