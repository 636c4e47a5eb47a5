// The vsd-physics command-line tool (see vsd/physics/tool.hpp).
#include "vsd/physics/tool.hpp"

#include <cctype>
#include <charconv>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <string>
#include <vector>

#include "vsd/core/environment.hpp"
#include "vsd/io/snapshot.hpp"
#include "vsd/physics/module.hpp"
#include "vsd/scene/scene.hpp"
#include "vsd/scene/urdf_loader.hpp"

namespace vsd::physics {

namespace {

constexpr std::string_view usage =
    R"(vsd-physics: simulate a robot description or a saved scene and print the final poses

Usage:
  vsd-physics <file> [--steps N] [--dt SECONDS] [--package-path DIR]... [--free-base]
      <file> is a URDF (.urdf, .xml) or a scene saved by vsd::io (.json vsd-text, .vsds binary).
      A URDF becomes rigid bodies (links with a mass) and joints (revolute/continuous: hinge, prismatic:
      slider, fixed: fixed); its root body is fixed to the world unless --free-base is given. A saved
      scene is simulated as it is (a physics::World is added on the Database when it has none).
      Runs N scheduler steps (default 1000) of SECONDS (default 0.001) and prints every body's final
      position, orientation (roll, pitch, yaw in radians) and speed.
  vsd-physics --help
)";

bool parse_number(std::string_view s, double& v) {
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && p == s.data() + s.size();
}

}  // namespace

int run_tool(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  std::string file;
  double steps = 1000;
  double dt = 0.001;
  bool fix_base = true;
  scene::UrdfOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    if (a == "--help" || a == "-h") {
      out << usage;
      return 0;
    }
    if (a == "--steps" || a == "--dt" || a == "--package-path") {
      if (i + 1 == args.size()) {
        err << "vsd-physics: " << a << " needs a value\n" << usage;
        return 2;
      }
      const std::string_view v = args[++i];
      if (a == "--package-path") {
        options.package_paths.emplace_back(std::string(v));
        continue;
      }
      double& target = a == "--steps" ? steps : dt;
      if (!parse_number(v, target) || !(target > 0) ||
          (a == "--steps" && target != static_cast<double>(static_cast<long long>(target)))) {
        err << "vsd-physics: " << a << " needs a positive " << (a == "--steps" ? "integer" : "number")
            << ", got '" << v << "'\n";
        return 2;
      }
    } else if (a == "--free-base") {
      fix_base = false;
    } else if (a.starts_with("-")) {
      err << "vsd-physics: unknown option " << a << '\n' << usage;
      return 2;
    } else if (file.empty()) {
      file = std::string(a);
    } else {
      err << "vsd-physics: more than one file given\n" << usage;
      return 2;
    }
  }
  if (file.empty()) {
    err << "vsd-physics: no file given\n" << usage;
    return 2;
  }
  try {
    Environment env;
    auto& physics = env.use<Module>();
    env.scheduler().set_base_step(dt);
    SimState& state = env.main_state();
    const std::filesystem::path path(file);
    std::string ext = path.extension().string();
    for (auto& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    std::vector<std::string> warnings;
    if (ext == ".urdf" || ext == ".xml") {
      scene::SceneReport r = scene::load_urdf(state.database(), path, options);
      warnings = std::move(r.warnings);
      out << "loaded " << r.links << " links, " << r.joints << " joints; " << make_dynamic(*r.scene, fix_base)
          << " bodies\n";
    } else {
      io::LoadReport r = io::load(state, path);
      warnings = std::move(r.warnings);
      if (state.index().all<World>().empty()) state.database().add_extension(state.create<World>());
      out << "loaded " << r.instances << " instances\n";
    }
    for (const auto& w : warnings) out << "warning: " << w << '\n';
    for (long long i = 0; i < static_cast<long long>(steps); ++i) env.step();
    for (const auto& w : physics.simulation().warnings()) out << "warning: " << w << '\n';
    const SimulationStats st = physics.simulation().stats();
    out << "simulated " << env.time() << " s (" << static_cast<long long>(steps) << " steps of " << dt
        << " s): " << st.bodies << " bodies, " << st.joints << " joints, " << st.geoms << " geoms, "
        << st.steps << " ODE steps\n";
    out << std::fixed << std::setprecision(6);
    for (RigidBody* b : state.index().all<RigidBody>()) {
      const scene::Node3D* n = b->node();
      if (n == nullptr) continue;
      const Eigen::Isometry3d& w = n->world_frame();
      const Eigen::Vector3d rpy = w.rotation().eulerAngles(2, 1, 0).reverse();
      out << n->path() << ": position " << w.translation().transpose() << "  rpy " << rpy.transpose()
          << "  speed " << b->linear_velocity().norm() << '\n';
    }
    return 0;
  } catch (const std::exception& e) {
    err << "vsd-physics: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace vsd::physics
