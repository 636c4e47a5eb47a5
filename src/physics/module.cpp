#include "vsd/physics/module.hpp"

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/scene/module.hpp"

namespace vsd::physics {

Module::~Module() = default;

void Module::register_types(vsd::Registry& registry) {
  registry.add_type<Solver>();
  registry.add_type<JointKind>();
  registry.add<World>();
  registry.add<RigidBody>();
  registry.add<Joint>();
}

void Module::attach(vsd::Environment& env) {
  env.use<scene::Module>();
  env_ = &env;
  simulation_ = std::make_unique<Simulation>(env.main_state());
  Simulation* sim = simulation_.get();
  // Every scheduler step advances ODE by that step's dt; each World divides it into its own fixed steps.
  task_ = env.scheduler().add_periodic(
      "physics", env.scheduler().base_step(), [sim](const vsd::StepInfo& s) { sim->advance(s.dt); },
      priority_);
}

void Module::detach(vsd::Environment& env) {
  if (task_ != 0) env.scheduler().remove(task_);
  task_ = 0;
  simulation_.reset();
  env_ = nullptr;
}

Simulation& Module::simulation() const {
  if (!simulation_) throw vsd::Error("vsd::physics::Module: not attached to an environment");
  return *simulation_;
}

}  // namespace vsd::physics
