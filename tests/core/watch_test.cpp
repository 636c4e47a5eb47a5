// Watch: class × property subscriptions, de-duplicated queues, at-once callbacks, and what stays fast.
#include "vsd/core/watch.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "test_classes.hpp"

using testing::ElementsAre;
using testing::HasSubstr;
using vsd_test::TGripper;
using vsd_test::TRobot;
using vsd_test::TTool;

namespace {

std::vector<vsd::Id> ids_of(vsd::Watch& w) {
  std::vector<vsd::Id> out;
  w.drain([&](const vsd::Watch::Report& r) { out.push_back(r.id); });
  return out;
}

class WatchTest : public testing::Test {
 protected:
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
};

TEST_F(WatchTest, ReportsEachChangedInstanceOnceUntilDrained) {
  auto& a = state.create<TRobot>();
  auto& b = state.create<TRobot>();
  vsd::Watch w(state);
  w.properties(TRobot::static_meta(), {&TRobot::vsd_prop_speed()});
  for (int i = 0; i < 100; ++i) a.set_speed(i);
  b.set_speed(5.0);
  a.set_speed(7.0);
  EXPECT_EQ(w.size(), 2u);
  EXPECT_THAT(ids_of(w), ElementsAre(a.id(), b.id()));
  EXPECT_TRUE(w.empty());
  b.set_speed(6.0);
  EXPECT_THAT(ids_of(w), ElementsAre(b.id()));
}

TEST_F(WatchTest, FiltersByPropertyPointerAndCoversSubclasses) {
  auto& r = state.create<TRobot>();
  auto& g = state.create<TGripper>();
  vsd::Watch w(state);
  w.properties(TRobot::static_meta(), {&TRobot::vsd_prop_axes()});
  r.set_speed(3.0);      // not watched
  g.set_closed(true);    // a property of the subclass only: not watched
  EXPECT_TRUE(w.empty());
  g.set_axes(7);  // inherited, watched through the subclass
  r.set_axes(5);
  EXPECT_THAT(ids_of(w), ElementsAre(g.id(), r.id()));
  // The generic paths report the same.
  TRobot::vsd_prop_axes().set(r, 9);
  r.set("axes", vsd::Value(10));
  EXPECT_THAT(ids_of(w), ElementsAre(r.id()));
}

TEST_F(WatchTest, PerPropertyGranularityKeepsTheProperty) {
  auto& r = state.create<TRobot>();
  vsd::Watch w(state, vsd::Watch::Granularity::per_property);
  w.all_properties(TRobot::static_meta());
  r.set_speed(2.0);
  r.set_axes(3);
  r.set_speed(4.0);
  const auto reports = w.take();
  ASSERT_EQ(reports.size(), 2u);
  EXPECT_EQ(reports[0].property, &TRobot::vsd_prop_speed());
  EXPECT_EQ(reports[1].property, &TRobot::vsd_prop_axes());
  EXPECT_EQ(reports[0].changes, vsd::Changes::property);
}

TEST_F(WatchTest, CreationDeletionAndParentsAreReported) {
  vsd::Watch w(state);
  w.created(TRobot::static_meta()).deleted(TRobot::static_meta()).reparented(TRobot::static_meta());
  auto& r = state.create<TRobot>();
  auto& t = state.create<TTool>();  // another class: not reported
  state.database().add_child(r);
  auto reports = w.take();
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].id, r.id());
  EXPECT_EQ(reports[0].changes, vsd::Changes::created | vsd::Changes::parent);
  const vsd::Id id = r.id();
  state.database().remove_child(r);  // the last composite reference: r is deleted
  reports = w.take();
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_TRUE(reports[0].changes.has(vsd::Changes::deleted));
  EXPECT_TRUE(reports[0].changes.has(vsd::Changes::parent));
  EXPECT_EQ(state.find(id), nullptr) << "a deleted instance is gone when its report is drained";
  state.destroy(t);
  EXPECT_TRUE(w.empty());
}

TEST_F(WatchTest, AtOnceCallbackSeesTheInstanceWhole) {
  auto& r = state.create<TRobot>();
  r.set_name("r");
  std::vector<std::string> seen;
  vsd::Watch w(state, [&](vsd::SimStateInstance& i, const vsd::MetaProperty* p, vsd::Changes what) {
    auto& robot = static_cast<TRobot&>(i);
    seen.push_back(robot.name() + (p != nullptr ? "." + p->name() : std::string()) +
                   (what.has(vsd::Changes::deleted) ? " deleted" : ""));
  });
  w.properties(TRobot::static_meta(), {&TRobot::vsd_prop_speed()}).deleted(TRobot::static_meta());
  r.set_speed(2.0);
  EXPECT_TRUE(w.empty()) << "an at-once watch queues nothing";
  state.destroy(r);
  EXPECT_THAT(seen, ElementsAre("r.speed", "r deleted"));
}

TEST_F(WatchTest, OnPendingFiresWhenTheFirstReportArrives) {
  auto& r = state.create<TRobot>();
  vsd::Watch w(state);
  w.properties(TRobot::static_meta(), {&TRobot::vsd_prop_speed()});
  int pending = 0;
  w.on_pending([&] { ++pending; });
  r.set_speed(1.5);
  r.set_speed(2.5);
  EXPECT_EQ(pending, 1);
  w.clear();
  r.set_speed(3.5);
  EXPECT_EQ(pending, 2);
}

