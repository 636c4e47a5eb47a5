// The inspector's timeline on its own: its entries are exactly the bundles the state handed out, kept in
// blocks that are filled and dropped in order; scrubbing back and forth across blocks restores every
// entry's state, the oldest entries go first at the budget, a bundle larger than a block is kept whole,
// and a change made while scrubbed back forks the history.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "vsd/core.hpp"
#include "web/timeline.hpp"

namespace {

using vsd::web::detail::Timeline;

struct TimelineTest : testing::Test {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
  std::vector<vsd::Node*> nodes;
  std::vector<std::vector<std::uint8_t>> heard;  // every bundle the state handed out, in order
  vsd::Connection listening;

  TimelineTest() {
    for (int i = 0; i < 8; ++i) {
      auto& n = state.create<vsd::Node>();
      state.database().add_child(n);
      nodes.push_back(&n);
    }
  }
  void listen() {
    listening = state.on_bundle().connect([this](const vsd::Transaction& t) { heard.push_back(t.bytes()); });
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const vsd::Node* n : nodes) out.push_back(n->name());
    return out;
  }
  // One step's changes: about @p bytes of names over a few nodes, never a name a node has already.
  void change(std::mt19937& rng, std::size_t bytes, int step) {
    const std::size_t per = bytes / 3 + 1;
    for (int k = 0; k < 3; ++k) {
      vsd::Node& n = *nodes[rng() % nodes.size()];
      n.set_name(std::to_string(step) + "." + std::to_string(k) + std::string(per, static_cast<char>('a' + rng() % 26)));
    }
  }
};

TEST_F(TimelineTest, ScrubbingAcrossBlocksRestoresEveryEntry) {
  Timeline timeline(state, std::size_t{2} << 20);  // blocks of 128 KiB
  listen();
  std::mt19937 rng(7);
  std::vector<std::vector<std::string>> after;  // the names after entry i
  for (int step = 0; step < 300; ++step) {
    change(rng, 500 + rng() % 2500, step);
    timeline.cut(static_cast<std::uint64_t>(step), step * 0.01);
    after.push_back(names());
  }
  ASSERT_EQ(timeline.first(), 0U);
  ASSERT_EQ(timeline.end(), 300U);
  ASSERT_EQ(heard.size(), 300U);
  std::size_t total = 0;
  for (std::uint64_t i = 0; i < timeline.end(); ++i) {
    EXPECT_EQ(timeline.entry(i).bytes(), heard[i]) << "entry " << i;
    total += heard[i].size();
  }
  EXPECT_EQ(timeline.bytes(), total);
  EXPECT_GT(total, std::size_t{5} * (128 << 10));  // the entries span several blocks

  for (const std::uint64_t to : {299U, 150U, 1U, 298U, 64U, 65U, 200U, 300U}) {
    timeline.seek(to, 300, 3.0);
    ASSERT_EQ(timeline.position(), to);
    EXPECT_EQ(names(), after[to - 1]) << "seek to " << to;
  }
  EXPECT_TRUE(timeline.live());
}

TEST_F(TimelineTest, TheOldestEntriesGoAtTheBudgetAndTheRestStayExact) {
  const std::size_t budget = std::size_t{256} << 10;
  Timeline timeline(state, budget);
  listen();
  std::mt19937 rng(11);
  std::vector<std::vector<std::string>> after;
  for (int step = 0; step < 3000; ++step) {
    change(rng, 300 + rng() % 1500, step);
    timeline.cut(static_cast<std::uint64_t>(step), step * 0.01);
    after.push_back(names());
    ASSERT_LE(timeline.bytes(), budget);
  }
  ASSERT_GT(timeline.first(), 0U);
  EXPECT_EQ(timeline.end(), 3000U);
  EXPECT_THROW((void)timeline.entry(timeline.first() - 1), vsd::Error);
  EXPECT_THROW((void)timeline.entry(timeline.end()), vsd::Error);
  for (std::uint64_t i = timeline.first(); i < timeline.end(); ++i)
    ASSERT_EQ(timeline.entry(i).bytes(), heard[i]) << "entry " << i;
  // Back to the oldest entry kept, and forward again.
  const std::uint64_t oldest = timeline.first();
  timeline.seek(oldest, 3000, 30.0);
  EXPECT_EQ(names(), after[oldest - 1]);
  EXPECT_THROW(timeline.seek(timeline.first() - 1, 3000, 30.0), vsd::Error);
  timeline.seek(timeline.end(), 3000, 30.0);
  EXPECT_EQ(names(), after.back());
}

