// vsd_dist_peer: one side of the multi-process tests (loopback, network namespaces).
//
//   vsd_dist_peer writer DOMAIN N [--config URI]    the seed: counts arm.counter 1..N, one bundle per step,
//                                                   then waits until a reader says "done" (60 s at most)
//   vsd_dist_peer reader DOMAIN N [--config URI] [--die-after K]
//                                                   joins, checks that every counter value after its
//                                                   snapshot arrives once and in order up to N, says "done";
//                                                   with --die-after it exits abruptly after K values
//   vsd_dist_peer lister DOMAIN N [--config URI]    joins, inserts N nodes of its own into arm.tools (and
//                                                   erases entries) while the others do the same, adds a
//                                                   "finished-<pid>" node, then waits for the seed's "done"
//                                                   and for two "finished-" nodes, and prints the list
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "dist_test_util.hpp"

using namespace std::chrono_literals;
using vsd_dist_test::DArm;

namespace {

int writer(std::uint32_t domain, int n, const std::string& config) {
  vsd::Environment env{21};
  vsd::SimState& s = env.main_state();
  auto& arm = s.create<DArm>();
  arm.set_name("arm");
  s.database().add_child(arm);
  auto o = vsd_dist_test::options("writer", domain, true);
  o.config = config;
  o.log = [](std::string_view l) { std::printf("writer: %.*s\n", static_cast<int>(l.size()), l.data()); };
  vsd::dist::Participant p(s, o);
  // Start counting once somebody listens, so that the readers see the stream from its start or mid-way.
  if (!p.wait_peers(1, 30s)) {
    std::printf("writer: nobody joined\n");
    return 1;
  }
  for (int i = 1; i <= n; ++i) {
    arm.set_counter(i);
    p.poll();
    std::this_thread::sleep_for(300us);
  }
  std::printf("writer: counted to %d\n", n);
  std::fflush(stdout);
  const bool done = p.poll_until([&] { return s.database().name() == "done"; }, 60s);
  std::printf("writer: %s\n", done ? "a reader is done" : "no reader finished");
  return done ? 0 : 1;
}

int reader(std::uint32_t domain, int n, const std::string& config, int die_after) {
  vsd::Environment env{static_cast<std::uint16_t>(22 + (::getpid() % 1000))};
  vsd::SimState& s = env.main_state();
  auto o = vsd_dist_test::options("reader", domain);
  o.config = config;
  o.log = [](std::string_view l) { std::printf("reader: %.*s\n", static_cast<int>(l.size()), l.data()); };
  vsd::dist::Participant p(s, o);
  int at_sync = -1, received = 0, last = 0;
  bool in_order = true;
  DArm* arm = nullptr;
  auto c = s.on_property_changed().connect([&](vsd::SimStateInstance& x, const vsd::MetaProperty& prop) {
    if (&x != arm || prop.name() != "counter") return;
    const int v = static_cast<DArm&>(x).counter();
    if (v != last + 1) {
      std::printf("reader: got %d after %d\n", v, last);
      in_order = false;
    }
    last = v;
    ++received;
    if (die_after > 0 && received >= die_after) {
      std::printf("reader: dying after %d values\n", received);
      std::fflush(stdout);
      ::_exit(9);  // no goodbye: the others see the participant vanish
    }
  });
  if (!p.wait_synced(30s)) {
    std::printf("reader: no snapshot\n");
    return 1;
  }
  for (auto* x : s.database().children())
    if (auto* a = x->as<DArm>()) arm = a;
  if (arm == nullptr) {
    std::printf("reader: no arm in the snapshot\n");
    return 1;
  }
  at_sync = last = arm->counter();
  if (!p.poll_until([&] { return arm->counter() == n; }, 60s)) {
    std::printf("reader: stuck at %d of %d\n", arm->counter(), n);
    return 1;
  }
  s.database().set_name("done");
  p.poll_until([] { return false; }, 300ms);  // let the writer read it
  std::printf("reader: synced at %d, then %d values %s, final %d, resyncs %llu\n", at_sync, received,
              in_order ? "in order" : "OUT OF ORDER", arm->counter(),
              static_cast<unsigned long long>(p.stats().resyncs));
  return in_order && received == n - at_sync ? 0 : 1;
}

// One of two processes that edit the same list as the seed at the same time (DistProcesses).
int lister(std::uint32_t domain, int n, const std::string& config) {
  const int pid = static_cast<int>(::getpid());
  vsd::Environment env{static_cast<std::uint16_t>(100 + pid % 1000)};
  vsd::SimState& s = env.main_state();
  auto o = vsd_dist_test::options("lister-" + std::to_string(pid), domain);
  o.config = config;
  o.log = [](std::string_view l) { std::printf("lister: %.*s\n", static_cast<int>(l.size()), l.data()); };
  vsd::dist::Participant p(s, o);
  if (!p.wait_synced(30s)) {
    std::printf("lister: no snapshot\n");
    return 1;
  }
  DArm* arm = nullptr;
  for (auto* x : s.database().children())
    if (auto* a = x->as<DArm>()) arm = a;
  if (arm == nullptr) {
    std::printf("lister: no arm in the snapshot\n");
    return 1;
  }
  for (int i = 1; i <= n; ++i) {
    auto& node = s.create<vsd::Node>();
    node.set_name(std::to_string(pid) + "-" + std::to_string(i));
    arm->edit_tools().insert(std::min<std::size_t>(static_cast<std::size_t>(i % 3), arm->tools().size()),
                             node);
    if (i % 4 == 0) arm->edit_tools().erase(0);
    p.poll();
    std::this_thread::sleep_for(std::chrono::microseconds(200 + (pid % 7) * 100));
  }
  auto& marker = s.create<vsd::Node>();
  marker.set_name("finished-" + std::to_string(pid));
  s.database().add_child(marker);
  p.poll();
  auto finished = [&] {
    int k = 0;
    for (auto* x : s.database().children()) k += x->name().rfind("finished-", 0) == 0 ? 1 : 0;
    return k;
  };
  if (!p.poll_until([&] { return s.database().name() == "done" && finished() == 2; }, 60s)) {
    std::printf("lister: no 'done' from the seed (finished: %d)\n", finished());
    return 1;
  }
  std::string list;
  for (vsd::Node* x : arm->tools()) list += " " + std::to_string(x->id());
  std::printf("lister: tools%s\nlister: resyncs %llu, bundles that waited for another's %llu\n", list.c_str(),
              static_cast<unsigned long long>(p.stats().resyncs),
              static_cast<unsigned long long>(p.stats().bundles_waited));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr,
                 "usage: vsd_dist_peer writer|reader|lister DOMAIN N [--config URI] [--die-after K]\n");
    return 2;
  }
  const std::string mode = argv[1];
  const auto domain = static_cast<std::uint32_t>(std::atoi(argv[2]));
  const int n = std::atoi(argv[3]);
  std::string config = std::string("file://") + VSD_DIST_LOOPBACK_CONFIG;
  int die_after = 0;
  for (int i = 4; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--config") == 0) config = argv[i + 1];
    if (std::strcmp(argv[i], "--die-after") == 0) die_after = std::atoi(argv[i + 1]);
  }
  setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    if (mode == "writer") return writer(domain, n, config);
    if (mode == "reader") return reader(domain, n, config, die_after);
    if (mode == "lister") return lister(domain, n, config);
  } catch (const std::exception& e) {
    std::printf("%s: error: %s\n", mode.c_str(), e.what());
    return 1;
  }
  return 2;
}
