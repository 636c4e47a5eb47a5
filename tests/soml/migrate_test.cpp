// SOML++ run-time class migration (Program::reload, docs/soml.md "Changing a running program"):
// properties kept, new, removed and converted, markings kept, new transitions and function bodies used,
// errors leaving everything as before, references from C++ nodes redirected, replicas following.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "script_fixture.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

#if VSD_SOML_TEST_IO
#include "vsd/io/snapshot.hpp"
#endif

namespace migrate_test {

// A C++ node that refers to script objects.
class Holder : public vsd::Node {
  VSD_INSTANCE(Holder, vsd::Node)
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, target, nullptr)
  VSD_PROPERTY(vsd::SharedRefList<vsd::Node>, watched, {})
};

}  // namespace migrate_test

namespace {

using migrate_test::Holder;
using ::testing::Contains;
using ::testing::HasSubstr;
using vsd::soml::MigrationReport;
using vsd::soml::Program;

using soml_test::error_of;

const char* const v1 = R"(
class Box : Node { int v = 1; }
class Job : Node { int n = 1; start waiting; }
shared<Box> b;
int count = 5;
int gone = 3;
int size = 7;
string label = "hello";
place ready = 2;
place old_place = 1;
place done;
place<Job> waiting;
transition t1 { do { count += 1; } }
arrow ready -> t1;
arrow t1 -> done;
object j1 : Job {}
object cell { int served = 2; }
int twice(int x) { return x * 2; }
void make() { b = new Box(); b.v = 41; }
)";

const char* const v2 = R"(
class Box : Node { int v = 1; string tag = "new"; }
class Job : Node { int n = 1; double weight = 2.5; start waiting; }
shared<Box> b;
int count = 100;
double size = 0.5;
int label = 4;
int added = 9;
place ready = 5;
place done;
place extra = 1;
place<Job> waiting;
transition t1 { do { count += 1; } }
transition t2 { do { count += twice(50); } }
arrow ready -> t1;
arrow t1 -> done;
arrow extra -> t2;
object j1 : Job {}
object cell { int served = 0; }
object fresh { int z = 12; }
int twice(int x) { return x * 3; }
void make() { b = new Box(); b.v = 41; }
)";

struct Migrate : soml_test::ScriptTest {
  vsd::SimState& state = env.main_state();
  void SetUp() override {
    reg.add<Holder>();
    ScriptTest::SetUp();
  }
  // The running v1: one firing of t1, a Box made by code.
  Program& running() {
    Program& p = load(v1);
    p.root().call("make", {});
    EXPECT_EQ(p.step(1), 1u);
    return p;
  }
  static std::int64_t int_of(const vsd::Node& n, const char* name) { return n.get<std::int64_t>(name); }
};

TEST_F(Migrate, PropertiesAreKeptNewRemovedAndConverted) {
  Program& p = running();
  EXPECT_EQ(int_of(p.root(), "count"), 6);
  const vsd::MetaInstance* old_box = reg.find_class("soml::Box");
  const MigrationReport r = p.reload("test.soml", v2);

  const vsd::MetaInstance* box = reg.find_class("soml::Box");
  ASSERT_NE(box, nullptr);
  EXPECT_NE(box, old_box);
  EXPECT_NE(box->find_property("tag"), nullptr);
  EXPECT_EQ(reg.find_class("soml::Box~1"), nullptr) << "the retired class is undefined";
  vsd::Node& root = p.root();
  EXPECT_EQ(int_of(root, "count"), 6) << "kept: the running value, not the new initialiser";
  EXPECT_EQ(int_of(root, "added"), 9) << "new: its initialiser";
  EXPECT_DOUBLE_EQ(root.get<double>("size"), 7.0) << "int converted to double";
  EXPECT_EQ(int_of(root, "label"), 4) << "a string that is no int keeps the initial value";
  EXPECT_EQ(root.meta().find_property("gone"), nullptr);
  // The object made by code migrated too, with its values.
  vsd::SimStateInstance* b = root.get<vsd::SharedRef<vsd::Node>>("b").get();
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(&b->meta(), box);
  EXPECT_EQ(b->get<std::int64_t>("v"), 41);
  EXPECT_EQ(b->get<std::string>("tag"), "new");
  EXPECT_EQ(int_of(*p.object("cell"), "served"), 2);
  EXPECT_EQ(int_of(*p.object("fresh"), "z"), 12);

  EXPECT_EQ(r.migrated, 4u);  // the script object, j1, cell and the Box made by code
  EXPECT_EQ(r.created, 1u);
  EXPECT_EQ(r.deleted, 0u);
  EXPECT_THAT(r.properties, Contains("test.count: kept"));
  EXPECT_THAT(r.properties, Contains("test.added: new"));
  EXPECT_THAT(r.properties, Contains("test.gone: removed"));
  EXPECT_THAT(r.properties, Contains("test.size: type changed from int64 to double"));
  EXPECT_THAT(r.properties, Contains("Box.tag: new"));
  EXPECT_THAT(r.warnings, Contains(HasSubstr("test.gone: the property was removed; its value 3 is dropped")));
  EXPECT_THAT(r.warnings, Contains(HasSubstr("test.label: the value \"hello\"")));
  EXPECT_THAT(r.warnings, Contains(HasSubstr("test.old_place: the place was removed; its 1 token(s)")));
}

