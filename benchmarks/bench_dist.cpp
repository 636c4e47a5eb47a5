// vsd_bench_dist: vsd::dist between two processes, side by side with raw Cyclone DDS samples of the same
// size and type in the same binary. The benchmark process starts a copy of itself as the peer ("--peer
// DOMAIN"), which applies what arrives and answers: a pong for each ping (round trip), an ack for every
// 1000th change (throughput). Both use the loopback configuration (no multicast) in a domain of their own.
//
//   vsd_bench_dist --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <dds/dds.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>
#include <vsd/dist/participant.hpp>
#include <vsd/dist/wire.hpp>
#include <vsd/vsd.hpp>

#include "vsd_dist.h"

extern char** environ;

namespace {

using namespace std::chrono_literals;

class BArm : public vsd::Node {
  VSD_INSTANCE(BArm, vsd::Node)
  VSD_PROPERTY(double, ping, 0.0)
  VSD_PROPERTY(double, pong, 0.0)
  VSD_PROPERTY(int, counter, 0)
  VSD_PROPERTY(int, ack, 0)
};

constexpr int ack_every = 1000;
enum RawKind : std::uint8_t { Ping = 1, Pong = 2, Data = 3, Ack = 4 };

vsd::dist::ParticipantOptions options(const char* name, std::uint32_t domain, bool seed) {
  vsd::dist::ParticipantOptions o;
  o.name = name;
  o.domain = domain;
  o.seed = seed;
  o.config = std::string("file://") + VSD_DIST_LOOPBACK_CONFIG;
  o.log = [](std::string_view) {};
  return o;
}

// Raw Cyclone DDS: the same message type and QoS as vsd::dist, on a topic of its own.
struct Raw {
  dds_entity_t participant = 0, writer = 0, reader = 0, waitset = 0;
  explicit Raw(std::uint32_t domain) {
    participant = dds_create_participant(domain, nullptr, nullptr);
    dds_qos_t* q = dds_create_qos();
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
    dds_qset_ignorelocal(q, DDS_IGNORELOCAL_PARTICIPANT);
    const dds_entity_t topic =
        dds_create_topic(participant, &vsd_dist_Message_desc, "vsd_bench_raw", q, nullptr);
    writer = dds_create_writer(participant, topic, q, nullptr);
    reader = dds_create_reader(participant, topic, q, nullptr);
    dds_delete_qos(q);
    // Waiting sleeps on the reader, as vsd::dist's poll_until() does on its own.
    waitset = dds_create_waitset(participant);
    dds_waitset_attach(waitset, dds_create_readcondition(reader, DDS_ANY_STATE), 0);
  }
  // Sleeps until data is there to take, or @p at_most passes.
  void wait(std::chrono::milliseconds at_most) const {
    dds_attach_t triggered = 0;
    (void)dds_waitset_wait(waitset, &triggered, 1, DDS_MSECS(at_most.count()));
  }
  ~Raw() { dds_delete(participant); }
  void write(std::uint8_t kind, std::uint64_t seq, std::vector<std::uint8_t>& payload) const {
    vsd_dist_Message m{};
    m.seq = seq;
    m.kind = kind;
    m.payload._buffer = payload.data();
    m.payload._length = m.payload._maximum = static_cast<std::uint32_t>(payload.size());
    dds_write(writer, &m);
  }
  // With the configuration's write batching, samples leave here (vsd::dist: in poll() and poll_until()).
  void flush() const { dds_write_flush(writer); }
  // Takes everything that arrived (in batches of 64, as vsd::dist does); calls f(kind, seq) for each.
  template <class F>
  void take(F&& f) const {
    for (;;) {
      void* samples[64] = {};
      dds_sample_info_t infos[64];
      const int n = dds_take(reader, samples, infos, 64, 64);
      for (int i = 0; i < n; ++i)
        if (infos[i].valid_data) {
          const auto* m = static_cast<const vsd_dist_Message*>(samples[i]);
          f(m->kind, m->seq);
        }
      if (n > 0) dds_return_loan(reader, samples, n);
      if (n < 64) return;
    }
  }
  std::size_t matched() const {
    dds_publication_matched_status_t st{};
    dds_get_publication_matched_status(writer, &st);
    return st.current_count;
  }
};

// The size of the vsd::dist sample payload for one property change (envelope + wire bundle).
std::size_t one_change_payload() {
  vsd::Environment env{9};
  auto& arm = env.main_state().create<BArm>();
  env.main_state().start_recording();
  arm.set_counter(12345);
  return 5 + vsd::dist::encode_bundle(env.main_state().stop_recording(), env.main_state()).bytes.size();
}

// ---- the peer process ----------------------------------------------------------------------------------

int peer(std::uint32_t domain) {
  vsd::Environment env{2};
  vsd::SimState& s = env.main_state();
  vsd::dist::Participant p(s, options("peer", domain, false));
  Raw raw(domain);
  std::vector<std::uint8_t> payload(one_change_payload(), 0xab);
  if (!p.wait_synced(30s)) return 1;
  BArm* arm = nullptr;
  for (auto* n : s.database().children())
    if (auto* a = n->as<BArm>()) arm = a;
  if (arm == nullptr) return 1;
  // Nothing here spins: the raw echo sleeps on its reader in a thread of its own, the vsd::dist side in
  // poll_until() on the participant's (on 2 loaded cores a spinning peer takes the CPU from Cyclone's own
  // receive and delivery threads, which both sides need).
  std::atomic<bool> stop{false};
  std::thread echo([&] {
    while (!stop) {
      raw.take([&](std::uint8_t kind, std::uint64_t seq) {
        if (kind == Ping) raw.write(Pong, seq, payload);
        if (kind == Data && seq % ack_every == 0) raw.write(Ack, seq, payload);
      });
      raw.flush();
      raw.wait(20ms);
    }
  });
  const auto end = std::chrono::steady_clock::now() + 300s;
  p.poll_until(
      [&] {
        bool changed = false;
        if (arm->pong() != arm->ping()) {
          arm->set_pong(arm->ping());
          changed = true;
        }
        if (arm->counter() % ack_every == 0 && arm->ack() != arm->counter()) {
          arm->set_ack(arm->counter());
          changed = true;
        }
        if (changed) p.publish();
        return std::chrono::steady_clock::now() >= end || ::getppid() == 1;
      },
      300s);
  stop = true;
  echo.join();
  return 0;
}

// ---- the benchmark process -------------------------------------------------------------------------------

struct Session {
  std::uint32_t domain = 120 + static_cast<std::uint32_t>(::getpid() % 100);
  vsd::Environment env{1};
  vsd::SimState& s = env.main_state();
  BArm& arm = s.create<BArm>();
  std::unique_ptr<vsd::dist::Participant> p;
  std::unique_ptr<Raw> raw;
  std::vector<std::uint8_t> payload = std::vector<std::uint8_t>(one_change_payload(), 0xab);
  pid_t child = 0;
  std::uint64_t raw_seq = 0;
  bool ok = false;

