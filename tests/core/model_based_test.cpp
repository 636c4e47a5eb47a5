// Randomised model-based test: thousands of random operations on a recording SimState, replayed on a
// replica that must stay equal, with every reference count consistent and undo restoring the start.
#include <gtest/gtest.h>

#include <random>

#include "random_model.hpp"
#include "test_classes.hpp"

using vsd_test::TRobot;
using vsd_test::TTool;

namespace {

class ModelBased : public testing::TestWithParam<std::uint32_t> {};

TEST_P(ModelBased, ReplicaStaysEqualAndCountsStayConsistent) {
  vsd::Environment env;
  vsd::SimState& source = env.main_state();
  vsd::SimState& replica = env.create_state("replica");
  vsd::SimState& initial = env.create_state("initial");
  vsd_test::RandomModel model(source, GetParam());
  for (int i = 0; i < 200; ++i) model.step();  // some history before recording starts
  replica.copy_from(source);
  initial.copy_from(source);
  source.start_recording();
  std::vector<vsd::Transaction> bundles;
  for (int batch = 0; batch < 40; ++batch) {
    for (int i = 0; i < 100; ++i) model.step();
    bundles.push_back(source.take_recording());
    // Half of the bundles travel through bytes, as they would between machines.
    replica.apply(batch % 2 == 0 ? bundles.back() : vsd::Transaction::from_bytes(bundles.back().bytes()));
    std::string diff;
    ASSERT_TRUE(source.equals(replica, &diff)) << "batch " << batch << ": " << diff;
    ASSERT_EQ(vsd_test::check_reference_counts(source), "") << "batch " << batch;
    ASSERT_EQ(vsd_test::check_reference_counts(replica), "") << "batch " << batch;
  }
  // Undo everything, newest first: the replica returns to the state recording started from.
  for (auto it = bundles.rbegin(); it != bundles.rend(); ++it) replica.apply(it->inverted());
  std::string diff;
  EXPECT_TRUE(replica.equals(initial, &diff)) << diff;
  EXPECT_EQ(vsd_test::check_reference_counts(replica), "");
  EXPECT_LT(model.rejected(), 4000 / 2) << "most random operations should be legal";
}

INSTANTIATE_TEST_SUITE_P(Seeds, ModelBased, testing::Values(1u, 2u, 3u, 20261121u));

}  // namespace
