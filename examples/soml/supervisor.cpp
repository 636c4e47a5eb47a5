// A SOML++ supervisor commanding a plant modelled in C++ (docs/soml.md, supervisory control).
//
// The plant is a water tank declared as a database node class with properties (level, consumer demand,
// an upstream inflow, a pump and a drain valve). A small module steps it over simulated time in the
// core Scheduler. The supervisor, examples/soml/supervisor.soml, is loaded by vsd::soml::Module; its
// transition conditions read the tank's properties, so the executor re-tests them only when the plant
// changes them, and its actions command the plant by setting the pump and the drain valve.
//
//   vsd_soml_supervisor [supervisor.soml]
//
// Prints what the supervisor does and a check line; exits 1 when the level left its safe bounds or
// the supervisor never acted.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vsd/soml.hpp>
#include <vsd/vsd.hpp>

#ifndef VSD_SUPERVISOR_SCRIPT
#define VSD_SUPERVISOR_SCRIPT "supervisor.soml"
#endif

namespace plant {

/// A water tank; level and rates in percent of its volume (per second).
class Tank : public vsd::Node {
  VSD_INSTANCE(Tank, vsd::Node)
  VSD_PROPERTY(double, time, 0.0)        // the plant's clock (s), for the supervisor's log
  VSD_PROPERTY(double, level, 50.0)      // %
  VSD_PROPERTY(double, demand, 1.0)      // %/s drawn by the consumers
  VSD_PROPERTY(double, inflow, 0.0)      // %/s from upstream (a disturbance)
  VSD_PROPERTY(bool, pump, false)        // commanded by the supervisor
  VSD_PROPERTY(bool, drain, false)       // drain valve, commanded by the supervisor
  VSD_PROPERTY(double, pump_rate, 2.5)   // %/s while the pump runs
  VSD_PROPERTY(double, drain_rate, 4.0)  // %/s while the drain valve is open
};

/// Registers Tank and steps every tank of the main state in the Scheduler's periodic phase (before
/// the event-driven "soml nets" task, which then sees this step's changes in the same step).
class PlantModule : public vsd::Module {
 public:
  std::string_view name() const override { return "plant"; }
  void register_types(vsd::Registry& r) override { r.add<Tank>(); }
  void attach(vsd::Environment& env) override {
    env.scheduler().add_periodic("tank physics", env.scheduler().base_step(), [&env](const vsd::StepInfo& s) {
      env.main_state().index().for_each(Tank::static_meta(), true, [&](vsd::SimStateInstance& i) {
        auto& t = static_cast<Tank&>(i);
        // Consumers draw between 0.5 and 1.5 %/s over a 40 s cycle.
        t.set_demand(1.0 + 0.5 * std::sin(2.0 * std::numbers::pi * s.time / 40.0));
        const double rate =
            (t.pump() ? t.pump_rate() : 0.0) + t.inflow() - t.demand() - (t.drain() ? t.drain_rate() : 0.0);
        t.set_level(std::max(0.0, t.level() + rate * s.dt));
        t.set_time(s.time);
      });
    }, vsd::Phase::dynamics);
  }
};

}  // namespace plant

namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw vsd::Error("cannot read " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

int main(int argc, char** argv) try {
  const std::string script = argc > 1 ? argv[1] : VSD_SUPERVISOR_SCRIPT;
  constexpr double low_bound = 10.0, high_bound = 95.0;  // below: consumers run dry; above: spill
  constexpr double surge_from = 50.0, surge_to = 80.0, surge = 3.0;

  vsd::Environment env;
  env.scheduler().set_base_step(0.1);
  env.use<plant::PlantModule>();
  auto& soml = env.use<vsd::soml::Module>();
  vsd::SimState& state = env.main_state();

  auto& tank = state.create<plant::Tank>();
  tank.set_name("tank");
  state.database().add_child(tank);

  vsd::soml::Program& net = soml.load(state, script, read_file(script));
  // The script reaches the C++ node through its reference property `shared<Tank> tank`.
  net.root().set("tank", vsd::Value(vsd::SharedRef<vsd::Node>(&tank)));

  double lo = tank.level(), hi = tank.level();
  std::printf("t=0 s  level=%.1f %%  plant: pump off, drain closed\n", tank.level());
  while (env.time() < 150.0 - 1e-9) {
    // The disturbance: an upstream inflow switched on and off by the plant's scenario.
    const double t = env.time();
    if (tank.inflow() == 0.0 && t >= surge_from && t < surge_to) {
      tank.set_inflow(surge);
      std::printf("t=%.1f s  level=%.1f %%  plant: upstream inflow %.1f %%/s starts\n", t, tank.level(),
                  surge);
    } else if (tank.inflow() != 0.0 && t >= surge_to) {
      tank.set_inflow(0.0);
      std::printf("t=%.1f s  level=%.1f %%  plant: upstream inflow stops\n", t, tank.level());
    }
    env.step();  // the tank physics, then the nets whose conditions read what changed
    lo = std::min(lo, tank.level());
    hi = std::max(hi, tank.level());
  }

  const auto commands = net.root().get<std::int64_t>("commands");
  const auto alarms = net.root().get<std::int64_t>("alarms");
  std::printf(
      "%llu steps, %llu firings, %llu condition tests (a condition is re-tested only when a property it read "
      "changed)\n",
      static_cast<unsigned long long>(env.scheduler().steps()),
      static_cast<unsigned long long>(net.firings()), static_cast<unsigned long long>(net.condition_tests()));
  for (const std::string& e : net.condition_errors()) std::printf("condition error: %s\n", e.c_str());
  const bool bounded = lo >= low_bound && hi <= high_bound;
  std::printf(
      "check: level %s [%.0f, %.0f] %% (min %.1f, max %.1f); supervisor issued %lld commands, "
      "%lld alarms\n",
      bounded ? "stayed within" : "LEFT its safe bounds", low_bound, high_bound, lo, hi,
      static_cast<long long>(commands), static_cast<long long>(alarms));
  return bounded && commands > 0 && alarms > 0 ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "vsd_soml_supervisor: %s\n", e.what());
  return 1;
}
