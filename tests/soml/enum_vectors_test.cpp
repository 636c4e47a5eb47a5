// SOML++ vectors of script enums (docs/soml.md 4.13): `vector<Mode>` with `enum Mode` declared in the
// script is the Registry's vector of the run-time enum soml::Mode once the script loads. C++ calls
// functions that take and return one with Values, reads and writes the properties as Values of that type;
// the changes record and replay, a reload keeps the value when the enum is unchanged, a refused load
// leaves the Registry as it was, the debugger shows the elements; misuse is an error with its position.
// Also: net results of vector and struct type, and vectors as arguments and results of built-in classes'
// MetaMethods.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "script_fixture.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace enum_vectors_test {

// A built-in class whose MetaMethods take and return vectors (std::vector<T> of the registry).
class Arm : public vsd::Node {
  VSD_INSTANCE(Arm, vsd::Node)
  VSD_PROPERTY(std::vector<double>, joints, {})
 public:
  std::vector<double> scaled(std::vector<double> v, double k) {
    for (double& x : v) x *= k;
    return v;
  }
  VSD_METHOD(scaled)
  std::int64_t count(std::vector<std::int32_t> ids) { return static_cast<std::int64_t>(ids.size()); }
  VSD_METHOD(count)
  std::vector<std::string> tags() { return {"left", "arm"}; }
  VSD_METHOD(tags)
};

}  // namespace enum_vectors_test

namespace {

using ::testing::HasSubstr;
using vsd::soml::Program;

struct EnumVectors : soml_test::ScriptTest {
  // The names of the enums of the elements of vector Value @p v ("Idle Run").
  static std::string names(const vsd::Value& v) {
    const vsd::MetaType& vt = *v.type();
    const vsd::MetaType& et = *vt.element();
    std::string s;
    vsd::Value e(et);
    for (std::size_t i = 0; i < vt.vector_size(v.data()); ++i) {
      vt.vector_get(v.data(), i, e.data());
      s += (s.empty() ? "" : " ") + std::string(et.enum_name(et.load_integer(e.data())));
    }
    return s;
  }
};

constexpr const char* kModes = R"(enum Mode { Idle, Run, Stop }
vector<Mode> cycle(int n) {
  vector<Mode> out;
  for (int i = 0; i < n; i++) out.push(i % 3 == 0 ? Mode::Idle : i % 3 == 1 ? Mode::Run : Mode::Stop);
  return out;
}
int runs(vector<Mode> v) { int n = 0; for (Mode m : v) if (m == Mode::Run) n++; return n; }
vector<Mode> reversed(vector<Mode> v) {
  vector<Mode> out;
  for (int i = v.size() - 1; i >= 0; i--) out.push(v[i]);
  v[0] = Mode::Stop;   // the caller's vector stays
  return out;
}
)";

TEST_F(EnumVectors, FunctionsTakingAndReturningThemAreMetaMethodsCalledWithValues) {
  Program& p = load(kModes);
  const vsd::MetaType* mode = reg.find_type("soml::Mode");
  const vsd::MetaType* modes = reg.find_type("vector<soml::Mode>");
  ASSERT_NE(mode, nullptr);
  ASSERT_NE(modes, nullptr) << "the loader made the vector of the run-time enum";
  EXPECT_EQ(modes->element(), mode);
  vsd::Node& root = p.root();

  const vsd::Value c = root.call("cycle", {vsd::Value(std::int64_t{4})});
  ASSERT_EQ(c.type(), modes);
  EXPECT_EQ(names(c), "Idle Run Stop Idle");
  EXPECT_EQ(c.to_text(), R"(["Idle", "Run", "Stop", "Idle"])");

  const vsd::Value in = vsd::Value::from_text(*modes, R"(["Run", "Stop", "Run"])");
  EXPECT_EQ(root.call("runs", {in}).as<std::int64_t>(), 2);
  const vsd::Value r = root.call("reversed", {in});
  EXPECT_EQ(names(r), "Run Stop Run");
  EXPECT_EQ(names(root.call("reversed", {c})), "Idle Stop Run Idle");
  EXPECT_EQ(names(in), "Run Stop Run") << "arguments are copies";
  EXPECT_EQ(root.call("runs", {vsd::Value(*modes)}).as<std::int64_t>(), 0) << "an empty vector";

  // A vector of ints or of another enum is a vsd::Error naming both types, never a crash.
  EXPECT_THAT(soml_test::error_of([&] { root.call("runs", {vsd::Value(std::vector<std::int64_t>{1})}); }),
              HasSubstr("runs argument 1: expected vector<soml::Mode>, got vector<int64>"));
  const vsd::MetaType& shade = vsd::EnumBuilder("Shade").value("Idle", 0).value("Run", 1).define(reg);
  EXPECT_THAT(soml_test::error_of([&] { root.call("runs", {vsd::Value(reg.vector_type(shade))}); }),
              HasSubstr("expected vector<soml::Mode>, got vector<Shade>"));
}

