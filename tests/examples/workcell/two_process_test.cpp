// The two-robot cell as two processes (docs/workcell.md, "Two processes"): the controller here, the ui
// as a child process (the built vsd_two_robot_cell, --role ui). The operator's commands travel from the
// ui as writes to the node it owns; at the end the ui's replica is byte-equal to the controller's state.
#include <gtest/gtest.h>

#include <unistd.h>

#include <sstream>

#include "two_process.hpp"
#include "vsd/core/error.hpp"

namespace {

using vsd_workcell::CellOptions;

CellOptions options(int parts) {
  CellOptions o;
  o.urdf = VSD_CELL_URDF;
  o.meta_script = VSD_CELL_META;
  o.robot_script = VSD_CELL_ROBOTS;
  o.seed = 1;
  o.parts = parts;
  o.step = 0.05;  // the seeded suite's coarser step
  o.physics_step = 0.01;
  return o;
}

std::uint32_t test_domain() { return 20 + static_cast<std::uint32_t>(::getpid() % 150); }

TEST(TwoProcessCell, HandlesItsPartsWithOperatorCommandsAndTheReplicaIsByteEqual) {
  std::ostringstream out;
  const auto r = vsd_workcell::run_controller(options(3), test_domain(), VSD_CELL_PROGRAM, true, out);
  const std::string log = out.str();
  EXPECT_EQ(r.cell.parts_injected, 1) << log;
  EXPECT_EQ(r.cell.parts_handled, 4) << log;
  EXPECT_EQ(r.cell.zone_violations, 0);
  EXPECT_EQ(r.cell.deadlocks, 0);
  EXPECT_FALSE(r.cell.timed_out);
  EXPECT_TRUE(r.replica_equal) << r.controller_digest << " vs " << r.replica_digest;
  EXPECT_FALSE(r.controller_digest.empty());
  EXPECT_EQ(r.ui_exit, 0);
  EXPECT_NE(log.find("controller: the ui joined domain"), std::string::npos) << log;
  EXPECT_NE(log.find("replica: byte-equal to the controller's state"), std::string::npos) << log;
}

TEST(TwoProcessCell, WithoutCommandsTheRunIsTheSeedsOwn) {
  std::ostringstream out;
  const auto r = vsd_workcell::run_controller(options(2), test_domain() + 1, VSD_CELL_PROGRAM, false, out);
  EXPECT_EQ(r.cell.parts_injected, 0);
  EXPECT_EQ(r.cell.parts_handled, 2);
  EXPECT_EQ(r.cell.zone_violations, 0);
  EXPECT_TRUE(r.replica_equal) << out.str();
  EXPECT_EQ(r.ui_exit, 0);
}

#ifdef VSD_CELL_PROGRAM_SERVES
// `--processes 2 --serve`: the ui serves the inspector of its replica while the cell runs (the URL goes to
// the ui's standard output, which is this test's), ends with the run (--no-linger), and the replica is
// still byte-equal: the server on it reads and records, it does not change it.
TEST(TwoProcessCell, TheUiServesItsReplicaAndItStaysByteEqual) {
  std::ostringstream out;
  const auto r = vsd_workcell::run_controller(options(1), test_domain() + 2, VSD_CELL_PROGRAM, false, out,
                                              {"--serve", "0", "--no-linger"});
  EXPECT_EQ(r.cell.parts_handled, 1) << out.str();
  EXPECT_TRUE(r.replica_equal) << r.controller_digest << " vs " << r.replica_digest;
  EXPECT_EQ(r.ui_exit, 0);
}
#endif

TEST(TwoProcessCell, BadOptionsAreClearErrors) {
  auto error = [](std::vector<std::string> args) {
    vsd_workcell::ProcessOptions p;
    try {
      vsd_workcell::take_process_options(args, p);
    } catch (const vsd::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error({"--processes", "3"}), "--processes: '3' is not 1 or 2");
  EXPECT_EQ(error({"--processes"}), "--processes: needs a value");
  EXPECT_EQ(error({"--role", "robot"}), "--role: 'robot' is not controller or ui");
  EXPECT_EQ(error({"--role", "ui"}), "--role ui needs --domain N");
  EXPECT_EQ(error({"--role", "ui", "--domain", "231"}), "--domain: '231' is not a whole number in [0, 230]");
  EXPECT_EQ(error({"--role", "ui", "--domain", "x"}), "--domain: 'x' is not a whole number in [0, 230]");
  EXPECT_EQ(error({"--processes", "2", "--role", "ui", "--domain", "5"}),
            "--processes 2 and --role exclude each other");
  EXPECT_EQ(error({"--domain", "5"}), "--domain is for --processes 2 or --role");
  std::vector<std::string> args{"--parts", "2", "--processes", "2", "--no-commands"};
  vsd_workcell::ProcessOptions p;
  vsd_workcell::take_process_options(args, p);
  EXPECT_EQ(p.processes, 2);
  EXPECT_FALSE(p.commands);
  EXPECT_EQ(args, (std::vector<std::string>{"--parts", "2"}));
}

}  // namespace
