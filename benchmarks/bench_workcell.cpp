// The paper's two-robot work cell (examples/workcell/two_robots, docs/workcell.md) as a benchmark: the
// wall time of its steps — both robots' control, physics, collision, the sensors and both SOML++ nets —
// without an inspector (arg 0), with a vsd::web::Server and one page connected to its event stream (arg
// 1), and the same with the server's timeline off (arg 2). Issue 23's goal: the inspector adds at most
// 5 % to a step of the work cell. Each iteration runs the cell over the same seeded 3 parts (the same
// steps every time); its time is the sum of its steps' wall times (manual time, so building the cell and
// its reach checks are not counted); the counters are the median and 99th percentile of one step, the
// main thread's CPU time in the steps of a run (step_cpu_ms: preemption by other processes does not
// count), and the change batches pushed to the page per run. Under callgrind the run takes some 50 times longer, so
// the 30-a-second pushes come 50 times as often per step: count a push's instructions apart (README).
#include <benchmark/benchmark.h>

#include <memory>

#include "cell.hpp"
#include "web_inspected.hpp"

namespace {

void BM_WorkcellStep(benchmark::State& st) {
  constexpr int parts = 3;
  double p50 = 0, p99 = 0, steps = 0, batches = 0, cpu = 0;
  for (auto _ : st) {
    vsd_workcell::CellOptions o;
    o.urdf = VSD_CELL_URDF;
    o.meta_script = VSD_CELL_META;
    o.robot_script = VSD_CELL_ROBOTS;
    o.seed = 1;
    o.parts = parts;
    o.step_cpu = true;
    std::unique_ptr<vsd_bench::Inspected> inspector;
    o.on_built = [&](vsd::Environment& env) {
      inspector = std::make_unique<vsd_bench::Inspected>(env, env.main_state(), st.range(0));
    };
    o.on_finished = [&](vsd::Environment&, bool) {
      if (inspector && inspector->server) batches += static_cast<double>(inspector->server->stats().batches);
      inspector.reset();
    };
    const vsd_workcell::CellReport r = vsd_workcell::run_cell(o);
    if (r.parts_handled != parts || r.zone_violations != 0 || r.deadlocks != 0) {
      st.SkipWithError("the cell did not handle its parts cleanly");
      break;
    }
    st.SetIterationTime(r.step_total);
    p50 += r.step_p50;
    p99 += r.step_p99;
    steps += static_cast<double>(r.steps);
    cpu += r.step_cpu_total;
  }
  const double n = static_cast<double>(st.iterations());
  if (n > 0) {
    st.counters["step_p50_us"] = 1e6 * p50 / n;
    st.counters["step_p99_us"] = 1e6 * p99 / n;
    st.counters["steps"] = steps / n;
    st.counters["step_cpu_ms"] = 1e3 * cpu / n;  // the main thread's CPU time in the steps of a run
    st.counters["batches"] = batches / n;  // pushed to the page (at most 30 a second of wall time)
  }
}
BENCHMARK(BM_WorkcellStep)->Arg(0)->Arg(1)->Arg(2)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
