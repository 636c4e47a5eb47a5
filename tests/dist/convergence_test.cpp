// Races between participants, each on its own thread with its own Environment: concurrent writes to the
// same unowned properties and concurrent claims of the same property end alike on every replica (the
// stamp order of docs/dist.md), and the losers are told.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <random>
#include <set>
#include <thread>
#include <vsd/io/snapshot.hpp>

#include "dist_test_util.hpp"

using namespace std::chrono_literals;
using vsd_dist_test::DArm;
using vsd_dist_test::options;

namespace {

constexpr int n_participants = 3;

// What every thread reports after a round, read by the main thread after the round's last barrier.
struct RoundResult {
  std::vector<std::uint8_t> bytes;  // vsd::io binary snapshot of the replica
  double target = 0;
  std::vector<double> joints;
  std::uint64_t owner = 0;
};

// A barrier whose waiters keep polling their participant (the others may need their answers to get
// there).
class PollingBarrier {
 public:
  explicit PollingBarrier(int n) : n_(n) {}
  void arrive_and_wait(vsd::dist::Participant& p) {
    const int gen = generation_.load();
    if (++arrived_ == n_) {
      arrived_ = 0;
      ++generation_;
      return;
    }
    while (generation_.load() == gen) {
      p.poll();
      std::this_thread::sleep_for(200us);
    }
  }
  /// Waits without polling, so nothing another participant sends after the barrier opens can be taken in
  /// before this thread acts: for actions that all must take before any sees another's (racing claims).
  /// Safe only where nobody waits for data to arrive.
  void arrive_and_wait_quietly() {
    const int gen = generation_.load();
    if (++arrived_ == n_) {
      arrived_ = 0;
      ++generation_;
      return;
    }
    while (generation_.load() == gen) std::this_thread::sleep_for(50us);
  }

 private:
  const int n_;
  std::atomic<int> arrived_{0}, generation_{0};
};

// Runs @p rounds rounds of @p body on n_participants threads, each with its own participant; the first is
// the seed and makes the model (one arm). Between rounds every replica settles (@p settled) and reports.
struct Race {
  std::uint32_t domain = vsd_dist_test::fresh_domain();
  PollingBarrier sync{n_participants};
  std::mutex mutex;
  std::vector<std::string> failures;  // written by the threads, asserted by the main thread
  std::array<std::atomic<std::uint64_t>, n_participants> sent{};
  std::array<std::uint64_t, n_participants> ids{};
  std::array<RoundResult, n_participants> results;
  std::atomic<vsd::Id> arm_id{0};

