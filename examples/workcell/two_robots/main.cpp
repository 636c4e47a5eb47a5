// The paper's work cell (section 4.2): two 8-axis robots under "Meta Control" and "Multi Robot Control",
// both SOML++ nets, in one process (cell.hpp says what it is).
//
//   vsd_two_robot_cell [--seed N] [--parts N] [--kinds 1|2] [--csv FILE] [--png FILE] [--quiet] [--step S] [--physics-step S]
//                      [--time-limit S] [--urdf IIWA14.URDF] [--meta meta_control.soml]
//                      [--robots multi_robot_control.soml] [--serve [PORT] [--no-linger]]
//                      [--processes 1|2] [--role controller|ui --domain N] [--no-commands]
//                      [--hardware [--simulator PATH] [--arm-a HOST:PORT] [--arm-b HOST:PORT]
//                       [--hardware-timeout S]] [--fault SPEC]...
//
// --hardware drives each arm over the UDP FRI-like protocol to a vsd_robot_simulator process and each linear
// axis through the fieldbus adapter (hardware.hpp); --fault injects a fault (faults.hpp has the grammar:
// arm_a_silent@T+D, arm_b_silent@T+D, zone_sensor_drop@T+D, slip@partN, slip_a@partN, slip_b@partN).
//
//   vsd_two_robot_cell --net-dot SCRIPT.soml      (the net's picture as Graphviz DOT, made from the script)
//
// --processes 2 (with vsd::dist built) runs the cell as a controller process and a ui process that
// replicates it and sends operator commands (docs/workcell.md, "Two processes"); --role runs one of them.
//
// --serve (with vsd::web built) shows the cell in the browser while it runs in real time and after, until
// Ctrl-C (docs/web.md): 127.0.0.1:PORT, 8080 by default, 0 for a free port; --no-linger ends with the run.
// With two processes the ui serves its replica (--processes 2 --serve, or --role ui --serve) and the
// controller keeps to real time; --role controller does not take --serve.
//
// Prints a timeline (σ events, γ commands, token moves, parts handled; --quiet leaves it out), then the
// summary. Exit code 0 when every part was handled with no zone violation, no deadlock and no condition
// error; 1 otherwise; 2 for bad options.
#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

#include "cell.hpp"
#include "net_picture.hpp"
#include "serve_option.hpp"
#ifdef VSD_WORKCELL_DIST
#include <unistd.h>

#include "two_process.hpp"
#endif
#include "vsd/core/error.hpp"
#ifdef VSD_WORKCELL_WEB
#include <memory>

#include "live_view.hpp"
#endif

int main(int argc, char** argv) {
  vsd_workcell::CellOptions o;
  o.urdf = VSD_CELL_URDF;
  o.meta_script = VSD_CELL_META;
  o.robot_script = VSD_CELL_ROBOTS;
  std::vector<std::string> args;
  bool quiet = false;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--quiet")
      quiet = true;
    else
      args.emplace_back(argv[i]);
  }
  // --net-dot SCRIPT: the net's picture as Graphviz DOT on stdout (scripts/net-pictures.sh), nothing else.
  if (args.size() == 2 && args[0] == "--net-dot") {
    try {
      std::cout << vsd_workcell::net_dot(args[1]);
      return 0;
    } catch (const std::exception& e) {
      std::cerr << "vsd_two_robot_cell: " << e.what() << '\n';
      return 1;
    }
  }
  int serve_port = -1;
  bool linger = true;  // with --serve: stay on the page after the run until Ctrl-C
#ifdef VSD_WORKCELL_DIST
  vsd_workcell::ProcessOptions processes;
