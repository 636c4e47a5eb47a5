// The verified supervisor: Multi Robot Control's place/transition abstraction (net_abstraction.hpp says
// how it corresponds to the real net) explored exhaustively — the shared zone is mutually exclusive in
// every reachable marking, and no reachable marking is dead.
#include "net_abstraction.hpp"

#include <gtest/gtest.h>

#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "vsd/analysis/explorer.hpp"
#include "vsd/core/error.hpp"

namespace {

using vsd::analysis::PtNet;
using Marking = std::vector<std::uint32_t>;

const std::string robot_script = VSD_CELL_ROBOTS;

// Every reachable marking, breadth first (the nets here have a few hundred).
std::vector<Marking> reachable(const PtNet& net) {
  std::set<Marking> seen{net.initial_marking()};
  std::deque<Marking> todo{net.initial_marking()};
  std::vector<Marking> all;
  while (!todo.empty()) {
    Marking m = todo.front();
    todo.pop_front();
    all.push_back(m);
    for (std::uint32_t t = 0; t < net.transition_count(); ++t) {
      if (!net.enabled(t, m)) continue;
      Marking next = m;
      net.fire(t, next);
      if (seen.insert(next).second) todo.push_back(next);
    }
  }
  return all;
}

// The reachable markings from which the initial marking can no longer be reached: a robot (or a
// resource) stuck for good. Since B has lane B to itself, a robot that is stuck no longer makes the whole
// net dead — B goes on with its own jobs — so "no dead marking" is not enough: the net must be able to
// return to rest from everywhere (reversible).
std::vector<Marking> stuck(const PtNet& net, const std::vector<Marking>& all) {
  std::map<Marking, std::vector<Marking>> back;  // marking -> its predecessors
  for (const Marking& m : all)
    for (std::uint32_t t = 0; t < net.transition_count(); ++t) {
      if (!net.enabled(t, m)) continue;
      Marking next = m;
      net.fire(t, next);
      back[next].push_back(m);
    }
  std::set<Marking> home{net.initial_marking()};
  std::deque<Marking> todo{net.initial_marking()};
  while (!todo.empty()) {
    const Marking m = todo.front();
    todo.pop_front();
    for (const Marking& p : back[m])
      if (home.insert(p).second) todo.push_back(p);
  }
  std::vector<Marking> r;
  for (const Marking& m : all)
    if (home.count(m) == 0) r.push_back(m);
  return r;
}

// The places of a robot "in the zone": between taking zone.free and giving it back (named zone_*).
std::vector<std::uint32_t> zone_places(const PtNet& net, const std::string& robot) {
  std::vector<std::uint32_t> r;
  for (std::uint32_t p = 0; p < net.place_count(); ++p)
    if (net.places()[p].id.rfind(robot + ".zone_", 0) == 0) r.push_back(p);
  return r;
}

std::uint32_t tokens(const Marking& m, const std::vector<std::uint32_t>& places) {
  std::uint32_t n = 0;
  for (auto p : places) n += m[p];
  return n;
}

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(MultiRobotControlAbstraction, ZoneIsMutuallyExclusiveInEveryReachableMarking) {
  std::vector<std::string> notes;
  const PtNet net = vsd_workcell::pt_abstraction(robot_script, &notes);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("conditions"), std::string::npos);
  const auto a = zone_places(net, "a");
  const auto b = zone_places(net, "b");
  ASSERT_EQ(a.size(), 4u);  // A: entering, lowering, leaving, exiting
  ASSERT_EQ(b.size(), 4u);  // B: approaching, descending, lifting, exiting
  const auto free = net.find_place("zone.free");
  ASSERT_TRUE(free.has_value());
  EXPECT_EQ(net.initial_marking()[*free], 1u);

  const auto all = reachable(net);
  for (const Marking& m : all) {
    ASSERT_LE(tokens(m, a) + tokens(m, b), 1u);
    ASSERT_EQ(m[*free] + tokens(m, a) + tokens(m, b), 1u);  // the zone's token is somewhere
  }
  // Both robots do get into the zone (the property is not vacuous).
  EXPECT_TRUE(std::any_of(all.begin(), all.end(), [&](const Marking& m) { return tokens(m, a) == 1; }));
  EXPECT_TRUE(std::any_of(all.begin(), all.end(), [&](const Marking& m) { return tokens(m, b) == 1; }));

