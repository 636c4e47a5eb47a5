// The SOML++ debugger: line breakpoints in functions, conditions and actions, transition breakpoints,
// the call stack and locals at a stop, step / next / finish / continue, print, the token trace, bad
// requests, and detaching (the code is restored).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using vsd::soml::Debugger;
using vsd::soml::Program;
using vsd::soml::Resume;
using vsd::soml::Stop;
using vsd::soml::StopReason;

constexpr const char* kScript = R"(int fib(int n) {
  if (n < 2) return n;
  int a = fib(n - 1);
  int b = fib(n - 2);
  return a + b;
}

object cell {
  int served = 0;
  string label = "cell";
  place free = 2;
  place done;
  transition go {
    when served < 2;
    do {
      int r = fib(3);
      served += 1;
      print("served " + served + " fib " + r);
    }
  }
  arrow free -> go;
  arrow go -> done;
}
)";

struct Dbg : ::testing::Test {
  vsd::Registry reg;
  vsd::Environment env{0, reg};
  std::ostringstream out;
  Program* p = nullptr;
  void SetUp() override {
    vsd::soml::RunOptions o;
    o.out = &out;
    p = &env.use<vsd::soml::Module>().load(env.main_state(), "dbg.soml", kScript, o);
  }
  // Where each stop happened: "line function" or "fire transition".
  std::vector<std::string> stops;
  std::string describe(Debugger& d, const Stop& s) {
    (void)d;
    if (s.reason == StopReason::Transition) return "fire " + vsd::soml::net_node_label(s.transition);
    return std::to_string(s.line) + " " + s.function;
  }
};

std::string joined(const std::vector<vsd::soml::Variable>& vars) {
  std::string s;
  for (const auto& v : vars) s += (s.empty() ? "" : ", ") + v.type + " " + v.name + " = " + v.value;
  return s;
}

TEST_F(Dbg, LineBreakpointInAFunctionShowsStackAndLocals) {
  Debugger d(*p);
  EXPECT_EQ(d.break_at("dbg.soml:5"), 1);
  std::vector<std::string> seen;
  d.on_stop([&](Debugger& dd, const Stop& s) {
    EXPECT_EQ(s.reason, StopReason::Breakpoint);
    EXPECT_EQ(s.breakpoint, 1);
    EXPECT_TRUE(dd.stopped());
    const auto stack = dd.call_stack();
    std::string frames;
    for (const auto& f : stack) frames += f.function + ":" + std::to_string(f.line) + " ";
    seen.push_back(frames + "| " + joined(dd.locals()));
    return Resume::Continue;
  });
  EXPECT_EQ(p->step(1), 1u);
  // fib(3) runs line 5 for fib(2) and fib(3): both stops, innermost frame first.
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0], "fib:5 fib:3 cell.go (action):16 | int n = 2, int a = 1, int b = 0");
  EXPECT_EQ(seen[1], "fib:5 cell.go (action):16 | int n = 3, int a = 1, int b = 1");
  EXPECT_EQ(d.breakpoints()[0].hits, 2u);
  EXPECT_FALSE(d.stopped());
  EXPECT_EQ(out.str(), "served 1 fib 2\n");
}

TEST_F(Dbg, BreakpointsInConditionAndActionAndOnATransition) {
  Debugger d(*p);
  d.break_at_line(14);  // the condition
  d.break_at_line(17);  // the action
  d.break_on_transition("cell.go");
  d.on_stop([&](Debugger& dd, const Stop& s) {
    stops.push_back(describe(dd, s));
    if (s.reason == StopReason::Transition) {
      EXPECT_TRUE(dd.call_stack().empty());
      EXPECT_EQ(dd.print("served"), "served = " + std::to_string(stops.size() == 2 ? 0 : 1));
    }
    if (s.line == 17) {
      EXPECT_EQ(joined(dd.locals()), "int r = 2");
    }
    return Resume::Continue;
  });
  EXPECT_EQ(p->run_until_quiet(), 2u);
  EXPECT_THAT(stops, ElementsAre("14 cell.go (condition)", "fire cell.go", "17 cell.go (action)",
                                 "14 cell.go (condition)", "fire cell.go", "17 cell.go (action)"));
  // No third test of the condition: the input place is empty, so the condition is not evaluated.
}

