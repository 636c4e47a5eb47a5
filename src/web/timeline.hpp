/** @file
 *  @brief Internal: the inspector's timeline — the state's recorded bundles, one entry per cut (a step,
 *  an edit), which the page scrubs: back applies inverted bundles, forward applies them again, and a
 *  change made while scrubbed back forks the history there (the entries after it are dropped).
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>

#include "vsd/core/signal.hpp"
#include "vsd/core/transaction.hpp"

namespace vsd {
class SimState;
}

namespace vsd::web::detail {

class JsonWriter;

class Timeline {
 public:
  /// @brief Listens to @p state's bundles (SimState::on_bundle) and makes the state record; keeps at most
  /// @p max_bytes of bundles (oldest dropped first).
  Timeline(SimState& state, std::size_t max_bytes);
  ~Timeline();
  Timeline(const Timeline&) = delete;
  Timeline& operator=(const Timeline&) = delete;

  /// @brief Cuts the state's recording; a bundle that is not empty becomes an entry at @p step, @p time.
  void cut(std::uint64_t step, double time);
  /// @brief Absolute index of the first entry kept (entries before it were dropped for memory).
  [[nodiscard]] std::uint64_t first() const noexcept { return first_; }
  /// @brief Absolute index one past the newest entry.
  [[nodiscard]] std::uint64_t end() const noexcept { return first_ + entries_.size(); }
  /// @brief Entries applied now: end() when live, less while scrubbed back.
  [[nodiscard]] std::uint64_t position() const noexcept { return position_; }
  [[nodiscard]] bool live() const noexcept { return position_ == end(); }
  [[nodiscard]] std::size_t size() const noexcept { return entries_.size(); }
  /// @brief Applies inverted (back) or recorded (forward) bundles until @p position entries are applied.
  /// @throws vsd::Error when @p position is outside [first(), end()] or a bundle does not apply (the
  /// state is then where the last bundle that applied left it, and position() says so).
  void seek(std::uint64_t position, std::uint64_t step, double time);
  /// @brief `{"entries": [...], "position", "live", "first"}` (at most the newest @p limit entries).
  void write(JsonWriter& out, std::size_t limit) const;

 private:
  struct Entry {
    std::uint64_t step;
    double time;
    Transaction bundle;
  };
  void heard(const Transaction& t);
  SimState& state_;
  std::size_t max_bytes_;
  std::size_t bytes_ = 0;
  std::deque<Entry> entries_;
  std::uint64_t first_ = 0;
  std::uint64_t position_ = 0;
  std::uint64_t step_ = 0;  // what cut() was told, for the entries heard meanwhile
  double time_ = 0.0;
  bool seeking_ = false;    // bundles of our own seeks are not entries
  bool started_recording_ = false;
  Connection bundles_;
};

}  // namespace vsd::web::detail
