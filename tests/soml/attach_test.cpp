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

#if VSD_SOML_TEST_IO
#include "vsd/io/snapshot.hpp"
#endif

namespace {

using ::testing::HasSubstr;
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

// Where a node is in the tree, by names: ids of instances made after a reload may differ from the
// original's (each Environment counts its own), names and places in the tree do not.
std::string path(const vsd::SimStateInstance* x) {
  if (x == nullptr) return "-";
  const vsd::Node* n = x->as<vsd::Node>();
  if (n == nullptr) return "#?";
  std::string s;
  for (; n != nullptr && n->parent() != nullptr; n = n->parent()) s = "/" + n->name() + s;
  return s.empty() ? "/" : s;
}

// The text of a value with every "@id" replaced by the path of that instance.
std::string with_paths(const vsd::SimState& state, const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '@' || i + 1 >= text.size() ||
        std::isdigit(static_cast<unsigned char>(text[i + 1])) == 0) {
      out += text[i];
      continue;
    }
    std::size_t j = i + 1;
    while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])) != 0) ++j;
    out += path(state.find(std::stoull(text.substr(i + 1, j - i - 1))));
    i = j - 1;
  }
  return out;
}

// The whole tree: every node's class and every property (references as paths), depth first.
std::string dump(const vsd::SimState& state) {
  std::string s;
  state.database().visit([&](const vsd::Node& n) {
    s += path(&n) + " " + n.meta().name() + " {";
    for (const vsd::MetaProperty* p : n.meta().properties()) {
      if (p->name() == "children") continue;
      s += " " + p->name() + "=" + with_paths(state, p->type().to_text(p->address(n)));
    }
    s += " }\n";
  });
  return s;
}

std::string describe(const vsd::SimState& state, const vsd::soml::Firing& f) {
  static const char* kinds[] = {"plain", "invoke", "finish", "complete"};
  std::string s = std::to_string(f.step) + " " + kinds[static_cast<int>(f.kind)] + " " + path(f.transition) +
                  " mark " + path(f.mark != 0 ? state.find(f.mark) : nullptr) + " " + path(f.from) + " -> " +
                  path(f.to);
  for (const auto& m : f.taken) s += " -" + std::to_string(m.count) + path(m.place);
  for (const auto& m : f.given) s += " +" + std::to_string(m.count) + path(m.place);
  return s;
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
// properties, `new`, script enums (run-time enums the file defines), weights and inhibitor arrows.
const char* const continuing[] = {
    "run_philosophers.soml",      "run_communication.soml",    "invoke_fetch.soml",
    "subst_relay.soml",           "run_supervisor.soml",       "run_place_properties.soml",
    "run_nodes_meta.soml",        "run_arrow_conditions.soml", "run_enums.soml",
    "run_weights_inhibitor.soml", "run_comm_objects.soml",     "subst_members.soml"};
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

#endif

}  // namespace
