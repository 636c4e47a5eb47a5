#include "vsd/soml/analysis/token_game.hpp"

#include "compiled_net.hpp"
#include "vsd/core/error.hpp"

namespace vsd::soml::analysis {

// Besides the compiled net, for every place the arcs that test it: firing then adjusts, per changed place,
// the count of unsatisfied arcs of each reading transition, instead of testing those transitions again.
struct TokenGame::Net {
  struct Test {
    std::uint32_t transition;
    std::uint32_t weight;
    bool inhibitor;
  };
  detail::Compiled c;
  std::vector<std::uint32_t> initial;
  std::vector<std::string> transition_ids;
  std::vector<std::uint32_t> tests_begin;  // per place, into tests
  std::vector<Test> tests;
  explicit Net(const PtNet& net) : c(net), initial(net.initial_marking()) {
    for (const auto& t : net.transitions()) transition_ids.push_back(t.id);
    std::vector<std::vector<Test>> by_place(net.place_count());
    for (std::uint32_t t = 0; t < net.transition_count(); ++t) {
      for (const auto& a : net.transitions()[t].inputs) by_place[a.place].push_back({t, a.weight, false});
      for (const auto& a : net.transitions()[t].inhibitors) by_place[a.place].push_back({t, a.weight, true});
    }
    for (const auto& v : by_place) {
      tests_begin.push_back(static_cast<std::uint32_t>(tests.size()));
      tests.insert(tests.end(), v.begin(), v.end());
    }
    tests_begin.push_back(static_cast<std::uint32_t>(tests.size()));
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
  unsatisfied_.assign(net_->c.transitions, 0);
  for (std::uint32_t p = 0; p < marking_.size(); ++p)
    for (std::uint32_t i = net_->tests_begin[p]; i < net_->tests_begin[p + 1]; ++i) {
      const auto& test = net_->tests[i];
      if ((marking_[p] >= test.weight) == test.inhibitor) ++unsatisfied_[test.transition];
    }
  for (std::uint32_t t = 0; t < net_->c.transitions; ++t)
    if (unsatisfied_[t] == 0) add(t);
}

void TokenGame::add(std::uint32_t t) {
  position_[t] = static_cast<std::uint32_t>(enabled_.size());
  enabled_.push_back(t);
}

void TokenGame::remove(std::uint32_t t) {
  const std::uint32_t last = enabled_.back();
  enabled_[position_[t]] = last;
  position_[last] = position_[t];
  enabled_.pop_back();
  position_[t] = kAbsent;
}

void TokenGame::fire_unchecked(std::uint32_t t) {
  const detail::Compiled& c = net_->c;
  for (std::uint32_t i = c.delta_begin[t]; i < c.delta_begin[t + 1]; ++i) {
    const auto& d = c.delta[i];
    const std::uint32_t before = marking_[d.place];
    const std::int64_t v = static_cast<std::int64_t>(before) + d.delta;
    if (v > static_cast<std::int64_t>(UINT32_MAX))
      vsd::detail::throw_error("TokenGame::fire: a place would exceed 2^32-1 tokens firing '" +
                               net_->transition_ids[t] + "'");
    const auto after = static_cast<std::uint32_t>(v);
    marking_[d.place] = after;
    for (std::uint32_t k = net_->tests_begin[d.place]; k < net_->tests_begin[d.place + 1]; ++k) {
      const auto& test = net_->tests[k];
      // An input arc is satisfied at >= weight, an inhibitor arc below it.
      const bool was = (before >= test.weight) != test.inhibitor;
      const bool is = (after >= test.weight) != test.inhibitor;
      if (was == is) continue;
      std::uint32_t& u = unsatisfied_[test.transition];
      if (is) {
        if (--u == 0) add(test.transition);
      } else {
        if (u++ == 0) remove(test.transition);
      }
    }
  }
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
