// Instance life cycle (create + delete) and element-index iteration (the table view of the database).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "fixture.hpp"

#if VSD_BENCH_HAVE_QT
#include "qt_peer.hpp"
#endif

namespace {

using bench::value;

// ---- create + delete --------------------------------------------------------------------------------------

void BM_CreateDestroy_Builtin(benchmark::State& state) {
  bench::World w;
  for (auto _ : state) {
    Robot& r = w.st.create<Robot>();
    benchmark::DoNotOptimize(&r);
    w.st.destroy(r);
  }
  if (w.st.size() != 1) state.SkipWithError("instances left behind");
}
BENCHMARK(BM_CreateDestroy_Builtin);

void BM_CreateDestroy_Runtime(benchmark::State& state) {
  bench::World w;
  const vsd::MetaInstance& cls = bench::runtime_robot_class();
  for (auto _ : state) {
    vsd::SimStateInstance& r = w.st.create(cls);
    benchmark::DoNotOptimize(&r);
    w.st.destroy(r);
  }
  if (w.st.size() != 1) state.SkipWithError("instances left behind");
}
BENCHMARK(BM_CreateDestroy_Runtime);

/// Baseline: new + delete of the raw struct.
void BM_CreateDestroy_Raw(benchmark::State& state) {
  for (auto _ : state) {
    auto* r = new bench::RawRobot;
    benchmark::DoNotOptimize(r);
    delete r;
  }
}
BENCHMARK(BM_CreateDestroy_Raw);

#if VSD_BENCH_HAVE_QT
/// Peer: new + delete of the QObject twin.
void BM_CreateDestroy_Qt(benchmark::State& state) {
  for (auto _ : state) {
    auto* r = new bench::QtRobot;
    benchmark::DoNotOptimize(r);
    delete r;
  }
}
BENCHMARK(BM_CreateDestroy_Qt);
#endif

// ---- element-index iteration ------------------------------------------------------------------------------
// 10 000 instances, each with its own speed; one iteration sums the speed of all of them. Times are per
// iteration (all 10 000); items_per_second counts instances.

constexpr std::size_t instance_count = 10000;

struct Population {
  bench::World w;
  explicit Population(const vsd::MetaInstance& cls) {
    const vsd::MetaProperty& speed = *cls.find_property("speed");
    for (std::size_t k = 0; k < instance_count; ++k) speed.set<double>(w.st.create(cls), value(k));
  }
};

void finish(benchmark::State& state, double sum) {
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(instance_count));
}

/// Typed: `index().exact(Robot::static_meta())`, then the inline getter.
void BM_Iterate_Index_Typed(benchmark::State& state) {
  Population pop(Robot::static_meta());
  const vsd::ElementIndex& index = pop.w.st.index();
  double sum = 0;
  for (auto _ : state) {
    double s = 0;
    for (vsd::SimStateInstance* i : index.exact(Robot::static_meta())) s += static_cast<Robot*>(i)->speed();
    benchmark::DoNotOptimize(s);
    sum += s;
  }
  if (index.exact(Robot::static_meta()).size() != instance_count) state.SkipWithError("wrong population");
  finish(state, sum);
}
BENCHMARK(BM_Iterate_Index_Typed);

/// Generic: the same loop reading through a MetaProperty handle, built-in or run-time class.
template <bool Runtime>
void BM_Iterate_Index_ByHandle(benchmark::State& state) {
  const vsd::MetaInstance& cls = Runtime ? bench::runtime_robot_class() : Robot::static_meta();
  Population pop(cls);
  const vsd::ElementIndex& index = pop.w.st.index();
  const vsd::MetaProperty& speed = *cls.find_property("speed");
  double sum = 0;
  for (auto _ : state) {
    double s = 0;
    for (vsd::SimStateInstance* i : index.exact(cls)) s += speed.get<double>(*i);
    benchmark::DoNotOptimize(s);
    sum += s;
  }
  if (index.exact(cls).size() != instance_count) state.SkipWithError("wrong population");
  finish(state, sum);
}
BENCHMARK(BM_Iterate_Index_ByHandle<false>)->Name("BM_Iterate_Index_ByHandle_Builtin");
BENCHMARK(BM_Iterate_Index_ByHandle<true>)->Name("BM_Iterate_Index_ByHandle_Runtime");