TEST_F(EnumVectors, PropertiesAreValuesOfTheRunTimeVectorThatRecordAndReplay) {
  Program& p = load(R"(enum Mode { Idle, Run, Stop }
class Cell : Node {
  enum Phase { Off, On }
  vector<Phase> phases;
  vector<Mode> modes;
}
shared<Cell> cell = new Cell();
vector<Mode> history;
int hits = 0;
place ready { vector<Mode> seen; }
place watch = 1;
transition t {
  vector<Mode> log;
  when history.size() > 1 && history[1] == Mode::Stop;   // re-tested when history changes
  do {
    log.push(history[0]);
    ready.seen = log;
    cell.modes = history;
    cell.phases.push(Cell::Phase::On);
    hits += 1;
  }
}
arrow watch -> t;
void record() {
  history.push(Mode::Run);
  history.push(Mode::Idle);
  history[1] = Mode::Stop;   // one change through the setter
}
)");
  vsd::Node& root = p.root();
  const vsd::MetaType* modes = reg.find_type("vector<soml::Mode>");
  ASSERT_NE(modes, nullptr);
  const vsd::Value empty = root.get("history");
  ASSERT_EQ(empty.type(), modes) << "the property's type is the run-time enum's vector";
  EXPECT_EQ(empty.to_text(), "[]");

  std::vector<std::string> changed;
  auto conn = env.main_state().on_property_changed().connect(
      [&](vsd::SimStateInstance&, const vsd::MetaProperty& mp) { changed.push_back(mp.name()); });
  vsd::SimState& replica = env.create_state("replica");
  replica.copy_from(env.main_state());
  env.main_state().start_recording();
  EXPECT_EQ(p.run_until_quiet(), 0u);
  root.call("record", {});
  EXPECT_EQ(std::count(changed.begin(), changed.end(), "history"), 3);
  EXPECT_EQ(p.run_until_quiet(), 1u) << "the change of history re-tested the condition";
  // C++ writes the property as a Value of the vector type, the script reads it.
  root.set("history", vsd::Value::from_text(*modes, R"(["Idle", "Stop", "Run"])"));
  EXPECT_EQ(names(root.get("history")), "Idle Stop Run");
  replica.apply(env.main_state().stop_recording());
  std::string diff;
  EXPECT_TRUE(replica.equals(env.main_state(), &diff)) << diff;

  const vsd::Node* cell = root.get<vsd::SharedRef<vsd::Node>>("cell").get();
  ASSERT_NE(cell, nullptr);
  EXPECT_EQ(names(cell->get("modes")), "Run Stop");
  EXPECT_EQ(cell->get("phases").type(), reg.find_type("vector<soml::Cell::Phase>"));
  EXPECT_EQ(names(cell->get("phases")), "On");
  EXPECT_EQ(names(p.place("ready")->get("seen")), "Run");
  EXPECT_EQ(root.get<std::int64_t>("hits"), 1);
}

