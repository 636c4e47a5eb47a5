// The two-robot cell with its hardware adapters (hardware.hpp): each arm over the UDP FRI-like protocol to
// a vsd_robot_simulator process, each linear axis on the fieldbus adapter — the same run as in simulation;
// the endpoints configurable; an arm that stops answering holds in a safe state, is reported and resumes.
#include "hardware.hpp"

#include <gtest/gtest.h>

#include <sstream>

#include "cell.hpp"
#include "simulator_process.hpp"
#include "vsd/core/error.hpp"

namespace {

vsd_workcell::CellOptions hardware_options(int parts) {
  vsd_workcell::CellOptions o;
  o.urdf = VSD_CELL_URDF;
  o.meta_script = VSD_CELL_META;
  o.robot_script = VSD_CELL_ROBOTS;
  o.seed = 1;
  o.parts = parts;
  o.step = 0.05;  // the seeded suite's step
  o.physics_step = 0.01;
  o.hardware.enabled = true;
  o.hardware.simulator = VSD_ROBOT_SIMULATOR;
  return o;
}

void expect_all_handled(const vsd_workcell::CellReport& r, int parts) {
  EXPECT_EQ(r.parts_handled, parts);
  EXPECT_EQ(r.zone_violations, 0);
  EXPECT_EQ(r.deadlocks, 0);
  EXPECT_FALSE(r.timed_out);
  EXPECT_TRUE(r.condition_errors.empty());
  EXPECT_NE(r.final_marking.find("zone.free 1"), std::string::npos) << r.final_marking;
}

TEST(CellHardware, RunsThroughTheAdapters) {
  const auto r = vsd_workcell::run_cell(hardware_options(3));
  expect_all_handled(r, 3);
  ASSERT_EQ(r.hardware.size(), 2u);
  for (const std::string& h : r.hardware) {
    EXPECT_NE(h.find(": udp 127.0.0.1:"), std::string::npos) << h;
    EXPECT_NE(h.find("; fieldbus axis: cycles "), std::string::npos) << h;
    EXPECT_NE(h.find("faults 0, recoveries 0; fieldbus axis"), std::string::npos) << h;  // the arm never lost
  }
  EXPECT_EQ(r.hardware[0].rfind("robot_a: ", 0), 0u);
  std::ostringstream summary;
  vsd_workcell::print_summary(summary, r);
  EXPECT_NE(summary.str().find("hardware robot_b: udp 127.0.0.1:"), std::string::npos);
}

TEST(CellHardware, EndpointsOfRunningSimulators) {
  // robot_a's arm is a simulator started here (as on another machine's loopback bridge); robot_b's the
  // cell starts itself.
  vsd_example::SimulatorProcess arm(VSD_ROBOT_SIMULATOR, {"--port", "0", "--dof", "7", "--idle-exit", "60"});
  auto o = hardware_options(1);
  o.hardware.arm[0] = "127.0.0.1:" + std::to_string(arm.port());
  std::ostringstream tl;
  o.timeline = &tl;
  const auto r = vsd_workcell::run_cell(o);
  expect_all_handled(r, 1);
  ASSERT_EQ(r.hardware.size(), 2u);
  EXPECT_NE(r.hardware[0].find("udp 127.0.0.1:" + std::to_string(arm.port()) + ":"), std::string::npos)
      << r.hardware[0];
  // An endpoint where nothing answers: a clear error before the first step, not a cell that waits.
  auto dead = hardware_options(1);
  dead.hardware.connect_timeout = 0.3;
  {
    vsd_example::SimulatorProcess gone(VSD_ROBOT_SIMULATOR, {"--port", "0"});
    dead.hardware.arm[1] = "127.0.0.1:" + std::to_string(gone.port());
  }  // killed: its port answers no more
  try {
    vsd_workcell::run_cell(dead);
    ADD_FAILURE() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("--hardware: robot_b's adapters do not deliver (udp 127.0.0.1:"),
              std::string::npos)
        << e.what();
  }
  // Its silence cannot be injected: this run does not own the process.
  o.faults.push_back(vsd_workcell::parse_fault("arm_a_silent@1+1"));
  EXPECT_THROW(vsd_workcell::run_cell(o), vsd::Error);
}

