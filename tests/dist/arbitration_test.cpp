// Races the stamp order alone does not settle: a set to an instance another participant deletes at the
// same time (the deletion wins everywhere), concurrent edits of one reference list (merged entry by entry),
// references to concurrently deleted instances and concurrent moves of one child. Every replica must end
// alike, and the losing writer be told.
// The two writers publish before either polls, so their bundles are concurrent by construction; the
// arrival order at the third participant varies from round to round.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <thread>

#include "three_participants.hpp"

using namespace std::chrono_literals;
using vsd_dist_test::DArm;
using vsd_dist_test::options;
using vsd_dist_test::poll_all;

namespace {

struct ArbitrationTest : vsd_dist_test::ThreeParticipants {
  DArm* keep = nullptr;  // an arm nobody deletes

  void populate() override {
    keep = &r.create<DArm>();
    keep->set_name("keep");
    r.database().add_child(*keep);
  }
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

std::vector<vsd::Id> tools_of(vsd::SimState& s, vsd::Id arm) {
  std::vector<vsd::Id> v;
  for (vsd::Node* n : s.find<DArm>(arm)->tools()) v.push_back(n->id());
  return v;
}

std::vector<vsd::Id> sorted(std::vector<vsd::Id> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// Two participants add to one list at once, and erase entries (sometimes the same one) at once: both
// additions stay, every erasure removes only the entry it saw, and the list is the same everywhere.
TEST_F(ArbitrationTest, ConcurrentListEditsMergeEntryByEntryEverywhere) {
  constexpr int rounds = 24;
  const vsd::Id arm = keep->id();
  for (int i = 1; i <= rounds; ++i) {
    SCOPED_TRACE("round " + std::to_string(i));
    const std::vector<vsd::Id> before = tools_of(r, arm);
    ASSERT_EQ(before, tools_of(u, arm));
    auto& mine_r = r.create<vsd::Node>();
    mine_r.set_name("r" + std::to_string(i));
    auto& mine_u = u.create<vsd::Node>();
    mine_u.set_name("u" + std::to_string(i));
    DArm& ukeep = *u.find<DArm>(arm);
    std::vector<vsd::Id> erased;
    // The ui erases the first entry on even rounds, the robot on every third: on rounds 6, 12, ... both
    // erase the same entry.
    if (i % 2 == 0 && !before.empty()) {
      ukeep.edit_tools().erase(0);
      erased.push_back(before[0]);
    }
    if (i % 3 == 0 && !before.empty()) {
      keep->edit_tools().erase(0);
      erased.push_back(before[0]);
    }
    // The robot appends, the ui inserts at the front and, on odd rounds, also in the middle.
    keep->edit_tools().push_back(mine_r);
    ukeep.edit_tools().insert(0, mine_u);
    vsd::Node* extra = nullptr;
    if (i % 2 == 1) {
      extra = &u.create<vsd::Node>();
      ukeep.edit_tools().insert(ukeep.tools().size() / 2, *extra);
    }
    ASSERT_TRUE(robot->publish());
    ASSERT_TRUE(ui->publish());
    std::vector<vsd::Id> expected;
    for (vsd::Id x : before)
      if (std::find(erased.begin(), erased.end(), x) == erased.end()) expected.push_back(x);
    expected.push_back(mine_r.id());
    expected.push_back(mine_u.id());
    if (extra != nullptr) expected.push_back(extra->id());
    ASSERT_TRUE(settle([&] {
      const auto a = tools_of(r, arm);
      return a == tools_of(u, arm) && a == tools_of(c, arm) && sorted(a) == sorted(expected);
    })) << "the lists did not merge alike: robot "
        << testing::PrintToString(tools_of(r, arm)) << ", ui " << testing::PrintToString(tools_of(u, arm))
        << ", monitor " << testing::PrintToString(tools_of(c, arm)) << ", expected the entries "
        << testing::PrintToString(sorted(expected));
    // Each writer's own order is kept: the ui's entry first, the robot's last (on an empty list both
    // insert at the front, and the later stamped one comes first).
    const auto merged = tools_of(c, arm);
    if (!before.empty()) {
      EXPECT_EQ(merged.front(), mine_u.id());
      EXPECT_EQ(merged.back(), mine_r.id());
    }
    expect_all_equal();
  }
  EXPECT_TRUE(seen_r.empty()) << seen_r.front().text;
  EXPECT_TRUE(seen_u.empty()) << seen_u.front().text;
  EXPECT_EQ(robot->stats().resyncs + ui->stats().resyncs + other->stats().resyncs, 0u);
  EXPECT_EQ(robot->stats().lost_writes + ui->stats().lost_writes + other->stats().lost_writes, 0u);
}

// A whole-value set of a list travels as erasures and insertions, so it merges with a concurrent append.
TEST_F(ArbitrationTest, AWholeListSetMergesWithAConcurrentAppend) {
  const vsd::Id arm = keep->id();
  for (int k = 0; k < 3; ++k) keep->edit_tools().push_back(r.create<vsd::Node>());
  ASSERT_TRUE(robot->publish());
  ASSERT_TRUE(settle([&] { return tools_of(u, arm).size() == 3 && tools_of(c, arm).size() == 3; }));
  auto& x = u.create<vsd::Node>();
  auto& y = u.create<vsd::Node>();
  vsd::SharedRefList<vsd::Node> fresh;
  fresh.push_back(&x);
  fresh.push_back(&y);
  u.find<DArm>(arm)->set_tools(fresh);  // the ui replaces the list ...
  auto& z = r.create<vsd::Node>();
  keep->edit_tools().push_back(z);  // ... while the robot appends to the old one
  ASSERT_TRUE(ui->publish());
  ASSERT_TRUE(robot->publish());
  ASSERT_TRUE(settle([&] {
    const auto a = tools_of(r, arm);
    return a == tools_of(u, arm) && a == tools_of(c, arm) && sorted(a) == sorted({x.id(), y.id(), z.id()});
  })) << testing::PrintToString(tools_of(r, arm))
      << " " << testing::PrintToString(tools_of(u, arm));
  expect_all_equal();
  EXPECT_EQ(robot->stats().resyncs + ui->stats().resyncs + other->stats().resyncs, 0u);
}

// All three insert at the same position at once: the three entries end in one order everywhere, next to
// each other, whatever order each participant received them in.
TEST_F(ArbitrationTest, ThreeInsertionsAtOnePlaceLandInOneOrderEverywhere) {
  const vsd::Id arm = keep->id();
  for (int k = 0; k < 3; ++k) keep->edit_tools().push_back(r.create<vsd::Node>());
  ASSERT_TRUE(robot->publish());
  ASSERT_TRUE(settle([&] { return tools_of(u, arm).size() == 3 && tools_of(c, arm).size() == 3; }));
  vsd::SimState* states[] = {&r, &u, &c};
  vsd::dist::Participant* ps[] = {robot.get(), ui.get(), other.get()};
  for (int i = 0; i < 10; ++i) {
    SCOPED_TRACE("round " + std::to_string(i));
    std::vector<vsd::Id> added;
    for (int k = 0; k < 3; ++k) {
      auto& n = states[k]->create<vsd::Node>();
      states[k]->find<DArm>(arm)->edit_tools().insert(1, n);
      added.push_back(n.id());
    }
    for (int k = 0; k < 3; ++k) ASSERT_TRUE(ps[(k + i) % 3]->publish());  // a different order each round
    ASSERT_TRUE(settle([&] {
      const auto a = tools_of(r, arm);
      return a.size() == static_cast<std::size_t>(3 + 3 * (i + 1)) && a == tools_of(u, arm) &&
             a == tools_of(c, arm);
    }));
    const auto a = tools_of(r, arm);
    const std::vector<vsd::Id> at_one(a.begin() + 1, a.begin() + 4);
    EXPECT_EQ(sorted(at_one), sorted(added)) << "the three insertions are not side by side at index 1";
  }
  expect_all_equal();
  EXPECT_EQ(robot->stats().resyncs + ui->stats().resyncs + other->stats().resyncs, 0u);
}

// An insertion after an entry that another participant erases at the same time stays, in its place.
TEST_F(ArbitrationTest, AnInsertionNextToAConcurrentlyErasedEntryStays) {
  const vsd::Id arm = keep->id();
  std::vector<vsd::Node*> base;
  for (int k = 0; k < 4; ++k) base.push_back(&r.create<vsd::Node>());
  for (vsd::Node* n : base) keep->edit_tools().push_back(*n);
  ASSERT_TRUE(robot->publish());
  ASSERT_TRUE(settle([&] { return tools_of(u, arm).size() == 4 && tools_of(c, arm).size() == 4; }));
  keep->edit_tools().erase(1);  // the robot erases the second entry ...
  auto& n = u.create<vsd::Node>();
  u.find<DArm>(arm)->edit_tools().insert(2, n);  // ... while the ui inserts right after it
  ASSERT_TRUE(ui->publish());
  ASSERT_TRUE(robot->publish());
  const std::vector<vsd::Id> want{base[0]->id(), n.id(), base[2]->id(), base[3]->id()};
  ASSERT_TRUE(settle([&] {
    return tools_of(r, arm) == want && tools_of(u, arm) == want && tools_of(c, arm) == want;
  })) << testing::PrintToString(tools_of(r, arm))
      << " " << testing::PrintToString(tools_of(u, arm));
  expect_all_equal();
}

// A participant that joins after lists were edited (erased entries included) gets their entries in the
// snapshot, and its own concurrent edits merge like anyone's.
TEST_F(ArbitrationTest, ALateJoinerMergesListEditsLikeEveryone) {
  const vsd::Id arm = keep->id();
  for (int k = 0; k < 6; ++k) {
    keep->edit_tools().push_back(r.create<vsd::Node>());
    ASSERT_TRUE(robot->publish());
  }
  keep->edit_tools().erase(2);
  keep->edit_tools().erase(0);
  ASSERT_TRUE(robot->publish());
  ASSERT_TRUE(settle([&] { return tools_of(u, arm).size() == 4; }));
  auto& un = u.create<vsd::Node>();
  u.find<DArm>(arm)->edit_tools().insert(1, un);
  ASSERT_TRUE(ui->publish());
  ASSERT_TRUE(settle([&] { return tools_of(r, arm).size() == 5 && tools_of(c, arm).size() == 5; }));
  vsd::Environment env_l{4};
  vsd::SimState& l = env_l.main_state();
  vsd::dist::Participant late(l, options("late", domain));
  ASSERT_TRUE(poll_all({robot.get(), ui.get(), other.get(), &late}, [&] { return late.synced(); }));
  EXPECT_EQ(tools_of(l, arm), tools_of(r, arm));
  for (int i = 0; i < 10; ++i) {
    SCOPED_TRACE("round " + std::to_string(i));
    // The late joiner and the robot edit at once: both insert after the first entry, and both erase the
    // last one (the same entry: it goes once).
    auto& a = l.create<vsd::Node>();
    l.find<DArm>(arm)->edit_tools().insert(1, a);
    l.find<DArm>(arm)->edit_tools().erase(l.find<DArm>(arm)->tools().size() - 1);
    auto& b = r.create<vsd::Node>();
    keep->edit_tools().insert(1, b);
    keep->edit_tools().erase(keep->tools().size() - 1);
    ASSERT_TRUE(late.publish());
    ASSERT_TRUE(robot->publish());
    ASSERT_TRUE(poll_all({robot.get(), ui.get(), other.get(), &late},
                         [&] {
                           const auto x = tools_of(r, arm);
                           return x == tools_of(l, arm) && x == tools_of(u, arm) && x == tools_of(c, arm) &&
                                  x.size() == static_cast<std::size_t>(6 + i) &&
                                  std::find(x.begin(), x.end(), a.id()) != x.end() &&
                                  std::find(x.begin(), x.end(), b.id()) != x.end();
                         }))
        << testing::PrintToString(tools_of(r, arm)) << " " << testing::PrintToString(tools_of(l, arm));
  }
  std::string diff;
  EXPECT_TRUE(r.equals(l, &diff)) << diff;
  EXPECT_EQ(late.stats().resyncs + robot->stats().resyncs + ui->stats().resyncs, 0u);
}

// A reference set to, and a list entry of, an instance another participant deletes at the same time: the
// deletion wins everywhere (the reference ends null, the entry removed), whatever the arrival order, and
// the writer is told.
TEST_F(ArbitrationTest, AReferenceToAConcurrentlyDeletedInstanceEndsNullEverywhere) {
  const vsd::Id arm = keep->id();
  for (int i = 1; i <= 16; ++i) {
    SCOPED_TRACE("round " + std::to_string(i));
    auto& n = r.create<vsd::Node>();
    r.database().add_child(n);
    const vsd::Id id = n.id();
    ASSERT_TRUE(robot->publish());
    ASSERT_TRUE(settle([&] { return u.find(id) != nullptr && c.find(id) != nullptr; }));
    DArm& ukeep = *u.find<DArm>(arm);
    ukeep.set_watched(u.find<vsd::Node>(id));
    ukeep.edit_tools().push_back(*u.find<vsd::Node>(id));
    if (i % 2 == 0) {  // and a new instance that refers to it, in the same bundle
      auto& fresh = u.create<DArm>();
      fresh.set_watched(u.find<vsd::Node>(id));
      u.database().add_child(fresh);
    }
    r.destroy(n);
    if (i % 2 == 0) {
      ASSERT_TRUE(ui->publish());
      ASSERT_TRUE(robot->publish());
    } else {
      ASSERT_TRUE(robot->publish());
      ASSERT_TRUE(ui->publish());
    }
    const std::uint64_t ui_seq = last_seq(*ui);
    ASSERT_TRUE(settle([&] {
      for (vsd::SimState* s : {&r, &u, &c})
        if (s->find(id) != nullptr || s->find<DArm>(arm)->watched().get() != nullptr ||
            !tools_of(*s, arm).empty())
          return false;
      return has(seen_u, vsd::dist::ConflictKind::Deleted, ui->id(), ui_seq);
    })) << "the deletion did not win everywhere, or the writer was not told";
    expect_all_equal();
  }
  const auto& x = seen_u.back();
  EXPECT_EQ(x.owner, robot->id());
  EXPECT_NE(x.target, vsd::null_id);
  EXPECT_TRUE(vsd_dist_test::contains(log_u, "concurrently"));
  EXPECT_EQ(robot->stats().resyncs + ui->stats().resyncs + other->stats().resyncs, 0u);
}

// Two participants move one node to different parents at once: the newer move wins everywhere, the node
// has one parent, and the participants report the lost move.
TEST_F(ArbitrationTest, ConcurrentMovesOfOneChildEndWithOneParentEverywhere) {
  vsd::Node* parents[3];
  for (auto*& p : parents) {
    p = &r.create<vsd::Node>();
    r.database().add_child(*p);
  }
  auto& child = r.create<vsd::Node>();
  child.set_name("child");
  parents[0]->add_child(child);
  ASSERT_TRUE(robot->publish());
  ASSERT_TRUE(settle([&] { return u.find(child.id()) != nullptr && c.find(child.id()) != nullptr; }));
  auto holders = [&](vsd::SimState& s) {
    std::vector<vsd::Id> v;
    for (vsd::Node* p : parents)
      for (vsd::Node* k : s.find<vsd::Node>(p->id())->children())
        if (k->id() == child.id()) v.push_back(p->id());
    return v;
  };
  for (int i = 0; i < 12; ++i) {
    SCOPED_TRACE("round " + std::to_string(i));
    const std::size_t seen_before = seen_r.size() + seen_u.size();
    // From wherever it is, the ui moves it to one parent and the robot to another.
    const vsd::Id at = holders(r).front();
    std::vector<vsd::Node*> others;
    for (vsd::Node* p : parents)
      if (p->id() != at) others.push_back(p);
    u.find<vsd::Node>(others[i % 2]->id())->add_child(*u.find<vsd::Node>(child.id()));
    others[(i + 1) % 2]->add_child(child);
    if (i % 2 == 0) {
      ASSERT_TRUE(ui->publish());
      ASSERT_TRUE(robot->publish());
    } else {
      ASSERT_TRUE(robot->publish());
      ASSERT_TRUE(ui->publish());
    }
    ASSERT_TRUE(settle([&] {
      const auto h = holders(r);
      return h.size() == 1 && h == holders(u) && h == holders(c) &&
             seen_r.size() + seen_u.size() > seen_before;
    })) << "robot "
        << testing::PrintToString(holders(r)) << ", ui " << testing::PrintToString(holders(u)) << ", monitor "
        << testing::PrintToString(holders(c));
    EXPECT_EQ(c.find<vsd::Node>(child.id())->parent()->id(), holders(r).front());
    expect_all_equal();
  }
  bool reported = false;
  for (const auto& x : seen_u) reported |= x.kind == vsd::dist::ConflictKind::ConcurrentMove;
  for (const auto& x : seen_r) reported |= x.kind == vsd::dist::ConflictKind::ConcurrentMove;
  EXPECT_TRUE(reported);
  EXPECT_TRUE(vsd_dist_test::contains(log_c, "concurrent moves of #" + std::to_string(child.id())));
  EXPECT_EQ(robot->stats().resyncs + ui->stats().resyncs + other->stats().resyncs, 0u);
}

// Tombstones (deleted instances, erased list entries) go after the horizon; lists still merge afterwards, and
// a participant that joins later synchronises from a pruned state.
TEST(Tombstones, ArePrunedAfterTheHorizonAndListsStillMerge) {
  const std::uint32_t domain = vsd_dist_test::fresh_domain();
  vsd::Environment env_a{1}, env_b{2}, env_l{3};
  vsd::SimState& a = env_a.main_state();
  vsd::SimState& b = env_b.main_state();
  auto& arm = a.create<DArm>();
  a.database().add_child(arm);
  auto o_a = options("a", domain, true);
  auto o_b = options("b", domain);
  o_a.tombstone_horizon = o_b.tombstone_horizon = 300ms;
  vsd::dist::Participant pa(a, o_a), pb(b, o_b);
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.synced(); }));
  std::vector<vsd::Node*> nodes;
  for (int k = 0; k < 10; ++k) {
    nodes.push_back(&a.create<vsd::Node>());
    arm.edit_tools().push_back(*nodes.back());
  }
  ASSERT_TRUE(pa.publish());
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return tools_of(b, arm.id()).size() == 10; }));
  for (int k = 0; k < 10; k += 2) a.destroy(*nodes[static_cast<std::size_t>(k)]);  // 5 deletions, 5 erasures
  ASSERT_TRUE(pa.publish());
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return tools_of(b, arm.id()).size() == 5; }));
  EXPECT_EQ(pa.stats().tombstones_pruned, 0u);
  // Past the horizon (and the pruning interval), both have pruned the 5 deleted ids and the 5 erased entries.
  poll_all(
      {&pa, &pb}, [] { return false; }, 700ms);
  EXPECT_EQ(pa.stats().tombstones_pruned, 10u);
  EXPECT_EQ(pb.stats().tombstones_pruned, 10u);
  for (int i = 0; i < 5; ++i) {  // concurrent edits next to where the pruned entries were
    a.find<DArm>(arm.id())->edit_tools().insert(1, a.create<vsd::Node>());
    b.find<DArm>(arm.id())->edit_tools().insert(1, b.create<vsd::Node>());
    b.find<DArm>(arm.id())->edit_tools().erase(0);
    ASSERT_TRUE(pa.publish());
    ASSERT_TRUE(pb.publish());
    ASSERT_TRUE(poll_all({&pa, &pb}, [&] {
      return tools_of(a, arm.id()) == tools_of(b, arm.id()) &&
             tools_of(a, arm.id()).size() == 6u + static_cast<std::size_t>(i);
    }));
  }
  vsd::SimState& l = env_l.main_state();
  vsd::dist::Participant pl(l, options("late", domain));
  ASSERT_TRUE(poll_all({&pa, &pb, &pl}, [&] { return pl.synced(); }));
  std::string diff;
  EXPECT_TRUE(a.equals(l, &diff)) << diff;
  EXPECT_TRUE(a.equals(b, &diff)) << diff;
  EXPECT_EQ(pa.stats().resyncs + pb.stats().resyncs, 0u);
}

