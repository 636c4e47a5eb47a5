#include "vsd/core/sim_state.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_classes.hpp"

using testing::ElementsAre;
using testing::HasSubstr;
using vsd_test::TGripper;
using vsd_test::TRobot;

namespace {

struct SimStateTest : testing::Test {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
};

TEST_F(SimStateTest, CreatesByClassAndByName) {
  auto& r = state.create<TRobot>();
  auto& n = state.create("Node");
  auto& g = state.create(TGripper::static_meta());
  EXPECT_EQ(&r.meta(), &TRobot::static_meta());
  EXPECT_EQ(&n.meta(), &vsd::Node::static_meta());
  EXPECT_TRUE(g.is_a<TRobot>());
  EXPECT_EQ(&r.state(), &state);
  EXPECT_EQ(state.size(), 4u);  // and the Database
}

TEST_F(SimStateTest, RejectsUnknownAbstractAndForeignClasses) {
  EXPECT_THAT([&] { state.create("NoSuchClass"); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("NoSuchClass")));
  EXPECT_THAT([&] { state.create(vsd::Instance::static_meta()); }, testing::Throws<vsd::Error>());
  EXPECT_THAT([&] { state.create(vsd::Environment::static_meta()); }, testing::Throws<vsd::Error>());
  EXPECT_THAT([&] { state.create<vsd::Database>(); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("Database")));
}

TEST_F(SimStateTest, IdsAreUniqueStableAndFindable) {
  auto& a = state.create<vsd::Node>();
  auto& b = state.create<vsd::Node>();
  EXPECT_NE(a.id(), b.id());
  EXPECT_NE(a.id(), vsd::null_id);
  EXPECT_EQ(state.find(a.id()), &a);
  EXPECT_EQ(state.find<TRobot>(a.id()), nullptr);
  EXPECT_EQ(state.find(999999), nullptr);
  auto all = state.instances();
  ASSERT_EQ(all.size(), 3u);
  EXPECT_TRUE(std::is_sorted(all.begin(), all.end(), [](auto* x, auto* y) { return x->id() < y->id(); }));
}

TEST_F(SimStateTest, DestroyingAnInstanceOfAnotherStateIsAnError) {
  auto& other = env.create_state("other");
  auto& n = other.create<vsd::Node>();
  EXPECT_THAT([&] { state.destroy(n); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("belongs to SimState")));
}

TEST_F(SimStateTest, SignalsCreationAndDeletion) {
  std::vector<std::string> log;
  auto c1 =
      state.on_created().connect([&](vsd::SimStateInstance& i) { log.push_back("+" + i.meta().name()); });
  auto c2 = state.on_deleted().connect([&](vsd::SimStateInstance& i) {
    // Deletion is announced while the instance is still whole.
    log.push_back("-" + i.meta().name() + ":" + static_cast<vsd::Node&>(i).name());
  });
  auto& r = state.create<TRobot>();
  r.set_name("r");
  state.destroy(r);
  EXPECT_THAT(log, ElementsAre("+TRobot", "-TRobot:r"));
}

TEST_F(SimStateTest, PropertyChangesSignalPerInstanceTypeAndState) {
  auto& r = state.create<TRobot>();
  auto& g = state.create<TGripper>();
  auto& n = state.create<vsd::Node>();
  int own = 0, exact = 0, tree = 0, all = 0;
  auto c1 = r.on_changed().connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++own; });
  auto c2 = state.on_property_changed(TRobot::static_meta(), false)
                .connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++exact; });
  auto c3 = state.on_property_changed(TRobot::static_meta(), true)
                .connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++tree; });
  auto c4 =
      state.on_property_changed().connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++all; });
  r.set_speed(2.0);
  g.set_speed(3.0);
  n.set_name("x");
  EXPECT_EQ(own, 1);
  EXPECT_EQ(exact, 1);
  EXPECT_EQ(tree, 2);
  EXPECT_EQ(all, 3);
}

TEST_F(SimStateTest, SettingAnEqualValueSignalsNothing) {
  auto& r = state.create<TRobot>();
  int n = 0;
  auto c = r.on_changed().connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++n; });
  r.set_speed(r.speed());
  r.set("speed", vsd::Value(1.0));
  EXPECT_EQ(n, 0);
  r.set_speed(1.5);
  EXPECT_EQ(n, 1);
}

