// The paper's work cell (section 4.2, figures 11 and 12) in one process: two 8-axis robots (an iiwa14 on a
// linear axis each) facing a shared zone, a conveyor bringing parts of two kinds, a hand-over station in
// the zone, and two SOML++ supervisory controls: "Meta Control" (meta_control.soml: arriving parts become
// jobs with a route) and "Multi Robot Control" (multi_robot_control.soml: each robot's motion sequence,
// the shared zone mutually exclusive, hand-overs synchronised by communication arrows).
//
// run_cell() builds the cell, runs it until the requested number of parts is handled and returns what
// the summary prints. main.cpp is the command line; tests/examples/workcell/two_robot_cell_test.cpp runs
// it on several seeds. build_cell() does the first half alone: the cell in an Environment the caller
// owns, its behaviour in the Environment's scheduler tasks and SOML++ nets, so that whoever steps the
// Environment runs the cell (the Python plugin, python_plugin.cpp, does so).
#pragma once

#include <coroutine>
#include <cstdint>
#include <exception>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "cycle_bound.hpp"
#include "faults.hpp"
#include "hardware.hpp"

namespace vsd {
class Environment;
}

namespace vsd_workcell {

/// What run_cell() needs. The defaults are the demo's.
struct CellOptions {
  std::string urdf;                  ///< the iiwa14 URDF (tests/scene/data/iiwa14.urdf)
  std::string meta_script;           ///< meta_control.soml
  std::string robot_script;          ///< multi_robot_control.soml
  std::uint64_t seed = 1;            ///< part kinds and arrival times; the nets' choices
  int parts = 20;                    ///< run until this many parts are handled
  /// 2: parts of both kinds (half each, drawn from the seed); 1: only small parts — they all go to robot
  /// A, B has nothing to do: the one-robot baseline of the benchmark (benchmarks/README.md).
  int kinds = 2;
  double step = 0.01;                ///< s: the scheduler's base step (control, sensors, checks)
  double physics_step = 0.001;       ///< s: ODE's fixed step inside a scheduler step
  std::string csv;                   ///< when not empty: one row per step (robots, distance, zone)
  std::string png;                   ///< when not empty: the picture of trace_plot.hpp (checked at the start)
  std::ostream* timeline = nullptr;  ///< when set: σ events, γ commands, token moves, parts handled
  double time_limit = 0;             ///< s of simulated time; 0: 60 s per part
  HardwareOptions hardware;          ///< --hardware: the arms over UDP, the rails over the fieldbus
  std::vector<FaultSpec> faults;     ///< --fault: injected faults (faults.hpp)
  bool step_cpu = false;             ///< also sum the thread's CPU time in the steps (CellReport::step_cpu_total)
  /// Called once the cell is built, before the first step (the `--serve` inspector attaches here).
  std::function<void(vsd::Environment&)> on_built;
  /// Called before every step; false ends the run there (`interrupted` in the report).
  std::function<bool(vsd::Environment&)> before_step;
  /// Called when the run ends, before the cell is torn down — also when it ends by an error (@p completed
  /// false then). Whatever on_built attached to the Environment must let go of it here.
  std::function<void(vsd::Environment&, bool completed)> on_finished;
};

/// What a run did: the summary's figures.
struct CellReport {
  int parts_arrived = 0;
  int parts_handled = 0;  ///< resting on their destination, taken away by the outfeed
  int parts_injected = 0;  ///< by the operator (`operator.injections`), on top of CellOptions::parts
  int handovers = 0;      ///< parts that went through the hand-over station
  double time = 0;        ///< s simulated
  double parts_per_hour = 0;
  CycleParameters cycle;  ///< the cell's motion times and arrival gap, with this run's shares of the routes
  CycleBound bound;       ///< cycle_bound(cycle): what parts_per_hour is compared with
  std::uint64_t steps = 0;
  int zone_violations = 0;         ///< steps in which both arms were in the shared zone (geometry)
  int deadlocks = 0;               ///< 1 when the cell stopped with parts left and nothing enabled or moving
  double min_arm_distance = 0;     ///< m, between the arms' collision spheres, over every step
  double utilisation[2] = {0, 0};  ///< fraction of the time each robot (A, B) was moving
  std::uint64_t firings = 0;       ///< both nets
  std::uint64_t condition_tests = 0;  ///< both nets
  std::vector<std::string> condition_errors;
  std::string final_marking;  ///< Multi Robot Control's places
  std::string png_error;      ///< why the picture (CellOptions::png) could not be written; empty: it was
  bool timed_out = false;
  bool interrupted = false;  ///< before_step ended the run
  double step_p50 = 0;       ///< s of wall time per step (Environment::step: control, physics, collision,
  double step_p99 = 0;       ///< sensors, both nets), median and 99th percentile
  double step_total = 0;     ///< s of wall time in Environment::step over the run
  double step_cpu_total = 0;  ///< with CellOptions::step_cpu: s of this thread's CPU time in those steps
                              ///< (time the thread was preempted does not count)
  std::vector<std::string> hardware;     ///< with --hardware: one line per robot, its adapters and their counts
  std::vector<FaultRecord> faults;       ///< one per CellOptions::faults
  std::vector<std::string> fault_lines;  ///< the faults' report lines, in time order
};

/// Adds the modules the cell uses to @p env — robotics, physics, collision (with the given update period),
/// the cell's own classes (Robot, Part, Orders, Conveyor, Station), SOML++ — so that its scripts check.
void add_cell_modules(vsd::Environment& env, double collision_period = 0.01);

/// Defines the run-time classes of the two scripts in @p env's Registry without running them: loads them
/// into a state of their own ("net classes", not stepped) next to stand-ins of the nodes they look up. A
/// process that replicates the cell (the ui of docs/workcell.md, "Two processes") needs the classes
/// before the first snapshot arrives: run-time class definitions do not travel (docs/dist.md).
void define_net_classes(vsd::Environment& env, const CellOptions& options);

/// A cell built into an Environment (build_cell). Its plant — the sensors, the parts' arrivals, the
/// operator's commands, the robots' σ/γ interface — is a scheduler task and its controls are two SOML++
/// programs, all referring to what this object holds: every step of the Environment runs the cell for as
/// long as the object lives. Destroy it before the Environment. Move-only.
///
/// It is the suspended coroutine of the whole run (build, then the demo's loop): its frame holds what the
/// tasks refer to, and run() resumes it for the loop that run_cell() drives.
class Cell {
 public:
  struct promise_type;
  Cell(Cell&& other) noexcept;
  Cell& operator=(Cell&&) = delete;
  ~Cell();
  /// The demo's loop (CellOptions::on_built first): steps the Environment until every part is handled
  /// and the robots rest, the time limit or a deadlock, then makes the report. Once only.
  /// @throws vsd::Error from the run (a plant fault), or when the cell has run already.
  CellReport run();