// Three processes edit one list at the same time (inserts at the front and in the middle, erasures): every
// process ends with the same list, holding every insertion nobody erased, with no resynchronisation.
TEST(DistProcesses, ThreeProcessesEditingOneListEndWithTheSameList) {
  const std::uint32_t domain = vsd_dist_test::fresh_domain();
  vsd::Environment env{1};
  vsd::SimState& s = env.main_state();
  auto& arm = s.create<DArm>();
  arm.set_name("arm");
  s.database().add_child(arm);
  std::vector<std::string> log;
  vsd::dist::Participant seed(s, options("seed", domain, true, &log));
  const std::string cmd =
      std::string("timeout 90 ") + VSD_DIST_PEER + " lister " + std::to_string(domain) + " 60 2>&1";
  FILE* a = ::popen(cmd.c_str(), "r");
  FILE* b = ::popen(cmd.c_str(), "r");
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  auto finished = [&] {
    int k = 0;
    for (auto* x : s.database().children()) k += x->name().rfind("finished-", 0) == 0 ? 1 : 0;
    return k;
  };
  int mine = 0;
  const auto end = std::chrono::steady_clock::now() + 60s;
  while (finished() < 2 && std::chrono::steady_clock::now() < end) {
    seed.poll();
    if (seed.peers() >= 2 && mine < 60) {  // edit while the listers do
      auto& n = s.create<vsd::Node>();
      arm.edit_tools().push_back(n);
      if (++mine % 5 == 0 && arm.tools().size() > 1) arm.edit_tools().erase(1);
    }
    std::this_thread::sleep_for(1ms);
  }
  EXPECT_EQ(finished(), 2) << "the listers did not finish";
  s.database().set_name("done");
  seed.poll_until([] { return false; }, 2s);
  std::string expected = "lister: tools";
  for (vsd::Node* x : arm.tools()) expected += " " + std::to_string(x->id());
  for (FILE* f : {a, b}) {
    std::string out;
    char buf[4096];
    while (std::fgets(buf, sizeof buf, f) != nullptr) out += buf;
    EXPECT_EQ(::pclose(f), 0) << out;
    EXPECT_NE(out.find(expected + "\n"), std::string::npos) << "a lister ended with another list:\n"
                                                            << out << "\nthe seed has\n"
                                                            << expected;
    EXPECT_NE(out.find("lister: resyncs 0,"), std::string::npos) << out;
  }
  EXPECT_GT(arm.tools().size(), 60u);  // 3 x 60 insertions, fewer than half of them erased
  EXPECT_EQ(seed.stats().resyncs, 0u);
}

}  // namespace