TEST(CellHardware, OptionsAndTheirErrors) {
  vsd_workcell::CellOptions o;
  vsd_workcell::parse_options({"--hardware", "--arm-b", "localhost:40123", "--hardware-timeout", "0.05"}, o);
  EXPECT_TRUE(o.hardware.enabled);
  EXPECT_EQ(o.hardware.arm[1], "localhost:40123");
  EXPECT_DOUBLE_EQ(o.hardware.timeout, 0.05);
  auto error = [](std::vector<std::string> args) {
    vsd_workcell::CellOptions c;
    try {
      vsd_workcell::parse_options(args, c);
    } catch (const vsd::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error({"--hardware", "--arm-a", "127.0.0.1"}),
            "--arm-a: '127.0.0.1' is not HOST:PORT (a loopback address and a port 1 to 65535)");
  EXPECT_EQ(error({"--hardware", "--arm-a", "127.0.0.1:70000"}),
            "--arm-a: '127.0.0.1:70000' is not HOST:PORT (a loopback address and a port 1 to 65535)");
  EXPECT_EQ(error({"--arm-a", "127.0.0.1:4000"}), "--arm-a, --arm-b and --simulator go with --hardware");
  EXPECT_EQ(error({"--hardware", "--arm-b", "10.0.0.7:4000"}),
            "--arm-b: '10.0.0.7' is not a loopback address (127.x.y.z or localhost): the UDP adapter talks to "
            "robots on this machine only");
  EXPECT_EQ(error({"--hardware-timeout", "2"}), "--hardware-timeout: '2' is not a number in [0.001, 1] (seconds)");
  auto bad = hardware_options(1);
  bad.hardware.simulator = "/nonexistent/vsd_robot_simulator";
  try {
    vsd_workcell::run_cell(bad);
    ADD_FAILURE() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot start /nonexistent/vsd_robot_simulator"), std::string::npos)
        << e.what();
  }
}

// An arm that stops answering: that robot holds (its pad does not move), the report says what and when,
// the other robot goes on, and the cell resumes when the arm answers again.
class CellArmSilent : public testing::TestWithParam<int> {};

TEST_P(CellArmSilent, HoldsIsReportedAndResumes) {
  const int robot = GetParam();
  const std::string spec = std::string(robot == 0 ? "arm_a_silent" : "arm_b_silent") + "@10s+2s";
  auto o = hardware_options(3);
  o.hardware.timeout = 0.01;  // each silent cycle waits this long: 40 of them
  o.faults.push_back(vsd_workcell::parse_fault(spec));
  std::ostringstream tl;
  o.timeline = &tl;
  const auto r = vsd_workcell::run_cell(o);
  expect_all_handled(r, 3);
  ASSERT_EQ(r.faults.size(), 1u);
  const auto& f = r.faults[0];
  EXPECT_DOUBLE_EQ(f.began, 10.0);
  EXPECT_GT(f.detected, f.began);
  EXPECT_LE(f.detected, f.began + 0.25);  // three missed cycles of 50 ms, and the step that sees it
  EXPECT_GE(f.recovered, 12.0);
  EXPECT_LE(f.recovered, 12.5);
  EXPECT_LT(f.affected_motion, 1e-9);  // the affected robot held where it stood
  const std::string name = robot == 0 ? "robot_a" : "robot_b";
  const std::string t = tl.str();
  EXPECT_NE(t.find("σ " + name + " faulted: udp 127.0.0.1:"), std::string::npos);
  EXPECT_NE(t.find("σ " + name + " delivers again"), std::string::npos);
  ASSERT_EQ(r.fault_lines.size(), 4u);
  EXPECT_NE(r.fault_lines[0].find(name + "'s arm stops answering on its UDP link"), std::string::npos);
  EXPECT_NE(r.fault_lines[1].find(name + " holds where it is (its binding is in Fault: udp 127.0.0.1:"),
            std::string::npos);
  EXPECT_NE(r.fault_lines[2].find(name + "'s arm answers again"), std::string::npos);
  EXPECT_NE(r.fault_lines[3].find(name + "'s adapters deliver again: it resumes"), std::string::npos);
  ASSERT_EQ(r.hardware.size(), 2u);
  EXPECT_NE(r.hardware[robot].find("faults 1, recoveries 1; fieldbus axis"), std::string::npos) << r.hardware[robot];
}

INSTANTIATE_TEST_SUITE_P(EachArm, CellArmSilent, testing::Values(0, 1));

TEST(CellHardware, TheOtherRobotGoesOnWhileBIsSilent) {
  // B silent from 10 s to 14 s: A goes on fetching and placing parts meanwhile (its pad moves).
  auto o = hardware_options(3);
  o.hardware.timeout = 0.01;
  o.faults.push_back(vsd_workcell::parse_fault("arm_b_silent@10s+4s"));
  const auto r = vsd_workcell::run_cell(o);
  expect_all_handled(r, 3);
  EXPECT_LT(r.faults[0].affected_motion, 1e-9);
  EXPECT_GT(r.faults[0].other_motion, 0.2);
}

}  // namespace
