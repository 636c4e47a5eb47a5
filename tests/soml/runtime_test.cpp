// SOML++ runtime: loading into the database, the bytecode VM through MetaMethods, run-time errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "script_fixture.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace soml_test {

// A built-in class with int properties narrower than SOML++'s int.
class Sized : public vsd::Node {
  VSD_INSTANCE(Sized, vsd::Node)
  VSD_PROPERTY(std::int8_t, i8, 0)
  VSD_PROPERTY(std::uint32_t, u32, 0)
};

}  // namespace soml_test

namespace {

using ::testing::HasSubstr;
using vsd::soml::Program;

using soml_test::error_of;

struct Runtime : soml_test::ScriptTest {};

TEST_F(Runtime, ClassesObjectsAndNetsBecomeDatabaseContent) {
  Program& p = load(R"(
enum Mode { Idle, Moving, Done }
class Demo : Node {
  double speed = 1.0;
  Mode mode = Mode::Idle;
  Demo(double s) { speed = s; }
  double time_to(double d) { return d / speed; }
  start cell.waiting;
}
object cell {
  int served = 0;
  place<Demo> waiting;
  place free = 2;
  transition go { do { served += 1; } }
  arrow waiting -> go;
  arrow free -> go;
}
object d1 : Demo(2.0) {}
)");
  const vsd::MetaInstance* demo = reg.find_class("soml::Demo");
  ASSERT_NE(demo, nullptr);
  EXPECT_TRUE(demo->is_runtime());
  EXPECT_TRUE(demo->is_a(vsd::Node::static_meta()));
  ASSERT_NE(demo->find_property("speed"), nullptr);
  EXPECT_EQ(&demo->find_property("speed")->type(), &vsd::meta_type<double>());
  ASSERT_NE(demo->find_method("time_to"), nullptr);
  const vsd::MetaType* mode = reg.find_type("soml::Mode");
  ASSERT_NE(mode, nullptr);
  EXPECT_EQ(mode->kind(), vsd::TypeKind::Enum);
  EXPECT_EQ(&demo->find_property("mode")->type(), mode);

  vsd::Node* cell = p.object("cell");
  vsd::Node* d1 = p.object("d1");
  ASSERT_NE(cell, nullptr);
  ASSERT_NE(d1, nullptr);
  EXPECT_EQ(cell->parent(), &p.root());
  EXPECT_EQ(p.root().parent(), &env.main_state().database());
  EXPECT_TRUE(d1->is_a(*demo));
  EXPECT_DOUBLE_EQ(d1->get<double>("speed"), 2.0) << "the constructor ran with the object's argument";

  // Places and transitions are children of their object; arrows children of what they leave.
  vsd::soml::Place* waiting = p.place("waiting", cell);
  vsd::soml::Place* free = p.place("free", cell);
  ASSERT_NE(waiting, nullptr);
  ASSERT_NE(free, nullptr);
  EXPECT_EQ(waiting->parent(), cell);
  EXPECT_TRUE(waiting->object_tokens());
  EXPECT_EQ(free->tokens(), 2);
  ASSERT_EQ(waiting->objects().size(), 1u) << "d1 started in cell.waiting";
  EXPECT_EQ(waiting->objects().at(0), d1);
  ASSERT_EQ(waiting->children().size(), 1u);
  auto* arrow = waiting->children()[0]->as<vsd::soml::Arrow>();
  ASSERT_NE(arrow, nullptr);
  EXPECT_EQ(arrow->target().get()->name(), "go");
  EXPECT_NE(cell->find_child("go"), nullptr);

  // The source components mirror the declarations.
  bool found = false;
  for (vsd::Node* n : env.main_state().database().children())
    if (auto* s = n->as<vsd::soml::SourceFile>()) {
      found = true;
      EXPECT_EQ(s->file(), "test.soml");
      EXPECT_NE(s->find_child("test"), nullptr);
    }
  EXPECT_TRUE(found);
}

TEST_F(Runtime, FunctionsAreMetaMethodsCallableFromCpp) {
  Program& p = load(R"(
int fib(int n) { if (n < 2) return n; return fib(n - 1) + fib(n - 2); }
double hyp(double a, double b) { return sqrt(a * a + b * b); }
string greet(string who, int times) {
  string s = "";
  for (int i = 0; i < times; i++) { s = s + "hi " + who + "; "; }
  return s + len(who);
}
int loop(int n) { int s = 0; int i = 0; while (i < n) { s += i % 7; i++; } return s; }
bool odd(int n) { return n % 2 == 1 && !(n == 3); }
)");
  vsd::Node& root = p.root();
  EXPECT_EQ(root.call("fib", {vsd::Value(std::int64_t{20})}).as<std::int64_t>(), 6765);
  EXPECT_DOUBLE_EQ(root.call("hyp", {vsd::Value(3.0), vsd::Value(4.0)}).as<double>(), 5.0);
  EXPECT_EQ(
      root.call("greet", {vsd::Value(std::string("bob")), vsd::Value(std::int64_t{2})}).as<std::string>(),
      "hi bob; hi bob; 3");
  std::int64_t expect = 0;
  for (int i = 0; i < 1000; ++i) expect += i % 7;
  EXPECT_EQ(root.call("loop", {vsd::Value(std::int64_t{1000})}).as<std::int64_t>(), expect);
  EXPECT_TRUE(root.call("odd", {vsd::Value(std::int64_t{5})}).as<bool>());
  EXPECT_FALSE(root.call("odd", {vsd::Value(std::int64_t{3})}).as<bool>());
}

TEST_F(Runtime, WrongArgumentsFromCppAreErrors) {
  Program& p = load("int twice(int n) { return 2 * n; }\n");
  EXPECT_THAT(error_of([&] { p.root().call("twice", {vsd::Value(std::string("x"))}); }), HasSubstr("twice"));
  EXPECT_THAT(error_of([&] { p.root().call("twice", {}); }), HasSubstr("twice"));
  EXPECT_THAT(error_of([&] { p.root().call("nope", {}); }), HasSubstr("nope"));
}

TEST_F(Runtime, EndlessLoopEndsInBudgetErrorWithCallStack) {
  vsd::soml::RunOptions o;
  o.instruction_budget = 100000;
  Program& p = load(R"(int spin(int n) {
  while (true) { n += 1; }
  return n;
}
int outer() {
  return spin(1);
}
)",
                    o);
  const std::string e = error_of([&] { p.root().call("outer", {}); });
  EXPECT_THAT(e, HasSubstr("budget"));
  EXPECT_THAT(e, HasSubstr("at spin (test.soml:2:10)"));
  EXPECT_THAT(e, HasSubstr("at outer (test.soml:6:14)"));
  // The program is still usable afterwards.
  EXPECT_THROW(p.root().call("outer", {}), vsd::Error);
}

