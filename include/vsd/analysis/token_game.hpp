/** @file
 *  @brief vsd::analysis::TokenGame: plays a PtNet, one firing at a time, with an incrementally kept
 *  set of enabled transitions.
 *
 *  The enabled transitions are kept as a bitset with counts per word and per block of words (for picking
 *  the index-th one), updated after each firing only where the firing can change something:
 *  each transition keeps the number of its arcs that the marking does not satisfy (input arcs short of
 *  tokens, inhibitor arcs with too many), and a firing adjusts the counts of the transitions reading the
 *  places it changes:
 *  - on a net that its P-semiflows prove safe (every place holds at most one token in every reachable
 *    marking: Dekker, Peterson, SharedMemory, ...) the marking is a bitset and the counts are bit-sliced,
 *    so one precomputed word operation per slice adjusts the counts of 64 transitions;
 *  - on other nets the counts are integers, adjusted arc by arc.
 *  The game owns a copy of what it needs from the net, so the PtNet may go away after construction.
 */
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "vsd/analysis/pt_net.hpp"

namespace vsd::analysis {

/// @brief The token game on a PtNet (see the file comment).
class TokenGame {
 public:
  /// @brief Starts in the initial marking of @p net.
  explicit TokenGame(const PtNet& net);
  ~TokenGame();
  TokenGame(TokenGame&&) noexcept;
  TokenGame& operator=(TokenGame&&) noexcept;

  /// @brief Back to the initial marking.
  void reset();
  /// @brief The current marking (one entry per place; a copy).
  std::vector<std::uint32_t> marking() const;
  /// @brief Whether the game plays on a bitset marking (the net is structurally safe; see the file comment).
  bool safe() const noexcept;
  /// @brief The transitions enabled now, in increasing index order (the order play() indexes; a copy).
  std::vector<std::uint32_t> enabled() const;
  /// @brief How many transitions are enabled now.
  std::uint32_t enabled_count() const noexcept { return count_; }
  /// @brief Whether @p t is enabled now (false for an index out of range).
  bool is_enabled(std::uint32_t t) const noexcept;
  /// @brief Fires @p t. @throws vsd::Error when @p t is not enabled or a place would exceed 2^32-1 tokens.
  void fire(std::uint32_t t);
  /// @brief Plays @p steps firings, each of an enabled transition picked by a pseudo-random generator seeded
  /// with @p seed; a dead marking starts the game again from the initial marking.
  ///
  /// The choice is uniform among the enabled transitions and deterministic: each step draws the next value
  /// r of xorshift64* (state seeded as seed * 0x9E3779B97F4A7C15 + 1), maps its high 32 bits onto [0, n)
  /// for the n = enabled_count() transitions enabled (index = (r >> 32) * n >> 32, uniform to within
  /// n / 2^32) and fires enabled()[index], the index-th enabled transition in index order. So the same net,
  /// starting marking, seed and steps give the same firings on every platform, whichever marking
  /// representation (safe() or not) the game uses.
  /// @return the number of firings done (== @p steps unless the initial marking is dead: then 0).
  std::uint64_t play(std::uint64_t steps, std::uint64_t seed);

 private:
  static constexpr std::uint32_t kGeneral = UINT32_MAX;  // play_loop: the general representation
  void add(std::uint32_t t);
  void remove(std::uint32_t t);
  std::uint32_t nth_enabled(std::uint32_t index) const noexcept;
  template <std::uint32_t S>
  void fire_safe(std::uint32_t t);
  void fire_general(std::uint32_t t);
  template <std::uint32_t W>
  std::uint64_t play_loop(std::uint64_t steps, std::uint64_t seed);

  struct Net;
  std::unique_ptr<Net> net_;
  std::vector<std::uint32_t> marking_;       // general nets: tokens per place
  std::vector<std::uint64_t> bits_;          // safe nets: one bit per place
  std::vector<std::uint64_t> counts_;        // safe nets: unsatisfied-arc counts, bit-sliced (see the .cpp)
  std::vector<std::uint64_t> enabled_bits_;  // one bit per transition
  std::vector<std::uint8_t> word_count_;     // enabled transitions per word of enabled_bits_
  std::vector<std::uint32_t> block_count_;   // ... per block of 8 words
  std::uint32_t count_ = 0;                  // ... in all
  std::vector<std::uint32_t> unsatisfied_;  // general nets, per transition: arcs the marking does not satisfy
};

}  // namespace vsd::analysis
