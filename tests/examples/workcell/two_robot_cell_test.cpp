// The two-robot work cell (examples/workcell/two_robots) run headless: seeded runs over many parts, each
// part handled, the shared zone never held by both arms (checked every step from the arms' geometry,
// not from the net's marking), no deadlock; the timeline, the CSV and the option errors.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cell.hpp"
#include "trace_plot.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/robotics.hpp"
#include "../../sanitized.hpp"

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
  // A large part is handed over only when lane B's queue runs ahead of lane A's, which a short run (the
  // sanitizer build's 10 parts per seed) may never see; over 100 parts and more every seed has some.
  if (parts >= 100) {
    EXPECT_GT(r.handovers, 0);
  }
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
#ifdef VSD_TEST_SANITIZED
constexpr int parts_per_seed = 10;
#else
constexpr int parts_per_seed = 250;
#endif

class SeededCell : public testing::TestWithParam<std::uint64_t> {};

TEST_P(SeededCell, EveryPartHandledZoneExclusiveNoDeadlock) {
  constexpr int parts = parts_per_seed;
  const CellReport r = vsd_workcell::run_cell(options(GetParam(), parts));
  expect_clean(r, parts);
  // Both robots work (issue 24's goal: >= 1.6 times the one robot's rate, measured in the benchmark),
  // and the analytic bound holds: the run never beats it, and comes within 15 % of it over 250 parts
  // (the start — the first part's trip down the belt — and the end are outside the bound's model).
  EXPECT_GT(r.utilisation[1], 0.5);
  EXPECT_LE(r.parts_per_hour, r.bound.parts_per_hour * 1.001);
  if (parts >= 100) {
    EXPECT_GT(r.parts_per_hour, 0.85 * r.bound.parts_per_hour) << r.bound.limit;
  }
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
  CellOptions o = options(1, 4);  // part1 comes down lane B, part3 is handed over
  o.timeline = &out;
  const CellReport r = vsd_workcell::run_cell(o);
  expect_clean(r, 4);
  const std::string t = out.str();
  EXPECT_NE(t.find("reach of robot_a: conveyor yes, conveyor_b no, station yes, dest_a yes, dest_b no"),
            std::string::npos);
  EXPECT_NE(t.find("reach of robot_b: conveyor no, conveyor_b yes, station yes, dest_a no, dest_b yes"),
            std::string::npos);
  EXPECT_NE(t.find("γ infeed.divert(part1, lane B)"), std::string::npos);
  EXPECT_NE(t.find("σ part1 rests on the conveyor's sensor on lane B"), std::string::npos);
  EXPECT_NE(t.find("γ orders_b.post(part1, route 3)"), std::string::npos);
  EXPECT_NE(t.find("γ infeed.divert(part3, lane A)"), std::string::npos);
  EXPECT_NE(t.find("γ orders.post(part3, route 2)"), std::string::npos);
  EXPECT_NE(t.find("A: hand over part3 at the station"), std::string::npos);
  EXPECT_NE(t.find("σ zone occupied by robot_a\n"), std::string::npos);
  EXPECT_NE(t.find("σ zone occupied by robot_b\n"), std::string::npos);
  EXPECT_EQ(t.find("ZONE VIOLATION"), std::string::npos);
  EXPECT_NE(t.find("γ robot_b.grasp(part1)"), std::string::npos);
  EXPECT_NE(t.find("token: multi_robot_control b.fetch: b.idle -1, b.approaching +1"), std::string::npos);
  EXPECT_NE(t.find("token: multi_robot_control a.fetch: a.idle -1, a.approaching +1"), std::string::npos);
  EXPECT_NE(t.find("token: multi_robot_control b.enter: b.idle -1, station.full -1, zone.free -1, "
                   "b.zone_approaching +1"),
            std::string::npos);
  EXPECT_NE(t.find(" (4 of 4)\n"), std::string::npos);
  std::ostringstream summary;
  vsd_workcell::print_summary(summary, r);
  const std::string s = summary.str();
  for (const char* line : {"parts handled: 4\n", "parts/hour: ", "parts/hour bound: ", "zone violations: 0\n", "deadlocks: 0\n",
                           "min arm distance: ", "utilisation: robot A ", "firings: ", "condition tests: "})
    EXPECT_NE(s.find(line), std::string::npos) << line << " in\n" << s;
}

TEST(TwoRobotCell, OneKindIsTheOneRobotBaseline) {
  // --kinds 1: only small parts; all go down lane A to robot A, B has nothing to do. The bound is then
  // robot A's direct cycle, and the run comes close to it.
  CellOptions o = options(2, 12);
  o.kinds = 1;
  const CellReport r = vsd_workcell::run_cell(o);
  EXPECT_EQ(r.parts_handled, 12);
  EXPECT_EQ(r.handovers, 0);
  EXPECT_EQ(r.utilisation[1], 0.0);
  EXPECT_EQ(r.bound.limit, "robot A");
  EXPECT_DOUBLE_EQ(r.bound.cycle, r.cycle.direct_a);
  EXPECT_LE(r.parts_per_hour, r.bound.parts_per_hour * 1.001);
  EXPECT_GT(r.parts_per_hour, 0.8 * r.bound.parts_per_hour);
}

