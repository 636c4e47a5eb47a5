#include "vsd/soml/module.hpp"

#include "program_impl.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/scheduler.hpp"

namespace vsd::soml {

Module::Module() = default;
Module::~Module() = default;

void Module::register_types(vsd::Registry& registry) {
  registry.add_type<ArrowType>();
  registry.add<SourceFile>();
  registry.add<SourceComponent>();
  registry.add<Place>();
  registry.add<Transition>();
  registry.add<Arrow>();
  registry.add<Invocation>();
  registry.add<Executor>();
}

void Module::attach(vsd::Environment& env) {
  env_ = &env;
  // Event-driven: the task runs in a step only when some transition of a program needs a test.
  task_ = env.scheduler().add_event_driven(
      "soml nets",
      [this](const StepInfo&) {
        for (auto& p : programs_) p->run_until_quiet(step_limit);
      },
      Phase::nets);
  has_task_ = true;
}

void Module::detach(vsd::Environment& env) {
  for (auto& p : programs_) p->impl().on_dirty_ = nullptr;
  if (has_task_) env.scheduler().remove(task_);
  has_task_ = false;
  env_ = nullptr;
}

Program& Module::load(SimState& state, std::string name, std::string text, RunOptions options) {
  return add(Program::load(state, std::move(name), std::move(text), options));
}

Program& Module::adopt(SimState& state, std::string name, std::string text, RunOptions options) {
  return add(Program::attach(state, std::move(name), std::move(text), options));
}

Program& Module::add(std::unique_ptr<Program> program) {
  programs_.push_back(std::move(program));
  Program& p = *programs_.back();
  if (env_ != nullptr && has_task_) {
    Scheduler* s = &env_->scheduler();
    const auto task = task_;
    p.impl().on_dirty_ = [s, task] { s->trigger(task); };
    s->trigger(task);
  }
  return p;
}

}  // namespace vsd::soml
