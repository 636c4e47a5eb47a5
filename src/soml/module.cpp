#include "vsd/soml/module.hpp"

#include "program_impl.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/scheduler.hpp"

namespace vsd::soml {

namespace {
// The programs the module loaded into one state, in that state's context: they go with the state (first
// thing in ~SimState, while their instances are whole) or when the module stops serving it.
struct ModulePrograms {
  bool stepped = false;  // the module runs the nets of this state
  std::vector<std::unique_ptr<Program>> programs;
};
}  // namespace

Module::Module() = default;

// The Environment destroys its modules after its states: the classes of the programs that went with the
// states (they could not go while their instances lived) go now, unless another program uses them.
Module::~Module() {
  if (registry_ != nullptr) sweep_soml_leftovers(*registry_);
}

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
  registry_ = &env.registry();
  // Event-driven: the task runs in a step only when some transition of a stepped state needs a test.
  task_ = env.scheduler().add_event_driven(
      "soml nets",
      [this](const StepInfo&) {
        for (SimState* state : env_->states_served(*this, Service::stepped))
          if (auto* mine = state->context().find<ModulePrograms>())
            for (auto& p : mine->programs) p->run_until_quiet(step_limit);
      },
      Phase::nets);
  has_task_ = true;
}

void Module::detach(vsd::Environment& env) {
  for (SimState* state : env.states_served(*this, Service::derived))
    if (auto* mine = state->context().find<ModulePrograms>())
      for (auto& p : mine->programs) p->impl().on_dirty_ = nullptr;
  if (has_task_) env.scheduler().remove(task_);
  has_task_ = false;
  env_ = nullptr;
}

void Module::serve(SimState& state, Service /*from*/, Service to) {
  if (to == Service::none) {
    state.context().erase<ModulePrograms>();  // the programs go; their content stays in the database
    return;
  }
  auto* mine = state.context().find<ModulePrograms>();
  if (mine == nullptr) return;  // made by the first load
  mine->stepped = to == Service::stepped;
  if (mine->stepped && has_task_) env_->scheduler().trigger(task_);  // tests that waited while derived
}

Program& Module::load(SimState& state, std::string name, std::string text, RunOptions options) {
  check_served(state);
  return add(state, Program::load(state, std::move(name), std::move(text), options));
}

Program& Module::adopt(SimState& state, std::string name, std::string text, RunOptions options) {
  check_served(state);
  return add(state, Program::attach(state, std::move(name), std::move(text), options));
}

void Module::check_served(const SimState& state) const {
  if (env_ == nullptr || &state.environment() != env_)
    throw Error("soml: the state '" + state.name() + "' is not of the Environment that uses this module");
  if (env_->service(*this, state) == Service::none)
    throw Error("soml: the module does not serve the state '" + state.name() +
                "' (Service::none): env.set_service<vsd::soml::Module>(state, ...) first");
}

Program& Module::add(SimState& state, std::unique_ptr<Program> program) {
  const Service service = env_->service(*this, state);
  auto& mine = state.context().get_or_emplace<ModulePrograms>();
  mine.stepped = service == Service::stepped;
  mine.programs.push_back(std::move(program));
  Program& p = *mine.programs.back();
  if (has_task_) {
    Scheduler* s = &env_->scheduler();
    const auto task = task_;
    const bool* stepped = &mine.stepped;  // the slot lives as long as the program
    p.impl().on_dirty_ = [s, task, stepped] {
      if (*stepped) s->trigger(task);
    };
    if (mine.stepped) s->trigger(task);
  }
  return p;
}

std::vector<Program*> Module::programs(const SimState& state) const {
  std::vector<Program*> out;
  if (const auto* mine = state.context().find<ModulePrograms>())
    for (const auto& p : mine->programs) out.push_back(p.get());
  return out;
}

std::vector<Program*> Module::programs() const {
  std::vector<Program*> out;
  if (env_ == nullptr) return out;
  for (SimState* state : env_->states_served(*this, Service::derived))
    for (Program* p : programs(*state)) out.push_back(p);
  return out;
}

}  // namespace vsd::soml