// A load refused after the loader made the run-time enum and its vector (the compiler refuses a
// construct), or refused by the checker, leaves the Registry as it was; the fixed script then loads.
TEST_F(EnumVectors, ARefusedLoadLeavesNoEnumAndNoVectorType) {
  const std::string good = R"(enum Mode { Idle, Run }
class Cell : Node { vector<Mode> modes; }
vector<Mode> history;
vector<Mode> twice(vector<Mode> v) { vector<Mode> out = v; for (Mode m : v) out.push(m); return out; }
)";
  const std::size_t classes = reg.classes().size();
  const std::size_t types = reg.types().size();
  std::string refused = good;
  refused += "void bad() { twice(history)[0] = Mode::Run; }\n";  // the compiler: an element of a temporary
  EXPECT_THAT(soml_test::error_of([&] { load(refused, "bad.soml"); }),
              HasSubstr("bad.soml:5:28: error: assigning to an element of a temporary vector"));
  EXPECT_EQ(reg.classes().size(), classes);
  EXPECT_EQ(reg.types().size(), types);
  EXPECT_EQ(reg.find_type("soml::Mode"), nullptr);
  EXPECT_EQ(reg.find_type("vector<soml::Mode>"), nullptr);
  EXPECT_THAT(soml_test::error_of([&] { load(good + "vector<Mode> broken = 1;\n", "bad.soml"); }),
              HasSubstr("bad.soml:5:"));
  EXPECT_EQ(reg.types().size(), types);
  Program& p = load(good);
  EXPECT_EQ(names(p.root().call("twice",
                                {vsd::Value::from_text(*reg.find_type("vector<soml::Mode>"), R"(["Run"])")})),
            "Run Run");
}

TEST_F(EnumVectors, AReloadKeepsTheValueWhenTheEnumIsUnchanged) {
  Program& p = load(R"(enum Mode { Idle, Run }
vector<Mode> history;
void f() { history.push(Mode::Run); history.push(Mode::Idle); }
)");
  p.root().call("f", {});
  const vsd::MetaType* modes = reg.find_type("vector<soml::Mode>");
  const vsd::soml::MigrationReport r = p.reload("test.soml", R"(enum Mode { Idle, Run }
vector<Mode> history;
vector<Mode> fresh;
int n = 0;
void f() { fresh = history; fresh.push(Mode::Run); n = fresh.size(); }
)");
  EXPECT_EQ(reg.find_type("vector<soml::Mode>"), modes) << "the same enum, so the same vector type";
  EXPECT_THAT(r.properties, ::testing::Contains(HasSubstr(".history: kept")));
  EXPECT_TRUE(r.warnings.empty());
  EXPECT_EQ(names(p.root().get("history")), "Run Idle");
  p.root().call("f", {});
  EXPECT_EQ(names(p.root().get("fresh")), "Run Idle Run");
  EXPECT_EQ(p.root().get<std::int64_t>("n"), 3);
  // Changing the enum's values at run time is refused with the position; the value stays.
  EXPECT_THAT(soml_test::error_of(
                  [&] { p.reload("test.soml", "enum Mode { Idle, Run, Stop }\nvector<Mode> history;\n"); }),
              HasSubstr("test.soml:1:6"));
  EXPECT_EQ(names(p.root().get("history")), "Run Idle");
  // Another type for the property: the value does not convert, a warning says so, the new one is empty.
  const vsd::soml::MigrationReport ints =
      p.reload("test.soml", "enum Mode { Idle, Run }\nvector<int> history;\n");
  EXPECT_THAT(ints.warnings, ::testing::Contains(HasSubstr("history: the value")));
  EXPECT_TRUE(p.root().get<std::vector<std::int64_t>>("history").empty());
}

TEST_F(EnumVectors, TheDebuggerShowsTheElementsAsEnums) {
  Program& p = load(R"(enum Mode { Idle, Run }
vector<Mode> history;
void f() {
  vector<Mode> v;
  v.push(Mode::Run);
  history = v;
  history.push(Mode::Idle);
}
)",
                    "dbg.soml");
  vsd::soml::Debugger d(p);
  d.break_at_line(7);
  std::string locals, printed;
  d.on_stop([&](vsd::soml::Debugger& dd, const vsd::soml::Stop&) {
    for (const auto& v : dd.locals()) locals += v.type + " " + v.name + " = " + v.value;
    printed = dd.print("history");
    return vsd::soml::Resume::Continue;
  });
  p.root().call("f", {});
  EXPECT_EQ(locals, "vector<Mode> v = [Mode::Run]");
  EXPECT_EQ(printed, "history = [Mode::Run]");
}

