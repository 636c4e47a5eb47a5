// The two-robot cell's analytic throughput bound (examples/workcell/two_robots/cycle_bound.hpp).
#include "cycle_bound.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "vsd/core/error.hpp"

namespace {

using vsd_workcell::CycleParameters;

CycleParameters cell() {
  CycleParameters p;
  p.arrival_gap = 4.0;
  p.direct_a = 10.0;
  p.direct_b = 9.0;
  p.give_a = 12.0;
  p.take_b = 8.0;
  p.zone_a = 4.0;
  p.zone_b = 5.0;
  p.share_direct_a = 0.5;
  p.share_handover = 0.1;
  p.share_direct_b = 0.4;
  return p;
}

TEST(CycleBound, TheMostLoadedResourceSetsTheCycle) {
  const auto b = vsd_workcell::cycle_bound(cell());
  EXPECT_DOUBLE_EQ(b.load_a, 0.5 * 10 + 0.1 * 12);  // 6.2 s of A per part
  EXPECT_DOUBLE_EQ(b.load_b, 0.4 * 9 + 0.1 * 8);    // 4.4 s of B
  EXPECT_DOUBLE_EQ(b.load_zone, 0.1 * (4 + 5));     // 0.9 s of the zone
  EXPECT_DOUBLE_EQ(b.cycle, 6.2);
  EXPECT_EQ(b.limit, "robot A");
  EXPECT_DOUBLE_EQ(b.parts_per_hour, 3600 / 6.2);
}

TEST(CycleBound, EachResourceCanBeTheLimit) {
  CycleParameters p = cell();
  p.share_direct_a = 0.1;
  p.share_direct_b = 0.8;
  EXPECT_EQ(vsd_workcell::cycle_bound(p).limit, "robot B");  // 0.8 * 9 + 0.8 > 1 * 10 + 1.2 ... 8.0 > 2.2
  p = cell();
  p.direct_a = p.direct_b = p.give_a = p.take_b = 1.0;
  const auto fast = vsd_workcell::cycle_bound(p);
  EXPECT_EQ(fast.limit, "the arrivals");
  EXPECT_DOUBLE_EQ(fast.parts_per_hour, 900);
  p.zone_a = p.zone_b = 30.0;  // 0.1 * 60 = 6 s per part
  EXPECT_EQ(vsd_workcell::cycle_bound(p).limit, "the shared zone");
  // One robot: everything on A's direct route.
  p = cell();
  p.share_direct_a = 1;
  p.share_handover = p.share_direct_b = 0;
  const auto one = vsd_workcell::cycle_bound(p);
  EXPECT_DOUBLE_EQ(one.cycle, 10.0);
  EXPECT_DOUBLE_EQ(one.parts_per_hour, 360);
}

TEST(CycleBound, RefusesNonsense) {
  CycleParameters p = cell();
  p.give_a = -1;
  EXPECT_THROW(vsd_workcell::cycle_bound(p), vsd::Error);
  p = cell();
  p.direct_b = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(vsd_workcell::cycle_bound(p), vsd::Error);
  p = cell();
  p.arrival_gap = 0;
  EXPECT_THROW(vsd_workcell::cycle_bound(p), vsd::Error);
  p = cell();
  p.share_direct_b = 0.5;  // 1.1 in all
  try {
    vsd_workcell::cycle_bound(p);
    ADD_FAILURE() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_STREQ(e.what(), "cycle_bound: the routes' shares do not add up to 1");
  }
}

TEST(CycleBound, AMoveTakesWholeSteps) {
  EXPECT_DOUBLE_EQ(vsd_workcell::move_cycle(1.0, 0.01), 1.0);
  EXPECT_NEAR(vsd_workcell::move_cycle(1.003, 0.01), 1.01, 1e-12);
  EXPECT_NEAR(vsd_workcell::move_cycle(0.12, 0.05), 0.15, 1e-12);
  EXPECT_DOUBLE_EQ(vsd_workcell::move_cycle(0.0, 0.05), 0.05);  // done in the first step
  EXPECT_THROW(vsd_workcell::move_cycle(1.0, 0.0), vsd::Error);
  EXPECT_THROW(vsd_workcell::move_cycle(-1.0, 0.01), vsd::Error);
}

}  // namespace