// The instruction budget counts jumps and calls: an action that made 10^8 `new Node()` exhausted the
// machine's memory first. A memory budget per call counts what the code makes: instances, growing
// strings and vectors, stored values and the records of changes; past it, the error names the position
// and the firing is undone.
TEST_F(Runtime, AMemoryBudgetStopsRunawayAllocationsWithThePosition) {
  vsd::soml::RunOptions o;
  o.memory_budget = std::size_t{4} << 20;
  Program& p = load(R"(int made = 0;
place go = 1;
place done;
transition spawn {
  do {
    for (int i = 0; i < 100000000; i++) { shared<Node> n = new Node(); made += 1; }
  }
}
arrow go -> spawn;
arrow spawn -> done;
int doubling(int n) { string s = "x"; for (int i = 0; i < n; i++) s = s + s; return len(s); }
int pushes(int n) { vector<int> v; for (int i = 0; i < n; i++) v.push(i); return v.size(); }
int strings(int n) { vector<string> v; for (int i = 0; i < n; i++) v.push("a long string that is not short"); return v.size(); }
int copies(int n) { vector<string> keep; string big = "x"; for (int i = 0; i < 17; i++) big = big + big; for (int i = 0; i < n; i++) keep.push(big); return keep.size(); }
)",
                    "alloc.soml", o);
  const std::size_t nodes = env.main_state().size();
  const std::string e = error_of([&] { p.step(1); });
  EXPECT_THAT(e, HasSubstr("SOML++ run-time error: memory budget exhausted (4194304 bytes of strings, vectors, "
                           "values, stored changes and instances in one call; "));
  EXPECT_THAT(e, HasSubstr("\n  at spawn (action) (alloc.soml:6:60)"));
  EXPECT_EQ(env.main_state().size(), nodes) << "the failed firing's instances are gone";
  EXPECT_EQ(p.place("go")->tokens(), 1) << "and its token is back";
  EXPECT_EQ(p.root().get<std::int64_t>("made"), 0);
  // Strings that double, vectors that grow, copies of a large vector: each stops at the budget, before it
  // is spent (s = s + s is refused before the string is made).
  EXPECT_THAT(error_of([&] { p.root().call("doubling", {vsd::Value(std::int64_t{64})}); }),
              HasSubstr("memory budget exhausted"));
  EXPECT_EQ(p.root().call("doubling", {vsd::Value(std::int64_t{10})}).as<std::int64_t>(), 1024);
  EXPECT_THAT(error_of([&] { p.root().call("pushes", {vsd::Value(std::int64_t{10'000'000})}); }),
              HasSubstr("memory budget exhausted"));
  EXPECT_EQ(p.root().call("pushes", {vsd::Value(std::int64_t{1000})}).as<std::int64_t>(), 1000);
  EXPECT_THAT(error_of([&] { p.root().call("strings", {vsd::Value(std::int64_t{1'000'000})}); }),
              HasSubstr("memory budget exhausted"));
  EXPECT_THAT(error_of([&] { p.root().call("copies", {vsd::Value(std::int64_t{1000})}); }),
              HasSubstr("memory budget exhausted"));
}