TEST_F(Migrate, MarkingsAreKeptAndNewTransitionsAndFunctionsRun) {
  Program& p = running();
  p.reload("test.soml", v2);
  EXPECT_EQ(p.place("ready")->tokens(), 1) << "the running marking, not the new initial one";
  EXPECT_EQ(p.place("done")->tokens(), 1);
  EXPECT_EQ(p.place("extra")->tokens(), 1) << "a new place has its initial marking";
  EXPECT_EQ(p.place("old_place"), nullptr);
  // The object token j1 lies in `waiting` as its new version.
  ASSERT_EQ(p.place("waiting")->objects().size(), 1u);
  EXPECT_EQ(p.place("waiting")->objects()[0], p.object("j1"));
  EXPECT_DOUBLE_EQ(p.object("j1")->get<double>("weight"), 2.5);
  // The new transition t2 fires, and t1 once more.
  EXPECT_EQ(p.run_until_quiet(), 2u);
  EXPECT_EQ(int_of(p.root(), "count"), 6 + 1 + 150) << "t2 calls the new twice()";
  EXPECT_EQ(p.firings(), 3u) << "the firing count goes on";
  // The changed body is used, from C++ and from code.
  EXPECT_EQ(p.root().call("twice", {vsd::Value(std::int64_t{5})}).as<std::int64_t>(), 15);
}

// A place or transition with members has a class of its own: its properties migrate and are reported
// like an object's, under the owner's class and the node's name.
TEST_F(Migrate, MembersOfPlacesAndTransitionsAreReportedAndKept) {
  Program& p = load(R"(
place ready = 1;
place done { int visits = 2; int dropped = 1; }
transition go { double effort = 0.5; do { effort += 1.0; done.visits += 1; } }
arrow ready -> go;
arrow go -> done;
)");
  EXPECT_EQ(p.step(1), 1u);
  const MigrationReport r = p.reload("test.soml", R"(
place ready = 1;
place done { int visits = 0; string note = "v2"; }
transition go { double effort = 0.0; int tries = 4; do { effort += 1.0; done.visits += 1; } }
arrow ready -> go;
arrow go -> done;
)");
  EXPECT_THAT(r.properties, Contains("test.done.visits: kept"));
  EXPECT_THAT(r.properties, Contains("test.done.note: new"));
  EXPECT_THAT(r.properties, Contains("test.done.dropped: removed"));
  EXPECT_THAT(r.properties, Contains("test.go.effort: kept"));
  EXPECT_THAT(r.properties, Contains("test.go.tries: new"));
  const vsd::Node* done = nullptr;
  const vsd::Node* go = nullptr;
  for (const vsd::Node* c : p.root().children()) {
    if (c->name() == "done") done = c;
    if (c->name() == "go") go = c;
  }
  ASSERT_NE(done, nullptr);
  ASSERT_NE(go, nullptr);
  EXPECT_EQ(done->get<std::int64_t>("visits"), 3) << "the running value, not the new initialiser";
  EXPECT_EQ(done->get<std::string>("note"), "v2");
  EXPECT_DOUBLE_EQ(go->get<double>("effort"), 1.5);
  EXPECT_EQ(go->get<std::int64_t>("tries"), 4);
}

