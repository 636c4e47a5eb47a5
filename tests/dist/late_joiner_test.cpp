// Late joiners: a snapshot plus the bundles after it, with no gap and no duplicate, while a writer in
// another thread keeps changing the state.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "dist_test_util.hpp"

using namespace std::chrono_literals;
using vsd_dist_test::DArm;
using vsd_dist_test::options;

namespace {

// A writer thread with its own Environment, SimState and participant (the seed): it counts up on one arm,
// and now and then adds an arm, one bundle per step, until told to stop; then it keeps polling (to answer
// snapshot requests) until told to leave.
struct Writer {
  std::uint32_t domain;
  std::atomic<bool> stop{false}, stopped{false}, leave{false};
  std::atomic<int> count{0};
  std::atomic<vsd::Id> arm_id{0};
  std::thread thread;

  explicit Writer(std::uint32_t d) : domain(d) {
    thread = std::thread([this] { run(); });
  }
  ~Writer() {
    stop = leave = true;
    thread.join();
  }
  void run() {
    vsd::Environment env{10};
    vsd::SimState& s = env.main_state();
    auto& arm = s.create<DArm>();
    s.database().add_child(arm);
    vsd::dist::Participant p(s, options("writer", domain, true));
    arm_id = arm.id();
    while (!stop) {
      const int n = count + 1;
      arm.set_counter(n);
      arm.set_joints({n * 0.1, n * 0.2});
      if (n % 25 == 0) {
        auto& extra = s.create<DArm>();
        extra.set_counter(n);
        arm.add_child(extra);
      }
      p.poll();  // publishes the step's changes as one bundle, answers requests
      count = n;
      std::this_thread::sleep_for(200us);
    }
    stopped = true;
    while (!leave) {
      p.poll();
      std::this_thread::sleep_for(1ms);
    }
  }
};

void wait_for(const std::function<bool()>& f, std::chrono::milliseconds t) {
  const auto end = std::chrono::steady_clock::now() + t;
  while (!f() && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(1ms);
}

// Joins while the writer runs; checks that after the snapshot every counter value arrives once, in order.
void join_and_check(vsd::SimState& s, vsd::dist::Participant& p, Writer& w) {
  std::vector<int> seen;
  int at_sync = -1;
  auto on_sync = p.on_synced().connect([&] { at_sync = s.find<DArm>(w.arm_id.load())->counter(); });
  auto c = s.on_property_changed().connect([&](vsd::SimStateInstance& x, const vsd::MetaProperty& prop) {
    if (x.id() == w.arm_id.load() && prop.name() == "counter")
      seen.push_back(static_cast<DArm&>(x).counter());
  });
  ASSERT_TRUE(p.wait_synced(10s)) << "no snapshot";
  ASSERT_GT(at_sync, 0) << "the writer had not started";
  // Let the writer go on for a while after the join, then stop it and wait for its last bundle.
  const int target = w.count + 200;
  ASSERT_TRUE(p.poll_until([&] { return w.count >= target; }, 20s));
  w.stop = true;
  wait_for([&] { return w.stopped.load(); }, 10s);
  ASSERT_TRUE(w.stopped);
  const int last = w.count;
  ASSERT_TRUE(p.poll_until([&] { return s.find<DArm>(w.arm_id.load())->counter() == last; }, 20s))
      << "stuck at " << s.find<DArm>(w.arm_id.load())->counter() << " of " << last;
  // What arrived after the snapshot: each value exactly once, none skipped.
  std::vector<int> after;
  bool past = false;
  for (int v : seen) {
    if (v == at_sync) {
      past = true;
      continue;
    }
    if (past || v > at_sync) after.push_back(v);
  }
  ASSERT_FALSE(after.empty());
  EXPECT_EQ(after.front(), at_sync + 1);
  for (std::size_t i = 1; i < after.size(); ++i) ASSERT_EQ(after[i], after[i - 1] + 1) << "at " << i;
  EXPECT_EQ(after.back(), last);
  // The arms the writer added (one per 25 steps) are all there, once.
  EXPECT_EQ(s.find<DArm>(w.arm_id.load())->children().size(), static_cast<std::size_t>(last / 25));
  EXPECT_EQ(p.stats().resyncs, 0u);
}

TEST(LateJoiner, JoinsWhileTheWriterKeepsChanging) {
  const std::uint32_t domain = vsd_dist_test::fresh_domain();
  Writer w(domain);
  wait_for([&] { return w.count > 50; }, 10s);
  vsd::Environment env{11};
  vsd::dist::Participant p(env.main_state(), options("joiner", domain));
  join_and_check(env.main_state(), p, w);
}

TEST(LateJoiner, SnapshotFromAnotherReaderThenTheWritersStream) {
  // A reader joins first; the second joiner may take its snapshot from the reader or the writer, whose
  // views differ by the bundles in flight: duplicates are dropped, nothing is missed.
  const std::uint32_t domain = vsd_dist_test::fresh_domain();
  Writer w(domain);
  wait_for([&] { return w.count > 20; }, 10s);
  vsd::Environment env_r{12}, env_j{13};
  vsd::dist::Participant r(env_r.main_state(), options("reader", domain));
  ASSERT_TRUE(r.wait_synced(10s));
  vsd::dist::Participant j(env_j.main_state(), options("joiner", domain));
  std::atomic<bool> done{false};
  std::thread poller;  // keeps the reader answering while the joiner's checks run on this thread
  // (a SimState belongs to one thread: the reader's is used only by the poller from now on)
  poller = std::thread([&] {
    while (!done) {
      r.poll();
      std::this_thread::sleep_for(1ms);
    }
  });
  join_and_check(env_j.main_state(), j, w);
  done = true;
  poller.join();
  ASSERT_TRUE(r.poll_until(
      [&] { return env_r.main_state().find<DArm>(w.arm_id.load())->counter() == w.count; }, 10s));
  std::string diff;
  EXPECT_TRUE(env_r.main_state().equals(env_j.main_state(), &diff)) << diff;
}

}  // namespace