  Session(const char* self) {
    s.database().add_child(arm);
    p = std::make_unique<vsd::dist::Participant>(s, options("bench", domain, true));
    raw = std::make_unique<Raw>(domain);
    const std::string d = std::to_string(domain);
    std::string exe = self, flag = "--peer";
    char* argv[] = {exe.data(), flag.data(), const_cast<char*>(d.c_str()), nullptr};
    if (posix_spawn(&child, self, nullptr, nullptr, argv, environ) != 0) return;
    // The peer has joined when it answered the ping (from its snapshot, or the bundle if it joined
    // first) and its raw reader and writer are matched. One ping only: a new one on every poll would stay
    // one ahead of the answers, which arrive while poll_until() sleeps.
    arm.set_ping(arm.ping() + 1);
    p->publish();
    ok = p->poll_until([&] { return arm.pong() == arm.ping() && raw->matched() >= 1; }, 30s);
  }
  ~Session() {
    p.reset();
    raw.reset();
    if (child > 0) {
      ::kill(child, SIGTERM);
      ::waitpid(child, nullptr, 0);
    }
  }
};

Session* session = nullptr;

// Calls @p poll until @p done, sleeping in @p wait (on the reader's data) in between; false (and the
// benchmark skipped with an error) after 30 s. Neither side spins (see peer()).
template <class Poll, class Done, class Wait>
bool wait_for(benchmark::State& st, Poll&& poll, Done&& done, Wait&& wait) {
  const auto end = std::chrono::steady_clock::now() + 30s;
  for (;;) {
    poll();
    if (done()) return true;
    if (std::chrono::steady_clock::now() > end) {
      st.SkipWithError("the peer did not answer within 30 s");
      return false;
    }
    wait();
  }
}
// Spins on @p poll until @p done (the in-process pairs: one thread serves both sides, so it cannot sleep
// on one side's reader); false after 30 s.
template <class Poll, class Done>
bool spin(benchmark::State& st, Poll&& poll, Done&& done) {
  const auto end = std::chrono::steady_clock::now() + 30s;
  while (!done()) {
    poll();
    if (std::chrono::steady_clock::now() > end) {
      st.SkipWithError("the peer did not answer within 30 s");
      return false;
    }
  }
  return true;
}
// vsd::dist: poll_until() polls and sleeps on the participant's reader.
template <class Done>
bool wait_for(benchmark::State& st, vsd::dist::Participant& p, Done&& done) {
  if (p.poll_until(done, 30s)) return true;
  st.SkipWithError("the peer did not answer within 30 s");
  return false;
}

void BM_DistRoundTrip(benchmark::State& st) {
  Session& x = *session;
  for (auto _ : st) {
    const double v = x.arm.ping() + 1;
    x.arm.set_ping(v);
    x.p->publish();
    if (!wait_for(st, *x.p, [&] { return x.arm.pong() == v; })) break;
  }
  st.counters["payload_bytes"] = static_cast<double>(x.payload.size());
}

void BM_RawDdsRoundTrip(benchmark::State& st) {
  Session& x = *session;
  for (auto _ : st) {
    const std::uint64_t seq = ++x.raw_seq;
    x.raw->write(Ping, seq, x.payload);
    x.raw->flush();
    bool back = false;
    if (!wait_for(
            st,
            [&] {
              x.raw->take([&](std::uint8_t kind, std::uint64_t s) { back |= kind == Pong && s == seq; });
            },
            [&] { return back; }, [&] { x.raw->wait(20ms); }))
      break;
  }
  st.counters["payload_bytes"] = static_cast<double>(x.payload.size());
}

// One property change per bundle (one sample each), acknowledged by the peer every 1000 changes.
void BM_DistChangesPerSecond(benchmark::State& st) {
  Session& x = *session;
  for (auto _ : st) {
    for (int i = 0; i < ack_every; ++i) {
      x.arm.set_counter(x.arm.counter() + 1);
      x.p->publish();
    }
    const int want = x.arm.counter();
    if (!wait_for(st, *x.p, [&] { return x.arm.ack() == want; })) break;
  }
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations()) * ack_every);
}

