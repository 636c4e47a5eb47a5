// SOML++ scripts as P/T nets and back: state spaces of hand-made scripts, the MCC nets through SOML++
// and back, and every construct outside black-token nets refused with its position.
#include "vsd/analysis/soml_net.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "vsd/core/error.hpp"
#include "vsd/analysis/explorer.hpp"
#include "vsd/analysis/pnml.hpp"

namespace an = vsd::analysis;
using an::PtNet;

namespace {

const std::string kSomlNetData = VSD_ANALYSIS_TEST_DATA_DIR;

std::string soml_net_error_of(const std::string& script) {
  try {
    (void)an::read_soml_net(script, "s.soml");
  } catch (const vsd::Error& e) {
    return e.what();
  }
  return "no error";
}

// Equal up to ids and names: markings, and every transition's arcs in order.
void expect_same_structure(const PtNet& a, const PtNet& b) {
  ASSERT_EQ(a.place_count(), b.place_count());
  ASSERT_EQ(a.transition_count(), b.transition_count());
  EXPECT_EQ(a.initial_marking(), b.initial_marking());
  auto strip = [](std::vector<an::ArcRef> arcs) {
    for (auto& x : arcs) x.id.clear();
    return arcs;
  };
  for (std::size_t t = 0; t < a.transition_count(); ++t) {
    EXPECT_EQ(strip(a.transitions()[t].inputs), strip(b.transitions()[t].inputs)) << "transition " << t;
    EXPECT_EQ(strip(a.transitions()[t].outputs), strip(b.transitions()[t].outputs)) << "transition " << t;
    EXPECT_EQ(strip(a.transitions()[t].inhibitors), strip(b.transitions()[t].inhibitors)) << "transition " << t;
  }
}

TEST(SomlNet, ObjectsDerivedFromAClassEachGetItsNet) {
  const an::SomlNetImport imp = an::read_soml_net(R"(
class Proc {
  place idle = 1;
  place busy;
  transition go;
  transition back;
  arrow idle -> go;
  arrow go -> busy;
  arrow busy -> back;
  arrow back -> idle;
}
object a : Proc;
object b : Proc { place log; transition note; arrow note -> log; arrow busy -o note; }
)",
                                                  "procs.soml");
  const PtNet& net = imp.net;
  // a: idle busy go back; b: idle busy (inherited) then its own log, note.
  ASSERT_EQ(net.place_count(), 5u);
  ASSERT_EQ(net.transition_count(), 5u);
  EXPECT_EQ(net.places()[0].id, "a.idle");
  EXPECT_EQ(net.places()[2].id, "b.idle");
  EXPECT_EQ(net.places()[4].id, "b.log");
  EXPECT_EQ(net.initial_marking(), (std::vector<std::uint32_t>{1, 0, 1, 0, 0}));
  const auto note = net.find_transition("b.note");
  ASSERT_TRUE(note);
  ASSERT_EQ(net.transitions()[*note].inhibitors.size(), 1u);
  EXPECT_EQ(net.places()[net.transitions()[*note].inhibitors[0].place].id, "b.busy");
  // The class's own net is not part of the static net, and a note says so.
  ASSERT_EQ(imp.notes.size(), 1u);
  EXPECT_NE(imp.notes[0].find("procs.soml:2:7: the net of class 'Proc'"), std::string::npos) << imp.notes[0];

  // a: 2 states; b: idle/busy x log unbounded while idle... note fires only while b.busy is empty, so
  // b.log grows without bound: the analysis says so.
  const an::ExploreResult r = an::explore(net);
  EXPECT_EQ(r.status, an::ExploreResult::Status::unbounded);
}

TEST(SomlNet, KnownStateSpaces) {
  {  // Two processes sharing one lock: (idle, idle), (crit, idle), (idle, crit).
    const an::SomlNetImport imp = an::read_soml_net(R"(
place lock = 1;
place idle1 = 1;  place crit1;  place idle2 = 1;  place crit2;
transition enter1;  transition leave1;  transition enter2;  transition leave2;
arrow lock -> enter1;  arrow idle1 -> enter1;  arrow enter1 -> crit1;
arrow crit1 -> leave1;  arrow leave1 -> idle1;  arrow leave1 -> lock;
arrow lock -> enter2;  arrow idle2 -> enter2;  arrow enter2 -> crit2;
arrow crit2 -> leave2;  arrow leave2 -> idle2;  arrow leave2 -> lock;
)");
    const an::ExploreResult r = an::explore(imp.net);
    EXPECT_EQ(r.states, 3u);
    EXPECT_EQ(r.edges, 4u);
    EXPECT_FALSE(r.deadlock);
    EXPECT_EQ(r.max_tokens_place, 1u);
  }
  {  // An inhibitor arc with weight 2 stops the moves after two tokens: a dead marking.
    const an::SomlNetImport imp = an::read_soml_net(R"(
place src = 3;
place dst;
transition move;
arrow src -> move;
arrow move -> dst;
arrow dst -o move * 2;
)");
    const an::ExploreResult r = an::explore(imp.net);
    EXPECT_EQ(r.states, 3u);
    EXPECT_EQ(r.edges, 2u);
    EXPECT_TRUE(r.deadlock);
    EXPECT_EQ(r.dead_marking, (std::vector<std::uint32_t>{1, 2}));
  }
  {  // Weights: a generator doubling its token is unbounded.
    const an::SomlNetImport imp = an::read_soml_net("place p = 1; transition gen; arrow p -> gen; arrow gen -> p * 2;");
    EXPECT_EQ(an::explore(imp.net).status, an::ExploreResult::Status::unbounded);
  }
}