TEST_F(TimelineTest, ABundleLargerThanABlockIsKeptWholeAndTheNewestAlwaysStays) {
  Timeline timeline(state, std::size_t{1} << 20);
  listen();
  nodes[0]->set_name("small");
  timeline.cut(1, 0.01);
  nodes[1]->set_name(std::string(300'000, 'x'));  // one bundle of some 900 KB: old and new names
  nodes[1]->set_name(std::string(300'000, 'y'));
  timeline.cut(2, 0.02);
  nodes[2]->set_name("after");
  timeline.cut(3, 0.03);
  ASSERT_EQ(timeline.end(), 3U);
  EXPECT_EQ(timeline.entry(1).bytes(), heard[1]);
  timeline.seek(1, 3, 0.03);
  EXPECT_EQ(nodes[1]->name(), "");
  EXPECT_EQ(nodes[2]->name(), "");
  timeline.seek(3, 3, 0.03);
  EXPECT_EQ(nodes[1]->name(), std::string(300'000, 'y'));
  EXPECT_EQ(nodes[2]->name(), "after");

  // A budget smaller than one bundle keeps the newest entry alone.
  Timeline tiny(state, 1000);
  nodes[3]->set_name(std::string(5000, 'z'));
  timeline.cut(4, 0.04);  // the first timeline cuts; both hear the bundle
  EXPECT_EQ(tiny.size(), 1U);
  EXPECT_GT(tiny.bytes(), 1000U);
  nodes[3]->set_name("short");
  timeline.cut(5, 0.05);
  EXPECT_EQ(tiny.size(), 1U);
  EXPECT_EQ(tiny.first(), 1U);
}

TEST_F(TimelineTest, SmallBundlesOfEveryLengthStayExactAndWithinTheBudget) {
  // Entries of every length follow each other in a block: each must come back byte for byte, and many
  // tiny bundles (edits) stay within the budget.
  const std::size_t budget = std::size_t{64} << 10;
  Timeline timeline(state, budget);
  listen();
  for (int step = 0; step < 4000; ++step) {
    nodes[static_cast<std::size_t>(step) % nodes.size()]->set_name(std::string(static_cast<std::size_t>(step % 37), 'n'));
    timeline.cut(static_cast<std::uint64_t>(step), 0.0);
    ASSERT_LE(timeline.bytes(), budget);
  }
  ASSERT_GT(timeline.first(), 0U);  // the budget dropped the oldest
  for (std::uint64_t i = timeline.first(); i < timeline.end(); ++i)
    ASSERT_EQ(timeline.entry(i).bytes(), heard[i]) << "entry " << i;
}

TEST_F(TimelineTest, AChangeWhileScrubbedBackForksAndLaterEntriesFitAfterIt) {
  Timeline timeline(state, std::size_t{1} << 20);
  listen();
  std::mt19937 rng(3);
  for (int step = 0; step < 120; ++step) {  // several blocks
    change(rng, 1500, step);
    timeline.cut(static_cast<std::uint64_t>(step), 0.0);
  }
  const std::vector<std::string> at40 = [&] {
    timeline.seek(40, 120, 0.0);
    return names();
  }();
  nodes[5]->set_name("the fork");
  timeline.cut(121, 0.0);
  EXPECT_EQ(timeline.end(), 41U);
  EXPECT_TRUE(timeline.live());
  EXPECT_EQ(timeline.entry(40).bytes(), heard.back());
  std::vector<std::vector<std::string>> after;
  for (int step = 0; step < 100; ++step) {
    change(rng, 2000, 1000 + step);
    timeline.cut(static_cast<std::uint64_t>(122 + step), 0.0);
    after.push_back(names());
  }
  EXPECT_EQ(timeline.end(), 141U);
  timeline.seek(40, 300, 0.0);
  EXPECT_EQ(names(), at40);
  timeline.seek(41, 300, 0.0);
  EXPECT_EQ(nodes[5]->name(), "the fork");
  timeline.seek(141, 300, 0.0);
  EXPECT_EQ(names(), after.back());
}

}  // namespace