void BM_RawDdsSamplesPerSecond(benchmark::State& st) {
  Session& x = *session;
  for (auto _ : st) {
    x.raw_seq = x.raw_seq / ack_every * ack_every;  // the batch ends on a multiple of ack_every
    for (int i = 0; i < ack_every; ++i) x.raw->write(Data, ++x.raw_seq, x.payload);
    x.raw->flush();  // as vsd::dist's poll_until() does before it waits
    const std::uint64_t want = x.raw_seq;
    bool acked = false;
    auto take = [&] {
      x.raw->take([&](std::uint8_t kind, std::uint64_t s) { acked |= kind == Ack && s == want; });
    };
    if (!wait_for(
            st, take, [&] { return acked; }, [&] { x.raw->wait(20ms); }))
      break;
  }
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations()) * ack_every);
}

// Many changes per bundle (a step of a simulation changes many properties): 100 sets, one sample.
void BM_DistChangesPerSecondBatched(benchmark::State& st) {
  Session& x = *session;
  for (auto _ : st) {
    for (int b = 0; b < ack_every / 100; ++b) {
      for (int i = 0; i < 100; ++i) x.arm.set_counter(x.arm.counter() + 1);
      x.p->publish();
    }
    const int want = x.arm.counter();
    if (!wait_for(st, *x.p, [&] { return x.arm.ack() == want; })) break;
  }
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations()) * ack_every);
}