#endif
  try {
#ifdef VSD_WORKCELL_DIST
    vsd_workcell::take_process_options(args, processes);
#else
    for (const std::string& a : args)
      if (a == "--processes" || a == "--role" || a == "--domain" || a == "--no-commands")
        throw vsd::Error(a + " needs vsd::dist, which this build left out (see the configure messages)");
#endif
    if (std::string error; !vsd_example::take_serve_option(args, serve_port, error)) throw vsd::Error(error);
    if (const auto it = std::find(args.begin(), args.end(), "--no-linger"); it != args.end()) {
      if (serve_port < 0) throw vsd::Error("--no-linger goes with --serve");
      linger = false;
      args.erase(it);
    }
#ifdef VSD_WORKCELL_DIST
    if (serve_port >= 0 && processes.role == "controller")
      throw vsd::Error("--serve: the ui serves the cell (its replica); give --serve to the ui process");
#endif
#ifndef VSD_WORKCELL_WEB
    if (serve_port >= 0) throw vsd::Error("--serve needs vsd::web, which this build left out (see the configure messages)");
#endif
    vsd_workcell::parse_options(args, o);
  } catch (const std::exception& e) {
    std::cerr << "vsd_two_robot_cell: " << e.what()
              << "\nusage: vsd_two_robot_cell [--seed N] [--parts N] [--kinds 1|2] [--csv FILE] [--png FILE] [--quiet] [--step S] "
                 "[--physics-step S] [--time-limit S] [--urdf FILE] [--meta FILE] [--robots FILE] "
                 "[--serve [PORT] [--no-linger]] [--processes 1|2] [--role controller|ui --domain N] [--no-commands] "
                 "[--hardware [--simulator PATH] [--arm-a HOST:PORT] [--arm-b HOST:PORT] [--hardware-timeout S]] "
                 "[--fault SPEC]...\n";
    return 2;
  }
  if (!quiet) o.timeline = &std::cout;
#ifdef VSD_WORKCELL_DIST
  const bool one_process = processes.processes == 1 && processes.role.empty();
#else
  const bool one_process = true;
#endif
  (void)one_process;
#ifdef VSD_WORKCELL_WEB
  std::unique_ptr<vsd_example::LiveView> view;
  if (serve_port >= 0 && one_process) {
    o.on_built = [&](vsd::Environment& env) { view = std::make_unique<vsd_example::LiveView>(env, env.main_state(), serve_port); };
    o.before_step = [&](vsd::Environment& env) { return view->pace(env); };
    o.on_finished = [&](vsd::Environment&, bool completed) {
      if (completed && linger) view->linger();
      view.reset();  // the server goes before the cell's Environment
    };
  }
#endif
#ifdef VSD_WORKCELL_DIST
  // Two processes with --serve: the ui serves its replica, and the controller keeps to real time so that
  // the page shows the cell moving (the ui's page cannot pause the controller: it edits the operator node).
  std::vector<std::string> ui_args;
  vsd_workcell::UiHooks ui_hooks;
  if (serve_port >= 0 && processes.processes == 2) {
    ui_args = {"--serve", std::to_string(serve_port), "--no-linger"};
    o.before_step = vsd_example::real_time_pacer<vsd::Environment>();
  }
#ifdef VSD_WORKCELL_WEB
  if (serve_port >= 0 && processes.role == "ui") {
    ui_hooks.joined = [&](vsd::Environment& env, vsd::SimState& replica) {
      view = std::make_unique<vsd_example::LiveView>(env, replica, serve_port);
    };
    ui_hooks.finished = [&](vsd::Environment&, bool equal) {
      if (equal && linger) view->linger();
      view.reset();
    };
  }
#endif
#endif
  try {
    bool replica_ok = true;
    vsd_workcell::CellReport r;
#ifdef VSD_WORKCELL_DIST
    if (processes.role == "ui") {
      std::cout.setf(std::ios::unitbuf);
      return vsd_workcell::run_ui(o, processes.domain, processes.commands, std::cout, ui_hooks);
    }
    if (processes.processes == 2 || processes.role == "controller") {
      // With --processes 2 the ui is this program again (/proc/self/exe: argv[0] need not be a path).
      const std::uint32_t domain = processes.has_domain ? processes.domain : 100 + ::getpid() % 100;
      const auto two = vsd_workcell::run_controller(o, domain, processes.processes == 2 ? "/proc/self/exe" : "",
                                                    processes.commands, std::cout, ui_args);
      r = two.cell;
      replica_ok = two.replica_equal && (two.ui_exit == 0 || processes.processes == 1);
    } else {
      r = vsd_workcell::run_cell(o);
    }
#else
    r = vsd_workcell::run_cell(o);
#endif
    vsd_workcell::print_summary(std::cout, r);
    const bool ok = r.parts_handled == o.parts + r.parts_injected && r.zone_violations == 0 &&
                    r.deadlocks == 0 && r.condition_errors.empty() && !r.timed_out && replica_ok && r.png_error.empty();
    std::cout << "check: " << (ok ? "every part handled, the zone exclusive, no deadlock" : "FAILED") << '\n';
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "vsd_two_robot_cell: " << e.what() << '\n';
    return 1;
  }
}