// The result of an invoked net reaches the invoking transition's action as `result` for every value
// type held out of the registers: vectors of script enums, of ints, structs.
TEST_F(EnumVectors, NetResultsOfVectorAndStructTypeReachTheInvokingAction) {
  Program& p = load(R"(enum Mode { Idle, Run }
net vector<Mode> modes(int n) {
  place s; start s;
  transition t { do { vector<Mode> r; for (int i = 0; i < n; i++) r.push(Mode::Run); finish r; } }
  arrow s -> t;
}
net vector<int> ints(int n) {
  place s; start s;
  transition t { do { vector<int> r; for (int i = 0; i < n; i++) r.push(i * 10); finish r; } }
  arrow s -> t;
}
net Vector3d point(double x) {
  place s; start s;
  transition t { do { finish Vector3d(x, 2, 3); } }
  arrow s -> t;
}
place a = 1;
place b;
place c;
place d;
transition get_modes { invoke modes(2); do { print("modes ", result, " ", result[1] == Mode::Run); } }
transition get_ints { invoke ints(3); do { print("ints ", result, " ", result.size()); } }
transition get_point { invoke point(1.5); do { print("point ", result, " x ", result.x); } }
arrow a -> get_modes;
arrow get_modes -> b;
arrow b -> get_ints;
arrow get_ints -> c;
arrow c -> get_point;
arrow get_point -> d;
)");
  p.run_until_quiet();
  EXPECT_EQ(out.str(), "modes [\"Run\", \"Run\"] true\nints [0, 10, 20] 3\npoint Vector3d(1.5, 2, 3) x 1.5\n");
  EXPECT_EQ(p.place("d")->tokens(), 1);
}

// Vectors as arguments and results of a built-in class's MetaMethods: converted to and from the
// method's std::vector<T> (sized integers range-checked like a property store).
TEST_F(EnumVectors, BuiltInMethodsTakeAndReturnVectors) {
  reg.add<enum_vectors_test::Arm>();
  Program& p = load(R"(shared<Arm> arm = new Arm();
void f() {
  vector<double> v;
  v.push(1.0);
  v.push(2.5);
  vector<double> w = arm.scaled(v, 2);
  arm.joints = arm.scaled(arm.joints, 3);
  vector<int32> ids;
  ids.push(7);
  ids.push(8);
  print(w, " ", arm.count(ids), " ", arm.tags(), " ", arm.tags().size(), " ", arm.joints);
}
int too_big() { vector<int32> ids; ids.push(5000000000); return arm.count(ids); }
)");
  auto* arm = p.root().get<vsd::SharedRef<vsd::Node>>("arm").get();
  ASSERT_NE(arm, nullptr);
  arm->set("joints", vsd::Value(std::vector<double>{1.0}));
  p.root().call("f", {});
  EXPECT_EQ(out.str(), "[2.0, 5.0] 2 [\"left\", \"arm\"] 2 [3.0]\n");
  EXPECT_THAT(
      soml_test::error_of([&] { p.root().call("too_big", {}); }),
      HasSubstr("the value 5000000000 does not fit argument 1 of method 'count' (elements int32)\n  at "
                "too_big (test.soml:13:74)"));
}

TEST_F(EnumVectors, MistakesAreReportedWithTheirPosition) {
  const std::string e = soml_test::error_of([&] {
    load(R"(enum Mode { Idle, Run }
enum Other { A, B }
vector<Mode> modes;
void f() {
  modes.push(1);
  modes.push(Other::A);
  vector<Other> o = modes;
  vector<int> i = modes;
  modes[0] = 1;
}
)",
         "bad.soml");
  });
  EXPECT_THAT(
      e, HasSubstr("bad.soml:5:14: error: type mismatch: the element to push must be 'Mode', not 'int'"));
  EXPECT_THAT(
      e, HasSubstr("bad.soml:6:14: error: type mismatch: the element to push must be 'Mode', not 'Other'"));
  EXPECT_THAT(
      e, HasSubstr("bad.soml:7:21: error: type mismatch: the initialiser of 'o' must be 'vector<Other>', "
                   "not 'vector<Mode>'"));
  EXPECT_THAT(e, HasSubstr("bad.soml:8:19: error: type mismatch: the initialiser of 'i' must be "
                           "'vector<int64>', not 'vector<Mode>'"));
  EXPECT_THAT(e, HasSubstr("bad.soml:9:14: error: type mismatch: cannot assign 'int' to 'Mode'"));
  EXPECT_EQ(reg.find_type("soml::Mode"), nullptr);
}

}  // namespace
