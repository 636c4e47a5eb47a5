// vsd-physics (see tool.hpp).
#include "tool.hpp"

#include <cmath>
#include <iomanip>
#include <ostream>
#include <string>
#include <vector>

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/physics/module.hpp"
#include "vsd/physics/rigid_body.hpp"
#include "vsd/physics/world.hpp"
#include "vsd/scene/scene.hpp"
#include "vsd_tool/arguments.hpp"
#include "vsd_tool/models.hpp"
#include "vsd_tool/runner.hpp"
#include "vsd_tool/scene_input.hpp"
#include "vsd_tool/text.hpp"

namespace vsd::tool::vsd_physics {

namespace {

constexpr std::string_view usage =
    R"(vsd-physics: simulate a robot description or a saved scene and print the final poses

Usage:
  vsd-physics <file> [--steps N] [--dt SECONDS] [--package-path DIR]... [--free-base]
      <file> is a URDF (.urdf, .xml) or a scene saved by vsd::io (.json vsd-text, .vsds binary); "-" reads
      standard input (XML is taken as a URDF).
      A URDF becomes rigid bodies (links with a mass) and joints (revolute/continuous: hinge, prismatic:
      slider, fixed: fixed); its root body is fixed to the world unless --free-base is given. A saved
      scene is simulated as it is (a physics::World is added on the Database when it has none).
      Runs N scheduler steps (default 1000, at most 100000000) of SECONDS (default 0.001, from 0.000001
      to 1) and prints every body's final position, orientation (roll, pitch, yaw in radians) and speed.
      Each world advances in its own fixed step (World::step, 1 ms by default); a run that would take a
      world more than 10000000 of them is refused.
  vsd-physics --help

Exit status: 0 simulated, 1 the file could not be loaded or simulated (or the simulation diverged), 2 a
usage error.
)";

const Tool tool{"vsd-physics", usage};

constexpr std::int64_t max_steps = 100'000'000;
constexpr double min_dt = 1e-6;
constexpr double max_dt = 1.0;
constexpr double max_world_steps = 1e7;

int body(std::span<const std::string_view> args, std::ostream& out, std::ostream& /*err: all is on out*/) {
  const Arguments a(args, {with_value("--steps"), with_value("--dt"), repeated("--package-path"), flag("--free-base")});
  a.expect_positional(1, 1, "one file");
  const std::int64_t steps = a.integer("--steps", 1000, 1, max_steps);
  const double dt = a.real("--dt", 0.001, min_dt, max_dt);
  scene::UrdfOptions options;
  for (const std::string_view p : a.values("--package-path")) options.package_paths.emplace_back(std::string(p));
  const bool fix_base = !a.has("--free-base");

  Workspace ws;
  Environment& env = ws.env();
  env.scheduler().set_base_step(dt);
  auto& physics = env.use<physics::Module>();
  SimState& state = ws.state();
  const SceneInput in = load_scene_input(state, a.positional()[0], options);
  if (in.urdf) {
    out << "loaded " << in.urdf->links << " links, " << in.urdf->joints << " joints; "
        << physics::make_dynamic(*in.urdf->scene, fix_base) << " bodies\n";
  } else {
    if (state.index().all<physics::World>().empty()) state.database().add_extension(state.create<physics::World>());
    out << "loaded " << in.saved->instances << " instances\n";
  }
  for (const auto& w : in.warnings) out << "warning: " << printable_lines(w) << '\n';
  // The work is known before it starts: each world takes steps * dt / its step ODE steps.
  const double seconds = static_cast<double>(steps) * dt;
  for (const physics::World* w : state.index().all<physics::World>()) {
    const double world_steps = seconds / w->step();
    if (!(world_steps <= max_world_steps))
      throw Error("simulating " + number_text(seconds) + " s would take " + number_text(std::floor(world_steps)) +
                  " steps of " + number_text(w->step()) + " s of the world on '" +
                  printable(w->owner() != nullptr ? w->owner()->name() : std::string("?")) + "' (at most " +
                  number_text(max_world_steps) + "): give fewer --steps or a smaller --dt");
  }
  for (std::int64_t i = 0; i < steps; ++i) env.step();
  for (const auto& w : physics.simulation().warnings()) out << "warning: " << printable_lines(w) << '\n';
  const physics::SimulationStats st = physics.simulation().stats();
  out << "simulated " << env.time() << " s (" << steps << " steps of " << dt << " s): " << st.bodies
      << " bodies, " << st.joints << " joints, " << st.geoms << " geoms, " << st.steps << " ODE steps\n";
  out << std::fixed << std::setprecision(6);
  for (physics::RigidBody* b : state.index().all<physics::RigidBody>()) {
    const scene::Node3D* n = b->node();
    if (n == nullptr) continue;
    const Eigen::Isometry3d& w = n->world_frame();
    const double speed = b->linear_velocity().norm();
    if (!w.matrix().allFinite() || !std::isfinite(speed))
      throw Error("the simulation diverged: " + printable(n->path()) + " has a pose or speed that is not finite");
    const Eigen::Vector3d rpy = w.rotation().eulerAngles(2, 1, 0).reverse();
    out << printable(n->path()) << ": position " << w.translation().transpose() << "  rpy " << rpy.transpose()
        << "  speed " << speed << '\n';
  }
  return exit_ok;
}

}  // namespace

int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  return tool::run(tool, args, out, err, body);
}

}  // namespace vsd::tool::vsd_physics