TEST_F(Migrate, ReferencesFromCppNodesFollowTheMigratedObjects) {
  Program& p = running();
  auto& h = state.create<Holder>();
  state.database().add_child(h);
  vsd::Node* b = p.root().get<vsd::SharedRef<vsd::Node>>("b").get();
  h.set_target(b);
  h.edit_watched().push_back(*p.object("cell"));
  h.edit_watched().push_back(p.root());
  h.add_child(*b);  // the C++ node owns the Box the code made
  // A C++ node the script object holds as a child moves with it.
  auto& child = state.create<vsd::Node>();
  child.set_name("attached");
  p.root().add_child(child);

  p.reload("test.soml", v2);
  ASSERT_NE(h.target().get(), nullptr);
  EXPECT_EQ(h.target().get(), p.root().get<vsd::SharedRef<vsd::Node>>("b").get());
  EXPECT_EQ(h.target()->get<std::int64_t>("v"), 41);
  EXPECT_EQ(h.target()->get<std::string>("tag"), "new");
  ASSERT_EQ(h.watched().size(), 2u);
  EXPECT_EQ(h.watched()[0], p.object("cell"));
  EXPECT_EQ(h.watched()[1], &p.root());
  ASSERT_EQ(h.children().size(), 1u);
  EXPECT_EQ(h.children()[0], h.target().get()) << "the composite holder holds the new Box";
  EXPECT_EQ(child.parent(), &p.root());
  EXPECT_EQ(p.root().parent(), &state.database());
  // The old script object and its source are gone: one of each is left.
  int roots = 0, sources = 0;
  for (vsd::Node* n : state.database().children()) {
    roots += n->name() == "test" ? 1 : 0;
    sources += n->is_a<vsd::soml::SourceFile>() ? 1 : 0;
  }
  EXPECT_EQ(roots, 1);
  EXPECT_EQ(sources, 1);
  EXPECT_EQ(state.find(h.id()), &h);
}

TEST_F(Migrate, ErrorsInTheNewScriptLeaveEverythingAsBefore) {
  Program& p = running();
  auto& h = state.create<Holder>();
  state.database().add_child(h);
  h.set_target(p.object("cell"));
  vsd::SimState& copy = env.create_state("copy");
  copy.copy_from(state);
  const vsd::MetaInstance* box = reg.find_class("soml::Box");
  vsd::Node* root = &p.root();
  vsd::Node* cell = p.object("cell");
  const auto classes = reg.classes().size();

  auto expect_unchanged = [&](const std::string& what) {
    SCOPED_TRACE(what);
    std::string diff;
    EXPECT_TRUE(state.equals(copy, &diff)) << diff;
    EXPECT_EQ(reg.find_class("soml::Box"), box);
    EXPECT_EQ(reg.classes().size(), classes);
    EXPECT_EQ(&p.root(), root);
    EXPECT_EQ(p.object("cell"), cell);
    EXPECT_EQ(h.target().get(), cell);
  };
  // A syntax error, with file:line:col.
  std::string e = error_of([&] { p.reload("v2.soml", "int x = ;\nint y = 2;\n"); });
  EXPECT_THAT(e, HasSubstr("v2.soml:1:9"));
  expect_unchanged("syntax error");
  // A semantic error.
  e = error_of([&] { p.reload("v2.soml", "int f() { return nope; }\n"); });
  EXPECT_THAT(e, HasSubstr("v2.soml:1:18"));
  EXPECT_THAT(e, HasSubstr("nope"));
  expect_unchanged("semantic error");
  // A run-time error while the new objects are made (after the instances were created): rolled back.
  e = error_of([&] {
    p.reload("v2.soml",
             std::string(v2) + "int zero() { return 0; }\nobject broken { int z = 10 / zero(); }\n");
  });
  EXPECT_THAT(e, HasSubstr("division by zero"));
  expect_unchanged("run-time error");
  // Removing a class that still has instances (b) is refused.
  e = error_of([&] { p.reload("v2.soml", "int count = 1;\n"); });
  EXPECT_THAT(e, HasSubstr("'Box' (1 live)"));
  expect_unchanged("removed class");
  // Changing an enum's values at run time is refused with its position.
  // The program runs on as before.
  EXPECT_EQ(p.root().call("twice", {vsd::Value(std::int64_t{5})}).as<std::int64_t>(), 10);
  EXPECT_EQ(p.run_until_quiet(), 1u);
  EXPECT_EQ(int_of(p.root(), "count"), 7);
  // And a good version still loads afterwards.
  p.reload("test.soml", v2);
  EXPECT_EQ(int_of(p.root(), "count"), 7);
}

