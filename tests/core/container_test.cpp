#include "vsd/core/container.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_classes.hpp"

using testing::ElementsAre;
using vsd_test::TRobot;

namespace {

struct ViewTest : testing::Test {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();

  TRobot& robot(const std::string& name, double speed) {
    auto& r = state.create<TRobot>();
    r.set_name(name);
    r.set_speed(speed);
    return r;
  }
  static std::vector<std::string> names(const vsd::View& v) {
    std::vector<std::string> out;
    for (vsd::Node* n : v) out.push_back(n->name());
    return out;
  }
};

TEST_F(ViewTest, FiltersAndOrdersTheNodes) {
  robot("slow", 1);
  robot("fast", 9);
  state.create<vsd::Node>().set_name("plain");
  vsd::View fastest_first(
      state, [](const vsd::Node& n) { return n.is_a<TRobot>(); },
      [](const vsd::Node& a, const vsd::Node& b) {
        return static_cast<const TRobot&>(a).speed() > static_cast<const TRobot&>(b).speed();
      });
  EXPECT_THAT(names(fastest_first), ElementsAre("fast", "slow"));
  EXPECT_EQ(fastest_first.size(), 2u);
}

TEST_F(ViewTest, FollowsCreationDeletionAndPropertyChanges) {
  vsd::View robots(
      state, [](const vsd::Node& n) { return n.is_a<TRobot>(); },
      [](const vsd::Node& a, const vsd::Node& b) {
        return static_cast<const TRobot&>(a).speed() < static_cast<const TRobot&>(b).speed();
      });
  std::vector<std::string> log;
  auto c1 = robots.on_added().connect([&](vsd::Node& n) { log.push_back("+" + std::to_string(n.id())); });
  auto c2 = robots.on_removed().connect([&](vsd::Node& n) { log.push_back("-" + std::to_string(n.id())); });
  auto& a = robot("a", 5);
  auto& b = robot("b", 1);
  EXPECT_THAT(names(robots), ElementsAre("b", "a"));
  b.set_speed(10);  // re-ordered
  EXPECT_THAT(names(robots), ElementsAre("a", "b"));
  const std::string ia = std::to_string(a.id()), ib = std::to_string(b.id());
  state.destroy(a);
  EXPECT_THAT(names(robots), ElementsAre("b"));
  EXPECT_THAT(log, ElementsAre("+" + ia, "+" + ib, "-" + ia));
}

TEST_F(ViewTest, MembershipFollowsTheFilter) {
  vsd::View named_x(state, [](const vsd::Node& n) { return !n.name().empty() && n.name()[0] == 'x'; });
  auto& n = state.create<vsd::Node>();
  EXPECT_FALSE(named_x.contains(n));
  n.set_name("x1");
  EXPECT_TRUE(named_x.contains(n));
  n.set_name("y1");
  EXPECT_FALSE(named_x.contains(n));
  int visited = 0;
  named_x.for_each([&](vsd::Node&) { ++visited; });
  EXPECT_EQ(visited, 0);
}

TEST_F(ViewTest, ANodeThatLeavesAndComesBackTakesItsCreationPlace) {
  vsd::View named(state, [](const vsd::Node& n) { return !n.name().empty(); });
  auto& a = robot("a", 1);
  auto& b = robot("b", 1);
  auto& c = robot("c", 1);
  EXPECT_THAT(names(named), ElementsAre("a", "b", "c"));
  a.set_name("");
  EXPECT_THAT(names(named), ElementsAre("b", "c"));
  a.set_name("a2");
  EXPECT_THAT(names(named), ElementsAre("a2", "b", "c")) << "creation order, not the order of entry";
  b.set_name("");
  c.set_name("c2");
  b.set_name("b2");
  EXPECT_THAT(names(named), ElementsAre("a2", "b2", "c2"));
  state.destroy(b);
  EXPECT_THAT(names(named), ElementsAre("a2", "c2"));
  EXPECT_TRUE(named.contains(a));
  EXPECT_FALSE(named.contains(state.database()));
}

TEST_F(ViewTest, ATypedViewFiltersOrdersAndIteratesItsClass) {
  robot("slow", 1);
  robot("fast", 9);
  state.create<vsd::Node>().set_name("plain");
  vsd::TypedView<TRobot> moving(
      state, [](const TRobot& r) { return r.speed() > 0; },
      [](const TRobot& a, const TRobot& b) { return a.speed() > b.speed(); });
  EXPECT_EQ(&moving.viewed_class(), &TRobot::static_meta());
  std::vector<double> speeds;
  for (TRobot* r : moving) speeds.push_back(r->speed());
  EXPECT_THAT(speeds, ElementsAre(9.0, 1.0));
  auto& mid = robot("mid", 5);
  EXPECT_EQ(moving[1], &mid);
  mid.home();  // speed 0: filtered out
  EXPECT_EQ(moving.size(), 2u);
  EXPECT_FALSE(moving.contains(mid));
}

TEST_F(ViewTest, AViewOfAClassIgnoresOtherInstances) {
  vsd::TypedView<TRobot> robots(state);
  int changes = 0;
  auto c = robots.on_added().connect([&](vsd::Node&) { ++changes; });
  auto& n = state.create<vsd::Node>();
  n.set_name("x");
  EXPECT_EQ(changes, 0);
  EXPECT_EQ(robots.size(), 0u);
  robot("r", 1);
  EXPECT_EQ(changes, 1);
  EXPECT_THAT([&] { vsd::View bad(state, vsd::Extension::static_meta()); },
              testing::ThrowsMessage<vsd::Error>(testing::HasSubstr("is not a Node")));
}

TEST_F(ViewTest, WithoutAnOrderKeepsCreationOrder) {
  auto& a = robot("a", 3);
  vsd::View all(state);
  auto& b = robot("b", 1);
  ASSERT_EQ(all.size(), 3u);  // the Database, a, b
  EXPECT_EQ(all.nodes()[1], &a);
  EXPECT_EQ(all.nodes()[2], &b);
}

}  // namespace
