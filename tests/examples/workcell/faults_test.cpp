// Fault injection in the two-robot cell (faults.hpp): the `--fault` grammar and its errors, and runs with a
// zone sensor that drops out and with parts that slip from a gripper — each ends in a safe state with its
// report lines and resumes, every part handled, the zone never held by both arms (geometry), no deadlock.
// The arms' adapter faults need the robot simulator: hardware_test.cpp.
#include "faults.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <sstream>

#include "cell.hpp"
#include "vsd/core/error.hpp"

namespace {

using vsd_workcell::FaultSpec;

// A short run at the seeded suite's step (50 ms, ODE at 10 ms) with @p faults, its timeline in @p timeline.
vsd_workcell::CellReport run_with(const std::vector<std::string>& faults, int parts, std::ostringstream& timeline) {
  vsd_workcell::CellOptions o;
  o.urdf = VSD_CELL_URDF;
  o.meta_script = VSD_CELL_META;
  o.robot_script = VSD_CELL_ROBOTS;
  std::vector<std::string> args{"--seed", "1", "--parts", std::to_string(parts), "--step", "0.05", "--physics-step",
                                "0.01"};
  for (const std::string& f : faults) args.insert(args.end(), {"--fault", f});
  vsd_workcell::parse_options(args, o);
  o.timeline = &timeline;
  return vsd_workcell::run_cell(o);
}

// What every faulted run must end with: all parts handled once, the zone exclusive, no deadlock, the nets
// at rest, every fault recovered.
void expect_safe_and_resumed(const vsd_workcell::CellReport& r, int parts) {
  EXPECT_EQ(r.parts_handled, parts);
  EXPECT_EQ(r.parts_arrived, parts);  // a part that slipped back onto the conveyor is no new arrival
  EXPECT_EQ(r.zone_violations, 0);
  EXPECT_EQ(r.deadlocks, 0);
  EXPECT_FALSE(r.timed_out);
  EXPECT_TRUE(r.condition_errors.empty());
  EXPECT_NE(r.final_marking.find("a.idle 1"), std::string::npos) << r.final_marking;
  EXPECT_NE(r.final_marking.find("b.idle 1"), std::string::npos) << r.final_marking;
  EXPECT_NE(r.final_marking.find("zone.free 1"), std::string::npos) << r.final_marking;
  for (const auto& f : r.faults) {
    EXPECT_GE(f.began, 0) << f.spec;
    EXPECT_GE(f.detected, f.began) << f.spec;
    EXPECT_GT(f.recovered, f.began) << f.spec;
  }
}

// The simulated times of the timeline's lines that contain @p what.
std::vector<double> times_of(const std::string& timeline, const std::string& what) {
  std::vector<double> t;
  std::istringstream in(timeline);
  for (std::string line; std::getline(in, line);)
    if (double v = 0; line.find(what) != std::string::npos && std::sscanf(line.c_str(), "t=%lf", &v) == 1)
      t.push_back(v);
  return t;
}

std::string parse_error(const std::string& spec) {
  try {
    vsd_workcell::parse_fault(spec);
  } catch (const vsd::Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(FaultSpecs, ParseTheGrammar) {
  const FaultSpec a = vsd_workcell::parse_fault("arm_b_silent@12s+5s");
  EXPECT_EQ(a.kind, FaultSpec::Kind::ArmSilent);
  EXPECT_EQ(a.robot, 1);
  EXPECT_DOUBLE_EQ(a.at, 12);
  EXPECT_DOUBLE_EQ(a.duration, 5);
  EXPECT_TRUE(a.active(12) && a.active(16.99) && !a.active(17) && !a.active(11.9));
  const FaultSpec z = vsd_workcell::parse_fault("zone_sensor_drop@0.5+2.25s");
  EXPECT_EQ(z.kind, FaultSpec::Kind::ZoneSensorDrop);
  EXPECT_DOUBLE_EQ(z.at, 0.5);
  EXPECT_DOUBLE_EQ(z.duration, 2.25);
  const FaultSpec s = vsd_workcell::parse_fault("slip@part7");
  EXPECT_EQ(s.kind, FaultSpec::Kind::Slip);
  EXPECT_EQ(s.part, "part7");
  EXPECT_EQ(s.robot, -1);
  EXPECT_EQ(vsd_workcell::parse_fault("slip_b@part12").robot, 1);
  EXPECT_FALSE(s.active(0));
}

TEST(FaultSpecs, MalformedSpecsSayWhatIsWrong) {
  EXPECT_EQ(parse_error("arm_c_silent@1+2"), "--fault 'arm_c_silent@1+2': unknown fault 'arm_c_silent' "
                                             "(arm_a_silent, arm_b_silent, zone_sensor_drop, slip, slip_a or slip_b)");
  EXPECT_EQ(parse_error("arm_a_silent"), "--fault 'arm_a_silent': no '@' (KIND@T+D, or slip@partN)");
  EXPECT_EQ(parse_error("arm_a_silent@12s"),
            "--fault 'arm_a_silent@12s': no duration: arm_a_silent@T+D (T when, D how long, in seconds)");
  EXPECT_EQ(parse_error("zone_sensor_drop@x+1"),
            "--fault 'zone_sensor_drop@x+1': the start 'x' is not a number of seconds (like 12, 12s or 0.5s)");
  EXPECT_EQ(parse_error("zone_sensor_drop@1+-1"),
            "--fault 'zone_sensor_drop@1+-1': the duration '-1' is not a number of seconds (like 12, 12s or 0.5s)");
  EXPECT_EQ(parse_error("zone_sensor_drop@1+0s"), "--fault 'zone_sensor_drop@1+0s': the duration must be positive");
  EXPECT_EQ(parse_error("zone_sensor_drop@1e3+1"),
            "--fault 'zone_sensor_drop@1e3+1': the start '1e3' is not a number of seconds (like 12, 12s or 0.5s)");
  EXPECT_EQ(parse_error("slip@7"), "--fault 'slip@7': '7' is not a part name partN (N from 1)");
  EXPECT_EQ(parse_error("slip@part0"), "--fault 'slip@part0': 'part0' is not a part name partN (N from 1)");
  EXPECT_EQ(parse_error("slip@part"), "--fault 'slip@part': 'part' is not a part name partN (N from 1)");
  // Through the command line: an arm's silence needs the arm's adapter.
  vsd_workcell::CellOptions o;
  try {
    vsd_workcell::parse_options({"--fault", "arm_a_silent@1+1"}, o);
    ADD_FAILURE() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_STREQ(e.what(),
                 "--fault 'arm_a_silent@1+1': needs --hardware with the arm's simulator started here (not --arm-a)");
  }
  EXPECT_THROW(vsd_workcell::parse_options({"--fault"}, o), vsd::Error);
}

TEST(CellFaults, ZoneSensorDropKeepsBothRobotsOutAndResumes) {
  std::ostringstream tl;
  const auto r = run_with({"zone_sensor_drop@14s+6s"}, 6, tl);
  expect_safe_and_resumed(r, 6);
  const std::string t = tl.str();
  ASSERT_EQ(r.faults.size(), 1u);
  EXPECT_DOUBLE_EQ(r.faults[0].began, 14.0);
  EXPECT_NEAR(r.faults[0].recovered, 20.0, 0.051);
  EXPECT_EQ(r.faults[0].zone_entries, 0);  // no net took zone.free while the sensor was down
  // No robot entered while it was down; both did again after it.
  for (const char* enter : {"token: multi_robot_control a.enter", "token: multi_robot_control b.enter"}) {
    const auto when = times_of(t, enter);
    for (double w : when) EXPECT_FALSE(w >= 14.0 && w < 20.0) << enter << " at " << w;
    EXPECT_TRUE(std::any_of(when.begin(), when.end(), [](double w) { return w >= 20.0; })) << enter;
  }
  EXPECT_NE(t.find("σ zone occupied by unknown (the sensor is down)"), std::string::npos);
  ASSERT_EQ(r.fault_lines.size(), 2u);
  EXPECT_EQ(r.fault_lines[0].rfind("t=14.00 s  fault zone_sensor_drop@14s+6s: the shared zone's presence sensor "
                                   "drops out: it reads as occupied (fail-safe)",
                                   0),
            0u)
      << r.fault_lines[0];
  EXPECT_EQ(r.fault_lines[1], "t=20.00 s  fault zone_sensor_drop@14s+6s: the zone's presence sensor is back: the "
                              "robots may enter again");
}

TEST(CellFaults, PartsThatSlipArePickedAgainByEitherRobot) {
  // Seed 1: part3 (kind 2) goes to A's lane and is handed over — A picks it from its lane's stop (it slips
  // back onto the stop), B from the station (it slips back onto the station, inside the zone). part1
  // (kind 2) goes down B's lane: it slips from whoever grasps it, B.
  std::ostringstream tl;
  const auto r = run_with({"slip_a@part3", "slip_b@part3", "slip@part1"}, 4, tl);
  expect_safe_and_resumed(r, 4);
  std::ostringstream clean_tl;
  EXPECT_EQ(r.handovers, run_with({}, 4, clean_tl).handovers);  // a slip on the station is no new hand-over
  EXPECT_NE(clean_tl.str().find("meta: job part3 (kind 2): A to the station, hand-over, B to dest_b"),
            std::string::npos);
  EXPECT_NE(clean_tl.str().find("meta: job part1 (kind 2): B to dest_b"), std::string::npos);
  const std::string t = tl.str();
  EXPECT_NE(t.find("token: multi_robot_control a.slipped: a.lifting -1, a.approaching +1"), std::string::npos);
  EXPECT_NE(t.find("token: multi_robot_control b.slipped: b.lifting -1, b.approaching +1"), std::string::npos);
  EXPECT_NE(t.find("token: multi_robot_control b.zone_slipped: b.zone_lifting -1, b.zone_approaching +1"),
            std::string::npos);
  EXPECT_NE(t.find("fault slip_a@part3: part3 slips from robot_a's gripper during the lift"), std::string::npos);
  EXPECT_NE(t.find("fault slip_b@part3: part3 slips from robot_b's gripper during the lift"), std::string::npos);
  EXPECT_NE(t.find("fault slip@part1: robot_b picked part1 again"), std::string::npos);
  EXPECT_NE(t.find("σ part3 rests on the station"), std::string::npos);
  ASSERT_EQ(r.faults.size(), 3u);
  for (const auto& f : r.faults) EXPECT_LT(f.recovered - f.began, 10.0) << f.spec;
  std::ostringstream summary;
  vsd_workcell::print_summary(summary, r);
  EXPECT_NE(summary.str().find("faults injected: 3, recovered: 3\n"), std::string::npos) << summary.str();
}

TEST(CellFaults, AFaultThatNeverHappensIsReported) {
  std::ostringstream tl;
  const auto r = run_with({"slip@part9", "zone_sensor_drop@500+1"}, 1, tl);
  EXPECT_EQ(r.parts_handled, 1);
  ASSERT_EQ(r.fault_lines.size(), 2u);
  EXPECT_NE(r.fault_lines[0].find("fault slip@part9: never happened: no robot grasped part9"), std::string::npos);
  EXPECT_NE(r.fault_lines[1].find("fault zone_sensor_drop@500+1: never happened: the run ended before it"),
            std::string::npos);
  EXPECT_LT(r.faults[0].began, 0);
}

}  // namespace
