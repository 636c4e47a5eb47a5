// The SOML++ VM's fused instructions (src/soml/opcodes.hpp): int compare-and-jump against a register or
// a constant, the counting loop's step-test-jump at the loop's bottom (LOOPLT and kin), calls on the
// frame's own self (CALLS), and compound assignments and returns straight in a local's register. Each is
// checked against C++ over the edge cases, with the overflow and budget errors inside fused loops, and
// with the debugger's line breakpoints and stepping inside a fused loop.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "script_fixture.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace {

using soml_test::error_of;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using vsd::soml::Program;

struct Opcodes : soml_test::ScriptTest {
  Program* p = nullptr;
  std::int64_t call(const char* f, std::vector<vsd::Value> args) {
    return p->root().call(f, args).as<std::int64_t>();
  }
  std::string error(const char* f, std::vector<vsd::Value> args) {
    return error_of([&] { p->root().call(f, args); });
  }
};

vsd::Value I(std::int64_t v) { return vsd::Value(v); }

constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();

TEST_F(Opcodes, CompareAndJumpOnRegistersAndConstants) {
  p = &load(R"(int lt(int a, int b) { if (a < b) return 1; return 0; }
int le(int a, int b) { if (a <= b) return 1; return 0; }
int gt(int a, int b) { if (a > b) return 1; return 0; }
int ge(int a, int b) { if (a >= b) return 1; return 0; }
int eq(int a, int b) { if (a == b) return 1; return 0; }
int ne(int a, int b) { if (a != b) return 1; return 0; }
int ltk(int a) { if (a < -3) return 1; return 0; }
int lek(int a) { if (a <= -3) return 1; return 0; }
int gtk(int a) { if (a > 32767) return 1; return 0; }
int gek(int a) { if (a >= -32768) return 1; return 0; }
int eqk(int a) { if (a == 7) return 1; return 0; }
int nek(int a) { if (a != 7) return 1; return 0; }
int big(int a) { if (a < 40000) return 1; return 0; }
int count_down(int n) { int k = 0; while (n > 0) { n -= 1; k += 1; } return k; }
)");
  const std::string d = p->disassemble();
  for (const char* op : {"JGEI ", "JGTI ", "JLEI ", "JLTI ", "JNEI ", "JEQI ", "JGEIK", "JGTIK", "JLEIK",
                         "JLTIK", "JNEIK", "JEQIK"})
    EXPECT_THAT(d, HasSubstr(op)) << "the condition fused into " << op;
  const std::vector<std::int64_t> values = {kMin, -40000, -32768, -32767, -4,    -3,    -2,
                                            0,    6,      7,      8,      32767, 32768, kMax};
  for (std::int64_t a : values) {
    for (std::int64_t b : values) {
      EXPECT_EQ(call("lt", {I(a), I(b)}), a < b ? 1 : 0) << a << " < " << b;
      EXPECT_EQ(call("le", {I(a), I(b)}), a <= b ? 1 : 0) << a << " <= " << b;
      EXPECT_EQ(call("gt", {I(a), I(b)}), a > b ? 1 : 0) << a << " > " << b;
      EXPECT_EQ(call("ge", {I(a), I(b)}), a >= b ? 1 : 0) << a << " >= " << b;
      EXPECT_EQ(call("eq", {I(a), I(b)}), a == b ? 1 : 0) << a << " == " << b;
      EXPECT_EQ(call("ne", {I(a), I(b)}), a != b ? 1 : 0) << a << " != " << b;
    }
    EXPECT_EQ(call("ltk", {I(a)}), a < -3 ? 1 : 0) << a;
    EXPECT_EQ(call("lek", {I(a)}), a <= -3 ? 1 : 0) << a;
    EXPECT_EQ(call("gtk", {I(a)}), a > 32767 ? 1 : 0) << a;
    EXPECT_EQ(call("gek", {I(a)}), a >= -32768 ? 1 : 0) << a;
    EXPECT_EQ(call("eqk", {I(a)}), a == 7 ? 1 : 0) << a;
    EXPECT_EQ(call("nek", {I(a)}), a != 7 ? 1 : 0) << a;
    EXPECT_EQ(call("big", {I(a)}), a < 40000 ? 1 : 0) << a << " (a constant past int16: a register)";
  }
  EXPECT_EQ(call("count_down", {I(5)}), 5);
  EXPECT_EQ(call("count_down", {I(-5)}), 0);
}

