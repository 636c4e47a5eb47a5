// Persistence: save and load of a model of 1 000 000 instances (vsd::io binary snapshots).
// Reported per run: instances/s and MB/s of the snapshot; peak memory is the process's high-water mark
// (VmHWM), which only grows: read it as "the largest footprint any benchmark so far needed".
#include <benchmark/benchmark.h>

#include <fstream>
#include <string>

#include "fixture.hpp"
#include "vsd/io.hpp"

namespace {

constexpr std::size_t model_size = 1'000'000;

// 1000 groups of 999 robots: names, speeds, frames and a shared reference each, like a large scene.
void build(vsd::SimState& s) {
  for (std::size_t g = 0; g < model_size / 1000; ++g) {
    auto& group = s.create<vsd::Node>();
    group.set_name("group" + std::to_string(g));
    s.database().add_child(group);
    for (std::size_t i = 0; i < 999; ++i) {
      auto& r = s.create<Robot>();
      r.set_name("robot" + std::to_string(i));
      r.set_speed(static_cast<double>(i) * 0.5);
      r.set_battery(static_cast<int>(i % 100));
      group.add_child(r);
    }
  }
}

double peak_mib() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0.0;
}

void BM_Io_SaveBinary_1M(benchmark::State& state) {
  vsd::Environment env;
  build(env.main_state());
  std::size_t bytes = 0;
  for (auto _ : state) {
    const auto out = vsd::io::save_bytes(env.main_state());
    bytes = out.size();
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["instances/s"] = benchmark::Counter(static_cast<double>(env.main_state().size()),
                                                     benchmark::Counter::kIsIterationInvariantRate);
  state.counters["MB/s"] =
      benchmark::Counter(static_cast<double>(bytes) / 1e6, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["snapshot_MB"] = static_cast<double>(bytes) / 1e6;
  state.counters["peak_MiB"] = peak_mib();
}
BENCHMARK(BM_Io_SaveBinary_1M)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_Io_LoadBinary_1M(benchmark::State& state) {
  std::vector<std::uint8_t> bytes;
  std::size_t instances = 0;
  {
    vsd::Environment env;
    build(env.main_state());
    bytes = vsd::io::save_bytes(env.main_state());
    instances = env.main_state().size();
  }
  for (auto _ : state) {
    state.PauseTiming();
    auto env = std::make_unique<vsd::Environment>();
    state.ResumeTiming();
    vsd::io::load_bytes(env->main_state(), bytes);
    state.PauseTiming();
    if (env->main_state().size() != instances) state.SkipWithError("the load lost instances");
    env.reset();  // freeing a million instances is not part of the load
    state.ResumeTiming();
  }
  state.counters["instances/s"] =
      benchmark::Counter(static_cast<double>(instances), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["MB/s"] = benchmark::Counter(static_cast<double>(bytes.size()) / 1e6,
                                              benchmark::Counter::kIsIterationInvariantRate);
  state.counters["peak_MiB"] = peak_mib();
}
BENCHMARK(BM_Io_LoadBinary_1M)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