TEST_F(Runtime, RunawayRecursionHitsTheDepthLimit) {
  vsd::soml::RunOptions o;
  o.max_depth = 50;
  Program& p = load("int down(int n) { return down(n + 1) + 1; }\n", o);
  const std::string e = error_of([&] { p.root().call("down", {vsd::Value(std::int64_t{0})}); });
  EXPECT_THAT(e, HasSubstr("depth limit (50)"));
  EXPECT_THAT(e, HasSubstr("at down (test.soml:1:30)"));
}

TEST_F(Runtime, NullDereferenceAndDivisionByZeroAreErrors) {
  Program& p = load(R"(
class Box : Node { int v = 1; }
shared<Box> b;
int read() { return b.v; }
int div(int a, int z) { return a / z; }
int conv(double d) { return int(d); }
)");
  EXPECT_THAT(error_of([&] { p.root().call("read", {}); }), HasSubstr("null reference"));
  EXPECT_THAT(error_of([&] {
                p.root().call("div", {vsd::Value(std::int64_t{1}), vsd::Value(std::int64_t{0})});
              }),
              HasSubstr("division by zero"));
  EXPECT_THAT(error_of([&] { p.root().call("conv", {vsd::Value(1e300)}); }), HasSubstr("does not fit"));
}

// int arithmetic wrapped silently (a token count overflowed to a negative number): every result outside
// [-2^63, 2^63-1] is now an error with the script position, like a division by zero.
TEST_F(Runtime, IntOverflowIsAnErrorWithItsPosition) {
  Program& p = load(R"(int max = 9223372036854775807;
int min = -9223372036854775807 - 1;
int small_ok = 0;
int add(int a, int b) { return a + b; }
int sub(int a, int b) { return a - b; }
int mul(int a, int b) { return a * b; }
int neg(int a) { return -a; }
int quot(int a, int b) { return a / b; }
int rem(int a, int b) { return a % b; }
int inc(int a) { a++; return a; }
int dec(int a) { --a; return a; }
int plus_k(int a) { return a + 7; }
int times_k(int a) { return a * 3; }
int add_into(int a, int b) { a += b; return a; }
void bump() { max += 1; }
int absolute(int a) { return abs(a); }
)",
                    "ovf.soml");
  auto call = [&](const char* f, std::vector<vsd::Value> args) { return p.root().call(f, args).as<std::int64_t>(); };
  auto error = [&](const char* f, std::vector<vsd::Value> args) {
    return error_of([&] { p.root().call(f, args); });
  };
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();
  const vsd::Value max(kMax), min(kMin), one(std::int64_t{1}), minus_one(std::int64_t{-1}), two(std::int64_t{2});
  EXPECT_EQ(call("add", {vsd::Value(kMax - 1), one}), kMax) << "up to the limit is fine";
  EXPECT_EQ(error("add", {max, one}),
            "SOML++ run-time error: integer overflow: 9223372036854775807 + 1 does not fit an int (64 bits)\n"
            "  at add (ovf.soml:4:34)");
  EXPECT_THAT(error("sub", {min, one}), HasSubstr("integer overflow: -9223372036854775808 - 1 does not fit"));
  EXPECT_THAT(error("mul", {max, two}), HasSubstr("integer overflow: 9223372036854775807 * 2 does not fit"));
  EXPECT_THAT(error("mul", {min, minus_one}), HasSubstr("integer overflow"));
  EXPECT_THAT(error("neg", {min}),
              HasSubstr("integer overflow: -(-9223372036854775808) does not fit an int (64 bits)\n  at neg "
                        "(ovf.soml:7:25)"));
  EXPECT_THAT(error("quot", {min, minus_one}),
              HasSubstr("integer overflow: -9223372036854775808 / -1 does not fit"));
  EXPECT_EQ(call("quot", {max, minus_one}), -kMax);
  EXPECT_EQ(call("rem", {min, minus_one}), 0) << "the remainder is 0, which fits";
  EXPECT_THAT(error("inc", {max}), HasSubstr("integer overflow: 9223372036854775807 + 1 does not fit"));
  EXPECT_THAT(error("dec", {min}), HasSubstr("integer overflow: -9223372036854775808 + -1 does not fit"));
  EXPECT_THAT(error("plus_k", {max}), HasSubstr("9223372036854775807 + 7 does not fit"));
  EXPECT_THAT(error("times_k", {min}), HasSubstr("-9223372036854775808 * 3 does not fit"));
  EXPECT_THAT(error("add_into", {max, max}), HasSubstr("9223372036854775807 + 9223372036854775807 does not fit"));
  EXPECT_THAT(error("bump", {}), HasSubstr("integer overflow: 9223372036854775807 + 1 does not fit an int"));
  EXPECT_EQ(p.root().get<std::int64_t>("max"), kMax) << "the failed compound assignment changed nothing";
  EXPECT_EQ(call("absolute", {vsd::Value(kMin + 1)}), kMax);
  EXPECT_THAT(error("absolute", {min}), HasSubstr("integer overflow: abs(-9223372036854775808) does not fit"));
}

