#include "vsd/core/detail/id_map.hpp"

#include <gtest/gtest.h>

#include <random>
#include <unordered_map>

namespace {

vsd::SimStateInstance* fake(std::uint64_t n) { return reinterpret_cast<vsd::SimStateInstance*>(n * 16 + 16); }

TEST(IdMap, AgreesWithAStandardMapUnderRandomInsertsAndErases) {
  vsd::detail::IdMap map;
  std::unordered_map<vsd::Id, vsd::SimStateInstance*> model;
  std::mt19937_64 rng(7);
  for (int step = 0; step < 200000; ++step) {
    // Dense ids (as an Environment hands out) plus some far apart ones (other sites).
    const vsd::Id id = (rng() % 4 == 0) ? (rng() % 8 + 1) << 48 | rng() % 64 : rng() % 3000 + 1;
    if (rng() % 3 == 0) {
      map.erase(id);
      model.erase(id);
    } else {
      const bool fresh = model.emplace(id, fake(id)).second;
      EXPECT_EQ(map.insert(id, fake(id)), fresh);
    }
    if (step % 997 == 0) {
      ASSERT_EQ(map.size(), model.size());
      for (const auto& [k, v] : model) ASSERT_EQ(map.find(k), v) << "id " << k;
    }
  }
  std::size_t seen = 0;
  map.for_each([&](vsd::Id k, vsd::SimStateInstance* v) {
    ++seen;
    EXPECT_EQ(model.at(k), v);
  });
  EXPECT_EQ(seen, model.size());
  EXPECT_EQ(map.find(999999999), nullptr);
}

// Dense ids fill one long run of the table, each at its home slot. Erasing them in the order they were
// made used to scan the rest of the run each time (a deep tree deleted from the top: quadratic).
TEST(IdMap, ErasingDenseIdsInOrderIsQuick) {
  constexpr vsd::Id n = 300'000;
  vsd::detail::IdMap map;
  for (vsd::Id id = 1; id <= n; ++id) map.insert(id, fake(id));
  for (vsd::Id id = 1; id <= n / 2; ++id) map.erase(id);
  ASSERT_EQ(map.size(), n - n / 2);
  for (vsd::Id id = n; id > n / 2; id -= 7) ASSERT_EQ(map.find(id), fake(id));
  EXPECT_EQ(map.find(n / 2), nullptr);
  // Still right where entries are displaced: a second site's ids landing in the same run.
  for (vsd::Id id = 1; id <= 1000; ++id) map.insert(vsd::Id{3} << 48 | id, fake(id));
  for (vsd::Id id = n / 2 + 1; id <= n; ++id) map.erase(id);
  for (vsd::Id id = 1; id <= 1000; ++id) ASSERT_EQ(map.find(vsd::Id{3} << 48 | id), fake(id)) << id;
  EXPECT_EQ(map.size(), 1000u);
}

// Ids only grow. A long-lived dense run (a tree of 65,536 nodes) and a churn of new instances: once the
// new ids wrap around the table they land on the run, and every insert walked it (an attach at depth
// 65,536 took 18 us). The table switches to a mixing hash instead.
TEST(IdMap, ChurnPastALongLivedDenseRunStaysQuick) {
  constexpr vsd::Id kept = 65'536;
  vsd::detail::IdMap map;
  for (vsd::Id id = 1; id <= kept; ++id) map.insert(id, fake(id));
  for (vsd::Id id = kept + 1; id <= kept + 400'000; ++id) {
    vsd::SimStateInstance** slot = map.try_insert(id);
    ASSERT_NE(slot, nullptr) << id;
    *slot = fake(id);
    ASSERT_EQ(map.find(id), fake(id)) << id;
    map.erase(id);
  }
  EXPECT_EQ(map.size(), kept);
  for (vsd::Id id = 1; id <= kept; ++id) ASSERT_EQ(map.find(id), fake(id)) << id;
  // The mixed table still agrees with a standard map.
  std::unordered_map<vsd::Id, vsd::SimStateInstance*> model;
  map.for_each([&](vsd::Id k, vsd::SimStateInstance* v) { model.emplace(k, v); });
  std::mt19937_64 rng(3);
  for (int step = 0; step < 100'000; ++step) {
    const vsd::Id id = rng() % (4 * kept) + 1;
    if (rng() % 2 == 0) {
      map.erase(id);
      model.erase(id);
    } else {
      EXPECT_EQ(map.insert(id, fake(id)), model.emplace(id, fake(id)).second);
    }
  }
  ASSERT_EQ(map.size(), model.size());
  for (const auto& [k, v] : model) ASSERT_EQ(map.find(k), v) << k;
}

TEST(IdMap, EraseOfAMissingIdChangesNothing) {
  vsd::detail::IdMap map;
  map.erase(5);
  EXPECT_TRUE(map.insert(5, fake(5)));
  EXPECT_FALSE(map.insert(5, fake(6)));
  map.erase(6);
  EXPECT_EQ(map.size(), 1u);
  EXPECT_EQ(map.find(5), fake(5));
  map.clear();
  EXPECT_EQ(map.find(5), nullptr);
}

TEST(IdMap, TryInsertChecksAndInsertsInOneProbe) {
  vsd::detail::IdMap map;
  vsd::SimStateInstance** slot = map.try_insert(42);
  ASSERT_NE(slot, nullptr);
  EXPECT_EQ(*slot, nullptr) << "a new entry starts empty";
  *slot = fake(42);
  EXPECT_EQ(map.find(42), fake(42));
  EXPECT_EQ(map.try_insert(42), nullptr) << "a present id is refused";
  EXPECT_EQ(map.find(42), fake(42)) << "and left as it was";
  EXPECT_EQ(map.size(), 1u);
}

TEST(IdMap, ReserveKeepsEntriesAndStopsGrowth) {
  vsd::detail::IdMap map;
  for (vsd::Id id = 1; id <= 100; ++id) map.insert(id, fake(id));
  map.reserve(100000);
  EXPECT_EQ(map.size(), 100u);
  for (vsd::Id id = 1; id <= 100; ++id) ASSERT_EQ(map.find(id), fake(id));
  // Entries up to the reserved count land without a rehash: the table (and so a slot) stays put.
  vsd::SimStateInstance** first = map.try_insert(1000);
  ASSERT_NE(first, nullptr);
  *first = fake(1000);
  for (vsd::Id id = 101; id < 50000; ++id) map.insert(id, fake(id));
  EXPECT_EQ(*first, fake(1000));
  map.reserve(10);  // never shrinks
  EXPECT_EQ(map.find(49999), fake(49999));
}

}  // namespace
