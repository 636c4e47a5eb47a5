#include "vsd/dist/module.hpp"

#include "vsd/core/environment.hpp"
#include "vsd/core/scheduler.hpp"

namespace vsd::dist {

void Module::attach(vsd::Environment& env) {
  task_ = env.scheduler().add_periodic(
      "dist poll", env.scheduler().base_step(),
      [this](const StepInfo&) {
        for (auto& p : participants_) p->poll();
      },
      -1000);
}

void Module::detach(vsd::Environment& env) {
  env.scheduler().remove(task_);
  participants_.clear();
}

Participant& Module::join(SimState& state, ParticipantOptions options) {
  participants_.push_back(std::make_unique<Participant>(state, std::move(options)));
  return *participants_.back();
}

}  // namespace vsd::dist