  void fail(const std::string& what) {
    std::lock_guard lock(mutex);
    failures.push_back(what);
    if (std::getenv("VSD_DIST_TEST_VERBOSE") != nullptr) std::fprintf(stderr, "FAIL %s\n", what.c_str());
  }
};

// Polls @p p until @p done, at most 20 s; false on timeout.
bool poll_until(vsd::dist::Participant& p, const std::function<bool()>& done) {
  return p.poll_until(done, 20s);
}

TEST(ConcurrentWrites, ThreadsWritingTheSameUnownedPropertiesConvergeAndTheLosersAreTold) {
  constexpr int rounds = 60;
  Race race;
  std::array<int, n_participants> told_lost{};    // rounds in which a participant's set lost and it was told
  std::array<int, n_participants> lost_rounds{};  // rounds in which a participant's value did not survive
  std::array<int, n_participants> won_rounds{};
  std::atomic<int> equal_rounds{0};

  auto run = [&](int k) {
    vsd::Environment env{static_cast<std::uint16_t>(30 + k)};
    vsd::SimState& s = env.main_state();
    if (k == 0) {
      auto& arm = s.create<DArm>();
      arm.set_name("arm");
      s.database().add_child(arm);
      race.arm_id = arm.id();
    }
    vsd::dist::Participant p(s, options("w" + std::to_string(k), race.domain, k == 0));
    race.ids[static_cast<std::size_t>(k)] = p.id();
    std::set<std::uint64_t> told;  // my bundle sequence numbers that lost a set
    auto c = p.on_conflict().connect([&](const vsd::dist::Conflict& x) {
      if (x.kind == vsd::dist::ConflictKind::ConcurrentWrite && x.writer == p.id()) told.insert(x.seq);
    });
    if (!p.wait_synced(20s)) race.fail("w" + std::to_string(k) + ": no snapshot");
    race.sync.arrive_and_wait(p);  // everyone synchronised
    std::mt19937 rng(static_cast<unsigned>(k) * 7919U + 1U);
    DArm* arm = s.find<DArm>(race.arm_id.load());
    if (arm == nullptr) {
      race.fail("w" + std::to_string(k) + ": no arm");
      return;
    }
    auto all_applied = [&] {
      std::uint64_t others = 0;
      for (int j = 0; j < n_participants; ++j)
        if (j != k) others += race.sent[static_cast<std::size_t>(j)].load();
      return p.stats().bundles_applied == others;
    };
    for (int r = 1; r <= rounds; ++r) {
      // Nobody writes before everyone is here, and nobody polls until its own writes are out: a writer that
      // took in another's bundle of this round first would write after it, not concurrently (a plain
      // overwrite, which nobody is told of, rightly).
      race.sync.arrive_and_wait_quietly();
      // 0-2 bundles of my own first (on a property nobody else writes this round), so that the clocks, and
      // with them the winners, differ from round to round.
      for (int extra = static_cast<int>(rng() % 3); extra > 0; --extra) {
        arm->set_counter(arm->counter() + 1);  // everyone touches counter too: more races, all must settle
        p.publish();
      }
      const double mine = r * 10.0 + k;
      arm->set_target(mine);
      arm->set_joints({mine, -mine});
      arm->set_position(mine);
      if (!p.publish()) race.fail("round " + std::to_string(r) + ": nothing published");
      const std::uint64_t my_seq = p.stats().bundles_sent;
      race.sent[static_cast<std::size_t>(k)] = p.stats().bundles_sent;
      race.sync.arrive_and_wait(p);  // every write of the round is made and sent before anyone sees another
      if (!poll_until(p, all_applied))
        race.fail("w" + std::to_string(k) + " round " + std::to_string(r) + ": bundles missing");
      race.sync.arrive_and_wait(p);  // everyone applied everything
      auto& res = race.results[static_cast<std::size_t>(k)];
      res.bytes = vsd::io::save_bytes(s);
      res.target = arm->target();
      res.joints = arm->joints();
      race.sync.arrive_and_wait(p);
      if (k == 0) {
        bool equal = true;
        for (int j = 1; j < n_participants; ++j)
          equal = equal && race.results[static_cast<std::size_t>(j)].bytes == res.bytes;
        if (equal)
          ++equal_rounds;
        else
          race.fail("round " + std::to_string(r) + ": replicas differ");
      }
      // The value that survived is one participant's, whole: target, joints and position from one bundle.
      const double final_target = res.target;
      if (res.joints != std::vector<double>{final_target, -final_target} || arm->position() != final_target)
        race.fail("round " + std::to_string(r) + ": a bundle was half applied");
      if (final_target == mine) {
        ++won_rounds[static_cast<std::size_t>(k)];
      } else {
        ++lost_rounds[static_cast<std::size_t>(k)];
        // The winner tells me (its report may still be on its way).
        if (poll_until(p, [&] { return told.count(my_seq) != 0; })) ++told_lost[static_cast<std::size_t>(k)];
      }
      race.sync.arrive_and_wait(p);
    }
    // Keep answering while the others finish.
    race.sync.arrive_and_wait(p);
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < n_participants; ++k) threads.emplace_back(run, k);
  for (auto& t : threads) t.join();
  for (const auto& f : race.failures) ADD_FAILURE() << f;
  EXPECT_EQ(equal_rounds.load(), rounds);
  int total_won = 0;
  for (int k = 0; k < n_participants; ++k) {
    total_won += won_rounds[static_cast<std::size_t>(k)];
    EXPECT_EQ(told_lost[static_cast<std::size_t>(k)], lost_rounds[static_cast<std::size_t>(k)])
        << "w" << k << " was not told of every lost write";
  }
  EXPECT_EQ(total_won, rounds);  // exactly one winner per round
  // The winners vary (the clocks differ from round to round): not always the same participant.
  int winners = 0;
  for (int k = 0; k < n_participants; ++k) winners += won_rounds[static_cast<std::size_t>(k)] > 0 ? 1 : 0;
  EXPECT_GE(winners, 2);
}

TEST(ConcurrentClaims, RacingClaimsEndWithOneOwnerEverywhereAndTheLosersRolledBack) {
  constexpr int rounds = 30;
  Race race;
  std::array<int, n_participants> told{}, lost{}, won{};
  std::atomic<int> agreed{0};

  auto run = [&](int k) {
    vsd::Environment env{static_cast<std::uint16_t>(40 + k)};
    vsd::SimState& s = env.main_state();
    if (k == 0) {
      auto& arm = s.create<DArm>();
      s.database().add_child(arm);
      race.arm_id = arm.id();
    }
    vsd::dist::Participant p(s, options("c" + std::to_string(k), race.domain, k == 0));
    race.ids[static_cast<std::size_t>(k)] = p.id();
    int claim_conflicts = 0;
    auto c = p.on_conflict().connect([&](const vsd::dist::Conflict& x) {
      if (x.kind == vsd::dist::ConflictKind::ClaimRace && x.writer == p.id()) ++claim_conflicts;
    });
    if (!p.wait_synced(20s)) race.fail("c" + std::to_string(k) + ": no snapshot");
    race.sync.arrive_and_wait(p);
    std::mt19937 rng(static_cast<unsigned>(k) * 104729U + 3U);
    DArm* arm = s.find<DArm>(race.arm_id.load());
    if (arm == nullptr) {
      race.fail("no arm");
      return;
    }
    const std::uint64_t expected_lost_per_round = n_participants - 1;
    for (int r = 1; r <= rounds; ++r) {
      for (int extra = static_cast<int>(rng() % 3); extra > 0; --extra) {
        arm->set_counter(arm->counter() + 1);
        p.publish();
      }
      // Nobody claims before everyone is here, and nobody polls in between: a claim that arrived first
      // would make the later local claim a plain error (owned by another) instead of a race.
      race.sync.arrive_and_wait_quietly();
      const int before = claim_conflicts;
      const bool instance_claim = r % 3 == 0;  // every third round races for the whole instance
      if (p.owner(arm->id(), "target") != 0) race.fail("round " + std::to_string(r) + ": still owned");
      if (instance_claim)
        p.claim(*arm);
      else
        p.claim(*arm, "target");  // everyone claims at once: it succeeds locally everywhere ...
      if (p.owner(arm->id(), "target") != p.id()) race.fail("a local claim did not take");
      race.sync.arrive_and_wait(p);
      // Every participant sees every claim and counts each lost one once.
      if (!poll_until(p, [&] {
            return p.synced() && p.stats().claims_lost >= expected_lost_per_round * static_cast<unsigned>(r);
          }))
        race.fail("c" + std::to_string(k) + " round " + std::to_string(r) + ": claims did not settle");
      race.sync.arrive_and_wait(p);
      // Everyone agrees on the owner; the replicas settle on the owner's value (resyncs included).
      const std::uint64_t owner = p.owner(arm->id(), "target");
      race.results[static_cast<std::size_t>(k)].owner = owner;
      race.sync.arrive_and_wait(p);
      std::size_t winner = n_participants;
      for (std::size_t j = 0; j < n_participants; ++j)
        if (race.ids[j] == race.results[0].owner) winner = j;
      if (owner != race.results[0].owner || winner == n_participants) {
        race.fail("round " + std::to_string(r) + ": owners differ");
      } else if (k == 0) {
        ++agreed;
      }
      if (owner == p.id()) {
        ++won[static_cast<std::size_t>(k)];
      } else {
        ++lost[static_cast<std::size_t>(k)];
        if (claim_conflicts == before + 1) ++told[static_cast<std::size_t>(k)];
      }
      arm = s.find<DArm>(race.arm_id.load());  // a resync replaced the instances
      race.sync.arrive_and_wait(p);
      // Compare the replicas, then the owner gives the property back for the next round.
      race.results[static_cast<std::size_t>(k)].bytes = vsd::io::save_bytes(s);
      race.sync.arrive_and_wait(p);
      if (race.results[static_cast<std::size_t>(k)].bytes != race.results[0].bytes)
        race.fail("c" + std::to_string(k) + " round " + std::to_string(r) + ": replica differs");
      if (owner == p.id()) {
        if (instance_claim)
          p.release(*arm);
        else
          p.release(*arm, "target");
      }
      if (!poll_until(p, [&] { return p.owner(arm->id(), "target") == 0; }))
        race.fail("c" + std::to_string(k) + " round " + std::to_string(r) + ": release not seen");
      race.sync.arrive_and_wait(p);
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < n_participants; ++k) threads.emplace_back(run, k);
  for (auto& t : threads) t.join();
  for (const auto& f : race.failures) ADD_FAILURE() << f;
  EXPECT_EQ(agreed.load(), rounds);
  int total_won = 0;
  for (std::size_t k = 0; k < n_participants; ++k) {
    total_won += won[k];
    EXPECT_EQ(told[k], lost[k]) << "c" << k << " was not told of every lost claim";
  }
  EXPECT_EQ(total_won, rounds);
}

// Every participant claims the arm's target (or the whole arm) at once and writes it right away, before it
// could know of the others' claims: the writes made under the claims that lose are writes to what the
// winner owns. Every replica must end with the winner's value, the losers' writes rejected and reported.
TEST(ConcurrentClaims, WritesUnderALosingClaimAreRejectedAndAllReplicasConverge) {
  constexpr int rounds = 60;
  Race race;
  std::array<std::atomic<std::uint64_t>, n_participants> write_seq{};  // this round's claimed write
  std::array<int, n_participants> won{}, told{};
  std::atomic<int> agreed{0};

  auto run = [&](int k) {
    const auto me = static_cast<std::size_t>(k);
    vsd::Environment env{static_cast<std::uint16_t>(50 + k)};
    vsd::SimState& s = env.main_state();
    if (k == 0) {
      auto& arm = s.create<DArm>();
      s.database().add_child(arm);
      race.arm_id = arm.id();
    }
    auto o = options("u" + std::to_string(k), race.domain, k == 0);
    // VSD_DIST_TEST_VERBOSE=1: every participant's log and every failure on stderr as they happen (the
    // order of events is what tells a race apart).
    if (std::getenv("VSD_DIST_TEST_VERBOSE") != nullptr)
      o.log = [k](std::string_view l) {
        std::fprintf(stderr, "u%d: %.*s\n", k, static_cast<int>(l.size()), l.data());
      };
    vsd::dist::Participant p(s, o);
    race.ids[me] = p.id();
    std::set<std::uint64_t> my_rejected;                           // my bundles rejected as Owned
    std::set<std::pair<std::uint64_t, std::uint64_t>> i_rejected;  // (writer, seq) rejected as the owner
    auto c = p.on_conflict().connect([&](const vsd::dist::Conflict& x) {
      if (x.kind != vsd::dist::ConflictKind::Owned) return;
      if (x.writer == p.id()) my_rejected.insert(x.seq);
      if (x.owner == p.id()) i_rejected.insert({x.writer, x.seq});
    });
    if (!p.wait_synced(20s)) race.fail("u" + std::to_string(k) + ": no snapshot");
    race.sync.arrive_and_wait(p);
    std::mt19937 rng(static_cast<unsigned>(k) * 15485863U + 5U);
    const std::string who = "u" + std::to_string(k);
    for (int r = 1; r <= rounds; ++r) {
      const std::string at = who + " round " + std::to_string(r) + ": ";
      DArm* arm = s.find<DArm>(race.arm_id.load());  // a resync replaces the instances
      if (arm == nullptr) {
        race.fail(at + "no arm");
        return;
      }
      // Varying clocks, so that the winner varies.
      for (int extra = static_cast<int>(rng() % 3); extra > 0; --extra) {
        arm->set_counter(arm->counter() + 1);
        p.publish();
      }
      race.sync.arrive_and_wait_quietly();  // nobody sees another's claim before making its own
      const bool instance_claim = r % 3 == 0;
      if (instance_claim)
        p.claim(*arm);
      else
        p.claim(*arm, "target");
      const double mine = r * 10.0 + k;
      arm->set_target(mine);
      arm->set_joints({mine, -mine});  // with target: the bundle must stay whole or go whole
      if (!p.publish()) race.fail(at + "the claimed write was not published");
      write_seq[me] = p.stats().bundles_sent + p.stats().claims_sent;
      race.sync.arrive_and_wait(p);
      // The claims settle alike everywhere ...
      if (!poll_until(p, [&] {
            return p.synced() && p.stats().claims_lost >= (n_participants - 1) * static_cast<unsigned>(r);
          }))
        race.fail(at + "claims did not settle");
      const std::uint64_t owner = p.owner(race.arm_id.load(), "target");
      std::size_t winner = n_participants;
      for (std::size_t j = 0; j < n_participants; ++j)
        if (race.ids[j] == owner) winner = j;
      if (winner == n_participants) {
        race.fail(at + "nobody owns the target");
        return;
      }
      const double winning = r * 10.0 + static_cast<double>(winner);
      // ... the winner rejects every loser's write, every loser is told, and everyone holds the winner's
      // value.
      const bool done = poll_until(p, [&] {
        if (winner == me) {
          for (std::size_t j = 0; j < n_participants; ++j)
            if (j != me && i_rejected.count({race.ids[j], write_seq[j].load()}) == 0) return false;
        } else if (my_rejected.count(write_seq[me].load()) == 0) {
          return false;
        }
        const DArm* a = s.find<DArm>(race.arm_id.load());
        return p.synced() && a != nullptr && a->target() == winning;
      });
      if (!done) race.fail(at + "did not settle on the winner's value " + std::to_string(winning));
      if (winner == me)
        ++won[me];
      else if (my_rejected.count(write_seq[me].load()) != 0)
        ++told[me];
      race.results[me].owner = owner;
      race.sync.arrive_and_wait(p);
      if (owner != race.results[0].owner) race.fail(at + "owners differ");
      race.results[me].bytes = vsd::io::save_bytes(s);
      race.sync.arrive_and_wait(p);
      if (race.results[me].bytes != race.results[0].bytes)
        race.fail(at + "replica differs");
      else if (k == 0)
        ++agreed;
      arm = s.find<DArm>(race.arm_id.load());
      if (arm != nullptr && arm->joints() != std::vector<double>{winning, -winning})
        race.fail(at + "a bundle was half applied");
      if (owner == p.id() && arm != nullptr) {
        if (instance_claim)
          p.release(*arm);
        else
          p.release(*arm, "target");
      }
      if (!poll_until(p, [&] { return p.synced() && p.owner(race.arm_id.load(), "target") == 0; }))
        race.fail(at + "release not seen");
      race.sync.arrive_and_wait(p);
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < n_participants; ++k) threads.emplace_back(run, k);
  for (auto& t : threads) t.join();
  for (const auto& f : race.failures) ADD_FAILURE() << f;
  EXPECT_EQ(agreed.load(), rounds);
  int total_won = 0;
  for (std::size_t k = 0; k < n_participants; ++k) {
    total_won += won[k];
    EXPECT_EQ(told[k] + won[k], rounds) << "u" << k << " was not told of every rejected write";
  }
  EXPECT_EQ(total_won, rounds);
}

}  // namespace