// A place's token count never wraps either: put() and the tokens an arrow gives stop at 2^63-1 with an
// error, and the firing changes nothing (with an action it runs under a savepoint; without one the check
// comes before anything changes).
TEST_F(Runtime, ATokenCountThatWouldOverflowIsAnErrorAndTheFiringIsUndone) {
  Program& p = load(R"(place full = 9223372036854775806;
place go = 2;
place src = 1;
int fired = 0;
transition fill { do { fired += 1; full.put(1); } }
arrow go -> fill;
transition plain { }
arrow src -> plain;
arrow plain -> full * 3;
)",
                    "tokens.soml");
  vsd::soml::Place* full = p.place("full");
  vsd::soml::Place* go = p.place("go");
  vsd::soml::Place* src = p.place("src");
  ASSERT_TRUE(full != nullptr && go != nullptr && src != nullptr);
  // The plain transition (no code: no savepoint) would give 3 tokens: refused before it takes one.
  // The action's put(1) reaches 2^63-1 once; the second time it would pass it.
  std::string errors;
  for (int i = 0; i < 3; ++i) {
    try {
      p.step(1);
    } catch (const vsd::Error& e) {
      errors += std::string(e.what()) + "\n";
    }
  }
  EXPECT_EQ(full->tokens(), std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(src->tokens(), 1) << "the plain transition took nothing";
  EXPECT_EQ(go->tokens(), 1) << "the failed firing gave its token back";
  EXPECT_EQ(p.root().get<std::int64_t>("fired"), 1);
  EXPECT_THAT(errors, HasSubstr("SOML++ run-time error: place 'full' would hold more than 9223372036854775807 "
                                "(2^63-1) tokens: "));
  EXPECT_THAT(errors, HasSubstr(" + 3\n  at the arrow (tokens.soml:9:1)"));
  EXPECT_THAT(errors, HasSubstr("place 'full' would hold more than 9223372036854775807 (2^63-1) tokens: "
                                "9223372036854775807 + 1\n  at fill (action) (tokens.soml:5:44)"));
}

