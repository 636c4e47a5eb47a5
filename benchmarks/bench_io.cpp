// Persistence: save and load of a model of 1 000 000 instances, in both formats of vsd::io.
// Reported per run: instances/s and MB/s of the file, its size, and the peak memory of the process during
// that benchmark (the kernel's high-water mark VmHWM, reset before each benchmark through
// /proc/self/clear_refs; where the kernel does not allow the reset it only grows, and "reset" says 0).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "fixture.hpp"
#include "vsd/io.hpp"

namespace {

constexpr std::size_t model_size = 1'000'000;
using vsd::io::Format;

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

// The model saved in @p format; @p instances is set to the size of the state it was saved from.
std::vector<std::uint8_t> model_file(Format format, std::size_t& instances) {
  vsd::Environment env;
  build(env.main_state());
  instances = env.main_state().size();
  return vsd::io::save_bytes(env.main_state(), format);
}

bool reset_peak() {
  std::ofstream out("/proc/self/clear_refs");
  out << "5";
  return static_cast<bool>(out.flush());
}

double peak_mib() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0.0;
}

void counters(benchmark::State& state, std::size_t instances, std::size_t bytes, bool reset) {
  state.counters["instances/s"] =
      benchmark::Counter(static_cast<double>(instances), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["MB/s"] =
      benchmark::Counter(static_cast<double>(bytes) / 1e6, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["file_MB"] = static_cast<double>(bytes) / 1e6;
  state.counters["peak_MiB"] = peak_mib();
  state.counters["reset"] = reset ? 1 : 0;
}

void BM_Io_Save_1M(benchmark::State& state, Format format) {
  const bool reset = reset_peak();
  vsd::Environment env;
  build(env.main_state());
  std::size_t bytes = 0;
  for (auto _ : state) {
    const auto out = vsd::io::save_bytes(env.main_state(), format);
    bytes = out.size();
    benchmark::DoNotOptimize(out.data());
  }
  counters(state, env.main_state().size(), bytes, reset);
}
BENCHMARK_CAPTURE(BM_Io_Save_1M, binary, Format::Binary)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Io_Save_1M, text, Format::Text)->Unit(benchmark::kMillisecond)->Iterations(3);

// Loads @p bytes into a fresh Environment per iteration; only the load is timed.
void timed_loads(benchmark::State& state, const std::vector<std::uint8_t>& bytes, std::size_t instances) {
  for (auto _ : state) {
    state.PauseTiming();
    auto env = std::make_unique<vsd::Environment>();
    state.ResumeTiming();
    vsd::io::load_bytes(env->main_state(), bytes);
    state.PauseTiming();
    if (env->main_state().size() != instances) state.SkipWithError("the load lost instances");
    env.reset();  // freeing the instances is not part of the load
    state.ResumeTiming();
  }
}

void BM_Io_Load_1M(benchmark::State& state, Format format) {
  std::size_t instances = 0;
  const std::vector<std::uint8_t> bytes = model_file(format, instances);
  const bool reset = reset_peak();  // the peak of the load: the file, the model and the loaded state
  timed_loads(state, bytes, instances);
  counters(state, instances, bytes.size(), reset);
}
BENCHMARK_CAPTURE(BM_Io_Load_1M, binary, Format::Binary)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Io_Load_1M, text, Format::Text)->Unit(benchmark::kMillisecond)->Iterations(3);

// Reading and checking alone (vsd::io::check_bytes): the cost of the format itself, without building the
// state that a load shares between both formats.
void BM_Io_Check_1M(benchmark::State& state, Format format) {
  std::size_t instances = 0;
  const std::vector<std::uint8_t> bytes = model_file(format, instances);
  const bool reset = reset_peak();
  for (auto _ : state) {
    const auto report = vsd::io::check_bytes(bytes);
    if (report.instances + 1 != instances) state.SkipWithError("the check miscounted");
  }
  counters(state, instances, bytes.size(), reset);
}
BENCHMARK_CAPTURE(BM_Io_Check_1M, binary, Format::Binary)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Io_Check_1M, text, Format::Text)->Unit(benchmark::kMillisecond)->Iterations(3);

// A chain of nodes as deep as the argument, loaded (binary) into an empty state: every link is checked
// for cycles as it is made, which used to cost the depth above it. Reported per node: flat when linear.
void BM_Io_Load_Chain(benchmark::State& state) {
  const auto depth = static_cast<std::size_t>(state.range(0));
  std::vector<std::uint8_t> bytes;
  {
    vsd::Environment env;
    vsd::Node* at = &env.main_state().database();
    for (std::size_t i = 0; i < depth; ++i) at = &at->add_child(env.main_state().create<vsd::Node>());
    bytes = vsd::io::save_bytes(env.main_state(), Format::Binary);
  }
  timed_loads(state, bytes, depth + 1);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_Io_Load_Chain)->Arg(1024)->Arg(16384)->Arg(262144)->Unit(benchmark::kMillisecond);

}  // namespace
