// State-space exploration and the token game of vsd::analysis.
//
//   BM_Explore_Mcc/<model>/<threads>  full exploration of one of the eight MCC nets (tests/analysis/data)
//   BM_Explore_Ring/<n>/<k>/<threads> the ring family (n places, k tokens): C(n+k-1, k) states and
//                                     n*C(n+k-2, k-1) firings, checked against the closed form every run;
//                                     16/8 has 490 314 states (1, 2 and, on 4 or more cores, 4 threads),
//                                     25/8 10 518 300 states and 65 739 375 firings
//   BM_TokenGame/<model>              random firings of the token game (a dead marking restarts the game)
//
// Reported: states/s and edges/s per second of CPU time of the whole process (MeasureProcessCPUTime), i.e.
// per core busy, whatever the thread count: on a shared machine wall time measures the other users too
// (the wall time is printed as well); peak_MiB is the explorer's own accounting of its data
// (arena, hash set, frontier buffers), VmHWM_MiB the process's high-water mark during the benchmark
// (reset through /proc/self/clear_refs before it; "reset" is 0 where the kernel refused).
#include <benchmark/benchmark.h>

#include <fstream>
#include <map>
#include <string>
#include <thread>

#include "vsd/analysis.hpp"

namespace {

namespace an = vsd::analysis;

const char* const kModels[] = {
    "ResAllocation-PT-R002C002", "Eratosthenes-PT-010", "TokenRing-PT-005", "Philosophers-PT-000005",
    "SharedMemory-PT-000005",    "FMS-PT-00002",        "Dekker-PT-010",    "Peterson-PT-2"};

const an::PtNet& mcc(int index) {
  static std::map<int, an::PtNet> cache;
  auto it = cache.find(index);
  if (it == cache.end())
    it =
        cache
            .emplace(index,
                     an::read_pnml_file(std::string(VSD_BENCH_PNML_DIR) + "/" + kModels[index] + ".pnml").net)
            .first;
  return it->second;
}

an::PtNet ring(unsigned n, unsigned k) {
  an::PtNet net("ring");
  for (unsigned i = 0; i < n; ++i) net.add_place("p" + std::to_string(i), {}, i == 0 ? k : 0);
  for (unsigned i = 0; i < n; ++i) {
    const auto t = net.add_transition("t" + std::to_string(i));
    net.add_input(t, i);
    net.add_output(t, (i + 1) % n);
  }
  return net;
}

std::uint64_t binomial(std::uint64_t n, std::uint64_t k) {
  std::uint64_t r = 1;
  for (std::uint64_t i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

bool reset_peak() {
  std::ofstream out("/proc/self/clear_refs");
  out << "5";
  return static_cast<bool>(out.flush());
}

double vm_hwm_mib() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0.0;
}

void explore_counters(benchmark::State& state, const an::PtNet& net, unsigned threads,
                      std::uint64_t want_states, std::uint64_t want_edges) {
  const bool reset = reset_peak();
  an::ExploreOptions o;
  o.threads = threads;
  o.progress = an::ExploreOptions::Progress::never;
  an::ExploreResult r;
  for (auto _ : state) {
    r = an::explore(net, o);
    benchmark::DoNotOptimize(r.states);
  }
  if (!r.complete() || (want_states != 0 && (r.states != want_states || r.edges != want_edges))) {
    state.SkipWithError(("wrong result: " + std::to_string(r.states) + " states, " + std::to_string(r.edges) +
                         " edges; " + r.message)
                            .c_str());
    return;
  }
  state.counters["states"] = static_cast<double>(r.states);
  state.counters["states/s"] =
      benchmark::Counter(static_cast<double>(r.states), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["edges/s"] =
      benchmark::Counter(static_cast<double>(r.edges), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["peak_MiB"] = static_cast<double>(r.peak_memory) / (1 << 20);
  state.counters["VmHWM_MiB"] = vm_hwm_mib();
  state.counters["reset"] = reset ? 1 : 0;
  state.counters["bits"] = r.bits_per_place;
}

void BM_Explore_Mcc(benchmark::State& state) {
  const auto& net = mcc(static_cast<int>(state.range(0)));
  state.SetLabel(kModels[state.range(0)]);
  explore_counters(state, net, static_cast<unsigned>(state.range(1)), 0, 0);
}
BENCHMARK(BM_Explore_Mcc)
    ->ArgsProduct({benchmark::CreateDenseRange(0, 7, 1), {1, 2}})
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);

void BM_Explore_Ring(benchmark::State& state) {
  const auto n = static_cast<unsigned>(state.range(0));
  const auto k = static_cast<unsigned>(state.range(1));
  explore_counters(state, ring(n, k), static_cast<unsigned>(state.range(2)), binomial(n + k - 1, k),
                   n * binomial(n + k - 2, k - 1));
}
BENCHMARK(BM_Explore_Ring)
    ->Args({16, 8, 1})
    ->Args({16, 8, 2})
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);
// 4 threads only where the machine has them: on fewer cores the figure measures the scheduler.
[[maybe_unused]] const bool kRingOnFour = [] {
  if (std::thread::hardware_concurrency() >= 4)
    benchmark::RegisterBenchmark("BM_Explore_Ring", BM_Explore_Ring)
        ->Args({16, 8, 4})
        ->MeasureProcessCPUTime()
        ->Unit(benchmark::kMillisecond);
  return true;
}();
// About 10^7 states: one iteration per repetition.
BENCHMARK(BM_Explore_Ring)
    ->Args({25, 8, 1})
    ->Args({25, 8, 2})
    ->Iterations(1)
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kSecond);

void BM_TokenGame(benchmark::State& state) {
  const auto& net = mcc(static_cast<int>(state.range(0)));
  state.SetLabel(kModels[state.range(0)]);
  an::TokenGame game(net);
  constexpr std::uint64_t kSteps = 1 << 16;
  std::uint64_t seed = 1;
  for (auto _ : state) benchmark::DoNotOptimize(game.play(kSteps, seed++));
  state.counters["firings/s"] =
      benchmark::Counter(static_cast<double>(kSteps), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_TokenGame)->DenseRange(0, 7, 1);

}  // namespace