// Ints that do not fit a property's narrower storage type are refused, never truncated.
TEST_F(Runtime, AnIntThatDoesNotFitASizedPropertyIsAnError) {
  reg.add<soml_test::Sized>();
  Program& p = load(R"(shared<Sized> s = new Sized();
void set8(int v) { s.i8 = v; }
void set32(int v) { s.u32 = v; }
)",
                    "sized.soml");
  p.root().call("set8", {vsd::Value(std::int64_t{-128})});
  EXPECT_THAT(error_of([&] { p.root().call("set8", {vsd::Value(std::int64_t{128})}); }),
              HasSubstr("the value 128 does not fit property 'i8' (int8)\n  at set8 (sized.soml:2:21)"));
  EXPECT_THAT(error_of([&] { p.root().call("set32", {vsd::Value(std::int64_t{-1})}); }),
              HasSubstr("the value -1 does not fit property 'u32' (uint32)"));
}

// Each class's net holds its bases' places and transitions: a chain of classes with nets holds the square
// of its length. The loader refuses past 4,000,000 copied, with the position of the class where it
// would pass them, instead of running out of memory. (Classes nest at most 256 deep, so the chain is
// short and wide: class Ci copies 200 * i * (i + 1) / 2 places, past 4,000,000 at i = 200, on line 201.)
TEST_F(Runtime, InheritedNetsThatWouldHoldTooMuchAreRefused) {
  constexpr int kPlaces = 200;
  std::string text = "class C0 : Node { ";
  for (int k = 0; k < kPlaces; ++k) text += "place q" + std::to_string(k) + "; ";
  text += "}\n";
  for (int i = 1; i < 250; ++i) {
    text += "class C" + std::to_string(i) + " : C" + std::to_string(i - 1) + " { ";
    for (int k = 0; k < kPlaces; ++k) text += "place p" + std::to_string(i) + "_" + std::to_string(k) + "; ";
    text += "}\n";
  }
  EXPECT_THAT(error_of([&] { load(text, "deep.soml"); }),
              HasSubstr("deep.soml:201:7: error: nets this large through inheritance (the classes would hold "
                        "more than 4000000 places and transitions of their bases) is not supported by the "
                        "SOML++ runtime yet"));
  EXPECT_EQ(reg.find_class_exact("soml::C0"), nullptr) << "the refused load left nothing behind";
}

TEST_F(Runtime, PropertyChangesGoThroughMetaPropertiesAndSignal) {
  Program& p = load(R"(
class Box : Node { int v = 1; string label = "box"; }
shared<Box> b;
int count = 0;
void make() { b = new Box(); b.v = 41; b.v += 1; b.label = b.label + "!"; count++; }
void rename(shared<Node> n, string s) { n.name = s; }
bool is_box(shared<Node> n) { return n is Box; }
)");
  int changes = 0;
  auto c = env.main_state().on_property_changed().connect(
      [&](vsd::SimStateInstance&, const vsd::MetaProperty&) { ++changes; });
  p.root().call("make", {});
  EXPECT_GT(changes, 3);
  const auto& ref = p.root().get<vsd::SharedRef<vsd::Node>>("b");
  ASSERT_NE(ref.get(), nullptr);
  EXPECT_EQ(ref.get()->get<std::int64_t>("v"), 42);
  EXPECT_EQ(ref.get()->get<std::string>("label"), "box!");
  EXPECT_EQ(p.root().get<std::int64_t>("count"), 1);
  vsd::Node& plain = env.main_state().create<vsd::Node>();
  p.root().call("rename",
                {vsd::Value(vsd::SharedRef<vsd::Node>(&plain)), vsd::Value(std::string("renamed"))});
  EXPECT_EQ(plain.name(), "renamed");
  EXPECT_TRUE(p.root().call("is_box", {vsd::Value(ref)}).as<bool>());
  EXPECT_FALSE(p.root().call("is_box", {vsd::Value(vsd::SharedRef<vsd::Node>(&plain))}).as<bool>());
}

TEST_F(Runtime, OverridesAreCalledThroughBaseReferences) {
  Program& p = load(R"(
class A : Node { int f() { return 1; } int g() { return f() * 10; } }
class B : A { int f() { return 2; } }
int via(shared<A> a) { return a.g(); }
shared<A> make_b() { return new B(); }
)");
  vsd::Value b = p.root().call("make_b", {});
  EXPECT_EQ(p.root().call("via", {b}).as<std::int64_t>(), 20);
}