TEST(SomlNet, ActionsThatChangeNoMarkingAreIgnoredWithANote) {
  const an::SomlNetImport imp = an::read_soml_net(R"(
int fired = 0;
void log(string s) { print(s); fired += 1; }
place p = 1;
transition t { do { log("t"); } }
arrow p -> t;
)",
                                                  "act.soml");
  ASSERT_EQ(imp.notes.size(), 1u);
  EXPECT_NE(imp.notes[0].find("act.soml:5:19: the action of transition 't' is ignored"), std::string::npos)
      << imp.notes[0];
  EXPECT_EQ(an::explore(imp.net).states, 2u);
}

TEST(SomlNet, ConstructsOutsideBlackTokenNetsAreRefusedWithTheirPositions) {
  const std::string e = soml_net_error_of(R"(class Job : Node { bool ready = true; start cell.waiting; }
object cell {
  place<Job> waiting;
  place free = 1;
  place done;
  transition go { when mark.ready; }
  arrow waiting -> go;
  arrow free -> go when true;
  transition refill { do { free.put(1); } }
  arrow refill ~> other.done;
}
object other { place done; }
object job : Job;
void fill() { other.done.put(2); }
transition helper { do { fill(); } }
)");
  EXPECT_NE(e.find("s.soml: the net is not a place/transition net"), std::string::npos) << e;
  EXPECT_NE(e.find("s.soml:1:45: error: start place"), std::string::npos) << e;
  EXPECT_NE(e.find("s.soml:3:14: error: place 'cell.waiting' holds object tokens"), std::string::npos) << e;
  EXPECT_NE(e.find("s.soml:6:14: error: transition 'cell.go' has a condition"), std::string::npos) << e;
  EXPECT_NE(e.find("s.soml:8:25: error: arrow condition"), std::string::npos) << e;
  EXPECT_NE(e.find("s.soml:9:28: error: the action of transition 'cell.refill' changes a marking"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("s.soml:10:3: error: communication arrow"), std::string::npos) << e;
  EXPECT_NE(e.find("s.soml:15:26: error: the action of transition 'helper' changes a marking"), std::string::npos)
      << e;
  // Each with its source line and a caret.
  EXPECT_NE(e.find("  transition go { when mark.ready; }\n"), std::string::npos) << e;
}

// Whether an action changes a marking through the functions it calls was found by recursing into each
// callee: a chain of 100,000 functions overflowed the stack. The call graph is walked without recursion,
// and a function that reaches a put through a cycle is found too.
TEST(SomlNet, ACallChainOfAnyLengthIsFollowedWithoutRecursion) {
  constexpr int kChain = 100'000;
  std::string text = "place p = 1;\n";
  for (int i = 0; i < kChain; ++i)
    text += "void f" + std::to_string(i) + "() { f" + std::to_string(i + 1) + "(); }\n";
  text += "void f" + std::to_string(kChain) + "() { p.put(1); }\ntransition t { do { f0(); } }\narrow p -> t;\n";
  const std::string e = soml_net_error_of(text);
  EXPECT_NE(e.find("s.soml:100003:21: error: the action of transition 't' changes a marking"), std::string::npos)
      << e.substr(0, 400);
  // g calls h before its own put, h calls g: both change a marking, whichever is asked about first.
  const std::string cycle = soml_net_error_of(R"(place p = 1;
void g() { h(); p.put(1); }
void h() { g(); }
transition a { do { h(); } }
arrow p -> a;
)");
  EXPECT_NE(cycle.find("s.soml:4:21: error: the action of transition 'a' changes a marking"), std::string::npos)
      << cycle;
}

TEST(SomlNet, NetsAndSubstitutionAndInvocationAreRefused) {
  const std::string e = soml_net_error_of(R"(net Relay(place in, place out) {
  transition pass;
  arrow in -> pass;
  arrow pass -> out;
}
net bool ask() { place begin; start begin; transition t { do { finish true; } } arrow begin -> t; }
place a = 1;
place b;
transition move = Relay(a, b);
transition call { invoke ask(); }
)");
  EXPECT_NE(e.find("s.soml:9:19: error: transition 'move' is substituted by a net"), std::string::npos) << e;
  EXPECT_NE(e.find("s.soml:10:26: error: transition 'call' invokes a net"), std::string::npos) << e;
}