  // From every reachable marking the net can come back to its initial marking: no robot gets stuck.
  EXPECT_TRUE(stuck(net, all).empty());

  // The library's explorer sees the same state space, and no dead marking in it.
  const auto r = vsd::analysis::explore(net);
  ASSERT_TRUE(r.complete());
  EXPECT_EQ(r.states, all.size());
  EXPECT_FALSE(r.deadlock);
  EXPECT_EQ(r.max_tokens_place, 1u);  // safe
  RecordProperty("places", static_cast<int>(net.place_count()));
  RecordProperty("transitions", static_cast<int>(net.transition_count()));
  RecordProperty("states", static_cast<int>(r.states));
}

TEST(MultiRobotControlAbstraction, FindsTheViolationWhenBIgnoresTheZone) {
  // B's `enter` without the zone's token: the exploration must find both robots in the zone.
  std::string text = read(robot_script);
  const std::string line = "  arrow zone.free ~> enter;\n";
  const auto at = text.rfind(line);  // the second one is B's
  ASSERT_NE(at, std::string::npos);
  text.erase(at, line.size());
  // B's exit still gives a token back: that would make the net unbounded; it gives nothing now either.
  const std::string give = "  arrow exit ~> zone.free;\n  arrow exit -> carrying;\n";
  const auto g = text.find(give);
  ASSERT_NE(g, std::string::npos);
  text.replace(g, give.size(), "  arrow exit -> carrying;\n");
  const auto path = std::filesystem::temp_directory_path() / "vsd_mrc_without_zone.soml";
  std::ofstream(path) << text;
  const PtNet net = vsd_workcell::pt_abstraction(path.string());
  std::filesystem::remove(path);
  const auto a = zone_places(net, "a");
  const auto b = zone_places(net, "b");
  const auto all = reachable(net);
  EXPECT_TRUE(std::any_of(all.begin(), all.end(),
                          [&](const Marking& m) { return tokens(m, a) + tokens(m, b) == 2; }));
}

TEST(MultiRobotControlAbstraction, FindsTheStuckRobotsWhenAKeepsTheZone) {
  // A's exit without giving zone.free back: markings are reachable from which the net never returns to
  // rest (A waits at its gate for the zone for good, the station stays full). The net is not dead —
  // B still works lane B — which is why the check is reversibility, not the explorer's deadlock.
  std::string text = read(robot_script);
  const std::string give = "  arrow exit ~> zone.free;\n  arrow exit -> idle;\n";
  const auto at = text.find(give);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, give.size(), "  arrow exit -> idle;\n");
  const auto path = std::filesystem::temp_directory_path() / "vsd_mrc_keeps_zone_abstraction.soml";
  std::ofstream(path) << text;
  const PtNet net = vsd_workcell::pt_abstraction(path.string());
  std::filesystem::remove(path);
  const auto all = reachable(net);
  const auto s = stuck(net, all);
  ASSERT_FALSE(s.empty());
  // Among them: the zone's token gone for good, the part left on the station.
  EXPECT_TRUE(std::any_of(s.begin(), s.end(), [&](const Marking& m) {
    return m[*net.find_place("zone.free")] == 0 && m[*net.find_place("station.full")] == 1;
  }));
  EXPECT_FALSE(vsd::analysis::explore(net).deadlock);  // what the explorer alone would miss
}

TEST(MultiRobotControlAbstraction, RefusesObjectTokensWithTheirPosition) {
  // Meta Control moves Job objects: not a place/transition net.
  try {
    (void)vsd_workcell::pt_abstraction(VSD_CELL_META);
    FAIL() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("meta_control.soml:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("outside the place/transition abstraction"), std::string::npos)
        << e.what();
  }
}

TEST(MultiRobotControlAbstraction, UnreadableScriptIsAClearError) {
  EXPECT_THROW((void)vsd_workcell::pt_abstraction("/nonexistent/mrc.soml"), vsd::Error);
}

}  // namespace
