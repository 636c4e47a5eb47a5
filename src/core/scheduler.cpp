#include "vsd/core/scheduler.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "vsd/core/error.hpp"

namespace vsd {

namespace {
constexpr int max_event_rounds = 1000;  // triggered tasks re-triggering each other: a livelock guard
}

Scheduler::Scheduler(double base_step) : base_step_(base_step) {
  if (!(base_step > 0.0) || !std::isfinite(base_step))
    detail::throw_error("scheduler base step must be > 0 and finite");
}

void Scheduler::set_base_step(double seconds) {
  if (!(seconds > 0.0) || !std::isfinite(seconds))
    detail::throw_error("scheduler base step must be > 0 and finite, got " + std::to_string(seconds));
  base_step_ = seconds;
}

const char* phase_name(Phase phase) noexcept {
  switch (phase) {
    case Phase::inputs: return "inputs";
    case Phase::controllers: return "controllers";
    case Phase::kinematics: return "kinematics";
    case Phase::dynamics: return "dynamics";
    case Phase::collision: return "collision";
    case Phase::sensors: return "sensors";
    case Phase::nets: return "nets";
    case Phase::outputs: return "outputs";
  }
  return "unknown";
}

Scheduler::TaskId Scheduler::add(std::string name, Task task, Phase phase, int order, std::uint64_t every) {
  if (!task) detail::throw_error("scheduler task '" + name + "' has no function");
  const TaskId id = next_id_++;
  Entry e{id, std::move(name), std::make_unique<Task>(std::move(task)), phase, order, every, steps_};
  const auto key = std::pair(static_cast<int>(phase), order);
  auto at = std::upper_bound(tasks_.begin(), tasks_.end(), key, [](const auto& k, const Entry& x) {
    return k < std::pair(static_cast<int>(x.phase), x.order);
  });
  tasks_.insert(at, std::move(e));
  return id;
}

Scheduler::TaskId Scheduler::add_periodic(std::string name, double period, Task task, Phase phase, int order) {
  if (!(period > 0.0) || !std::isfinite(period))
    detail::throw_error("period of task '" + name + "' must be > 0 and finite");
  const auto every = static_cast<std::uint64_t>(std::clamp(std::round(period / base_step_), 1.0, 9.0e15));
  return add(std::move(name), std::move(task), phase, order, every);
}

Scheduler::TaskId Scheduler::add_event_driven(std::string name, Task task, Phase phase, int order) {
  return add(std::move(name), std::move(task), phase, order, 0);
}

Phase Scheduler::task_phase(TaskId id) const {
  for (const auto& e : tasks_)
    if (e.id == id && !e.removed) return e.phase;
  detail::throw_error("no scheduler task #" + std::to_string(id));
}

Scheduler::Entry* Scheduler::find(TaskId id) noexcept {
  for (auto& e : tasks_)
    if (e.id == id && !e.removed) return &e;
  return nullptr;
}

void Scheduler::trigger(TaskId id) {
  Entry* e = find(id);
  if (e == nullptr) detail::throw_error("no scheduler task #" + std::to_string(id));
  if (e->every != 0) detail::throw_error("task '" + e->name + "' is periodic and cannot be triggered");
  e->pending = true;
  any_pending_ = true;
}

void Scheduler::remove(TaskId id) {
  if (Entry* e = find(id)) {
    e->removed = true;  // erased between steps: a running task may remove itself or others
    e->pending = false;
  }
}

std::size_t Scheduler::task_count() const noexcept {
  return static_cast<std::size_t>(
      std::count_if(tasks_.begin(), tasks_.end(), [](auto& e) { return !e.removed; }));
}

const std::string& Scheduler::task_name(TaskId id) const {
  for (const auto& e : tasks_)
    if (e.id == id && !e.removed) return e.name;
  detail::throw_error("no scheduler task #" + std::to_string(id));
}

void Scheduler::run(Entry& e) {
  const StepInfo info{time_, static_cast<double>(steps_ - e.last_step) * base_step_, steps_};
  e.last_step = steps_;
  Task& task = *e.task;  // stays put if the task adds tasks (the entry may move)
  task(info);
}

void Scheduler::step() {
  ++steps_;
  time_ = static_cast<double>(steps_) * base_step_;
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    Entry& e = tasks_[i];
    if (e.removed || e.every == 0 || steps_ % e.every != 0) continue;
    run(e);
  }
  for (int round = 0; any_pending_; ++round) {
    if (round == max_event_rounds)
      detail::throw_error("event-driven tasks kept triggering each other for " +
                          std::to_string(max_event_rounds) + " rounds in step " + std::to_string(steps_));
    any_pending_ = false;
    for (std::size_t i = 0; i < tasks_.size(); ++i) {
      if (!tasks_[i].pending || tasks_[i].removed) continue;
      tasks_[i].pending = false;
      run(tasks_[i]);
    }
  }
  std::erase_if(tasks_, [](const Entry& e) { return e.removed; });
}

void Scheduler::run_for(double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds))
    detail::throw_error("run_for needs a finite time >= 0, got " + std::to_string(seconds));
  const double steps = std::round(seconds / base_step_);
  if (steps > 9007199254740992.0)  // 2^53: beyond it steps are no longer counted exactly
    detail::throw_error("run_for(" + std::to_string(seconds) + " s) would take more than 2^53 steps of " +
                        std::to_string(base_step_) + " s");
  const auto n = static_cast<std::uint64_t>(steps);
  for (std::uint64_t i = 0; i < n; ++i) step();
}

}  // namespace vsd