 private:
  explicit Cell(std::coroutine_handle<promise_type> h) : h_(h) {}
  void rethrow();
  std::coroutine_handle<promise_type> h_;
  friend Cell build_cell(vsd::Environment& env, const CellOptions& options);
  friend CellReport run_cell(const CellOptions& options);
};

/// Builds the cell into @p env (its base step becomes CellOptions::step): the modules of
/// add_cell_modules, the nodes under the main state's database, the tasks and the nets. @p options must
/// outlive the Cell; `csv`, `png`, `time_limit`, `on_built`, `before_step` and `on_finished` are the
/// loop's (Cell::run), unused by whoever steps the Environment alone.
/// @throws vsd::Error on bad options, unreadable files or an unreachable layout.
Cell build_cell(vsd::Environment& env, const CellOptions& options);

/// Builds the cell in an Environment of its own and runs it (Cell::run).
/// @throws vsd::Error on bad options, unreadable files or a plant fault.
CellReport run_cell(const CellOptions& options);

/// Writes the summary lines (`parts handled: N`, `parts/hour: X`, `zone violations: N`, ...).
void print_summary(std::ostream& out, const CellReport& report);

/// Parses the command line (argv[0] excluded) into @p options.
/// @throws vsd::Error naming the bad option and why.
void parse_options(const std::vector<std::string>& args, CellOptions& options);

}  // namespace vsd_workcell