/// `index().for_each(cls, include_subtypes = true, fn)`: the subclass walk copies the list of subclasses.
void BM_Iterate_Index_ForEach(benchmark::State& state) {
  Population pop(Robot::static_meta());
  const vsd::ElementIndex& index = pop.w.st.index();
  double sum = 0;
  for (auto _ : state) {
    double s = 0;
    index.for_each(Robot::static_meta(), true,
                   [&s](vsd::SimStateInstance& i) { s += static_cast<Robot&>(i).speed(); });
    benchmark::DoNotOptimize(s);
    sum += s;
  }
  finish(state, sum);
}
BENCHMARK(BM_Iterate_Index_ForEach);

/// Baseline: a vector of pointers to individually allocated raw structs (same indirection, but the structs
/// are 24 bytes, allocated back to back, where a Robot is larger and shares the heap with the SimState's
/// own bookkeeping).
void BM_Iterate_RawPointers(benchmark::State& state) {
  std::vector<std::unique_ptr<bench::RawRobot>> robots;
  std::vector<bench::RawRobot*> ptrs;
  for (std::size_t k = 0; k < instance_count; ++k) {
    robots.push_back(std::make_unique<bench::RawRobot>());
    robots.back()->speed = value(k);
    ptrs.push_back(robots.back().get());
  }
  double sum = 0;
  for (auto _ : state) {
    double s = 0;
    for (const bench::RawRobot* r : ptrs) s += r->speed;
    benchmark::DoNotOptimize(s);
    sum += s;
  }
  finish(state, sum);
}
BENCHMARK(BM_Iterate_RawPointers);

/// Baseline: a contiguous vector of raw structs (no indirection at all).
void BM_Iterate_RawContiguous(benchmark::State& state) {
  std::vector<bench::RawRobot> robots(instance_count);
  for (std::size_t k = 0; k < instance_count; ++k) robots[k].speed = value(k);
  benchmark::DoNotOptimize(robots.data());
  double sum = 0;
  for (auto _ : state) {
    double s = 0;
    for (const bench::RawRobot& r : robots) s += r.speed;
    benchmark::DoNotOptimize(s);
    sum += s;
  }
  finish(state, sum);
}
BENCHMARK(BM_Iterate_RawContiguous);

// The same three loops summing the int property `battery` into an int64: an integer add has a one-cycle
// latency, so these show the memory access pattern that the floating-point sums above (bound by the
// latency of the add, ~4 cycles per element) partly hide. The contiguous loop is vectorised by the compiler.

void BM_Iterate_Int_Index_Typed(benchmark::State& state) {
  Population pop(Robot::static_meta());
  const vsd::ElementIndex& index = pop.w.st.index();
  std::int64_t sum = 0;
  for (auto _ : state) {
    std::int64_t s = 0;
    for (vsd::SimStateInstance* i : index.exact(Robot::static_meta())) s += static_cast<Robot*>(i)->battery();
    benchmark::DoNotOptimize(s);
    sum += s;
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(instance_count));
}
BENCHMARK(BM_Iterate_Int_Index_Typed);

void BM_Iterate_Int_RawPointers(benchmark::State& state) {
  std::vector<std::unique_ptr<bench::RawRobot>> robots;
  std::vector<bench::RawRobot*> ptrs;
  for (std::size_t k = 0; k < instance_count; ++k) {
    robots.push_back(std::make_unique<bench::RawRobot>());
    ptrs.push_back(robots.back().get());
  }
  std::int64_t sum = 0;
  for (auto _ : state) {
    std::int64_t s = 0;
    for (const bench::RawRobot* r : ptrs) s += r->battery;
    benchmark::DoNotOptimize(s);
    sum += s;
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(instance_count));
}
BENCHMARK(BM_Iterate_Int_RawPointers);

void BM_Iterate_Int_RawContiguous(benchmark::State& state) {
  std::vector<bench::RawRobot> robots(instance_count);
  benchmark::DoNotOptimize(robots.data());
  std::int64_t sum = 0;
  for (auto _ : state) {
    std::int64_t s = 0;
    for (const bench::RawRobot& r : robots) s += r.battery;
    benchmark::DoNotOptimize(s);
    sum += s;
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(instance_count));
}
BENCHMARK(BM_Iterate_Int_RawContiguous);

}  // namespace