TEST_F(Runtime, PrintWritesToTheGivenStream) {
  Program& p = load(R"(
enum Mode { Idle, Busy }
void show() { print("x = ", 3, ", y = ", 2.5, ", ", true, ", ", Mode::Busy); }
)");
  p.root().call("show", {});
  EXPECT_EQ(out.str(), "x = 3, y = 2.5, true, Busy\n");
}

TEST_F(Runtime, ScriptErrorsAndUnsupportedConstructsAreReportedWithPositions) {
  EXPECT_THAT(error_of([&] { load("int f() { return x; }\n"); }),
              HasSubstr("test.soml:1:18: error: undefined name 'x'"));
  const std::string e = error_of([&] {
    load(R"(class C : Node {
  int k = 0;
  net Relay(place in, place out) {
    transition t { do { k += 1; } }
    arrow in -> t;
    arrow t -> out;
  }
  place a = 1;
  place b;
  transition move = Relay(a, b);
}
object o : C;
)");
  });
  EXPECT_THAT(e, HasSubstr("test.soml:4:25"));
  EXPECT_THAT(e, HasSubstr("not supported"));
}

}  // namespace

#include <filesystem>
#include <fstream>

namespace {

constexpr const char* kJobs = R"(enum Mode { Idle, Busy }
class Job : Node {
  Mode mode = Mode::Idle;
  int done = 0;
  void work() { done += 1; }
  start cell.queue;
}
object cell {
  place<Job> queue;
  transition go { do { mark.work(); } }
  arrow queue -> go;
}
object first : Job {}
int made() { shared<Job> j = new Job(); return j.done; }
)";

// A script's run-time classes stayed in the Registry after its Environment was gone, so the same script
// could not be loaded again ("class name 'soml::Job' is already registered"), as when a simulation is
// restarted in one process. They go with the last program that uses them.
TEST(ProgramLifetime, TheSameScriptLoadsAgainAfterItsEnvironmentIsGone) {
  vsd::Registry reg;  // shared by the Environments, as the global Registry is
  for (int round = 0; round < 3; ++round) {
    SCOPED_TRACE(round);
    vsd::Environment env(0, reg);
    Program& p = env.use<vsd::soml::Module>().load(env.main_state(), "jobs.soml", kJobs);
    EXPECT_EQ(p.run_until_quiet(100), 1u);
    ASSERT_NE(reg.find_class_exact("soml::Job"), nullptr);
    EXPECT_EQ(p.script_class("Job"), reg.find_class_exact("soml::Job"));
  }
  EXPECT_EQ(reg.find_class_exact("soml::Job"), nullptr) << "gone with the last Environment that used it";
  EXPECT_EQ(reg.find_class_exact("soml::cell"), nullptr);
  EXPECT_EQ(reg.find_class_exact("soml::jobs"), nullptr) << "the script object's class too";
  EXPECT_EQ(reg.find_type("soml::Mode"), nullptr);
}

TEST(ProgramLifetime, EnvironmentsOnOneRegistryShareTheClassesOfTheSameScript) {
  vsd::Registry reg;
  auto a = std::make_unique<vsd::Environment>(0, reg);
  auto b = std::make_unique<vsd::Environment>(0, reg);
  Program& pa = a->use<vsd::soml::Module>().load(a->main_state(), "jobs.soml", kJobs);
  Program& pb = b->use<vsd::soml::Module>().load(b->main_state(), "jobs.soml", kJobs);
  EXPECT_EQ(pa.script_class("Job"), pb.script_class("Job")) << "one class, used by both";
  EXPECT_EQ(pa.run_until_quiet(100), 1u);
  EXPECT_EQ(pb.run_until_quiet(100), 1u);
  // The first goes; the class stays for the second, whose methods and `new` go on working.
  a.reset();
  ASSERT_NE(reg.find_class_exact("soml::Job"), nullptr);
  vsd::Node* job = pb.object("first");
  ASSERT_NE(job, nullptr);
  job->call("work", {});
  EXPECT_EQ(job->get<std::int64_t>("done"), 2);
  EXPECT_EQ(pb.root().call("made", {}).as<std::int64_t>(), 0);
  b.reset();
  EXPECT_EQ(reg.find_class_exact("soml::Job"), nullptr);
  EXPECT_EQ(reg.find_type("soml::Mode"), nullptr);

  // Another script with the same class names while the first runs: refused, naming the difference, and
  // the running one is untouched.
  std::string changed = kJobs;
  changed.replace(changed.find("int done = 0;"), 13, "int done = 0; double speed = 1.0;");
  {
    vsd::Environment c(0, reg), d(0, reg);
    Program& pc = c.use<vsd::soml::Module>().load(c.main_state(), "jobs.soml", kJobs);
    EXPECT_THAT(error_of([&] { d.use<vsd::soml::Module>().load(d.main_state(), "jobs.soml", changed); }),
                HasSubstr("jobs.soml:2:7: class 'soml::Job' is registered already, in use with another "
                          "definition: the registered one has no property 'speed'"));
    EXPECT_EQ(pc.run_until_quiet(100), 1u);
  }
  EXPECT_EQ(reg.find_class_exact("soml::Job"), nullptr);

  // A Program its caller holds and drops while its state lives: the classes stay while their instances
  // do; once those are gone too, the next load replaces them (with another definition here).
  {
    vsd::Environment e(0, reg);
    { auto held = Program::load(e.main_state(), "jobs.soml", kJobs); }
    EXPECT_NE(reg.find_class_exact("soml::Job"), nullptr) << "its instances are still in the state";
  }
  vsd::Environment f(0, reg);
  Program& pf = f.use<vsd::soml::Module>().load(f.main_state(), "jobs.soml", changed);
  ASSERT_NE(pf.script_class("Job"), nullptr);
  EXPECT_NE(pf.script_class("Job")->find_property("speed"), nullptr);
}


