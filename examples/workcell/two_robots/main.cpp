// The paper's work cell (section 4.2): two 8-axis robots under "Meta Control" and "Multi Robot Control",
// both SOML++ nets, in one process (cell.hpp says what it is).
//
//   vsd_two_robot_cell [--seed N] [--parts N] [--csv FILE] [--quiet] [--step S] [--physics-step S]
//                      [--time-limit S] [--urdf IIWA14.URDF] [--meta meta_control.soml]
//                      [--robots multi_robot_control.soml] [--serve [PORT]]
//
// --serve (with vsd::web built) shows the cell in the browser while it runs in real time and after, until
// Ctrl-C (docs/web.md): 127.0.0.1:PORT, 8080 by default, 0 for a free port.
//
// Prints a timeline (σ events, γ commands, token moves, parts handled; --quiet leaves it out), then the
// summary. Exit code 0 when every part was handled with no zone violation, no deadlock and no condition
// error; 1 otherwise; 2 for bad options.
#include <iostream>
#include <string>
#include <vector>

#include "cell.hpp"
#include "serve_option.hpp"
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
  int serve_port = -1;
  try {
    if (std::string error; !vsd_example::take_serve_option(args, serve_port, error)) throw vsd::Error(error);
#ifndef VSD_WORKCELL_WEB
    if (serve_port >= 0) throw vsd::Error("--serve needs vsd::web, which this build left out (see the configure messages)");
#endif
    vsd_workcell::parse_options(args, o);
  } catch (const std::exception& e) {
    std::cerr << "vsd_two_robot_cell: " << e.what()
              << "\nusage: vsd_two_robot_cell [--seed N] [--parts N] [--csv FILE] [--quiet] [--step S] "
                 "[--physics-step S] [--time-limit S] [--urdf FILE] [--meta FILE] [--robots FILE] "
                 "[--serve [PORT]]\n";
    return 2;
  }
  if (!quiet) o.timeline = &std::cout;
#ifdef VSD_WORKCELL_WEB
  std::unique_ptr<vsd_example::LiveView> view;
  if (serve_port >= 0) {
    o.on_built = [&](vsd::Environment& env) { view = std::make_unique<vsd_example::LiveView>(env, env.main_state(), serve_port); };
    o.before_step = [&](vsd::Environment& env) { return view->pace(env); };
    o.on_finished = [&](vsd::Environment&, bool completed) {
      if (completed) view->linger();
      view.reset();  // the server goes before the cell's Environment
    };
  }
#endif
  try {
    const auto r = vsd_workcell::run_cell(o);
    vsd_workcell::print_summary(std::cout, r);
    const bool ok = r.parts_handled == o.parts && r.zone_violations == 0 && r.deadlocks == 0 &&
                    r.condition_errors.empty() && !r.timed_out;
    std::cout << "check: " << (ok ? "every part handled, the zone exclusive, no deadlock" : "FAILED") << '\n';
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "vsd_two_robot_cell: " << e.what() << '\n';
    return 1;
  }
}
