#include "vsd/core/scheduler.hpp"

#include <algorithm>
#include <cmath>

#include "vsd/core/error.hpp"

namespace vsd {

namespace {
constexpr int max_event_rounds = 1000;  // triggered tasks re-triggering each other: a livelock guard
}

Scheduler::Scheduler(double base_step) : base_step_(base_step) {
  if (!(base_step > 0.0)) detail::throw_error("scheduler base step must be > 0");
}

void Scheduler::set_base_step(double seconds) {
  if (!(seconds > 0.0))
    detail::throw_error("scheduler base step must be > 0, got " + std::to_string(seconds));
  base_step_ = seconds;
}

Scheduler::TaskId Scheduler::add(std::string name, Task task, int priority, std::uint64_t every) {
  if (!task) detail::throw_error("scheduler task '" + name + "' has no function");
  const TaskId id = next_id_++;
  Entry e{id, std::move(name), std::move(task), priority, every, steps_};
  auto at = std::upper_bound(tasks_.begin(), tasks_.end(), priority,
                             [](int p, const Entry& x) { return p < x.priority; });
  tasks_.insert(at, std::move(e));
  return id;
}

Scheduler::TaskId Scheduler::add_periodic(std::string name, double period, Task task, int priority) {
  if (!(period > 0.0)) detail::throw_error("period of task '" + name + "' must be > 0");
  const auto every = static_cast<std::uint64_t>(std::max(1.0, std::round(period / base_step_)));
  return add(std::move(name), std::move(task), priority, every);
}

Scheduler::TaskId Scheduler::add_event_driven(std::string name, Task task, int priority) {
  return add(std::move(name), std::move(task), priority, 0);
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
  Task task = e.task;  // the entry may move if the task adds tasks
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
  const auto n = static_cast<std::uint64_t>(std::llround(seconds / base_step_));
  for (std::uint64_t i = 0; i < n; ++i) step();
}

}  // namespace vsd
