#include "vsd/soml/analysis/token_game.hpp"

#include "compiled_net.hpp"
#include "vsd/core/error.hpp"

namespace vsd::soml::analysis {

struct TokenGame::Net {
  detail::Compiled c;
  std::vector<std::uint32_t> initial;
  std::vector<std::string> transition_ids;
  explicit Net(const PtNet& net) : c(net), initial(net.initial_marking()) {
    for (const auto& t : net.transitions()) transition_ids.push_back(t.id);
  }
};

TokenGame::TokenGame(const PtNet& net) : net_(std::make_unique<Net>(net)) { reset(); }
TokenGame::~TokenGame() = default;
TokenGame::TokenGame(TokenGame&&) noexcept = default;
TokenGame& TokenGame::operator=(TokenGame&&) noexcept = default;

void TokenGame::reset() {
  marking_ = net_->initial;
  enabled_.clear();
  position_.assign(net_->c.transitions, kAbsent);
  for (std::uint32_t t = 0; t < net_->c.transitions; ++t) update(t);
}

void TokenGame::update(std::uint32_t t) {
  const bool on = net_->c.enabled(t, marking_.data());
  if (on && position_[t] == kAbsent) {
    position_[t] = static_cast<std::uint32_t>(enabled_.size());
    enabled_.push_back(t);
  } else if (!on && position_[t] != kAbsent) {
    const std::uint32_t last = enabled_.back();
    enabled_[position_[t]] = last;
    position_[last] = position_[t];
    enabled_.pop_back();
    position_[t] = kAbsent;
  }
}

void TokenGame::fire_unchecked(std::uint32_t t) {
  const detail::Compiled& c = net_->c;
  for (std::uint32_t i = c.delta_begin[t]; i < c.delta_begin[t + 1]; ++i) {
    const auto& d = c.delta[i];
    const std::int64_t v = static_cast<std::int64_t>(marking_[d.place]) + d.delta;
    if (v > static_cast<std::int64_t>(UINT32_MAX))
      vsd::detail::throw_error("TokenGame::fire: a place would exceed 2^32-1 tokens firing '" +
                               net_->transition_ids[t] + "'");
    marking_[d.place] = static_cast<std::uint32_t>(v);
  }
  for (std::uint32_t i = c.aff_begin[t]; i < c.aff_begin[t + 1]; ++i) update(c.aff[i]);
}

void TokenGame::fire(std::uint32_t t) {
  if (!is_enabled(t))
    vsd::detail::throw_error("TokenGame::fire: transition " +
                             (t < net_->transition_ids.size() ? "'" + net_->transition_ids[t] + "'"
                                                              : "index " + std::to_string(t)) +
                             " is not enabled");
  fire_unchecked(t);
}

std::uint64_t TokenGame::play(std::uint64_t steps, std::uint64_t seed) {
  std::uint64_t x = seed * 0x9E3779B97F4A7C15ull + 1;  // xorshift64*: cheap and good enough to pick
  std::uint64_t done = 0;
  while (done < steps) {
    if (enabled_.empty()) {
      reset();
      if (enabled_.empty()) return done;  // the initial marking is dead
    }
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    const std::uint64_t r = x * 0x2545F4914F6CDD1Dull;
    // Multiply-shift maps r onto [0, n) without a division.
    const auto pick = static_cast<std::uint32_t>(((r >> 32) * enabled_.size()) >> 32);
    fire_unchecked(enabled_[pick]);
    ++done;
  }
  return done;
}

}  // namespace vsd::soml::analysis
