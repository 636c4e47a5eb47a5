#include "vsd/collision/module.hpp"

#include "vsd/core/environment.hpp"
#include "vsd/core/scheduler.hpp"
#include "vsd/scene/module.hpp"

namespace vsd::collision {

namespace {
// The module's world of one state, in the state's context.
struct StateWorld {
  std::unique_ptr<CollisionWorld> world;
};
}  // namespace

Module::~Module() = default;

void Module::attach(vsd::Environment& env) {
  env.use<scene::Module>();
  env_ = &env;
  if (period_ > 0) {
    // After the dynamics have moved the bodies of this step.
    task_ = env.scheduler().add_periodic(
        "collision update", period_,
        [this](const StepInfo&) {
          for (SimState* s : env_->states_served(*this, Service::stepped)) world(*s).update();
        },
        Phase::collision);
  }
}

void Module::detach(vsd::Environment& env) {
  if (task_ != 0) env.scheduler().remove(task_);
  task_ = 0;
  env_ = nullptr;
}

void Module::serve(SimState& state, Service /*from*/, Service to) {
  if (to == Service::none) state.context().erase<StateWorld>();
}

CollisionWorld& Module::world(SimState& state, const Options& options) {
  auto& w = state.context().get_or_emplace<StateWorld>();
  if (w.world == nullptr) w.world = std::make_unique<CollisionWorld>(state, options);
  return *w.world;
}

}  // namespace vsd::collision
