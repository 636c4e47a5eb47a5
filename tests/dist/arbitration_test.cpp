// Races the stamp order alone does not settle: a set to an instance another participant deletes at the
// same time (the deletion wins everywhere), and concurrent edits of one reference list (a list is one
// register: the later stamped list wins whole). Every replica must end alike and the losing writer be told.
// The two writers publish before either polls, so their bundles are concurrent by construction; the
// arrival order at the third participant varies from round to round.
#include <gtest/gtest.h>

#include "dist_test_util.hpp"

using namespace std::chrono_literals;
using vsd_dist_test::DArm;
using vsd_dist_test::options;
using vsd_dist_test::poll_all;

namespace {

struct ArbitrationTest : testing::Test {
  std::uint32_t domain = vsd_dist_test::fresh_domain();
  vsd::Environment env_r{1}, env_u{2}, env_c{3};
  vsd::SimState& r = env_r.main_state();
  vsd::SimState& u = env_u.main_state();
  vsd::SimState& c = env_c.main_state();
  DArm* keep = nullptr;  // an arm nobody deletes
  std::vector<std::string> log_r, log_u, log_c;
  std::unique_ptr<vsd::dist::Participant> robot, ui, other;
  std::vector<vsd::dist::Conflict> seen_r, seen_u;
  vsd::Connection cr, cu;

