// The paper's work cell (section 4.2): two 8-axis robots under "Meta Control" and "Multi Robot Control",
// both SOML++ nets, in one process (cell.hpp says what it is).
//
//   vsd_two_robot_cell [--seed N] [--parts N] [--csv FILE] [--quiet] [--step S] [--physics-step S]
//                      [--time-limit S] [--urdf IIWA14.URDF] [--meta meta_control.soml]
//                      [--robots multi_robot_control.soml]
//
// Prints a timeline (σ events, γ commands, token moves, parts handled; --quiet leaves it out), then the
// summary. Exit code 0 when every part was handled with no zone violation, no deadlock and no condition
// error; 1 otherwise; 2 for bad options.
#include <iostream>
#include <string>
#include <vector>

#include "cell.hpp"
#include "vsd/core/error.hpp"

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
  try {
    vsd_workcell::parse_options(args, o);
  } catch (const std::exception& e) {
    std::cerr << "vsd_two_robot_cell: " << e.what()
              << "\nusage: vsd_two_robot_cell [--seed N] [--parts N] [--csv FILE] [--quiet] [--step S] "
                 "[--physics-step S] [--time-limit S] [--urdf FILE] [--meta FILE] [--robots FILE]\n";
    return 2;
  }
  if (!quiet) o.timeline = &std::cout;
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