TEST_F(Migrate, MigratingTwiceAndRemovingObjects) {
  Program& p = running();
  p.reload("test.soml", v2);
  const std::string v3 = R"(
class Box : Node { int v = 1; }
class Job : Node { double weight = 1.0; start waiting; }
shared<Box> b;
int count = 0;
place ready;
place done;
place<Job> waiting;
transition t1 { do { count += 1; } }
arrow ready -> t1;
arrow t1 -> done;
object j1 : Job {}
int twice(int x) { return x * 4; }
)";
  const MigrationReport r = p.reload("test.soml", v3);
  EXPECT_EQ(r.deleted, 2u);  // cell and fresh
  EXPECT_EQ(p.object("cell"), nullptr);
  EXPECT_EQ(p.object("fresh"), nullptr);
  EXPECT_EQ(p.root().call("twice", {vsd::Value(std::int64_t{5})}).as<std::int64_t>(), 20);
  EXPECT_EQ(p.root().get<vsd::SharedRef<vsd::Node>>("b")->get<std::int64_t>("v"), 41);
  EXPECT_DOUBLE_EQ(p.object("j1")->get<double>("weight"), 2.5);
  EXPECT_EQ(p.object("j1")->meta().find_property("n"), nullptr);
  EXPECT_EQ(p.place("ready")->tokens(), 1);
  EXPECT_EQ(p.place("extra"), nullptr);
  EXPECT_THAT(r.warnings, Contains(HasSubstr("test.extra: the place was removed; its 1 token(s)")));
  EXPECT_EQ(reg.find_class("soml::Box~1"), nullptr);
  EXPECT_EQ(reg.find_class("soml::cell"), nullptr);
  EXPECT_EQ(p.run_until_quiet(), 1u);
}

TEST_F(Migrate, AReplicaFollowsThroughTheRecording) {
  Program& p = running();
  vsd::SimState& replica = env.create_state("replica");
  replica.copy_from(state);
  state.start_recording();
  const MigrationReport r = p.reload("test.soml", v2);
  p.run_until_quiet();
  replica.apply(state.stop_recording());
  std::string diff;
  EXPECT_TRUE(state.equals(replica, &diff)) << diff;
  // The replica's copies of the old instances kept the retired classes alive until it applied the bundle.
  EXPECT_THAT(r.warnings, Contains(HasSubstr("the retired class 'soml::Box~1' stays")));
}

TEST_F(Migrate, EnumsKeptWhenUnchangedAndRefusedWhenChanged) {
  Program& p = load("enum Mode { Idle, Busy }\nMode m = Mode::Busy;\nint k = 1;\n");
  const vsd::MetaType* mode = reg.find_type("soml::Mode");
  p.reload("test.soml", "enum Mode { Idle, Busy }\nMode m = Mode::Idle;\nint k = 2;\nint j = 3;\n");
  EXPECT_EQ(reg.find_type("soml::Mode"), mode);
  EXPECT_EQ(p.root().get("m").to_text(), "\"Busy\"");
  const std::string e =
      error_of([&] { p.reload("test.soml", "enum Mode { Idle, Busy, Off }\nMode m = Mode::Idle;\n"); });
  EXPECT_THAT(e, HasSubstr("test.soml:1:6"));
  EXPECT_THAT(e, HasSubstr("enum 'Mode'"));
  EXPECT_EQ(p.root().get<std::int64_t>("j"), 3);
}

TEST_F(Migrate, TheModuleRunsTheNewVersionInTheSchedulerStep) {
  Program& p = load(v1);
  env.step();
  EXPECT_EQ(int_of(p.root(), "count"), 7);
  p.reload("test.soml", v2);
  env.step();  // t2 is enabled in the new version: the module's task runs it
  EXPECT_EQ(int_of(p.root(), "count"), 157);
}