  void SetUp() override {
    keep = &r.create<DArm>();
    keep->set_name("keep");
    r.database().add_child(*keep);
    robot = std::make_unique<vsd::dist::Participant>(r, options("robot", domain, true, &log_r));
    ui = std::make_unique<vsd::dist::Participant>(u, options("ui", domain, false, &log_u));
    other = std::make_unique<vsd::dist::Participant>(c, options("monitor", domain, false, &log_c));
    ASSERT_TRUE(
        poll_all({robot.get(), ui.get(), other.get()}, [&] { return ui->synced() && other->synced(); }));
    cr = robot->on_conflict().connect([&](const vsd::dist::Conflict& x) { seen_r.push_back(x); });
    cu = ui->on_conflict().connect([&](const vsd::dist::Conflict& x) { seen_u.push_back(x); });
  }
  bool settle(const std::function<bool()>& f) { return poll_all({robot.get(), ui.get(), other.get()}, f); }
  static std::uint64_t last_seq(const vsd::dist::Participant& p) {
    return p.stats().bundles_sent + p.stats().claims_sent;
  }
  static bool has(const std::vector<vsd::dist::Conflict>& seen, vsd::dist::ConflictKind kind,
                  std::uint64_t writer, std::uint64_t seq) {
    for (const auto& x : seen)
      if (x.kind == kind && x.writer == writer && x.seq == seq) return true;
    return false;
  }
  void expect_all_equal() {
    std::string diff;
    EXPECT_TRUE(r.equals(u, &diff)) << diff;
    EXPECT_TRUE(r.equals(c, &diff)) << diff;
  }
};

TEST_F(ArbitrationTest, ASetRacingADeletionIsDroppedEverywhereAndTheWriterIsTold) {
  constexpr int rounds = 20;
  for (int i = 1; i <= rounds; ++i) {
    SCOPED_TRACE("round " + std::to_string(i));
    auto& arm = r.create<DArm>();
    r.database().add_child(arm);
    const vsd::Id id = arm.id();
    ASSERT_TRUE(robot->publish());
    ASSERT_TRUE(settle([&] { return u.find(id) != nullptr && c.find(id) != nullptr; }));
    // The ui sets the arm and, in the same bundle, another instance; the robot deletes the arm. Neither
    // has seen the other's change.
    u.find<DArm>(id)->set_target(i);
    u.find<DArm>(id)->set_joints({1.0 * i});
    u.find<DArm>(keep->id())->set_target(i);
    ASSERT_TRUE(ui->publish());
    const std::uint64_t ui_seq = last_seq(*ui);
    r.destroy(arm);
    ASSERT_TRUE(robot->publish());
    ASSERT_TRUE(settle([&] {
      return u.find(id) == nullptr && c.find(id) == nullptr && keep->target() == i &&
             c.find<DArm>(keep->id())->target() == i &&
             has(seen_u, vsd::dist::ConflictKind::Deleted, ui->id(), ui_seq) &&
             has(seen_r, vsd::dist::ConflictKind::Deleted, ui->id(), ui_seq);
    })) << "the deletion did not win everywhere, or the writer was not told";
    EXPECT_EQ(r.find(id), nullptr);
    expect_all_equal();
  }
  // Nobody needed a snapshot: the race is settled by the rule, not by resynchronising.
  EXPECT_EQ(robot->stats().resyncs + ui->stats().resyncs + other->stats().resyncs, 0u);
  EXPECT_GE(robot->stats().lost_writes, static_cast<std::uint64_t>(rounds));
  EXPECT_TRUE(vsd_dist_test::contains(log_u, "dropped: 'robot' deleted #"));
  const auto& x = seen_u.back();
  EXPECT_EQ(x.owner, robot->id());
  EXPECT_EQ(x.property, "target");
}

TEST_F(ArbitrationTest, TwoDeletionsOfOneInstanceAreNoConflict) {
  auto& arm = r.create<DArm>();
  const vsd::Id id = arm.id();
  ASSERT_TRUE(robot->publish());
  ASSERT_TRUE(settle([&] { return u.find(id) != nullptr && c.find(id) != nullptr; }));
  u.destroy(*u.find(id));
  ASSERT_TRUE(ui->publish());
  r.destroy(arm);
  ASSERT_TRUE(robot->publish());
  ASSERT_TRUE(settle([&] {
    return c.find(id) == nullptr && robot->stats().bundles_applied >= 1 && ui->stats().bundles_applied >= 2;
  }));
  EXPECT_TRUE(seen_r.empty());
  EXPECT_TRUE(seen_u.empty());
  EXPECT_EQ(robot->stats().resyncs + ui->stats().resyncs + other->stats().resyncs, 0u);
  expect_all_equal();
}

TEST_F(ArbitrationTest, ConcurrentListEditsEndWithOneWholeListEverywhereAndTheLoserIsTold) {
  constexpr int rounds = 20;
  std::vector<std::string> names;  // the list as it must be after the round, by node name
  for (int i = 1; i <= rounds; ++i) {
    SCOPED_TRACE("round " + std::to_string(i));
    // Both append a node of their own to the same list, and the ui also removes the first entry.
    auto& mine_r = r.create<vsd::Node>();
    mine_r.set_name("r" + std::to_string(i));
    keep->edit_tools().push_back(mine_r);
    auto& mine_u = u.create<vsd::Node>();
    mine_u.set_name("u" + std::to_string(i));
    DArm& ukeep = *u.find<DArm>(keep->id());
    if (i % 2 == 0 && !ukeep.tools().empty()) ukeep.edit_tools().erase(0);
    ukeep.edit_tools().push_back(mine_u);
    const std::vector<vsd::Id> r_list = [&] {
      std::vector<vsd::Id> v;
      for (vsd::Node* n : keep->tools()) v.push_back(n->id());
      return v;
    }();
    const std::vector<vsd::Id> u_list = [&] {
      std::vector<vsd::Id> v;
      for (vsd::Node* n : ukeep.tools()) v.push_back(n->id());
      return v;
    }();
    ASSERT_TRUE(robot->publish());
    const std::uint64_t r_seq = last_seq(*robot);
    ASSERT_TRUE(ui->publish());
    const std::uint64_t u_seq = last_seq(*ui);
    auto list_of = [&](vsd::SimState& s) {
      std::vector<vsd::Id> v;
      for (vsd::Node* n : s.find<DArm>(keep->id())->tools()) v.push_back(n->id());
      return v;
    };
    // One writer's list wins whole at every replica; the other is told by the winner.
    ASSERT_TRUE(settle([&] {
      const auto a = list_of(r);
      if (a != list_of(u) || a != list_of(c) || (a != r_list && a != u_list)) return false;
      if (a == r_list) return has(seen_u, vsd::dist::ConflictKind::ConcurrentWrite, ui->id(), u_seq);
      return has(seen_r, vsd::dist::ConflictKind::ConcurrentWrite, robot->id(), r_seq);
    })) << "the lists did not converge on one writer's list, or the loser was not told";
    // Both nodes exist everywhere (creations are not arbitrated), whichever list won.
    EXPECT_NE(c.find(mine_r.id()), nullptr);
    EXPECT_NE(c.find(mine_u.id()), nullptr);
    expect_all_equal();
  }
  EXPECT_EQ(robot->stats().resyncs + ui->stats().resyncs + other->stats().resyncs, 0u);
}

}  // namespace
