/** @file
 *  @brief Scheduler: the step loop of the micro-kernel. Quasi-continuous algorithms run at fixed steps;
 *  event-driven ones run when a signal triggers them, within the same step.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "vsd/core/signal.hpp"

namespace vsd {

/// @brief The phases of a step, in the order in which they run. Within a phase, tasks run by their
/// order number, then in the order they were added.
enum class Phase : int {
  inputs = 0,          ///< what arrives from outside: vsd::dist receives, user input
  controllers = 100,   ///< joint controllers and hardware bindings compute, send and read back
  kinematics = 200,    ///< kinematic animation that is not derived at once
  dynamics = 300,      ///< rigid-body physics integrates and writes poses back
  collision = 400,     ///< contacts and their begin/end signals
  sensors = 500,       ///< sensors turn continuous state into discrete facts (the nets' events σ)
  nets = 600,          ///< SOML++ nets react to what changed in this step
  outputs = 700,       ///< logging, recording, user interfaces
};

/// @brief The name of a phase ("controllers", ...).
[[nodiscard]] const char* phase_name(Phase phase) noexcept;

/// @brief What a task learns about the step it runs in.
struct StepInfo {
  double time;         ///< simulated time at the end of this step, in seconds
  double dt;           ///< time since this task last ran
  std::uint64_t step;  ///< number of the step (1 for the first)
};

class Scheduler {
 public:
  using Task = std::function<void(const StepInfo&)>;
  using TaskId = std::uint32_t;

  /// @param base_step the fixed step of the loop, in seconds (> 0).
  explicit Scheduler(double base_step = 0.01);

  [[nodiscard]] double base_step() const noexcept { return base_step_; }
  /// @brief Changes the fixed step. @throws vsd::Error unless > 0.
  void set_base_step(double seconds);
  [[nodiscard]] double time() const noexcept { return time_; }
  [[nodiscard]] std::uint64_t steps() const noexcept { return steps_; }

  /// @brief Runs @p task every @p period seconds (rounded to whole base steps, at least one), in
  /// @p phase; within a phase lower @p order runs first, equal ones in the order they were added.
  /// @throws vsd::Error when @p period is not > 0 or @p task is empty.
  TaskId add_periodic(std::string name, double period, Task task, Phase phase = Phase::controllers, int order = 0);
  /// @brief Adds a task that runs only when triggered, once per step however often it was triggered,
  /// after the periodic tasks of the step, by phase and order.
  TaskId add_event_driven(std::string name, Task task, Phase phase = Phase::nets, int order = 0);
  /// @brief Makes an event-driven task run in the current step (or the next one, between steps).
  void trigger(TaskId id);
  /// @brief Triggers task @p id whenever @p signal is emitted.
  template <class... A>
  Connection trigger_on(TaskId id, Signal<void(A...)>& signal) {
    return signal.connect([this, id](A...) { trigger(id); });
  }
  template <class... A>
  Connection trigger_on(TaskId id, Sink<void(A...)> sink) {
    return sink.connect([this, id](A...) { trigger(id); });
  }
  /// @brief Removes a task (safe from inside a task).
  void remove(TaskId id);
  [[nodiscard]] std::size_t task_count() const noexcept;
  [[nodiscard]] const std::string& task_name(TaskId id) const;

  /// @brief Advances one base step: due periodic tasks, then triggered tasks until none is pending.
  /// @throws vsd::Error when event-driven tasks keep triggering each other beyond a bound.
  void step();
  /// @brief Steps until @p seconds more of simulated time have passed (rounded to whole base steps).
  /// @throws vsd::Error when @p seconds is negative, not finite, or more than 2^53 base steps.
  void run_for(double seconds);
  /// @brief The phase of task @p id. @throws vsd::Error for an unknown task.
  [[nodiscard]] Phase task_phase(TaskId id) const;

 private:
  struct Entry {
    TaskId id;
    std::string name;
    std::unique_ptr<Task> task;  // not moved when the table grows: a running task may add tasks
    Phase phase;
    int order;
    std::uint64_t every;      // base steps between runs; 0 for event-driven
    std::uint64_t last_step;  // step it last ran in
    bool pending = false;
    bool removed = false;
  };
  Entry* find(TaskId id) noexcept;
  TaskId add(std::string name, Task task, Phase phase, int order, std::uint64_t every);
  void run(Entry& e);

  double base_step_;
  double time_ = 0.0;
  std::uint64_t steps_ = 0;
  TaskId next_id_ = 1;
  std::vector<Entry> tasks_;  // sorted by phase and order, stable
  bool any_pending_ = false;
};

}  // namespace vsd