// The same round trips between two participants in this process (Cyclone delivers locally, no network):
// what vsd::dist itself costs per round trip (two bundles recorded, encoded, decoded and applied).
void BM_DistRoundTripInProcess(benchmark::State& st) {
  Session& x = *session;
  vsd::Environment env_b{3};
  vsd::dist::ParticipantOptions o = options("local", x.domain, false);
  vsd::dist::Participant pb(env_b.main_state(), o);
  if (!spin(
          st,
          [&] {
            x.p->poll();
            pb.poll();
          },
          [&] { return pb.synced(); }))
    return;
  BArm* b = env_b.main_state().find<BArm>(x.arm.id());
  for (auto _ : st) {
    const double v = x.arm.ping() + 1;
    x.arm.set_ping(v);
    x.p->publish();
    x.p->flush();
    if (!spin(
            st, [&] { pb.poll(); }, [&] { return b->ping() == v; }))
      break;
    b->set_pong(v);
    pb.publish();
    pb.flush();
    if (!wait_for(st, *x.p, [&] { return x.arm.pong() == v; })) break;
  }
}

void BM_RawDdsRoundTripInProcess(benchmark::State& st) {
  Session& x = *session;
  Raw echo(x.domain);  // a second participant here; the peer process answers too, so count our pongs only
  std::vector<std::uint8_t> payload = x.payload;
  if (!spin(
          st, [] {}, [&] { return echo.matched() >= 2; }))
    return;
  for (auto _ : st) {
    const std::uint64_t seq = ++x.raw_seq;
    x.raw->write(Data, seq, payload);  // Data: the peer process acks only multiples of 1000, never these
    x.raw->flush();
    bool got = false;
    if (!spin(
            st, [&] { echo.take([&](std::uint8_t k, std::uint64_t s) { got |= k == Data && s == seq; }); },
            [&] { return got; }))
      break;
    echo.write(Pong, seq, payload);
    echo.flush();
    bool back = false;
    if (!spin(
            st, [&] { x.raw->take([&](std::uint8_t k, std::uint64_t s) { back |= k == Pong && s == seq; }); },
            [&] { return back; }))
      break;
  }
}

BENCHMARK(BM_DistRoundTrip)->UseRealTime();
BENCHMARK(BM_RawDdsRoundTrip)->UseRealTime();
BENCHMARK(BM_DistChangesPerSecond)->UseRealTime();
BENCHMARK(BM_RawDdsSamplesPerSecond)->UseRealTime();
BENCHMARK(BM_DistChangesPerSecondBatched)->UseRealTime();
BENCHMARK(BM_DistRoundTripInProcess)->UseRealTime();
BENCHMARK(BM_RawDdsRoundTripInProcess)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::strcmp(argv[1], "--peer") == 0)
    return peer(static_cast<std::uint32_t>(std::atoi(argv[2])));
  benchmark::Initialize(&argc, argv);
  Session s(argv[0]);
  if (!s.ok) {
    std::fprintf(stderr, "vsd_bench_dist: the peer process did not join\n");
    return 1;
  }
  session = &s;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  session = nullptr;
  return 0;
}
