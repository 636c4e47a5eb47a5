// Transactions: recording N property sets into a bundle, and applying a bundle of N sets to a replica.
// Times are per bundle (N sets); items_per_second counts sets.
#include <cstddef>

#include "fixture.hpp"

namespace {

using bench::value;

void bundle_sizes(benchmark::internal::Benchmark* b) { b->ArgName("sets")->Arg(1)->Arg(100)->Arg(10000); }

/// Reference: the same N sets with nobody recording.
void BM_Tx_SetsWithoutRecording(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  bench::World w;
  Robot& r = w.st.create<Robot>();
  std::size_t i = 0;
  for (auto _ : state) {
    for (std::size_t k = 0; k < n; ++k) {
      r.set_speed(value(i++));
      benchmark::ClobberMemory();
    }
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Tx_SetsWithoutRecording)->Apply(bundle_sizes);

/// Record: N sets with `start_recording()` active, then `take_recording()`.
void BM_Tx_Record(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  bench::World w;
  Robot& r = w.st.create<Robot>();
  w.st.start_recording();
  std::size_t i = 0;
  std::size_t ops = 0;
  for (auto _ : state) {
    for (std::size_t k = 0; k < n; ++k) {
      r.set_speed(value(i++));
      benchmark::ClobberMemory();
    }
    vsd::Transaction t = w.st.take_recording();
    ops += t.size();
    benchmark::DoNotOptimize(t.bytes().data());
  }
  if (ops != static_cast<std::size_t>(state.iterations()) * n)
    state.SkipWithError("sets missing from the bundles");
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Tx_Record)->Apply(bundle_sizes);

/// Apply: a recorded bundle of N sets applied to a replica made with `create_state` + `copy_from`.
void BM_Tx_Apply(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  bench::World w;
  Robot& r = w.st.create<Robot>();
  vsd::SimState& replica = w.env.create_state("replica");
  replica.copy_from(w.st);
  w.st.start_recording();
  for (std::size_t k = 0; k < n; ++k) r.set_speed(value(k));
  const vsd::Transaction t = w.st.stop_recording();
  if (t.size() != n) state.SkipWithError("the bundle does not hold N sets");
  for (auto _ : state) {
    replica.apply(t);
    benchmark::ClobberMemory();
  }
  const Robot* copy = replica.find<Robot>(r.id());
  if (copy == nullptr || copy->speed() != r.speed())
    state.SkipWithError("the replica does not match the source");
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.counters["bytes_per_set"] = static_cast<double>(t.bytes().size()) / static_cast<double>(n);
}
BENCHMARK(BM_Tx_Apply)->Apply(bundle_sizes);

}  // namespace
