#include "vsd/collision/module.hpp"

#include "vsd/core/environment.hpp"
#include "vsd/core/scheduler.hpp"
#include "vsd/scene/module.hpp"

namespace vsd::collision {

Module::~Module() = default;

void Module::attach(vsd::Environment& env) {
  env.use<scene::Module>();
  if (period_ > 0) {
    // After the dynamics (priority 20 by convention) have moved the bodies of this step.
    env.scheduler().add_periodic(
        "collision update", period_, [this, &env](const StepInfo&) { world(env.main_state()).update(); }, 30);
  }
}

void Module::detach(vsd::Environment& /*env*/) { worlds_.clear(); }

CollisionWorld& Module::world(SimState& state, const Options& options) {
  auto& w = worlds_[&state];
  if (w == nullptr) w = std::make_unique<CollisionWorld>(state, options);
  return *w;
}

}  // namespace vsd::collision
