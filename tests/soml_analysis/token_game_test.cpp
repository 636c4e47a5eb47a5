#include "vsd/soml/analysis/token_game.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "nets.hpp"
#include "vsd/core/error.hpp"
#include "vsd/soml/analysis/pnml.hpp"

namespace an = vsd::soml::analysis;

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
    const an::PtNet net = an::read_pnml_file(std::string(VSD_SOML_TEST_DATA_DIR) + "/" + model + ".pnml").net;
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

TEST(TokenGame, PlayCountsFiringsAndRestartsAtDeadMarkings) {
  const an::PtNet net =
      an::read_pnml_file(std::string(VSD_SOML_TEST_DATA_DIR) + "/ResAllocation-PT-R002C002.pnml").net;
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
