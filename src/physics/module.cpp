#include "vsd/physics/module.hpp"

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/scene/module.hpp"

namespace vsd::physics {

namespace {
// The module's simulation of one state, in the state's context.
struct StateSimulation {
  explicit StateSimulation(SimState& s) : simulation(s) {}
  Simulation simulation;
};
}  // namespace

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
  // Every scheduler step advances ODE by that step's dt; each World divides it into its own fixed steps.
  task_ = env.scheduler().add_periodic(
      "physics", env.scheduler().base_step(),
      [this](const vsd::StepInfo& s) {
        for (SimState* state : env_->states_served(*this, Service::stepped))
          state->context().get<StateSimulation>().simulation.advance(s.dt);
      },
      phase_);
}

void Module::detach(vsd::Environment& env) {
  if (task_ != 0) env.scheduler().remove(task_);
  task_ = 0;
  env_ = nullptr;
}

vsd::Service Module::default_service(const vsd::SimState& state) const {
  return state.is_main() ? Service::stepped : Service::none;
}

void Module::serve(vsd::SimState& state, vsd::Service /*from*/, vsd::Service to) {
  if (to == Service::none) {
    state.context().erase<StateSimulation>();
  } else {
    state.context().get_or_emplace<StateSimulation>(state);
  }
}

Simulation& Module::simulation() const {
  if (env_ == nullptr) throw vsd::Error("vsd::physics::Module: not attached to an environment");
  return simulation(env_->main_state());
}

Simulation& Module::simulation(vsd::SimState& state) const {
  if (auto* s = state.context().find<StateSimulation>()) return s->simulation;
  throw vsd::Error("vsd::physics::Module does not simulate SimState '" + state.name() +
                   "' (its service is none: see Environment::set_service)");
}

}  // namespace vsd::physics