// Every golden script that checks clean either loads and runs (a bounded number of firings) or is
// refused with the position of what the runtime cannot run yet; never a crash.
TEST(RuntimeScripts, EveryCleanGoldenScriptLoadsOrIsRefusedWithAPosition) {
  namespace fs = std::filesystem;
  int loaded = 0, refused = 0;
  for (const auto& entry : fs::directory_iterator(VSD_SOML_SCRIPTS_DIR)) {
    if (entry.path().extension() != ".soml") continue;
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string name = entry.path().filename().string();
    if (!vsd::soml::check_source(name, text)->ok()) continue;
    SCOPED_TRACE(name);
    vsd::Registry reg;
    vsd::Environment env(0, reg);
    std::ostringstream out;
    vsd::soml::RunOptions o;
    o.out = &out;
    o.instruction_budget = 100000;
    try {
      auto p = Program::load(env.main_state(), name, text, o);
      p->step(100);
      ++loaded;
    } catch (const vsd::Error& e) {
      const std::string what = e.what();
      EXPECT_THAT(what, ::testing::AnyOf(HasSubstr("not supported by the SOML++ runtime yet"),
                                         HasSubstr("SOML++ run-time error")));
      EXPECT_THAT(what, HasSubstr(name + ":"));
      ++refused;
    }
  }
  EXPECT_GE(loaded, 3);
  std::cout << "golden scripts: " << loaded << " loaded and ran, " << refused << " refused\n";
}

TEST_F(Runtime, DisassemblyNamesFunctionsOpcodesOperandsAndLines) {
  Program& p = load(R"(int fib(int n) {
  if (n < 2) return n;
  return fib(n - 1) + fib(n - 2);
}
object cell {
  string label = "a\nb";
  double big = 12345678.5;
}
)");
  const std::string d = p.disassemble();
  EXPECT_THAT(d, ::testing::HasSubstr("function f0 fib ("));
  EXPECT_THAT(d, ::testing::HasSubstr("params 1, registers 5, result int"));
  EXPECT_THAT(d, ::testing::HasSubstr("local r0 n: int [0, "));
  // `if (n < 2)` is one compare-with-constant-and-jump, `return n` returns the local's register, and
  // the recursive calls run on the frame's own self (no SELF).
  EXPECT_THAT(d, ::testing::ContainsRegex("  0  JGEIK +r0, #2, -> 2 +; 2:9"));
  EXPECT_THAT(d, ::testing::ContainsRegex("  1  RET +r0 +; 2:14"));
  EXPECT_THAT(d, ::testing::ContainsRegex("CALLS +r2, f0 +; 3:13  fib"));
  EXPECT_THAT(d, ::testing::HasSubstr("s1 = \"a\\nb\""));  // strings quoted, control characters escaped
  EXPECT_THAT(d, ::testing::HasSubstr("\nconstants\n"));
  EXPECT_THAT(d, ::testing::HasSubstr(".label"));  // a property operand names the property
}

}  // namespace