TEST_F(WatchTest, ChangesMadeWhileDrainingWaitForTheNextDrain) {
  auto& r = state.create<TRobot>();
  vsd::Watch w(state);
  w.properties(TRobot::static_meta(), {&TRobot::vsd_prop_speed()});
  r.set_speed(1.5);
  int calls = 0;
  w.drain([&](const vsd::Watch::Report&) {
    ++calls;
    r.set_speed(2.0);
  });
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(w.size(), 1u);
}

TEST_F(WatchTest, ManyInstancesAreDeduplicated) {
  std::vector<TRobot*> robots;
  for (int i = 0; i < 5000; ++i) robots.push_back(&state.create<TRobot>());
  vsd::Watch w(state);
  w.properties(TRobot::static_meta(), {&TRobot::vsd_prop_speed()});
  for (int round = 0; round < 3; ++round)
    for (TRobot* r : robots) r->set_speed(round + 10.0);
  auto ids = ids_of(w);
  EXPECT_EQ(ids.size(), robots.size());
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(std::unique(ids.begin(), ids.end()), ids.end());
  robots[7]->set_speed(1.0);  // after a burst the queue works as before
  EXPECT_THAT(ids_of(w), ElementsAre(robots[7]->id()));
}

TEST_F(WatchTest, RefusesPropertiesOfOtherClassesAndNonNodeParents) {
  vsd::Watch w(state);
  EXPECT_THAT([&] { w.properties(TRobot::static_meta(), {&TTool::vsd_prop_length()}); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("has no property 'length'")));
  EXPECT_THAT([&] { w.properties(TRobot::static_meta(), {&vsd_test::TGripper::vsd_prop_closed()}); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("has no property 'closed'")));
  EXPECT_THAT([&] { w.reparented(vsd::NamedModelInstance::static_meta()); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("neither a Node nor an Extension")));
}

TEST_F(WatchTest, ExtensionsAttachedAndDetachedAreReparented) {
  auto& r = state.create<TRobot>();
  auto& other = state.create<TRobot>();
  auto& sensor = state.create<vsd_test::TSensor>();
  vsd::Watch w(state);
  w.reparented(vsd_test::TSensor::static_meta());
  r.add_extension(sensor);
  EXPECT_FALSE(r.observed()) << "the owner's class is not watched";
  EXPECT_THAT(ids_of(w), ElementsAre(sensor.id()));
  other.add_extension(sensor);  // moved: attached to the other, detached from the first
  EXPECT_THAT(ids_of(w), ElementsAre(sensor.id()));
  const vsd::Id sensor_id = sensor.id();
  other.remove_extension(sensor);  // a composite part: detaching it releases it
  EXPECT_THAT(ids_of(w), ElementsAre(sensor_id));
}

// The point of per-class subscriptions: an instance of a class nobody watches keeps its fast setter.
TEST_F(WatchTest, InstancesOfUnwatchedClassesStayUnobserved) {
  auto& tool = state.create<TTool>();
  auto& robot = state.create<TRobot>();
  vsd::Watch w(state);
  w.properties(TRobot::static_meta(), {&TRobot::vsd_prop_speed()});
  EXPECT_FALSE(tool.observed());
  EXPECT_TRUE(robot.observed());
  auto& later_tool = state.create<TTool>();
  auto& later_robot = state.create<TGripper>();
  EXPECT_FALSE(later_tool.observed());
  EXPECT_TRUE(later_robot.observed());
  tool.set_length(0.5);
  EXPECT_FALSE(tool.observed());
}

TEST_F(WatchTest, ADestroyedWatchReleasesItsClassesLazily) {
  auto& robot = state.create<TRobot>();
  {
    vsd::Watch w(state);
    w.properties(TRobot::static_meta(), {&TRobot::vsd_prop_speed()});
    EXPECT_TRUE(robot.observed());
  }
  robot.set_speed(3.0);  // finds nobody: back to the fast path
  EXPECT_FALSE(robot.observed());
  EXPECT_FALSE(state.create<TRobot>().observed());
}

TEST_F(WatchTest, AWatchMayBeDestroyedInsideItsOwnCallback) {
  auto& r = state.create<TRobot>();
  auto* w = new vsd::Watch(state, [&](vsd::SimStateInstance&, const vsd::MetaProperty*, vsd::Changes) {});
  int calls = 0;
  vsd::Watch killer(state, [&](vsd::SimStateInstance&, const vsd::MetaProperty*, vsd::Changes) {
    ++calls;
    delete w;
    w = nullptr;
  });
  killer.properties(TRobot::static_meta(), {&TRobot::vsd_prop_speed()});
  w->properties(TRobot::static_meta(), {&TRobot::vsd_prop_speed()});
  r.set_speed(2.0);
  r.set_speed(3.0);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(w, nullptr);
}

TEST_F(WatchTest, RecordingDoesNotMakeWatchesHearMore) {
  auto& tool = state.create<TTool>();
  auto& robot = state.create<TRobot>();
  vsd::Watch w(state);
  w.properties(TRobot::static_meta(), {&TRobot::vsd_prop_speed()});
  state.start_recording();
  tool.set_length(2.0);
  robot.set_axes(4);
  EXPECT_TRUE(w.empty());
  robot.set_speed(9.0);
  EXPECT_EQ(w.size(), 1u);
  EXPECT_EQ(state.stop_recording().size(), 3u);
}

}  // namespace