TEST_F(SimStateTest, ListenersSeeTheNewValueAndTheProperty) {
  auto& r = state.create<TRobot>();
  std::string seen;
  auto c = state.on_property_changed().connect([&](vsd::SimStateInstance& i, const vsd::MetaProperty& p) {
    seen = p.name() + "=" + p.get_value(i).to_text();
  });
  r.set_joints({1.0, 2.5});
  EXPECT_EQ(seen, "joints=[1, 2.5]");
}

TEST_F(SimStateTest, DisconnectingStopsNotificationAndTheFastPathReturns) {
  auto& r = state.create<TRobot>();
  int n = 0;
  {
    auto c = r.on_changed().connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++n; });
    r.set_speed(5.0);
  }
  r.set_speed(6.0);
  r.set_speed(7.0);
  EXPECT_EQ(n, 1);
}

// Setters leave the slow path lazily when nobody listens; a listener connected later through a signal
// reference kept from before must switch it on again.
TEST_F(SimStateTest, ListenersConnectedThroughAKeptSignalAreCalled) {
  auto& r = state.create<TRobot>();
  auto& other = state.create<TRobot>();
  auto own = r.on_changed();
  auto all = state.on_property_changed();
  auto robots = state.on_property_changed(TRobot::static_meta());
  int first = 0;
  {
    auto c = own.connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++first; });
    r.set_speed(2.0);
  }
  r.set_speed(3.0);  // nobody listens: the instance goes back to the fast path
  other.set_speed(3.0);
  int own_calls = 0, all_calls = 0, robot_calls = 0;
  auto c1 = own.connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++own_calls; });
  auto c2 = all.connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++all_calls; });
  auto c3 = robots.connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++robot_calls; });
  r.set_speed(4.0);
  other.set_speed(4.0);
  EXPECT_EQ(first, 1);
  EXPECT_EQ(own_calls, 1);
  EXPECT_EQ(all_calls, 2);
  EXPECT_EQ(robot_calls, 2);
}

TEST_F(SimStateTest, AListenerMayDeleteTheInstanceItIsToldAbout) {
  auto& r = state.create<TRobot>();
  auto& other = state.create<TRobot>();
  const vsd::Id id = r.id();
  std::vector<vsd::Id> later;
  auto c1 = state.on_property_changed().connect([&](vsd::SimStateInstance& i, const vsd::MetaProperty&) {
    if (i.id() == id && !i.is_being_deleted()) state.destroy(i);
  });
  auto c2 = state.on_property_changed().connect(
      [&](vsd::SimStateInstance& i, const vsd::MetaProperty&) { later.push_back(i.id()); });
  r.set_speed(9.0);
  EXPECT_EQ(state.find(id), nullptr);
  other.set_speed(2.0);
  EXPECT_THAT(later, testing::Contains(other.id()));
}

TEST_F(SimStateTest, CreateThrowsInsteadOfReturningAnInstanceItsListenerDeleted) {
  auto veto = state.on_created().connect([&](vsd::SimStateInstance& i) {
    if (i.is_a<TGripper>()) state.destroy(i);
  });
  std::vector<std::string> log;
  auto seen = state.on_deleted().connect([&](vsd::SimStateInstance& i) { log.push_back(i.meta().name()); });
  state.start_recording();
  EXPECT_THAT([&] { (void)state.create<TGripper>(); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("was deleted by a listener of its creation")));
  const vsd::Transaction t = state.stop_recording();
  EXPECT_EQ(t.size(), 2u) << t.describe();  // create and delete, both recorded
  EXPECT_THAT(log, ElementsAre("TGripper"));
  EXPECT_EQ(state.size(), 1u);
  EXPECT_TRUE(state.index().exact(TGripper::static_meta()).empty());
  auto& kept = state.create<TRobot>();  // others are untouched
  EXPECT_EQ(state.find(kept.id()), &kept);
}

TEST_F(SimStateTest, AnInstanceCreatedInsideAListenerIsUsableThere) {
  std::vector<vsd::Id> made;
  auto c = state.on_created().connect([&](vsd::SimStateInstance& i) {
    if (!i.is_a<TRobot>() || i.is_a<TGripper>()) return;
    auto& g = state.create<TGripper>();  // nested create: returns a live instance
    g.set_speed(4.0);
    made.push_back(g.id());
  });
  auto& r = state.create<TRobot>();
  ASSERT_EQ(made.size(), 1u);
  EXPECT_EQ(state.find<TGripper>(made[0])->speed(), 4.0);
  EXPECT_EQ(state.find(r.id()), &r);
}

