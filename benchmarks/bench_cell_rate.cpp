// The two-robot work cell's throughput (issue 24, item 7; benchmarks/README.md "On the two-robot work
// cell"): the one-robot cell — the same plant with only small parts (`--kinds 1`), which all go to robot
// A while B has nothing to do — and the two-robot cell (both kinds, both robots) run for the same
// simulated time at the demo's step (10 ms, ODE at 1 ms) on the same seed (the benchmark's argument).
// Counters: parts/hour of each and their ratio (goal >= 1.6), the analytic bound of each
// (examples/workcell/two_robots/cycle_bound.hpp) and the two-robot cell's share of its bound (goal >= 90
// %), and the two-robot cell's step time — both robots' control, physics, collision, the sensors, both
// SOML++ nets — median and 99th percentile. The iteration's time is the two-robot run's step time in all
// (manual time: building the cell and its IK are not counted). The simulation is deterministic: the
// parts/hour figures are the same in every repetition; only the wall times vary.
#include <benchmark/benchmark.h>

#include "cell.hpp"

namespace {

constexpr double simulated = 600.0;  // s of simulated time per run

vsd_workcell::CellReport run(std::uint64_t seed, int kinds) {
  vsd_workcell::CellOptions o;
  o.urdf = VSD_CELL_URDF;
  o.meta_script = VSD_CELL_META;
  o.robot_script = VSD_CELL_ROBOTS;
  o.seed = seed;
  o.kinds = kinds;
  o.parts = 100000;  // more than arrive: the time limit ends the run
  o.time_limit = simulated;
  return vsd_workcell::run_cell(o);
}

void BM_CellRate(benchmark::State& st) {
  const auto seed = static_cast<std::uint64_t>(st.range(0));
  for (auto _ : st) {
    const vsd_workcell::CellReport one = run(seed, 1);
    const vsd_workcell::CellReport two = run(seed, 2);
    if (one.zone_violations != 0 || two.zone_violations != 0 || one.deadlocks != 0 || two.deadlocks != 0 ||
        !two.condition_errors.empty()) {
      st.SkipWithError("a run had a zone violation, a deadlock or a condition error");
      break;
    }
    st.SetIterationTime(two.step_total);
    st.counters["one_pph"] = one.parts_per_hour;
    st.counters["one_bound_pph"] = one.bound.parts_per_hour;
    st.counters["two_pph"] = two.parts_per_hour;
    st.counters["two_bound_pph"] = two.bound.parts_per_hour;
    st.counters["ratio"] = one.parts_per_hour > 0 ? two.parts_per_hour / one.parts_per_hour : 0;
    st.counters["of_bound"] = two.bound.parts_per_hour > 0 ? two.parts_per_hour / two.bound.parts_per_hour : 0;
    st.counters["handovers"] = two.handovers;
    st.counters["parts"] = two.parts_handled;
    st.counters["step_p50_us"] = 1e6 * two.step_p50;
    st.counters["step_p99_us"] = 1e6 * two.step_p99;
    st.counters["steps"] = static_cast<double>(two.steps);
  }
}
BENCHMARK(BM_CellRate)->Arg(1)->Arg(2)->Arg(3)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
