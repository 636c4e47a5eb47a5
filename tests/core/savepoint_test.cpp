// Tests of vsd::Savepoint (undoing changes since a point), SimStateInstance::referrers() and
// Registry::rename(): the core pieces that run-time class migration (vsd::soml) builds on.
#include "vsd/core/savepoint.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_classes.hpp"

using testing::HasSubstr;
using vsd_test::TRobot;
using vsd_test::TTool;

namespace {

struct SavepointTest : testing::Test {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
  vsd::SimState& replica = env.create_state("replica");
};

TEST_F(SavepointTest, RollbackRestoresValuesReferencesAndDeletedInstances) {
  auto& r = state.create<TRobot>();
  r.set_name("r");
  state.database().add_child(r);
  auto& t = state.create<TTool>();
  r.set_tool(&t);
  auto& other = state.create<vsd::Node>();
  state.database().add_child(other);
  r.set_target(&other);
  const vsd::Id rid = r.id(), tid = t.id(), oid = other.id();
  const std::size_t before = state.size();
  {
    vsd::Savepoint sp(state);
    r.set_speed(7.0);
    auto& extra = state.create<vsd::Node>();
    r.add_child(extra);
    state.destroy(other);  // nulls r.target
    EXPECT_EQ(r.target().get(), nullptr);
    sp.rollback();
    EXPECT_FALSE(sp.open());
  }
  EXPECT_EQ(state.size(), before);
  EXPECT_DOUBLE_EQ(r.speed(), 1.0);
  EXPECT_TRUE(r.children().empty());
  ASSERT_NE(state.find(oid), nullptr);
  EXPECT_EQ(r.target().get(), state.find(oid));
  EXPECT_EQ(state.find(rid), &r);
  EXPECT_EQ(state.find(tid), &t);
  EXPECT_FALSE(state.recording());  // the savepoint's own recording ended with it
}

TEST_F(SavepointTest, DestructorRollsBackAndCommitKeeps) {
  auto& r = state.create<TRobot>();
  state.database().add_child(r);
  {
    vsd::Savepoint sp(state);
    r.set_speed(3.0);
  }
  EXPECT_DOUBLE_EQ(r.speed(), 1.0);
  {
    vsd::Savepoint sp(state);
    r.set_speed(4.0);
    sp.commit();
    sp.rollback();  // closed: nothing happens
  }
  EXPECT_DOUBLE_EQ(r.speed(), 4.0);
}

TEST_F(SavepointTest, RolledBackChangesLeaveTheRecordingAndCommittedOnesStay) {
  state.start_recording();
  auto& r = state.create<TRobot>();
  state.database().add_child(r);
  {
    vsd::Savepoint sp(state);
    r.set_speed(9.0);
    state.create<vsd::Node>();
    sp.rollback();
  }
  {
    vsd::Savepoint sp(state);
    r.set_axes(3);
    sp.commit();
  }
  EXPECT_TRUE(state.recording());
  const vsd::Transaction t = state.stop_recording();
  EXPECT_EQ(t.describe().find("speed"), std::string::npos) << t.describe();
  EXPECT_NE(t.describe().find("axes"), std::string::npos) << t.describe();
  replica.apply(t);
  std::string diff;
  EXPECT_TRUE(state.equals(replica, &diff)) << diff;
}

TEST_F(SavepointTest, NestedSavepoints) {
  auto& r = state.create<TRobot>();
  state.database().add_child(r);
  vsd::Savepoint outer(state);
  r.set_speed(2.0);
  {
    vsd::Savepoint inner(state);
    r.set_axes(1);
    inner.rollback();
  }
  EXPECT_EQ(r.axes(), 6);
  EXPECT_DOUBLE_EQ(r.speed(), 2.0);
  outer.rollback();
  EXPECT_DOUBLE_EQ(r.speed(), 1.0);
}

TEST_F(SavepointTest, TakenRecordingIsAnError) {
  auto& r = state.create<TRobot>();
  state.database().add_child(r);
  vsd::Savepoint sp(state);
  r.set_speed(2.0);
  (void)state.take_recording();
  state.stop_recording();
  try {
    sp.rollback();
    FAIL() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("nothing was undone"));
  }
  EXPECT_FALSE(sp.open());
  EXPECT_DOUBLE_EQ(r.speed(), 2.0);
}

TEST_F(SavepointTest, ReferrersListsCompositeAndSharedHolders) {
  auto& a = state.create<TRobot>();
  auto& b = state.create<TRobot>();
  state.database().add_child(a);
  state.database().add_child(b);
  auto& n = state.create<vsd::Node>();
  a.add_child(n);
  b.set_target(&n);
  b.edit_watched().push_back(n);
  b.edit_watched().push_back(n);
  const auto refs = n.referrers();
  ASSERT_EQ(refs.size(), 3u);
  EXPECT_EQ(refs[0].first, &a);
  EXPECT_EQ(refs[0].second->name(), "children");
  EXPECT_EQ(refs[1].first, &b);
  EXPECT_EQ(refs[1].second->name(), "target");
  EXPECT_EQ(refs[2].first, &b);
  EXPECT_EQ(refs[2].second->name(), "watched");
  EXPECT_TRUE(state.create<vsd::Node>().referrers().empty());
}

TEST(RegistryRename, RenamesARunTimeClass) {
  vsd::Registry reg;
  const vsd::MetaInstance& c =
      vsd::ClassBuilder("rn::Cell", vsd::Node::static_meta()).property<std::int64_t>("n", 1).define(reg);
  reg.rename(c, "rn::Cell~1");
  EXPECT_EQ(c.name(), "rn::Cell~1");
  EXPECT_EQ(reg.find_class("rn::Cell"), nullptr);
  EXPECT_EQ(reg.find_class("rn::Cell~1"), &c);
  EXPECT_EQ(reg.find_class("Cell~1"), &c);  // short name
  // The name is free again: a new version can take it.
  const vsd::MetaInstance& c2 = vsd::ClassBuilder("rn::Cell", vsd::Node::static_meta()).define(reg);
  EXPECT_EQ(reg.find_class("Cell"), &c2);
  EXPECT_THROW(reg.rename(c, "rn::Cell"), vsd::Error);  // taken
  EXPECT_THROW(reg.rename(c, "rn::"), vsd::Error);      // not a class name
  EXPECT_THROW(reg.rename(vsd::Node::static_meta(), "X"), vsd::Error);
  (void)reg.get_type("shared<rn::Cell>");
  try {
    reg.rename(c2, "rn::Other");
    FAIL() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("shared<rn::Cell>"));
  }
  EXPECT_EQ(c2.name(), "rn::Cell");
  vsd::Registry other;
  EXPECT_THROW(other.rename(c, "rn::Zed"), vsd::Error);
}

}  // namespace
