// Program::attach (docs/soml.md 8.7): a run saved by vsd::io mid-execution, loaded into a fresh
// Environment and attached, continues exactly like the run that was never saved — the same firings (step
// numbers, transitions, marks, token moves), the same printed output and the same final database — and so
// does a replica that applied the recorded bundles. Content that does not match the script is a clear
// vsd::Error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "vsd/core.hpp"
#include "vsd/soml.hpp"
#include "state_dump.hpp"

#if VSD_SOML_TEST_IO
#include "vsd/io/snapshot.hpp"
#endif

namespace {

using ::testing::HasSubstr;
using vsd_test::describe;
using vsd_test::dump;
using vsd::soml::Program;

std::string read_script(const std::string& name) {
  std::ifstream in(std::string(VSD_SOML_SCRIPTS_DIR) + "/" + name, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The seed a golden script asks for in its "// args:" line (1 when it names none).
std::uint64_t seed_of(const std::string& text) {
  const auto at = text.find("--seed ");
  if (at == std::string::npos || at > text.find('\n')) return 1;
  return std::stoull(text.substr(at + 7));
}

// One Environment running one program, with its trace and its printed output.
struct Session {
  vsd::Registry reg;
  vsd::Environment env{0, reg};
  std::ostringstream out;
  Program* p = nullptr;
  std::vector<std::string> trace;
  Session() { env.use<vsd::soml::Module>(); }
  vsd::soml::RunOptions options(std::uint64_t seed) {
    vsd::soml::RunOptions o;
    o.out = &out;
    o.seed = seed;
    o.instruction_budget = 1'000'000;
    return o;
  }
  void watch(vsd::SimState& state) {
    p->on_firing([this, &state](const vsd::soml::Firing& f) { trace.push_back(describe(state, f)); });
  }
  Program& load(const std::string& text, std::uint64_t seed) {
    p = &env.use<vsd::soml::Module>().load(env.main_state(), "golden.soml", text, options(seed));
    watch(env.main_state());
    return *p;
  }
  Program& attach(vsd::SimState& state, const std::string& text) {
    p = &env.use<vsd::soml::Module>().adopt(state, "golden.soml", text, options(99));
    watch(state);
    return *p;
  }
};

std::string joined(const std::vector<std::string>& v, std::size_t from = 0) {
  std::string s;
  for (std::size_t i = from; i < v.size(); ++i) s += v[i] + "\n";
  return s;
}

// Scripts that run without errors: object tokens (philosophers, supervisor), communication arrows,
// invocations that are mid-flight at many of the split points, substitution, place and transition
// properties, `new`, script enums (run-time enums the file defines), weights and inhibitor arrows,
// struct and vector<Vector3d> properties, vectors of script enums (vectors of the run-time enums).
const char* const continuing[] = {
    "run_philosophers.soml",      "run_communication.soml",    "invoke_fetch.soml",
    "subst_relay.soml",           "run_supervisor.soml",       "run_place_properties.soml",
    "run_nodes_meta.soml",        "run_arrow_conditions.soml", "run_enums.soml",
    "run_weights_inhibitor.soml", "run_comm_objects.soml",     "subst_members.soml",
    "run_structs.soml",           "run_enum_vectors.soml"};
constexpr std::uint64_t most = 40;  // firings per script at most (the philosophers never stop)

TEST(Attach, AReplicaThatAppliedTheRecordedBundlesContinuesIdentically) {
  for (const char* name : continuing) {
    SCOPED_TRACE(name);
    const std::string text = read_script(name);
    Session ref;
    ref.load(text, seed_of(text));
    const std::uint64_t total = ref.p->step(most);
    ASSERT_GT(total, 2u);
    const std::string ref_state = dump(ref.env.main_state());
    for (const std::uint64_t n : {std::uint64_t{0}, std::uint64_t{1}, total / 2, total - 1}) {
      SCOPED_TRACE("split after " + std::to_string(n) + " of " + std::to_string(total));
      Session a;
      vsd::SimState& replica = a.env.create_state("replica");
      a.env.main_state().start_recording();  // the recording carries the load too
      a.load(text, seed_of(text));
      ASSERT_EQ(a.p->step(n), n);
      replica.apply(a.env.main_state().stop_recording());
      // Another program on the replica (the same Registry: the classes are a's, which it checks and uses).
      std::unique_ptr<Program> b = Program::attach(replica, "golden.soml", text, a.options(5));
      std::vector<std::string> trace;
      b->on_firing([&](const vsd::soml::Firing& f) { trace.push_back(describe(replica, f)); });
      EXPECT_EQ(b->firings(), n);
      EXPECT_EQ(b->step(most - n), total - n);
      EXPECT_EQ(joined(a.trace) + joined(trace), joined(ref.trace));
      EXPECT_EQ(dump(replica), ref_state);
    }
  }
}

#if VSD_SOML_TEST_IO

TEST(Attach, ARunSavedMidExecutionByVsdIoContinuesIdenticallyAfterLoading) {
  for (const char* name : continuing) {
    SCOPED_TRACE(name);
    const std::string text = read_script(name);
    Session ref;  // N + M firings without saving
    ref.load(text, seed_of(text));
    const std::uint64_t total = ref.p->step(most);
    ASSERT_GT(total, 2u);
    const std::string ref_trace = joined(ref.trace);
    const std::string ref_out = ref.out.str();
    const std::string ref_state = dump(ref.env.main_state());
    const bool quiet = ref.p->step(1) == 0;  // the philosophers never stop
    for (std::uint64_t n = 0; n <= total; n += total > 20 ? 3 : 1) {
      // Every split point (every third of a long run), in both formats in turn.
      const auto format = n % 2 == 0 ? vsd::io::Format::Text : vsd::io::Format::Binary;
      SCOPED_TRACE("split after " + std::to_string(n) + " of " + std::to_string(total) +
                   (n % 2 == 0 ? " (text)" : " (binary)"));
      Session a;
      a.load(text, seed_of(text));
      ASSERT_EQ(a.p->step(n), n);
      const auto bytes = vsd::io::save_bytes(a.env.main_state(), format);
      Session b;
      vsd::io::load_bytes(b.env.main_state(), bytes);
      b.attach(b.env.main_state(), text);
      EXPECT_EQ(b.p->firings(), n);
      EXPECT_EQ(b.p->step(most - n), total - n);
      EXPECT_EQ(joined(a.trace) + joined(b.trace), ref_trace);
      EXPECT_EQ(a.out.str() + b.out.str(), ref_out);
      EXPECT_EQ(dump(b.env.main_state()), ref_state);
      if (quiet) {
        EXPECT_EQ(b.p->step(1), 0u);
      }
      if (::testing::Test::HasFailure()) return;  // one broken split says it all
    }
  }
}

// The saved dependencies are not needed: attaching tests every transition once, so a condition on a
// property is watched again and a C++ change re-enables it.
TEST(Attach, AnAttachedProgramHearsPropertyChangesAndTheSchedulerRunsIt) {
  const std::string text = R"(
int go = 0;
place a = 2;
place b;
transition t { when go > 0; do { go -= 1; } }
arrow a -> t;
arrow t -> b;
)";
  Session a;
  a.load(text, 1);
  EXPECT_EQ(a.p->run_until_quiet(), 0u);
  const auto bytes = vsd::io::save_bytes(a.env.main_state(), vsd::io::Format::Binary);
  Session b;
  vsd::io::load_bytes(b.env.main_state(), bytes);
  Program& p = b.attach(b.env.main_state(), text);
  EXPECT_FALSE(p.enabled_any());
  p.root().set("go", std::int64_t{1});
  b.env.step();  // the Module's task: adopt() registered the program like load()
  EXPECT_EQ(p.place("b")->tokens(), 1);
  EXPECT_EQ(p.root().get<std::int64_t>("go"), 0);
  EXPECT_EQ(p.firings(), 1u);
}

struct BadAttach : ::testing::Test {
  const std::string text = R"(
class Job : Node { int done = 0; start line.queue; }
object line {
  place<Job> queue;
  place<Job> finished;
  place credits = 2;
  transition work { do { mark.done = 1; } }
  arrow queue -> work;
  arrow credits -> work;
  arrow work -> finished;
}
object j1 : Job;
object j2 : Job;
)";
  Session a;
  void SetUp() override {
    a.load(text, 1);
    a.p->step(1);
  }
  std::string attach_error(const std::vector<std::uint8_t>& bytes, const std::string& script,
                           const std::string& name = "golden.soml") {
    Session b;
    vsd::io::load_bytes(b.env.main_state(), bytes);
    const std::size_t before = b.env.main_state().size();
    try {
      Program::attach(b.env.main_state(), name, script);
    } catch (const vsd::Error& e) {
      EXPECT_EQ(b.env.main_state().size(), before);  // nothing was created
      return e.what();
    }
    ADD_FAILURE() << "attached";
    return {};
  }
  std::vector<std::uint8_t> saved() { return vsd::io::save_bytes(a.env.main_state(), vsd::io::Format::Text); }
};

TEST_F(BadAttach, AScriptThatDiffersFromTheSavedOneNamesTheFirstDifferentLine) {
  std::string changed = text;
  changed.replace(changed.find("credits = 2"), 11, "credits = 3");
  const std::string e = attach_error(saved(), changed);
  EXPECT_THAT(e, HasSubstr("golden.soml:6: the script differs from the one the state was loaded from"));
}

TEST_F(BadAttach, AStateWithoutTheScriptObjectOrWithoutAnyScript) {
  EXPECT_THAT(attach_error(saved(), text, "other.soml"),
              HasSubstr("the state holds no script object 'other' (a node of class soml::other"));
  Session empty;
  empty.env.main_state().database().add_child(empty.env.main_state().create<vsd::Node>());
  EXPECT_THAT(attach_error(vsd::io::save_bytes(empty.env.main_state()), text),
              HasSubstr("the state holds no script object 'golden'"));
}

TEST_F(BadAttach, AMissingObjectPlaceTransitionOrExecutorStateIsNamed) {
  auto without = [&](vsd::SimStateInstance& x) {
    Session c;
    c.load(text, 1);
    c.p->step(1);
    c.env.main_state().destroy(*c.env.main_state().find(x.id()));
    return vsd::io::save_bytes(c.env.main_state(), vsd::io::Format::Binary);
  };
  EXPECT_THAT(attach_error(without(*a.p->object("j2")), text),
              HasSubstr("object 'j2' (a node of class soml::j2"));
  EXPECT_THAT(attach_error(without(*a.p->place("credits", a.p->object("line"))), text),
              HasSubstr("the net of soml::line 'line' (#"));
  EXPECT_THAT(attach_error(without(*a.p->place("credits", a.p->object("line"))), text),
              HasSubstr("does not match the script: place 'credits' is missing"));
  vsd::Node* work = a.p->object("line")->find_child("work");
  ASSERT_NE(work, nullptr);
  EXPECT_THAT(attach_error(without(*work), text), HasSubstr("transition 'work' is missing"));
  vsd::Node* exec = a.p->root().find_child("(executor)");
  ASSERT_NE(exec, nullptr);
  EXPECT_THAT(attach_error(without(*exec), text), HasSubstr("script object 'golden' has no executor state"));
}

TEST_F(BadAttach, AClassOfTheStateThatDisagreesWithTheScriptIsNamed) {
  Session b;
  // This program has its own soml::Job, with a double where the script has an int: the file's values
  // load into it, and attaching refuses it.
  vsd::ClassBuilder("soml::Job", vsd::Node::static_meta()).property("done", 0.0).define(b.reg);
  vsd::io::load_bytes(b.env.main_state(), saved());
  try {
    Program::attach(b.env.main_state(), "golden.soml", text);
    FAIL() << "attached";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(
        std::string(e.what()),
        HasSubstr("golden.soml:2:7: class 'soml::Job' of the state does not match the script: property "
                  "'done' is double in the state, int64 in the script"));
  }
}

TEST_F(BadAttach, ASyntaxErrorIsReportedLikeForALoad) {
  EXPECT_THAT(attach_error(saved(), text + "\nplace ;\n"), HasSubstr("golden.soml:15:"));
}

// The functions of classes a file defined are MetaMethods of the attached program (docs/soml.md 8.7):
// C++ calls them with arguments and receives their results exactly as after a load; wrong arguments are a
// clear vsd::Error; subclasses, objects, the script object and place classes have theirs.
TEST(Attach, FunctionsOfClassesTheFileDefinedAreCallableFromCpp) {
  const std::string text = R"(
enum Mode { Idle, Busy }
class Counter : Node {
  int n = 0;
  Mode mode = Mode::Idle;
  int add(int k) { n += k; mode = Mode::Busy; return n; }
  string label(string prefix, double x) { return prefix + string(x); }
  bool busy() { return mode == Mode::Busy; }
}
class Twice : Counter { int add(int k) { n += 2 * k; return n; } }
object c : Counter;
object t : Twice;
int total() { return c.n + t.n; }
place tank { double level = 1.5; double half() { return level / 2.0; } }
)";
  Session a;
  a.load(text, 1);
  EXPECT_EQ(a.p->object("c")->call("add", {vsd::Value(std::int64_t{2})}).as<std::int64_t>(), 2);
  const auto bytes = vsd::io::save_bytes(a.env.main_state(), vsd::io::Format::Binary);
  Session b;
  vsd::io::load_bytes(b.env.main_state(), bytes);
  const vsd::MetaInstance* counter = b.reg.find_class_exact("soml::Counter");
  ASSERT_NE(counter, nullptr);
  EXPECT_EQ(counter->find_method("add"), nullptr);  // the file carries the properties only
  Program& p = b.attach(b.env.main_state(), text);
  vsd::Node& c = *p.object("c");
  vsd::Node& t = *p.object("t");
  EXPECT_EQ(&c.meta(), b.reg.find_class_exact("soml::c"));
  EXPECT_EQ(c.call("add", {vsd::Value(std::int64_t{3})}).as<std::int64_t>(), 5);
  EXPECT_EQ(c.get<std::int64_t>("n"), 5);
  EXPECT_TRUE(c.call("busy").as<bool>());
  EXPECT_EQ(c.call("label", {vsd::Value(std::string("x=")), vsd::Value(0.5)}).as<std::string>(), "x=0.5");
  EXPECT_EQ(t.call("add", {vsd::Value(std::int64_t{4})}).as<std::int64_t>(), 8) << "the override";
  EXPECT_FALSE(t.call("busy").as<bool>());
  EXPECT_EQ(p.root().call("total").as<std::int64_t>(), 13);
  vsd::soml::Place* tank = p.place("tank");
  ASSERT_NE(tank, nullptr);
  EXPECT_EQ(tank->call("half").as<double>(), 0.75);
  // Wrong arguments: the MetaMethod's checks, then the program's.
  EXPECT_THROW(c.call("add"), vsd::Error);
  try {
    (void)c.call("add", {vsd::Value(std::string("three"))});
    FAIL() << "called";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("argument 1"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("int64"));
  }
  EXPECT_THROW((void)c.call("label", {vsd::Value(1.0), vsd::Value(0.5)}), vsd::Error);
  EXPECT_THROW((void)c.call("nothing"), vsd::Error);
  EXPECT_EQ(c.get<std::int64_t>("n"), 5);
}

