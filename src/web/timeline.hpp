/** @file
 *  @brief Internal: the inspector's timeline — the state's recorded bundles, one entry per cut (a step,
 *  an edit), which the page scrubs: back applies inverted bundles, forward applies them again, and a
 *  change made while scrubbed back forks the history there (the entries after it are dropped).
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>

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
  /// @p max_bytes of bundles (oldest dropped first; the newest entry is kept even when it alone is
  /// larger). Memory: the bundles kept plus at most two blocks of max_bytes / 16 (64 KiB to 1 MiB).
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
  /// @brief Bytes of the bundles kept.
  [[nodiscard]] std::size_t bytes() const noexcept { return bytes_; }
  /// @brief The bundle of entry @p index (absolute, in [first(), end())), for tests and tools.
  /// @throws vsd::Error when @p index is not kept.
  [[nodiscard]] Transaction entry(std::uint64_t index) const;
  /// @brief Applies inverted (back) or recorded (forward) bundles until @p position entries are applied.
  /// @throws vsd::Error when @p position is outside [first(), end()] or a bundle does not apply (the
  /// state is then where the last bundle that applied left it, and position() says so).
  void seek(std::uint64_t position, std::uint64_t step, double time);
  /// @brief `{"entries": [...], "position", "live", "first"}` (at most the newest @p limit entries).
  void write(JsonWriter& out, std::size_t limit) const;

 private:
  // The entries' bytes live in blocks, filled in order and dropped in order; a block whose last entry
  // is dropped is kept as the spare for the next one. So an entry is one copy into memory that is mapped
  // and was used before, not an allocation: a malloc of a few KiB a step makes glibc consolidate its
  // fast bins every step, and a bundle kept in the recording's own buffer (the buffer moved, not copied)
  // made every step record into fresh memory (benchmarks/README.md, "On the two-robot work cell").
  struct Block {
    std::unique_ptr<std::uint8_t[]> data;
    std::size_t capacity = 0;
    std::size_t used = 0;
    std::size_t entries = 0;  // entries whose bytes are here
  };
  struct Entry {
    std::uint64_t step;
    double time;
    std::size_t ops;
    const std::uint8_t* bytes;
    std::size_t size;
    Block* block;  // std::deque keeps it valid while blocks come and go at either end
  };
  void heard(const Transaction& t);
  void add(const Transaction& bundle);
  void drop_back();
  void drop_front();
  void retire(Block&& block);
  [[nodiscard]] Transaction bundle(const Entry& e) const;
  SimState& state_;
  std::size_t max_bytes_;
  std::size_t block_bytes_;
  std::size_t bytes_ = 0;
  std::deque<Entry> entries_;
  std::deque<Block> blocks_;
  Block spare_;
  Transaction scratch_;  // the last bundle cut; its buffer goes back to the state for the next one
  std::uint64_t first_ = 0;
  std::uint64_t position_ = 0;
  std::uint64_t step_ = 0;  // what cut() was told, for the entries heard meanwhile
  double time_ = 0.0;
  bool seeking_ = false;    // bundles of our own seeks are not entries
  bool cutting_ = false;    // our own cut: kept from take_recording(), not from the signal
  bool started_recording_ = false;
  Connection bundles_;
};

}  // namespace vsd::web::detail