TEST_F(SimStateTest, AListenerMayDisconnectAnotherDuringDispatch) {
  auto& r = state.create<TRobot>();
  int first = 0, second = 0;
  vsd::Connection c2;
  auto c1 = state.on_property_changed().connect([&](vsd::SimStateInstance&, const vsd::MetaProperty&) {
    ++first;
    c2.disconnect();
  });
  c2 = state.on_property_changed().connect(
      [&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++second; });
  r.set_speed(2.0);
  r.set_speed(3.0);
  EXPECT_EQ(first, 2);
  EXPECT_EQ(second, 0);
}

TEST_F(SimStateTest, EqualsComparesDeeplyAndNamesTheDifference) {
  auto& a = env.create_state("a");
  auto& b = env.create_state("b");
  auto& ra = a.create<TRobot>();
  a.database().add_child(ra);
  b.copy_from(a);
  std::string diff;
  EXPECT_TRUE(a.equals(b, &diff)) << diff;
  ra.set_speed(4.0);
  EXPECT_FALSE(a.equals(b, &diff));
  EXPECT_THAT(diff, HasSubstr("speed"));
  ra.set_cache("local only");  // Transient: not compared
  static_cast<TRobot*>(b.find(ra.id()))->set_speed(4.0);
  EXPECT_TRUE(a.equals(b, &diff)) << diff;
}

TEST_F(SimStateTest, CopyFromNeedsAnEmptyState) {
  auto& a = env.create_state("a");
  state.create<vsd::Node>();
  EXPECT_THAT([&] { state.copy_from(a); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("empty")));
}

// Derived changes: a module derives `axes` from `speed` (as robotics derives a link frame from its joint
// value). The bundle carries the cause only; a state with the same module derives the rest itself, and
// what listeners do in reaction to a derived change is recorded as usual.
struct Deriver {
  explicit Deriver(vsd::SimState& s) {
    derive = s.on_property_changed(TRobot::static_meta()).connect([&s](vsd::SimStateInstance& i, const vsd::MetaProperty& p) {
      if (&p != &TRobot::vsd_prop_speed()) return;
      vsd::SimState::Deriving scope(s);
      static_cast<TRobot&>(i).set_axes(static_cast<int>(static_cast<TRobot&>(i).speed() * 2));
    });
    react = s.on_property_changed(TRobot::static_meta()).connect([](vsd::SimStateInstance& i, const vsd::MetaProperty& p) {
      if (&p == &TRobot::vsd_prop_axes()) static_cast<TRobot&>(i).set_joints(std::vector<double>(static_cast<std::size_t>(static_cast<TRobot&>(i).axes()), 0.5));
    });
  }
  vsd::Connection derive, react;
};

TEST_F(SimStateTest, DerivedChangesAreSignalledButNotRecorded) {
  auto& r = state.create<TRobot>();
  auto& replica = env.create_state("replica");
  replica.copy_from(state);
  Deriver here(state), there(replica);
  state.start_recording();
  r.set_speed(3.5);
  EXPECT_EQ(r.axes(), 7);
  EXPECT_EQ(r.joints().size(), 7u);
  const vsd::Transaction t = state.stop_recording();
  ASSERT_EQ(t.size(), 2u) << "the speed and the reaction to the derived axes; not the axes themselves";
  EXPECT_THAT(t.describe(), testing::Not(HasSubstr(".axes")));
  replica.apply(t);
  std::string diff;
  EXPECT_TRUE(replica.equals(state, &diff)) << diff;
}

TEST_F(SimStateTest, RollingBackReDerives) {
  auto& r = state.create<TRobot>();
  Deriver d(state);
  r.set_speed(2.0);
  const auto sp = state.savepoint();
  r.set_speed(5.0);
  EXPECT_EQ(r.axes(), 10);
  state.roll_back(sp);
  EXPECT_EQ(r.speed(), 2.0);
  EXPECT_EQ(r.axes(), 4) << "the undone speed derives the axes again";
}

}  // namespace
