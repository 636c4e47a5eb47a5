// The executor's dependency table (src/soml/dep_table.hpp): watcher lists stay in transition order, a key
// whose last watcher left stays dormant and is reused, and dormant keys do not pile up.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "../../src/soml/dep_table.hpp"
#include "vsd/core/node.hpp"

namespace vsd::soml {
namespace {

const MetaProperty* prop() { return &Node::vsd_prop_children(); }

std::vector<std::uint32_t> watchers(const DepTable& t, DepKey k) {
  const DepTable::Watchers* w = t.find(k);
  return w == nullptr ? std::vector<std::uint32_t>{} : *w;
}

TEST(DepTable, WatchersStayInTransitionOrder) {
  DepTable t;
  const DepKey k{7, prop()};
  EXPECT_TRUE(t.add(k, 5));
  EXPECT_FALSE(t.add(k, 2));
  EXPECT_FALSE(t.add(k, 9));
  EXPECT_FALSE(t.add(k, 3));
  EXPECT_EQ(watchers(t, k), (std::vector<std::uint32_t>{2, 3, 5, 9}));
  t.remove(k, 3);
  EXPECT_EQ(watchers(t, k), (std::vector<std::uint32_t>{2, 5, 9}));
  EXPECT_EQ(t.size(), 1u);
}

TEST(DepTable, EmptiedKeyStaysDormantAndIsReused) {
  DepTable t;
  const DepKey a{1, prop()};
  const DepKey b{2, prop()};
  t.add(a, 0);
  t.add(b, 1);
  t.remove(a, 0);
  EXPECT_EQ(t.size(), 1u) << "a dormant key is no watched property";
  EXPECT_EQ(t.used_slots(), 2u);
  ASSERT_NE(t.find(a), nullptr);
  EXPECT_TRUE(t.find(a)->empty());
  const std::uint32_t* storage = t.find(a)->data();
  EXPECT_TRUE(t.add(a, 4)) << "a dormant key counts as new for its first watcher again";
  EXPECT_EQ(t.find(a)->data(), storage) << "the dormant key's list is reused, not allocated again";
  EXPECT_EQ(t.size(), 2u);
  t.remove(a, 4);
  t.remove(a, 4);  // not a watcher any more: nothing
  t.remove(DepKey{3, prop()}, 0);  // absent: nothing
  EXPECT_EQ(t.size(), 1u);
  std::size_t seen = 0;
  t.for_each([&](const DepKey& k, const DepTable::Watchers&) {
    EXPECT_EQ(k, b);
    ++seen;
  });
  EXPECT_EQ(seen, 1u) << "for_each skips dormant keys";
}

TEST(DepTable, DormantKeysDoNotPileUp) {
  // Keys of instances that come and go (ids never reused): the table stays at a bounded size.
  DepTable t;
  t.add(DepKey{1, prop()}, 0);
  std::size_t largest = 0;
  for (std::uint64_t id = 2; id < 100000; ++id) {
    t.add(DepKey{id, prop()}, 1);
    t.remove(DepKey{id, prop()}, 1);
    largest = std::max(largest, t.capacity());
    ASSERT_EQ(t.size(), 1u);
  }
  EXPECT_LE(largest, 64u);
  EXPECT_EQ(watchers(t, DepKey{1, prop()}), (std::vector<std::uint32_t>{0}));
  // Many live keys grow it; all of them are found after the rehashes.
  for (std::uint64_t id = 1000000; id < 1001000; ++id) t.add(DepKey{id, prop()}, static_cast<std::uint32_t>(id % 7));
  EXPECT_EQ(t.size(), 1001u);
  for (std::uint64_t id = 1000000; id < 1001000; ++id)
    ASSERT_EQ(watchers(t, DepKey{id, prop()}), (std::vector<std::uint32_t>{static_cast<std::uint32_t>(id % 7)}));
}

TEST(DepTable, UpdateAllDropsEmptiedKeys) {
  DepTable t;
  t.update_all([](const DepKey&, DepTable::Watchers&) {});  // empty: nothing
  t.add(DepKey{1, prop()}, 3);
  t.add(DepKey{2, prop()}, 4);
  t.add(DepKey{3, prop()}, 5);
  t.remove(DepKey{3, prop()}, 5);
  t.update_all([](const DepKey& k, DepTable::Watchers& w) {
    if (k.id == 1) w.clear();
  });
  EXPECT_EQ(t.size(), 1u);
  EXPECT_EQ(t.used_slots(), 1u);
  EXPECT_EQ(t.find(DepKey{1, prop()}), nullptr);
  EXPECT_EQ(t.find(DepKey{3, prop()}), nullptr);
  EXPECT_EQ(watchers(t, DepKey{2, prop()}), (std::vector<std::uint32_t>{4}));
}

}  // namespace
}  // namespace vsd::soml
