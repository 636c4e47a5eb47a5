#include "vsd/analysis/token_game.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "nets.hpp"
#include "vsd/core/error.hpp"
#include "vsd/analysis/pnml.hpp"

namespace an = vsd::analysis;

namespace {

std::vector<std::uint32_t> sorted(std::vector<std::uint32_t> v) {
  std::sort(v.begin(), v.end());
  return v;
}

std::vector<std::uint32_t> brute_enabled(const an::PtNet& net, const std::vector<std::uint32_t>& m) {
  std::vector<std::uint32_t> e;
  for (std::uint32_t t = 0; t < net.transition_count(); ++t)
    if (net.enabled(t, m)) e.push_back(t);
  return e;
}

TEST(TokenGame, IncrementalEnabledSetMatchesBruteForceOnTheMccNets) {
  for (const char* model : {"Dekker-PT-010", "FMS-PT-00002", "Philosophers-PT-000005", "TokenRing-PT-005",
                            "Eratosthenes-PT-010"}) {
    SCOPED_TRACE(model);
    const an::PtNet net = an::read_pnml_file(std::string(VSD_ANALYSIS_TEST_DATA_DIR) + "/" + model + ".pnml").net;
    an::TokenGame game(net);
    auto m = net.initial_marking();
    for (int step = 0; step < 300; ++step) {
      ASSERT_EQ(sorted(game.enabled()), brute_enabled(net, game.marking()));
      if (game.enabled().empty()) break;
      const std::uint32_t t = game.enabled()[static_cast<std::size_t>(step) % game.enabled().size()];
      game.fire(t);
      net.fire(t, m);
      ASSERT_EQ(game.marking(), m);
    }
  }
}

const char* const kAllModels[] = {
    "ResAllocation-PT-R002C002", "Eratosthenes-PT-010", "TokenRing-PT-005", "Philosophers-PT-000005",
    "SharedMemory-PT-000005",    "FMS-PT-00002",        "Dekker-PT-010",    "Peterson-PT-2"};

an::PtNet mcc(const char* model) {
  return an::read_pnml_file(std::string(VSD_ANALYSIS_TEST_DATA_DIR) + "/" + model + ".pnml").net;
}

// Plays the game one firing at a time through play(1, seed) and checks every firing against the net's own
// firing rule: the transition fired was enabled in the marking before (brute force over all transitions),
// the marking after is the net's, and the enabled set after is the brute-force one.
void check_random_firings(const an::PtNet& net, int firings, std::uint64_t seed) {
  an::TokenGame game(net);
  auto m = game.marking();
  ASSERT_EQ(m, net.initial_marking());
  for (int step = 0; step < firings; ++step) {
    const auto now = brute_enabled(net, m);
    ASSERT_EQ(game.enabled(), now) << "step " << step;  // enabled() is in index order
    ASSERT_EQ(game.enabled_count(), now.size());
    for (std::uint32_t t = 0; t < net.transition_count(); ++t)
      ASSERT_EQ(game.is_enabled(t), std::binary_search(now.begin(), now.end(), t));
    // play() restarts a dead game from the initial marking before it fires.
    const auto from = now.empty() ? net.initial_marking() : m;
    const auto candidates = now.empty() ? brute_enabled(net, from) : now;
    if (candidates.empty()) {
      EXPECT_EQ(game.play(1, seed), 0u);
      return;
    }
    ASSERT_EQ(game.play(1, seed + static_cast<std::uint64_t>(step)), 1u);
    const auto after = game.marking();
    // The firing must be one of an enabled transition: some enabled t turns `from` into `after`.
    bool found = false;
    for (const std::uint32_t t : candidates) {
      auto next = from;
      net.fire(t, next);
      found = found || next == after;
    }
    ASSERT_TRUE(found) << "step " << step << ": no enabled transition leads to the game's marking";
    m = after;
  }
}

TEST(TokenGame, PlayFiresOnlyEnabledTransitionsOnAllMccNets) {
  for (const char* model : kAllModels) {
    SCOPED_TRACE(model);
    check_random_firings(mcc(model), 3000, 11);
  }
}

TEST(TokenGame, SafeNetsUseTheBitsetMarking) {
  EXPECT_TRUE(an::TokenGame(mcc("Dekker-PT-010")).safe());
  EXPECT_TRUE(an::TokenGame(mcc("SharedMemory-PT-000005")).safe());
  EXPECT_FALSE(an::TokenGame(mcc("FMS-PT-00002")).safe());   // places hold up to 2 tokens
  EXPECT_FALSE(an::TokenGame(an::test::ring(7, 4)).safe());  // 4 tokens on the ring
  an::PtNet unbounded("u");
  unbounded.add_place("p", {}, 1);
  const auto t = unbounded.add_transition("t");
  unbounded.add_input(t, 0);
  unbounded.add_output(t, 0, 2);
  EXPECT_FALSE(an::TokenGame(unbounded).safe());
}

// A safe net with inhibitor arcs (weight 1 and 2), an input arc of weight 2 (never enabled), a read arc,
// a transition with many inputs (count slices beyond one word of bits) and more than 64 transitions, so
// the bitset spans words.
an::PtNet safe_mix() {
  an::PtNet net("mix");
  constexpr std::uint32_t kCells = 40;
  // kCells cells, each on or off: on_i + off_i = 1.
  for (std::uint32_t i = 0; i < kCells; ++i) {
    net.add_place("on" + std::to_string(i), {}, i % 3 == 0 ? 1 : 0);
    net.add_place("off" + std::to_string(i), {}, i % 3 == 0 ? 0 : 1);
  }
  auto on = [](std::uint32_t i) { return 2 * i; };
  auto off = [](std::uint32_t i) { return 2 * i + 1; };
  for (std::uint32_t i = 0; i < kCells; ++i) {
    const std::uint32_t j = (i + 1) % kCells;
    // set_i: off_i -> on_i, only while cell j is off (inhibitor on on_j).
    auto t = net.add_transition("set" + std::to_string(i));
    net.add_input(t, off(i));
    net.add_output(t, on(i));
    net.add_inhibitor(t, on(j));
    // clear_i: on_i -> off_i, reading on_j (read arc), inhibitor of weight 2 (always satisfied).
    t = net.add_transition("clear" + std::to_string(i));
    net.add_input(t, on(i));
    net.add_output(t, off(i));
    net.add_input(t, on(j));
    net.add_output(t, on(j));
    net.add_inhibitor(t, off(j), 2);
  }
  // all: needs every cell on (40 inputs: 6 count slices), turns cell 0 off.
  auto t = net.add_transition("all");
  for (std::uint32_t i = 0; i < kCells; ++i) {
    net.add_input(t, on(i));
    if (i != 0) net.add_output(t, on(i));
  }
  net.add_output(t, off(0));
  // flipflop: off_0 and on_1 -> on_0 and off_1 (two places change, both directions).
  t = net.add_transition("flipflop");
  net.add_input(t, off(0));
  net.add_input(t, on(1));
  net.add_output(t, on(0));
  net.add_output(t, off(1));
  // never: needs 2 tokens on a place that holds at most one.
  t = net.add_transition("never");
  net.add_input(t, on(3), 2);
  net.add_output(t, off(3), 2);
  return net;
}

TEST(TokenGame, SafeNetWithInhibitorsWeightsAndManyTransitionsMatchesBruteForce) {
  const an::PtNet net = safe_mix();
  ASSERT_GT(net.transition_count(), 64u);
  an::TokenGame game(net);
  ASSERT_TRUE(game.safe());
  EXPECT_FALSE(game.is_enabled(static_cast<std::uint32_t>(net.transition_count() - 1)));  // never
  check_random_firings(net, 20000, 5);
}

TEST(TokenGame, GeneralNetWithInhibitorsMatchesBruteForce) {
  // The ring of 3 tokens with an inhibitor: moving on from place i needs fewer than 2 tokens on i+1.
  an::PtNet net("ring-inh");
  constexpr std::uint32_t kN = 70;
  for (std::uint32_t i = 0; i < kN; ++i) net.add_place("p" + std::to_string(i), {}, i < 3 ? 1 : 0);
  for (std::uint32_t i = 0; i < kN; ++i) {
    const auto t = net.add_transition("t" + std::to_string(i));
    net.add_input(t, i);
    net.add_output(t, (i + 1) % kN);
    net.add_inhibitor(t, (i + 1) % kN, 2);
  }
  an::TokenGame game(net);
  EXPECT_FALSE(game.safe());
  check_random_firings(net, 20000, 9);
}

TEST(TokenGame, PlayIsDeterministicAndPicksUniformly) {
  // Same seed, same firings; and on a net whose initial marking enables k independent transitions
  // that each lead straight back, every one of them is picked about equally often.
  const an::PtNet dekker = mcc("Dekker-PT-010");
  an::TokenGame a(dekker), b(dekker);
  a.play(5000, 3);
  b.play(5000, 3);
  EXPECT_EQ(a.marking(), b.marking());
  EXPECT_EQ(a.enabled(), b.enabled());

  an::PtNet star("star");
  constexpr std::uint32_t kArms = 5;
  star.add_place("hub", {}, 1);
  for (std::uint32_t i = 0; i < kArms; ++i) star.add_place("arm" + std::to_string(i));
  for (std::uint32_t i = 0; i < kArms; ++i) {
    auto t = star.add_transition("out" + std::to_string(i));
    star.add_input(t, 0);
    star.add_output(t, 1 + i);
    t = star.add_transition("back" + std::to_string(i));
    star.add_input(t, 1 + i);
    star.add_output(t, 0);
  }
  an::TokenGame game(star);
  ASSERT_TRUE(game.safe());
  std::vector<int> hits(kArms, 0);
  constexpr int kRounds = 20000;
  for (int i = 0; i < kRounds; ++i) {
    ASSERT_EQ(game.play(1, 1000 + static_cast<std::uint64_t>(i)), 1u);
    const auto m = game.marking();
    for (std::uint32_t k = 0; k < kArms; ++k)
      if (m[1 + k] == 1) ++hits[k];
    ASSERT_EQ(game.play(1, 7), 1u);  // the only enabled transition: back to the hub
  }
  for (std::uint32_t k = 0; k < kArms; ++k) {
    SCOPED_TRACE(k);
    EXPECT_NEAR(hits[k], kRounds / kArms, kRounds / kArms / 10);  // within 10 %: ~7 standard deviations
  }
}

TEST(TokenGame, PlayCountsFiringsAndRestartsAtDeadMarkings) {
  const an::PtNet net =
      an::read_pnml_file(std::string(VSD_ANALYSIS_TEST_DATA_DIR) + "/ResAllocation-PT-R002C002.pnml").net;
  an::TokenGame game(net);
  EXPECT_EQ(game.play(10000, 42), 10000u);  // the net deadlocks quickly: many restarts
  EXPECT_EQ(sorted(game.enabled()), brute_enabled(net, game.marking()));
  // Tokens are conserved on the ring however long it plays.
  an::TokenGame ring(an::test::ring(7, 4));
  EXPECT_EQ(ring.play(100000, 7), 100000u);
  std::uint32_t sum = 0;
  for (auto v : ring.marking()) sum += v;
  EXPECT_EQ(sum, 4u);
}

TEST(TokenGame, DeadInitialMarkingPlaysNothing) {
  an::PtNet net("dead");
  net.add_place("p");
  const auto t = net.add_transition("t");
  net.add_input(t, 0);
  an::TokenGame game(net);
  EXPECT_EQ(game.play(5, 1), 0u);
  EXPECT_FALSE(game.is_enabled(t));
  EXPECT_FALSE(game.is_enabled(99));
  EXPECT_THROW(game.fire(t), vsd::Error);
  EXPECT_THROW(game.fire(99), vsd::Error);
}

}  // namespace