// The executor's database state (docs/soml.md 8.7) describes the new version after a reload, so a run
// saved after a reload continues after attaching the new text.
TEST_F(Migrate, TheExecutorStateFollowsTheReloadAndAttachContinues) {
  Program& p = running();
  p.reload("test.soml", v2);
  std::vector<const vsd::Node*> execs;
  for (const vsd::Node* c : p.root().children())
    if (c->as<vsd::soml::Executor>() != nullptr) execs.push_back(c);
  ASSERT_EQ(execs.size(), 1u);
  EXPECT_EQ(execs[0]->as<vsd::soml::Executor>()->firings(), 1u);
  EXPECT_TRUE(p.enabled_any());
#if VSD_SOML_TEST_IO
  const auto bytes = vsd::io::save_bytes(state);
  vsd::Registry reg2;
  reg2.add<Holder>();
  vsd::Environment env2{0, reg2};
  auto& soml2 = env2.use<vsd::soml::Module>();
  vsd::io::load_bytes(env2.main_state(), bytes);
  vsd::soml::RunOptions o;
  std::ostringstream out2;
  o.out = &out2;
  Program& q = soml2.adopt(env2.main_state(), "test.soml", v2, o);
  EXPECT_EQ(q.firings(), 1u);
  EXPECT_EQ(q.run_until_quiet(), p.run_until_quiet());
  EXPECT_EQ(q.root().get<std::int64_t>("count"), p.root().get<std::int64_t>("count"));
  EXPECT_EQ(q.firings(), p.firings());
#endif
}

#if VSD_SOML_TEST_IO
// A replica with a Registry of its own (here: loaded from a file, then attached) follows a reload on the
// source with Program::follow_reload: the new classes are defined before the source's recording applies,
// and the replica's program runs the new version from there exactly like the source's.
TEST_F(Migrate, AReplicaWithItsOwnRegistryFollowsAReload) {
  Program& p = running();
  vsd::Registry reg2;
  reg2.add<Holder>();
  vsd::Environment env2{0, reg2};
  auto& soml2 = env2.use<vsd::soml::Module>();
  vsd::io::load_bytes(env2.main_state(), vsd::io::save_bytes(state));
  vsd::soml::RunOptions o;
  std::ostringstream out2;
  o.out = &out2;
  Program& q = soml2.adopt(env2.main_state(), "test.soml", v1, o);
  // Without the new classes the recording of the reload does not apply (it creates soml::fresh).
  state.start_recording();
  p.reload("test.soml", v2);
  const vsd::Transaction bundle = state.take_recording();
  {
    vsd::Registry reg3;
    reg3.add<Holder>();
    vsd::Environment env3{0, reg3};
    env3.use<vsd::soml::Module>();
    vsd::io::load_bytes(env3.main_state(), vsd::io::save_bytes(env2.main_state()));
    EXPECT_THROW(env3.main_state().apply(bundle), vsd::Error);
  }
  // A text with errors, or another text than the source's: refused, the replica runs v1 on.
  const vsd::MetaInstance* box1 = reg2.find_class_exact("soml::Box");
  EXPECT_THAT(error_of([&] { q.follow_reload("test.soml", std::string(v2) + "\nint broken = ;\n", bundle); }),
              HasSubstr("error: "));
  std::string other = v2;
  other.replace(other.find("int added = 9;"), 14, "int added = 8;");
  EXPECT_THAT(error_of([&] { q.follow_reload("test.soml", other, bundle); }),
              HasSubstr("the script differs from the one the state was loaded from"));
  EXPECT_EQ(reg2.find_class_exact("soml::Box"), box1);
  EXPECT_EQ(reg2.find_class_exact("soml::fresh"), nullptr);
  EXPECT_EQ(q.root().get<std::int64_t>("count"), 6);
  EXPECT_EQ(q.root().call("twice", {vsd::Value(std::int64_t{2})}).as<std::int64_t>(), 4);
  // The right text: the replica equals the source and runs on like it.
  q.follow_reload("test.soml", v2, bundle);
  EXPECT_NE(reg2.find_class_exact("soml::fresh"), nullptr);
  EXPECT_EQ(reg2.find_class_exact("soml::Box~1"), nullptr) << "the retired classes are gone";
  EXPECT_EQ(q.root().get<std::int64_t>("count"), p.root().get<std::int64_t>("count"));
  EXPECT_EQ(q.root().call("twice", {vsd::Value(std::int64_t{2})}).as<std::int64_t>(), 6);
  std::vector<std::string> fired_p, fired_q;
  p.on_firing([&](const vsd::soml::Firing& f) { fired_p.push_back(f.transition->name()); });
  q.on_firing([&](const vsd::soml::Firing& f) { fired_q.push_back(f.transition->name()); });
  EXPECT_EQ(q.run_until_quiet(), p.run_until_quiet());
  EXPECT_EQ(fired_q, fired_p);
  EXPECT_FALSE(fired_p.empty());
  EXPECT_EQ(q.root().get<std::int64_t>("count"), p.root().get<std::int64_t>("count"));
  EXPECT_EQ(q.firings(), p.firings());
}
#endif

}  // namespace
