#include "vsd/dist/module.hpp"

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/scheduler.hpp"

namespace vsd::dist {

namespace {
// The participants of one state, in the state's context.
struct StateParticipants {
  std::vector<std::unique_ptr<Participant>> all;
};
}  // namespace

void Module::attach(vsd::Environment& env) {
  env_ = &env;
  task_ = env.scheduler().add_periodic(
      "dist poll", env.scheduler().base_step(),
      [this](const StepInfo&) {
        for (Participant* p : participants()) p->poll();
      },
      Phase::inputs);
}

void Module::detach(vsd::Environment& env) {
  if (task_ != 0) env.scheduler().remove(task_);
  task_ = 0;
  env_ = nullptr;
}

void Module::serve(SimState& state, Service /*from*/, Service to) {
  if (to == Service::none) state.context().erase<StateParticipants>();
}

Participant& Module::join(SimState& state, ParticipantOptions options) {
  if (env_ == nullptr || env_->service(*this, state) == Service::none)
    throw vsd::Error("vsd::dist::Module: SimState '" + state.name() + "' is not served by this module");
  auto& list = state.context().get_or_emplace<StateParticipants>().all;
  list.push_back(std::make_unique<Participant>(state, std::move(options)));
  return *list.back();
}

std::vector<Participant*> Module::participants() const {
  std::vector<Participant*> out;
  if (env_ == nullptr) return out;
  for (SimState* s : env_->states())
    if (auto* list = s->context().find<StateParticipants>())
      for (const auto& p : list->all) out.push_back(p.get());
  return out;
}

}  // namespace vsd::dist
