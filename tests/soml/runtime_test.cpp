// SOML++ runtime: loading into the database, the bytecode VM through MetaMethods, run-time errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "script_fixture.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

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
  EXPECT_THAT(e, HasSubstr("at spin (test.soml:2)"));
  EXPECT_THAT(e, HasSubstr("at outer (test.soml:6)"));
  // The program is still usable afterwards.
  EXPECT_THROW(p.root().call("outer", {}), vsd::Error);
}

TEST_F(Runtime, RunawayRecursionHitsTheDepthLimit) {
  vsd::soml::RunOptions o;
  o.max_depth = 50;
  Program& p = load("int down(int n) { return down(n + 1) + 1; }\n", o);
  const std::string e = error_of([&] { p.root().call("down", {vsd::Value(std::int64_t{0})}); });
  EXPECT_THAT(e, HasSubstr("depth limit (50)"));
  EXPECT_THAT(e, HasSubstr("at down (test.soml:1)"));
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

}  // namespace
