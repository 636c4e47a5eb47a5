/** @file
 *  @brief Scheduler: the step loop of the micro-kernel. Quasi-continuous algorithms run at fixed steps;
 *  event-driven ones run when a signal triggers them, within the same step.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vsd/core/signal.hpp"

namespace vsd {

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

  /// @brief Runs @p task every @p period seconds (rounded to whole base steps, at least one). Lower
  /// @p priority runs first; equal priorities run in the order they were added.
  TaskId add_periodic(std::string name, double period, Task task, int priority = 0);
  /// @brief Adds a task that runs only when triggered, once per step however often it was triggered.
  TaskId add_event_driven(std::string name, Task task, int priority = 0);
  /// @brief Makes an event-driven task run in the current step (or the next one, between steps).
  void trigger(TaskId id);
  /// @brief Triggers task @p id whenever @p signal is emitted.
  template <class... A>
  Connection trigger_on(TaskId id, Signal<void(A...)>& signal) {
    return signal.connect([this, id](A...) { trigger(id); });
  }
  /// @brief Removes a task (safe from inside a task).
  void remove(TaskId id);
  [[nodiscard]] std::size_t task_count() const noexcept;
  [[nodiscard]] const std::string& task_name(TaskId id) const;

  /// @brief Advances one base step: due periodic tasks, then triggered tasks until none is pending.
  /// @throws vsd::Error when event-driven tasks keep triggering each other beyond a bound.
  void step();
  /// @brief Steps until @p seconds more of simulated time have passed.
  void run_for(double seconds);

 private:
  struct Entry {
    TaskId id;
    std::string name;
    Task task;
    int priority;
    std::uint64_t every;      // base steps between runs; 0 for event-driven
    std::uint64_t last_step;  // step it last ran in
    bool pending = false;
    bool removed = false;
  };
  Entry* find(TaskId id) noexcept;
  TaskId add(std::string name, Task task, int priority, std::uint64_t every);
  void run(Entry& e);

  double base_step_;
  double time_ = 0.0;
  std::uint64_t steps_ = 0;
  TaskId next_id_ = 1;
  std::vector<Entry> tasks_;  // sorted by priority, stable
  bool any_pending_ = false;
};

}  // namespace vsd