TEST(SomlNet, ScriptErrorsComeWithTheirDiagnostics) {
  const std::string e = soml_net_error_of("place p = 1;\narrow p -> nowhere;\n");
  EXPECT_NE(e.find("s.soml:2:12: error:"), std::string::npos) << e;
  EXPECT_NE(e.find("nowhere"), std::string::npos) << e;
  EXPECT_NE(soml_net_error_of("place p = ;").find("s.soml:1:11: error:"), std::string::npos);
}

TEST(SomlNet, MccNetsSurviveTheWayThroughSomlAndHaveTheSameStateSpace) {
  for (const char* model : {"ResAllocation-PT-R002C002", "Eratosthenes-PT-010", "TokenRing-PT-005",
                            "Philosophers-PT-000005", "SharedMemory-PT-000005", "FMS-PT-00002", "Dekker-PT-010",
                            "Peterson-PT-2"}) {
    SCOPED_TRACE(model);
    const an::PnmlImport pnml = an::read_pnml_file(kSomlNetData + "/" + std::string(model) + ".pnml");
    std::vector<std::string> renamed;
    const std::string script = an::write_soml(pnml.net, &renamed);
    const an::SomlNetImport back = an::read_soml_net(script, std::string(model) + ".soml");
    EXPECT_TRUE(back.notes.empty());
    expect_same_structure(pnml.net, back.net);
    // Ids that are identifiers are kept; the others are renamed and the note names both.
    for (std::size_t i = 0; i < pnml.net.place_count(); ++i)
      if (back.net.places()[i].id != pnml.net.places()[i].id) {
        bool noted = false;
        for (const auto& r : renamed) noted = noted || r.find("'" + pnml.net.places()[i].id + "'") != std::string::npos;
        EXPECT_TRUE(noted) << pnml.net.places()[i].id;
      }
  }
  // One full state space through SOML++, against expected.tsv's figures for TokenRing-PT-005.
  const an::PnmlImport ring = an::read_pnml_file(kSomlNetData + "/TokenRing-PT-005.pnml");
  const an::SomlNetImport back = an::read_soml_net(an::write_soml(ring.net));
  const an::ExploreResult a = an::explore(ring.net), b = an::explore(back.net);
  EXPECT_EQ(a.states, b.states);
  EXPECT_EQ(a.edges, b.edges);
  EXPECT_EQ(a.deadlock, b.deadlock);
}

TEST(SomlNet, IdsThatAreNotIdentifiersAreRenamedUniquelyAndKeptInComments) {
  PtNet net("odd", "odd ids");
  const auto p1 = net.add_place("1-a", "first\nplace", 2);
  const auto p2 = net.add_place("_1_a", {}, 0);  // what "1-a" would become: the renamed one must differ
  const auto p3 = net.add_place("while", {}, 1);
  const auto t = net.add_transition("t.x");
  net.add_input(t, p1, 2);
  net.add_output(t, p2, 3);
  net.add_inhibitor(t, p3, 4);
  std::vector<std::string> notes;
  const std::string script = an::write_soml(net, &notes);
  EXPECT_NE(script.find("place _1_a_2 = 2;  // id \"1-a\", name \"first place\""), std::string::npos) << script;
  EXPECT_NE(script.find("place while_ = 1;  // id \"while\""), std::string::npos) << script;
  EXPECT_NE(script.find("arrow _1_a_2 -> t_x * 2;"), std::string::npos) << script;
  EXPECT_NE(script.find("arrow t_x -> _1_a * 3;"), std::string::npos) << script;
  EXPECT_NE(script.find("arrow while_ -o t_x * 4;"), std::string::npos) << script;
  EXPECT_EQ(notes.size(), 3u);
  const an::SomlNetImport back = an::read_soml_net(script);
  expect_same_structure(net, back.net);
}

TEST(SomlNet, FilesAndUnreadableFiles) {
  const auto dir = std::filesystem::temp_directory_path() / ("vsd_soml_net_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  PtNet net("n");
  const auto p = net.add_place("p", {}, 1);
  const auto t = net.add_transition("t");
  net.add_input(t, p);
  an::write_soml_file(net, dir / "n.soml");
  expect_same_structure(net, an::read_soml_net_file(dir / "n.soml").net);
  EXPECT_THROW((void)an::read_soml_net_file(dir / "missing.soml"), vsd::Error);
  EXPECT_THROW(an::write_soml_file(net, dir / "no" / "such" / "dir.soml"), vsd::Error);
  std::filesystem::remove_all(dir);
}

}  // namespace