// A script whose functions differ from the methods the state's classes have is refused with its
// position; the classes keep their methods.
TEST(Attach, MethodsOfTheStateThatDifferFromTheScriptAreNamed) {
  const std::string text = "class A : Node { int n = 0; int f(int k) { return k; } }\nobject a : A;\n";
  Session a;
  a.load(text, 1);
  vsd::SimState& replica = a.env.create_state("replica");
  replica.copy_from(a.env.main_state());
  std::string changed = text;
  changed.replace(changed.find("int f(int k)"), 12, "int f(bool k)");
  changed.replace(changed.find("return k;"), 9, "return 1;");
  try {
    Program::attach(replica, "golden.soml", changed);
    FAIL() << "attached";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(std::string(e.what()),
                HasSubstr("golden.soml:1:7: class 'soml::A' of the state does not match the script: method "
                          "'f' is f(int64) -> int64 in the state"));
  }
  EXPECT_EQ(a.p->object("a")->call("f", {vsd::Value(std::int64_t{7})}).as<std::int64_t>(), 7);
}

#endif

// Two programs run the same classes (a replica with the Registry of the original): a C++ call on an
// instance runs in the program of that instance's state, whichever program defined the class.
TEST(Attach, ACallOnAReplicasInstanceRunsInTheReplicasProgram) {
  const std::string text =
      "class A : Node { int n = 0; int bump(int k) { n += k; return n; } }\nobject a : A;\n";
  Session s;
  s.load(text, 1);
  vsd::SimState& replica = s.env.create_state("replica");
  replica.copy_from(s.env.main_state());
  std::unique_ptr<Program> r = Program::attach(replica, "golden.soml", text);
  EXPECT_EQ(r->object("a")->call("bump", {vsd::Value(std::int64_t{5})}).as<std::int64_t>(), 5);
  EXPECT_EQ(s.p->object("a")->get<std::int64_t>("n"), 0) << "the original is untouched";
  EXPECT_EQ(s.p->object("a")->call("bump", {vsd::Value(std::int64_t{1})}).as<std::int64_t>(), 1);
  EXPECT_EQ(r->object("a")->get<std::int64_t>("n"), 5);
  // Without a program on its state, a call is a clear error.
  vsd::SimState& bare = s.env.create_state("bare");
  bare.copy_from(s.env.main_state());
  vsd::Node* a = bare.database().find_child("golden")->find_child("a");
  ASSERT_NE(a, nullptr);
  try {
    (void)a->call("bump", {vsd::Value(std::int64_t{1})});
    FAIL() << "called";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("no SOML++ program runs the state of soml::a"));
  }
}

}  // namespace