TEST(TwoRobotCell, WritesThePictureAndFailsClearlyWhereItCannot) {
  const auto dir = std::filesystem::temp_directory_path();
  const auto path = dir / "vsd_two_robot_cell_test.png";
  CellOptions o = options(3, 2);
  o.png = path.string();
  const CellReport r = vsd_workcell::run_cell(o);
  EXPECT_TRUE(r.png_error.empty()) << r.png_error;
  std::ifstream in(path, std::ios::binary);
  std::string head(8, '\0');
  in.read(head.data(), 8);
  EXPECT_EQ(head, std::string("\x89PNG\r\n\x1a\n", 8));
  std::filesystem::remove(path);
  // A directory that is not there: the run refuses to start, naming the file and the reason.
  o.png = "/nonexistent-dir/cell.png";
  try {
    vsd_workcell::run_cell(o);
    ADD_FAILURE() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write /nonexistent-dir/cell.png: No such file or directory");
  }
}

TEST(TwoRobotCell, ThePicturesSamplesStayBoundedInALongRun) {
  vsd_workcell::TracePlot plot;
  vsd_workcell::TraceSample s;
  for (int i = 0; i < 2'000'000; ++i) {  // 20,000 s at the demo's 10 ms step
    s.t = i * 0.01;
    s.a_in_zone = i % 5000 < 300;  // the zone's occupancy changes now and then
    plot.add(s);
    ASSERT_LT(plot.size(), vsd_workcell::TracePlot::max_samples);
  }
  EXPECT_GT(plot.size(), vsd_workcell::TracePlot::max_samples / 4);
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
  EXPECT_EQ(error({"--kinds", "3"}), "--kinds: '3' is not a whole number in [1, 2]");
  EXPECT_EQ(error({"--png"}), "--png: needs a value");
  CellOptions o;
  vsd_workcell::parse_options({"--seed", "42", "--parts", "12", "--csv", "x.csv", "--png", "x.png", "--kinds", "1"}, o);
  EXPECT_EQ(o.seed, 42u);
  EXPECT_EQ(o.parts, 12);
  EXPECT_EQ(o.csv, "x.csv");
  EXPECT_EQ(o.png, "x.png");
  EXPECT_EQ(o.kinds, 1);
  // Files that are not there.
  CellOptions missing = options(1, 1);
  missing.robot_script = "/nonexistent/mrc.soml";
  EXPECT_THROW(vsd_workcell::run_cell(missing), vsd::Error);
}

// build_cell: the cell in the caller's Environment, run by whoever steps it (the Python plugin does so) —
// the same cell as run_cell's, part by part. (Its tasks and nets refer to the Cell: it goes before the
// Environment, which is not stepped after that.)
TEST(TwoRobotCell, BuiltIntoAnEnvironmentRunsWhenItIsStepped) {
  const CellOptions o = options(1, 2);
  const CellReport whole = vsd_workcell::run_cell(o);
  vsd::Environment env;
  {
    vsd_workcell::Cell cell = vsd_workcell::build_cell(env, o);
    EXPECT_DOUBLE_EQ(env.scheduler().base_step(), o.step);
    vsd::Node* outfeed = nullptr;
    for (vsd::Node* n : env.main_state().database().children())
      if (n->name() == "outfeed") outfeed = n;
    ASSERT_NE(outfeed, nullptr);
    std::vector<double> first;
    bool moved = false;
    for (vsd::SimStateInstance* i : env.main_state().instances())
      if (auto* tree = i->as<vsd::robotics::KinematicTree>(); tree != nullptr && first.empty())
        first = tree->positions();
    while (outfeed->children().size() < 2 && env.time() < whole.time + 1) {
      env.step();
      for (vsd::SimStateInstance* i : env.main_state().instances())
        if (auto* tree = i->as<vsd::robotics::KinematicTree>(); tree != nullptr && tree->positions() != first)
          moved = true;
    }
    EXPECT_EQ(outfeed->children().size(), 2u);  // both parts handled, in no more time than run_cell took
    EXPECT_TRUE(moved);
  }
  // Bad options fail before anything is built; a Cell runs once.
  CellOptions bad = o;
  bad.parts = 0;
  vsd::Environment other;
  EXPECT_THROW(vsd_workcell::build_cell(other, bad), vsd::Error);
  vsd_workcell::Cell cell = vsd_workcell::build_cell(other, o);
  EXPECT_EQ(cell.run().parts_handled, 2);
  try {
    cell.run();
    FAIL() << "a second run";
  } catch (const vsd::Error& e) {
    EXPECT_STREQ(e.what(), "Cell::run: the cell has run already");
  }
}

}  // namespace