// `for (...; i < n; i++)` runs its step and test as one instruction at the bottom; the loop runs exactly
// as the C++ loop, also when the body changes the counter or the bound, continues or breaks.
TEST_F(Opcodes, CountingLoopsFuseStepTestAndJump) {
  p = &load(R"(int lt(int from, int n) { int s = 0; for (int i = from; i < n; i++) s += i; return s; }
int le(int from, int n) { int s = 0; for (int i = from; i <= n; ++i) { s += i; } return s; }
int ltk(int from) { int s = 0; for (int i = from; i < 10; i += 1) s += i; return s; }
int lek(int from) { int s = 0; for (int i = from; i <= -2; i++) s += i; return s; }
int skip(int n) {
  int s = 0;
  for (int i = 0; i < n; i++) {
    if (i % 3 == 0) continue;
    if (i > 20) break;
    s += i;
  }
  return s;
}
int moving(int n) { int s = 0; for (int i = 0; i < n; i++) { s += 1; i += 1; n -= 1; } return s; }
int nested(int n) {
  int s = 0;
  for (int i = 0; i < n; i++) for (int j = 0; j <= i; j++) s += j;
  return s;
}
)");
  const std::string d = p->disassemble();
  for (const char* op : {"LOOPLT ", "LOOPLE ", "LOOPLTK", "LOOPLEK"}) EXPECT_THAT(d, HasSubstr(op));
  auto sum = [](std::int64_t from, std::int64_t to_incl) {
    std::int64_t s = 0;
    for (std::int64_t i = from; i <= to_incl; i++) s += i;
    return s;
  };
  for (std::int64_t from : {-5, 0, 3, 9, 10, 11}) {
    for (std::int64_t n : {-6, 0, 1, 7, 10}) {
      EXPECT_EQ(call("lt", {I(from), I(n)}), sum(from, n - 1)) << from << " " << n;
      EXPECT_EQ(call("le", {I(from), I(n)}), sum(from, n)) << from << " " << n;
    }
    EXPECT_EQ(call("ltk", {I(from)}), sum(from, 9)) << from;
    EXPECT_EQ(call("lek", {I(from - 5)}), sum(from - 5, -2)) << from;
  }
  std::int64_t skip = 0;
  for (std::int64_t i = 0; i < 100; i++) {
    if (i % 3 == 0) continue;
    if (i > 20) break;
    skip += i;
  }
  EXPECT_EQ(call("skip", {I(100)}), skip);
  std::int64_t moving = 0;
  for (std::int64_t i = 0, n = 20; i < n; i++) {
    moving += 1;
    i += 1;
    n -= 1;
  }
  EXPECT_EQ(call("moving", {I(20)}), moving);
  std::int64_t nested = 0;
  for (std::int64_t i = 0; i < 30; i++)
    for (std::int64_t j = 0; j <= i; j++) nested += j;
  EXPECT_EQ(call("nested", {I(30)}), nested);
}

TEST_F(Opcodes, OverflowInsideAFusedLoopNamesItsPosition) {
  p = &load(R"(int upto(int from, int n) {
  int k = 0;
  for (int i = from; i <= n; i++) k += 1;
  return k;
}
int sum(int from, int n) {
  int s = 0;
  for (int i = from; i < n; i++) s += i;
  return s;
}
)",
            "loop.soml");
  EXPECT_EQ(call("upto", {I(kMax - 3), I(kMax - 1)}), 3);
  // i <= kMax holds for every int: the step past it overflows at `i++`, the LOOPLE instruction.
  EXPECT_EQ(error("upto", {I(kMax - 3), I(kMax)}),
            "SOML++ run-time error: integer overflow: 9223372036854775807 + 1 does not fit an int (64 bits)\n"
            "  at upto (loop.soml:3:31)");
  // The sum in the body (ADDI straight into the local) overflows at its `+=`.
  EXPECT_EQ(
      error("sum", {I(kMax - 3), I(kMax)}),
      "SOML++ run-time error: integer overflow: 9223372036854775804 + 9223372036854775805 does not fit an "
      "int (64 bits)\n  at sum (loop.soml:8:36)");
}

// The fused loop's backward jump costs one unit of the budget, as OP_JMP's did: a loop of N iterations
// jumps back N - 1 times.
TEST_F(Opcodes, TheBudgetCountsTheFusedLoopsBackwardJumps) {
  vsd::soml::RunOptions o;
  o.instruction_budget = 100;
  p = &load(R"(int spin(int n) {
  int s = 0;
  for (int i = 0; i < n; i++) s += 1;
  return s;
}
int spin_k() {
  int s = 0;
  for (int i = 0; i <= 1000; i++) s += 1;
  return s;
}
)",
            "budget.soml", o);
  EXPECT_EQ(call("spin", {I(100)}), 100) << "99 backward jumps fit a budget of 100";
  EXPECT_EQ(error("spin", {I(101)}),
            "SOML++ run-time error: instruction budget exhausted (100 jumps and calls): an endless loop?\n"
            "  at spin (budget.soml:3:27)");
  EXPECT_THAT(error("spin_k", {}), HasSubstr("instruction budget exhausted (100 jumps and calls)"));
  EXPECT_EQ(call("spin", {I(5)}), 5) << "the program is usable afterwards";
}