TEST_F(Dbg, StepEntersCallsNextStepsOverThemFinishLeaves) {
  Debugger d(*p);
  d.break_at_line(16);
  std::vector<Resume> plan = {Resume::Step, Resume::Step, Resume::Next,    Resume::Finish,
                              Resume::Next, Resume::Next, Resume::Continue};
  std::size_t k = 0;
  d.on_stop([&](Debugger& dd, const Stop& s) {
    stops.push_back(describe(dd, s) + " depth " + std::to_string(dd.call_stack().size()));
    return k < plan.size() ? plan[k++] : Resume::Continue;
  });
  EXPECT_EQ(p->step(1), 1u);
  EXPECT_THAT(stops, ElementsAre("16 cell.go (action) depth 1",    // breakpoint
                                 "2 fib depth 2",                  // step: into fib(3)
                                 "3 fib depth 2",                  // step
                                 "4 fib depth 2",                  // next: over fib(2)
                                 "17 cell.go (action) depth 1",    // finish: back in the action
                                 "18 cell.go (action) depth 1"));  // next
  // The last next ran off the action's end: the next code run is the next test of the condition.
  EXPECT_EQ(p->step(1), 1u);
  ASSERT_EQ(stops.size(), 8u);
  EXPECT_EQ(stops[6], "14 cell.go (condition) depth 1");
  EXPECT_EQ(stops[7], "16 cell.go (action) depth 1");  // the breakpoint again, in the second firing
}

TEST_F(Dbg, StepIntoNextStopsAtTheFirstLineRun) {
  Debugger d(*p);
  d.on_stop([&](Debugger& dd, const Stop& s) {
    stops.push_back(describe(dd, s));
    return Resume::Continue;
  });
  d.step_into_next();
  EXPECT_EQ(p->step(1), 1u);
  EXPECT_THAT(stops, ElementsAre("14 cell.go (condition)"));
  d.step_into_next(false);
  EXPECT_EQ(p->step(1), 1u);
  EXPECT_EQ(stops.size(), 1u);
}

