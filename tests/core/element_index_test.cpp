#include "vsd/core/element_index.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_classes.hpp"

using vsd_test::TGripper;
using vsd_test::TRobot;

namespace {

struct ElementIndexTest : testing::Test {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
  vsd::ElementIndex& index = state.index();
};

TEST_F(ElementIndexTest, ListsInstancesOfExactlyAType) {
  auto& r1 = state.create<TRobot>();
  auto& r2 = state.create<TRobot>();
  auto& g = state.create<TGripper>();
  state.create<vsd::Node>();
  EXPECT_THAT(index.of<TRobot>(), testing::UnorderedElementsAre(&r1, &r2));
  EXPECT_THAT(index.of<TGripper>(), testing::ElementsAre(&g));
  EXPECT_EQ(index.count(TRobot::static_meta(), false), 2u);
}

TEST_F(ElementIndexTest, IncludesSubtypesOnRequest) {
  auto& r = state.create<TRobot>();
  auto& g = state.create<TGripper>();
  auto& n = state.create<vsd::Node>();
  EXPECT_THAT(index.all<TRobot>(), testing::UnorderedElementsAre(&r, &g));
  EXPECT_EQ(index.count(TRobot::static_meta()), 2u);
  // Every node, the Database included.
  EXPECT_EQ(index.count(vsd::Node::static_meta()), 4u);
  EXPECT_THAT(index.all<vsd::Node>(), testing::Contains(&n));
}

TEST_F(ElementIndexTest, StaysCurrentOnDelete) {
  std::vector<TRobot*> robots;
  for (int i = 0; i < 10; ++i) robots.push_back(&state.create<TRobot>());
  state.destroy(*robots[3]);
  state.destroy(*robots[0]);
  state.destroy(*robots[9]);
  std::vector<TRobot*> expected{robots[1], robots[2], robots[4], robots[5], robots[6], robots[7], robots[8]};
  EXPECT_THAT(index.of<TRobot>(), testing::UnorderedElementsAreArray(expected));
  for (TRobot* r : expected) r->set_speed(2.0);  // still valid instances
}

TEST_F(ElementIndexTest, RunTimeSubclassesAreFound) {
  const vsd::MetaInstance& cls = vsd::ClassBuilder("TIndexedRuntimeRobot", TRobot::static_meta())
                                     .property<double>("reach", 1.5)
                                     .define();
  auto& x = state.create(cls);
  EXPECT_THAT(index.exact(cls), testing::ElementsAre(&x));
  EXPECT_THAT(index.all<TRobot>(), testing::Contains(static_cast<TRobot*>(&x)));
  state.destroy(x);
  EXPECT_TRUE(index.exact(cls).empty());
  vsd::Registry::global().undefine(cls);
}

TEST_F(ElementIndexTest, SignalsPerTypeWithAndWithoutSubtypes) {
  std::vector<std::string> log;
  auto c1 = index.on_created(TRobot::static_meta(), false).connect([&](vsd::SimStateInstance& i) {
    log.push_back("exact+" + i.meta().name());
  });
  auto c2 = index.on_created(TRobot::static_meta(), true).connect([&](vsd::SimStateInstance& i) {
    log.push_back("tree+" + i.meta().name());
  });
  auto c3 = index.on_deleted(vsd::Node::static_meta(), true).connect([&](vsd::SimStateInstance& i) {
    log.push_back("node-" + i.meta().name());
  });
  auto& r = state.create<TRobot>();
  state.create<TGripper>();
  state.create<vsd::Extension>();
  state.destroy(r);
  EXPECT_THAT(log, testing::ElementsAre("exact+TRobot", "tree+TRobot", "tree+TGripper", "node-TRobot"));
}

}  // namespace
