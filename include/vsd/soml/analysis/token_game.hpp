/** @file
 *  @brief vsd::soml::analysis::TokenGame: plays a PtNet, one firing at a time, with an incrementally kept
 *  set of enabled transitions.
 *
 *  Each transition keeps the number of its arcs that the marking does not satisfy (input arcs short of
 *  tokens, inhibitor arcs with too many); a firing adjusts these counts only for the arcs on the places
 *  it changes, so it never tests a whole transition again. The game owns a copy of what it needs from the
 * net, so the PtNet may go away after construction.
 */
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "vsd/soml/analysis/pt_net.hpp"

namespace vsd::soml::analysis {

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
  /// @brief The current marking (one entry per place).
  const std::vector<std::uint32_t>& marking() const noexcept { return marking_; }
  /// @brief The transitions enabled now, in no particular order.
  const std::vector<std::uint32_t>& enabled() const noexcept { return enabled_; }
  /// @brief Whether @p t is enabled now (false for an index out of range).
  bool is_enabled(std::uint32_t t) const noexcept { return t < position_.size() && position_[t] != kAbsent; }
  /// @brief Fires @p t. @throws vsd::Error when @p t is not enabled or a place would exceed 2^32-1 tokens.
  void fire(std::uint32_t t);
  /// @brief Plays @p steps firings, each of an enabled transition picked by a pseudo-random generator seeded
  /// with @p seed; a dead marking starts the game again from the initial marking.
  /// @return the number of firings done (== @p steps unless the initial marking is dead: then 0).
  std::uint64_t play(std::uint64_t steps, std::uint64_t seed);

 private:
  static constexpr std::uint32_t kAbsent = UINT32_MAX;
  void add(std::uint32_t t);
  void remove(std::uint32_t t);
  void fire_unchecked(std::uint32_t t);

  struct Net;
  std::unique_ptr<Net> net_;
  std::vector<std::uint32_t> marking_;
  std::vector<std::uint32_t> enabled_;
  std::vector<std::uint32_t> position_;     // index in enabled_, or kAbsent
  std::vector<std::uint32_t> unsatisfied_;  // per transition: arcs the marking does not satisfy
};

}  // namespace vsd::soml::analysis