TEST_F(Dbg, PrintReadsLocalsPropertiesObjectsAndPlaces) {
  Debugger d(*p);
  d.break_at_line(18);
  std::vector<std::string> printed;
  d.on_stop([&](Debugger& dd, const Stop&) {
    printed.push_back(dd.print("r"));
    printed.push_back(dd.print("served"));
    printed.push_back(dd.print("label"));
    printed.push_back(dd.print("free"));
    printed.push_back(dd.print("cell.done"));
    printed.push_back(dd.print("cell"));
    printed.push_back(dd.print("this"));
    EXPECT_THAT([&] { (void)dd.print("nope"); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("'nope'")));
    EXPECT_THAT([&] { (void)dd.print("r.x"); },
                ::testing::ThrowsMessage<vsd::Error>(HasSubstr("no members")));
    EXPECT_THAT([&] { (void)dd.print("cell.x"); },
                ::testing::ThrowsMessage<vsd::Error>(HasSubstr("has no member 'x'")));
    EXPECT_THAT([&] { (void)dd.print("a + b"); },
                ::testing::ThrowsMessage<vsd::Error>(HasSubstr("is not a name or a path")));
    EXPECT_THAT([&] { (void)dd.print("mark"); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("no mark")));
    EXPECT_THAT([&] { (void)dd.locals(5); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("no frame 5")));
    return Resume::Continue;
  });
  p->step(1);
  EXPECT_THAT(printed, ElementsAre("r = 2", "served = 1", "label = \"cell\"", "cell.free = 1",
                                   "cell.done = 0", "cell = cell (soml::cell) {served = 1, label = \"cell\"}",
                                   "this = go (soml::Transition) {firings = 0}"));
  // Between runs print starts from the script object.
  EXPECT_EQ(d.print("cell.served"), "cell.served = 1");
  EXPECT_THAT([&] { (void)d.locals(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("not stopped")));
  EXPECT_EQ(d.marking(), "cell.free = 1\ncell.done = 1\n");
}

TEST_F(Dbg, TraceReportsEveryTokenMove) {
  std::vector<std::string> before;
  p->on_firing([&](const vsd::soml::Firing& f) { before.push_back(std::to_string(f.step)); });
  std::vector<std::string> moves;
  {
    Debugger d(*p);
    d.on_firing([&](const vsd::soml::Firing& f) {
      std::string s = "step " + std::to_string(f.step) + " " + vsd::soml::net_node_label(f.transition);
      for (const auto& m : f.taken)
        s += " " + vsd::soml::net_node_label(m.place) + " -" + std::to_string(m.count);
      for (const auto& m : f.given)
        s += " " + vsd::soml::net_node_label(m.place) + " +" + std::to_string(m.count);
      moves.push_back(s);
    });
    p->run_until_quiet();
  }
  EXPECT_THAT(moves, ElementsAre("step 1 cell.go cell.free -1 cell.done +1",
                                 "step 2 cell.go cell.free -1 cell.done +1"));
  EXPECT_THAT(before, ElementsAre("1", "2"));  // the program's own trace still hears every firing
}

TEST_F(Dbg, BadRequestsAreClearErrors) {
  Debugger d(*p);
  EXPECT_THAT([&] { d.break_at_line(7); },
              ::testing::ThrowsMessage<vsd::Error>(
                  HasSubstr("no code on dbg.soml:7 (the nearest lines with code: 5 and 9)")));
  EXPECT_THAT([&] { d.break_at("other.soml:3"); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("'other.soml' is not the script debugged")));
  EXPECT_THAT([&] { d.break_at("dbg.soml:x"); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("is not FILE:LINE or LINE")));
  EXPECT_THAT([&] { d.break_on_transition("cell.nothing"); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("no transition 'cell.nothing'")));
  EXPECT_FALSE(d.remove(42));
  EXPECT_THAT([&] { Debugger second(*p); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("another debugger")));
}

TEST_F(Dbg, DetachingRestoresTheCodeAndRemovedBreakpointsNoLongerStop) {
  {
    Debugger d(*p);
    const int id = d.break_at_line(3);
    d.on_stop([&](Debugger& dd, const Stop& s) {
      stops.push_back(describe(dd, s));
      return Resume::Continue;
    });
    EXPECT_TRUE(d.remove(id));
    p->step(1);
    EXPECT_TRUE(stops.empty());
    d.break_at_line(3);
  }
  // Detached: nothing stops, and the program runs on correctly.
  EXPECT_EQ(p->root().call("fib", {vsd::Value(std::int64_t{20})}).as<std::int64_t>(), 6765);
  EXPECT_TRUE(stops.empty());
}

TEST_F(Dbg, AnErrorInTheStopHandlerUnwindsTheProgramCleanly) {
  Debugger d(*p);
  d.break_at_line(17);
  d.on_stop([](Debugger&, const Stop&) -> Resume { throw vsd::Error("stop here"); });
  EXPECT_THAT([&] { p->step(1); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("stop here")));
  EXPECT_EQ(p->place("free", p->object("cell"))->tokens(), 2);  // the firing was undone
  d.on_stop({});
  EXPECT_EQ(p->run_until_quiet(), 2u);
}


TEST_F(Dbg, ShowsTheSourceAndTheLinesThatTakeABreakpoint) {
  Debugger d(*p);
  EXPECT_EQ(d.file(), "dbg.soml");
  EXPECT_EQ(d.source(), kScript);
  const std::vector<std::uint32_t> lines = d.lines();
  ASSERT_FALSE(lines.empty());
  EXPECT_TRUE(std::is_sorted(lines.begin(), lines.end()));
  for (std::uint32_t l : lines) EXPECT_NO_THROW(d.remove(d.break_at_line(l))) << "line " << l;
  EXPECT_THAT(lines, ::testing::Contains(2u));               // in a function
  EXPECT_THAT(lines, ::testing::Not(::testing::Contains(7u)));  // a blank line
  EXPECT_THAT([&] { d.break_at_line(7); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("no code")));
}

TEST(DebuggerLifetime, OutlivingItsProgramDetachesIt) {
  vsd::Registry reg;
  vsd::Environment env{0, reg};
  auto& soml = env.use<vsd::soml::Module>();
  std::ostringstream out;
  vsd::soml::RunOptions o;
  o.out = &out;
  vsd::SimState& copy = env.create_state("other");
  Program& p = soml.load(copy, "dbg.soml", kScript, o);
  Debugger d(p);
  d.break_at_line(3);
  d.break_on_transition("cell.go");
  EXPECT_TRUE(d.attached());
  env.remove_state(copy);  // the program goes with its state
  EXPECT_FALSE(d.attached());
  EXPECT_EQ(d.breakpoints().size(), 2u);  // still readable
  EXPECT_TRUE(d.call_stack().empty());
  EXPECT_THAT([&] { d.break_at_line(3); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("is gone")));
  EXPECT_THAT([&] { (void)d.print("cell"); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("is gone")));
  EXPECT_THAT([&] { (void)d.program(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("is gone")));
  EXPECT_THAT([&] { (void)d.remove(1); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("is gone")));
}

}  // namespace