// Calls of a function of the same scope run on the caller's self (CALLS, no SELF instruction): in an
// object, in a class (through an instance, so self is that instance) and at the script's top level.
TEST_F(Opcodes, CallsOnTheFramesOwnSelf) {
  p = &load(R"(int base = 100;
int twice(int x) { return x * 2; }
int top(int x) { return twice(x) + base; }
class Acc : Node {
  int k = 0;
  int add(int x) { k += x; return k; }
  int add_twice(int x) { add(x); return add(x); }
}
object a : Acc {}
object b : Acc {}
int run() {
  a.add_twice(5);
  b.add_twice(1);
  return a.k * 1000 + b.k;
}
)");
  EXPECT_THAT(p->disassemble(), HasSubstr("CALLS "));
  EXPECT_EQ(call("top", {I(4)}), 108);
  EXPECT_EQ(call("run", {}), 10002) << "each add ran on the instance add_twice ran on";
}

// A compound assignment to a local int or double computes into its register; an error leaves nothing
// half done; `return local` returns the local's register.
TEST_F(Opcodes, CompoundAssignmentsAndReturnsUseTheLocalsRegister) {
  p = &load(R"(int ops(int a, int b) { int s = a; s += b; s -= 1; s *= b; s /= 2; s %= 1000; return s; }
double mixed(double d, int i) { d += i; d *= 1.5; d -= i; d /= 2; return d; }
int quot(int a, int b) { a /= b; return a; }
int rem(int a, int b) { a %= b; return a; }
int self_add(int a) { a += a; return a; }
)");
  auto ops = [](std::int64_t a, std::int64_t b) {
    std::int64_t s = a;
    s += b;
    s -= 1;
    s *= b;
    s /= 2;
    s %= 1000;
    return s;
  };
  for (std::int64_t a : {-7, 0, 3, 12345})
    for (std::int64_t b : {-3, 1, 9}) EXPECT_EQ(call("ops", {I(a), I(b)}), ops(a, b)) << a << " " << b;
  EXPECT_DOUBLE_EQ(p->root().call("mixed", {vsd::Value(2.5), I(3)}).as<double>(), ((2.5 + 3) * 1.5 - 3) / 2);
  EXPECT_EQ(call("self_add", {I(21)}), 42);
  EXPECT_THAT(error("quot", {I(1), I(0)}), HasSubstr("division by zero"));
  EXPECT_THAT(error("rem", {I(1), I(0)}), HasSubstr("division by zero"));
  EXPECT_THAT(error("quot", {I(kMin), I(-1)}), HasSubstr("integer overflow: -9223372036854775808 / -1"));
  EXPECT_THAT(error("self_add", {I(kMax)}),
              HasSubstr("9223372036854775807 + 9223372036854775807 does not fit"));
}

// Breakpoints patch OP_BREAK over line starts, and the patched instruction runs from the function's
// trampoline: a breakpoint on the loop's header line stops at the loop's start and at each fused
// step-test-jump, one in the body at each iteration; stepping walks header and body in turn; the result
// is the loop's.
constexpr const char* kLoop = R"(int sum(int n) {
  int s = 0;
  for (int i = 0; i < n; i++) {
    s += i;
  }
  return s;
}
)";

struct FusedLoopDebugger : ::testing::Test {
  vsd::Registry reg;
  vsd::Environment env{0, reg};
  Program* p = nullptr;
  void SetUp() override { p = &env.use<vsd::soml::Module>().load(env.main_state(), "loop.soml", kLoop); }
};

TEST_F(FusedLoopDebugger, LineBreakpointsInsideAFusedLoopStopEveryIteration) {
  vsd::soml::Debugger d(*p);
  d.break_at_line(4);
  std::vector<std::string> seen;
  d.on_stop([&](vsd::soml::Debugger& dd, const vsd::soml::Stop& s) {
    seen.push_back(std::to_string(s.line) + (s.line == 4 ? ": " + dd.print("i") : ""));
    return vsd::soml::Resume::Continue;
  });
  EXPECT_EQ(p->root().call("sum", {I(4)}).as<std::int64_t>(), 6);
  EXPECT_THAT(seen, ElementsAre("4: i = 0", "4: i = 1", "4: i = 2", "4: i = 3"));
  EXPECT_EQ(d.breakpoints()[0].hits, 4u);

  EXPECT_TRUE(d.remove(1));
  d.break_at_line(3);
  seen.clear();
  EXPECT_EQ(p->root().call("sum", {I(3)}).as<std::int64_t>(), 3);
  EXPECT_THAT(seen, ElementsAre("3", "3", "3", "3"))
      << "the loop's start, then its step after each iteration";
}

TEST_F(FusedLoopDebugger, SteppingWalksTheFusedLoop) {
  vsd::soml::Debugger d(*p);
  d.break_at_line(2);
  std::vector<std::uint32_t> lines;
  d.on_stop([&](vsd::soml::Debugger&, const vsd::soml::Stop& s) {
    lines.push_back(s.line);
    return vsd::soml::Resume::Step;
  });
  EXPECT_EQ(p->root().call("sum", {I(2)}).as<std::int64_t>(), 1);
  EXPECT_THAT(lines, ElementsAre(2u, 3u, 4u, 3u, 4u, 3u, 6u));
}

}  // namespace
