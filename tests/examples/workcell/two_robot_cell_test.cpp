// The two-robot work cell (examples/workcell/two_robots) run headless: seeded runs over many parts, each
// part handled, the shared zone never held by both arms (checked every step from the arms' geometry,
// not from the net's marking), no deadlock; the timeline, the CSV and the option errors.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cell.hpp"
#include "vsd/core/error.hpp"

namespace {

using vsd_workcell::CellOptions;
using vsd_workcell::CellReport;

CellOptions options(std::uint64_t seed, int parts) {
  CellOptions o;
  o.urdf = VSD_CELL_URDF;
  o.meta_script = VSD_CELL_META;
  o.robot_script = VSD_CELL_ROBOTS;
  o.seed = seed;
  o.parts = parts;
  // Coarser than the demo (10 ms, ODE at 1 ms) to fit the test budget: the same nets, the same zone check.
  o.step = 0.05;
  o.physics_step = 0.01;
  return o;
}

void expect_clean(const CellReport& r, int parts) {
  EXPECT_EQ(r.parts_handled, parts);
  EXPECT_EQ(r.parts_arrived, parts);
  EXPECT_EQ(r.zone_violations, 0);
  EXPECT_EQ(r.deadlocks, 0);
  EXPECT_FALSE(r.timed_out);
  EXPECT_TRUE(r.condition_errors.empty()) << r.condition_errors.front();
  EXPECT_GT(r.min_arm_distance, 0.05);
  EXPECT_GT(r.handovers, 0);
  EXPECT_LT(r.handovers, parts);
  // Everything back at rest: both robots idle, the zone's token and the station's empty token at home.
  EXPECT_NE(r.final_marking.find("a.idle 1"), std::string::npos) << r.final_marking;
  EXPECT_NE(r.final_marking.find("b.idle 1"), std::string::npos) << r.final_marking;
  EXPECT_NE(r.final_marking.find("zone.free 1"), std::string::npos) << r.final_marking;
  EXPECT_NE(r.final_marking.find("station.empty 1"), std::string::npos) << r.final_marking;
}

// Four seeds of 250 parts: 1,000 parts in all (two suites, so that ctest runs them in parallel). The
// sanitizer build (Debug, ASan: some twenty times slower) runs the same nets and checks on 10 parts per
// seed, so that CI stays in its time budget; the Release suite carries the 1,000.
#if defined(__SANITIZE_ADDRESS__)
constexpr int parts_per_seed = 10;
#else
constexpr int parts_per_seed = 250;
#endif

class SeededCell : public testing::TestWithParam<std::uint64_t> {};

TEST_P(SeededCell, EveryPartHandledZoneExclusiveNoDeadlock) {
  constexpr int parts = parts_per_seed;
  const CellReport r = vsd_workcell::run_cell(options(GetParam(), parts));
  expect_clean(r, parts);
  EXPECT_GT(r.parts_per_hour, 100);
}

INSTANTIATE_TEST_SUITE_P(Seeds12, SeededCell, testing::Values(1, 2));
INSTANTIATE_TEST_SUITE_P(Seeds34, SeededCell, testing::Values(3, 4));

// A longer soak on request: VSD_WORKCELL_SOAK=<parts> (seeds 100, 101, ...).
TEST(TwoRobotCell, Soak) {
  const char* soak = std::getenv("VSD_WORKCELL_SOAK");
  if (soak == nullptr) GTEST_SKIP() << "set VSD_WORKCELL_SOAK=<parts> to run";
  const int parts = std::atoi(soak);
  ASSERT_GT(parts, 0);
  for (std::uint64_t seed = 100; seed < 104; ++seed)
    expect_clean(vsd_workcell::run_cell(options(seed, parts)), parts);
}

TEST(TwoRobotCell, TimelineShowsEventsCommandsTokensAndParts) {
  std::ostringstream out;
  CellOptions o = options(7, 4);
  o.timeline = &out;
  const CellReport r = vsd_workcell::run_cell(o);
  expect_clean(r, 4);
  const std::string t = out.str();
  EXPECT_NE(t.find("reach of robot_a: conveyor yes, station yes, dest_a yes, dest_b no"), std::string::npos);
  EXPECT_NE(t.find("reach of robot_b: conveyor no, station yes, dest_a no, dest_b yes"), std::string::npos);
  EXPECT_NE(t.find("σ part1 rests on the conveyor's sensor"), std::string::npos);
  EXPECT_NE(t.find("γ orders.post(part1"), std::string::npos);
  EXPECT_NE(t.find("σ zone occupied by robot_a\n"), std::string::npos);
  EXPECT_NE(t.find("σ zone occupied by robot_b\n"), std::string::npos);
  EXPECT_EQ(t.find("ZONE VIOLATION"), std::string::npos);
  EXPECT_NE(t.find("γ robot_a.grasp(part1)"), std::string::npos);
  EXPECT_NE(t.find("token: multi_robot_control a.fetch: a.idle -1, a.approaching +1"), std::string::npos);
  EXPECT_NE(t.find("token: multi_robot_control b.enter: b.idle -1, station.full -1, zone.free -1, "
                   "b.zone_approaching +1"),
            std::string::npos);
  EXPECT_NE(t.find("part handled: part4 (4 of 4)"), std::string::npos);
  std::ostringstream summary;
  vsd_workcell::print_summary(summary, r);
  const std::string s = summary.str();
  for (const char* line : {"parts handled: 4\n", "parts/hour: ", "zone violations: 0\n", "deadlocks: 0\n",
                           "min arm distance: ", "utilisation: robot A ", "firings: ", "condition tests: "})
    EXPECT_NE(s.find(line), std::string::npos) << line << " in\n" << s;
}

TEST(TwoRobotCell, WritesOneCsvRowPerStep) {
  const auto path = std::filesystem::temp_directory_path() / "vsd_two_robot_cell_test.csv";
  CellOptions o = options(3, 2);
  o.csv = path.string();
  const CellReport r = vsd_workcell::run_cell(o);
  std::ifstream in(path);
  std::string header, row;
  std::getline(in, header);
  EXPECT_EQ(header, "time,a_x,a_y,a_z,b_x,b_y,b_z,a_in_zone,b_in_zone,arm_distance,parts_handled");
  std::uint64_t rows = 0;
  while (std::getline(in, row)) ++rows;
  EXPECT_EQ(rows, r.steps);
  std::filesystem::remove(path);
}

TEST(TwoRobotCell, ReportsADeadlockAndStops) {
  // A Multi Robot Control that never gives the zone back after A's first hand-over: B cannot take the
  // part, A cannot bring the next one. The run must say so and stop, not run into its time limit.
  std::ifstream in(VSD_CELL_ROBOTS);
  std::ostringstream text;
  text << in.rdbuf();
  std::string script = text.str();
  const std::string give = "  arrow exit ~> zone.free;\n  arrow exit -> idle;\n";
  const auto at = script.find(give);
  ASSERT_NE(at, std::string::npos);
  script.replace(at, give.size(), "  arrow exit -> idle;\n");
  const auto path = std::filesystem::temp_directory_path() / "vsd_mrc_keeps_zone.soml";
  std::ofstream(path) << script;
  CellOptions o = options(1, 6);
  o.robot_script = path.string();
  const CellReport r = vsd_workcell::run_cell(o);
  std::filesystem::remove(path);
  EXPECT_EQ(r.deadlocks, 1);
  EXPECT_LT(r.parts_handled, 6);
  EXPECT_FALSE(r.timed_out);
  EXPECT_EQ(r.zone_violations, 0);
}

TEST(TwoRobotCell, BadOptionsAreClearErrors) {
  auto error = [](std::vector<std::string> args) {
    CellOptions o;
    try {
      vsd_workcell::parse_options(args, o);
    } catch (const vsd::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error({"--parts", "0"}), "--parts: '0' is not a whole number in [1, 1e+06]");
  EXPECT_EQ(error({"--parts", "ten"}), "--parts: 'ten' is not a whole number in [1, 1e+06]");
  EXPECT_EQ(error({"--seed"}), "--seed: needs a value");
  EXPECT_EQ(error({"--step", "0.1x"}), "--step: '0.1x' is not a number in [0.0001, 0.05]");
  EXPECT_EQ(error({"--step", "0.01", "--physics-step", "0.02"}), "--physics-step must not exceed --step");
  EXPECT_EQ(error({"--frobnicate"}), "unknown option '--frobnicate'");
  CellOptions o;
  vsd_workcell::parse_options({"--seed", "42", "--parts", "12", "--csv", "x.csv"}, o);
  EXPECT_EQ(o.seed, 42u);
  EXPECT_EQ(o.parts, 12);
  EXPECT_EQ(o.csv, "x.csv");
  // Files that are not there.
  CellOptions missing = options(1, 1);
  missing.robot_script = "/nonexistent/mrc.soml";
  EXPECT_THROW(vsd_workcell::run_cell(missing), vsd::Error);
}

}  // namespace
