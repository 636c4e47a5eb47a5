// SOML++ net substitution and invocation (docs/soml.md 4.11, 5.5): the firing rule of substituted
// sub-nets and of invoking transitions, the database content they make (sub-nodes, net instances under
// the invoking transition, the invocation hierarchy), run-time errors, and recording, replicas and
// vsd::io save/reload in the middle of an invocation.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "script_fixture.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace {

using ::testing::HasSubstr;
using vsd::soml::Invocation;
using vsd::soml::Place;
using vsd::soml::Program;
using vsd::soml::Transition;

struct Nets : soml_test::ScriptTest {
  Nets() { script_file = "net.soml"; }
  template <class T>
  static T* child(const vsd::Node& n, std::string_view name) {
    return dynamic_cast<T*>(n.find_child(name));
  }
  // Every invocation instance below @p n (depth first).
  static void invocations(const vsd::Node& n, std::vector<const Invocation*>& all) {
    for (const vsd::Node* c : n.children()) {
      if (c == nullptr) continue;
      if (const auto* inv = dynamic_cast<const Invocation*>(c)) all.push_back(inv);
      invocations(*c, all);
    }
  }
  std::vector<const Invocation*> invocations(const Program& p) {
    std::vector<const Invocation*> all;
    invocations(p.root(), all);
    return all;
  }
};

// ---- substitution ------------------------------------------------------------------------------------

TEST_F(Nets, SubstitutionCopiesThePortNetWithItsPortsFusedToTheSockets) {
  Program& p = load(R"(
net Relay(place in, place out) {
  place mid;
  transition first;
  transition second;
  arrow in -> first;
  arrow first -> mid;
  arrow mid -> second;
  arrow second -> out * 2;
}
place a = 3;
place b;
place c;
transition move = Relay(a, b);
transition back = Relay(b, c);
)");
  // The sub-net is part of the database: its places and transitions are children of the substitution
  // transition's node, and its ports are the socket places themselves.
  auto* move = child<Transition>(p.root(), "move");
  ASSERT_NE(move, nullptr);
  ASSERT_NE(child<Place>(*move, "mid"), nullptr);
  ASSERT_NE(child<Transition>(*move, "first"), nullptr);
  EXPECT_EQ(child<Place>(p.root(), "mid"), nullptr);
  EXPECT_EQ(child<Place>(*move, "in"), nullptr);  // a port is no node of its own
  auto* back = child<Transition>(p.root(), "back");
  ASSERT_NE(back, nullptr);
  EXPECT_NE(child<Place>(*back, "mid"), child<Place>(*move, "mid"));  // one copy per substitution

  EXPECT_EQ(p.run_until_quiet(), 3u * 2 + 6u * 2);
  EXPECT_EQ(p.place("a")->tokens(), 0);
  EXPECT_EQ(p.place("b")->tokens(), 0);
  EXPECT_EQ(p.place("c")->tokens(), 12);  // 3 -> 6 through move, 6 -> 12 through back
  EXPECT_EQ(child<Transition>(*move, "first")->firings(), 3);
  EXPECT_EQ(child<Transition>(*back, "second")->firings(), 6);
  EXPECT_EQ(move->firings(), 0);  // the substitution transition itself never fires
}

TEST_F(Nets, SubstitutedTransitionsTestMarksConditionsAndNestedSubstitutions) {
  Program& p = load(R"(
class Part : Node { bool ready = false; int hops = 0; start line.waiting; Part(bool r) { ready = r; } }
net Relay(place<Part> in, place<Part> out) {
  transition pass { when mark.ready; do { mark.hops += 1; } }
  arrow in -> pass;
  arrow pass -> out;
}
net Twice(place<Part> in, place<Part> out) {
  place<Part> half;
  transition one = Relay(in, half);
  transition two = Relay(half, out);
}
object line {
  place<Part> waiting;
  place<Part> done;
  transition move = Twice(waiting, done);
}
object p1 : Part(true);
object p2 : Part(false);
)");
  EXPECT_EQ(p.run_until_quiet(), 2u);
  vsd::Node* line = p.object("line");
  ASSERT_EQ(p.place("done", line)->objects().size(), 1u);
  EXPECT_EQ(p.place("done", line)->objects()[0]->id(), p.object("p1")->id());
  EXPECT_EQ(p.object("p1")->get<std::int64_t>("hops"), 2);
  // The nested copies: move -> one -> pass, and move.half between them.
  auto* move = child<Transition>(*line, "move");
  ASSERT_NE(move, nullptr);
  auto* one = child<Transition>(*move, "one");
  ASSERT_NE(one, nullptr);
  ASSERT_NE(child<Transition>(*one, "pass"), nullptr);
  EXPECT_EQ(child<Transition>(*one, "pass")->firings(), 1);
  EXPECT_NE(child<Place>(*move, "half"), nullptr);
  // p2 becomes ready: the condition it read is re-tested, it travels too.
  p.object("p2")->set("ready", true);
  EXPECT_EQ(p.run_until_quiet(), 2u);
  EXPECT_EQ(p.place("done", line)->objects().size(), 2u);
}

TEST_F(Nets, EveryInstanceOfAClassGetsItsOwnCopyAndSubclassesInheritIt) {
  Program& p = load(R"(
net Relay(place in, place out) { transition pass; arrow in -> pass; arrow pass -> out; }
class Cell : Node {
  place in = 2;
  place out;
  transition move = Relay(in, out);
}
class BigCell : Cell { place extra = 1; }
object c1 : Cell;
object c2 : BigCell;
)");
  EXPECT_EQ(p.run_until_quiet(), 4u);
  for (const char* n : {"c1", "c2"}) {
    SCOPED_TRACE(n);
    EXPECT_EQ(p.place("out", p.object(n))->tokens(), 2);
    auto* move = child<Transition>(*p.object(n), "move");
    ASSERT_NE(move, nullptr);
    EXPECT_EQ(child<Transition>(*move, "pass")->firings(), 2);
  }
  EXPECT_EQ(p.place("extra", p.object("c2"))->tokens(), 1);
}

// A port net with members: the substitution transition's node is the copy's instance.
constexpr const char* kCounted = R"(
object log { place reports; }
net Relay(place in, place out) {
  int passed = 0;
  int limit = 2;
  shared<log> sink = log;
  int left() { return limit - passed; }
  int waiting() { return in.count; }   // the copy's port: its socket place
  transition pass {
    int moved = 0;
    when passed < limit;
    do { passed += 1; moved += 1; }
  }
  arrow in -> pass;
  arrow pass -> out;
  arrow pass ~> sink.reports when left() == 0;
}
class Cell : Node {
  place in = 5;
  place mid;
  place out;
  transition first = Relay(in, mid);
  transition second = Relay(mid, out);
}
object c1 : Cell;
object c2 : Cell;
)";

TEST_F(Nets, APortNetsPropertiesAndFunctionsBelongToEachCopy) {
  Program& p = load(kCounted);
  // Every copy is an instance of the port net's run-time class, a soml::Transition.
  vsd::Node* c1 = p.object("c1");
  auto* first = child<Transition>(*c1, "first");
  auto* second = child<Transition>(*c1, "second");
  ASSERT_NE(first, nullptr);
  ASSERT_NE(second, nullptr);
  EXPECT_EQ(first->meta().name(), "soml::Relay");
  EXPECT_TRUE(first->meta().is_a(Transition::static_meta()));
  EXPECT_EQ(&second->meta(), &first->meta());
  EXPECT_EQ(p.run_until_quiet(), 8u);  // 2 copies per cell, each lets 2 tokens pass
  for (const char* n : {"c1", "c2"}) {
    SCOPED_TRACE(n);
    vsd::Node* c = p.object(n);
    EXPECT_EQ(p.place("in", c)->tokens(), 3);
    EXPECT_EQ(p.place("mid", c)->tokens(), 0);
    EXPECT_EQ(p.place("out", c)->tokens(), 2);
    for (const char* t : {"first", "second"}) {
      auto* copy = child<Transition>(*c, t);
      EXPECT_EQ(copy->get<std::int64_t>("passed"), 2);
      EXPECT_EQ(child<Transition>(*copy, "pass")->get<std::int64_t>("moved"), 2);
      EXPECT_EQ(copy->call("left", {}).as<std::int64_t>(), 0);  // a MetaMethod on the copy
    }
    EXPECT_EQ(child<Transition>(*c, "first")->call("waiting", {}).as<std::int64_t>(), 3);   // in
    EXPECT_EQ(child<Transition>(*c, "second")->call("waiting", {}).as<std::int64_t>(), 0);  // mid
  }
  // One report per copy that reached its limit (the arrow's condition calls the copy's function).
  EXPECT_EQ(p.place("reports", p.object("log"))->tokens(), 4);
  // C++ raises one copy's limit: its condition read it, so that copy is re-tested and goes on alone.
  first->set("limit", vsd::Value(std::int64_t{4}));
  EXPECT_EQ(p.run_until_quiet(), 2u);
  EXPECT_EQ(first->get<std::int64_t>("passed"), 4);
  EXPECT_EQ(second->get<std::int64_t>("passed"), 2);
  EXPECT_EQ(child<Transition>(*p.object("c2"), "first")->get<std::int64_t>("passed"), 2);
  EXPECT_EQ(p.place("mid", c1)->tokens(), 2);
  EXPECT_EQ(p.place("reports", p.object("log"))->tokens(), 5);
  // A null reference on the copy's path disables that copy only.
  second->set("limit", vsd::Value(std::int64_t{3}));
  second->set("sink", vsd::Value(vsd::SharedRef<vsd::Node>()));
  EXPECT_EQ(p.run_until_quiet(), 0u);
  second->set("sink", vsd::Value(vsd::SharedRef<vsd::Node>(p.object("log"))));
  EXPECT_EQ(p.run_until_quiet(), 1u);
  EXPECT_EQ(p.place("out", c1)->tokens(), 3);
  EXPECT_EQ(p.place("reports", p.object("log"))->tokens(), 6);
}

TEST_F(Nets, APortNetsMembersAreRecordedReplayedAndKeptByAReload) {
  Program& p = load(kCounted);
  vsd::SimState& replica = env.create_state("replica");
  replica.copy_from(env.main_state());
  env.main_state().start_recording();
  EXPECT_EQ(p.step(3), 3u);
  replica.apply(env.main_state().stop_recording());
  std::string diff;
  EXPECT_TRUE(replica.equals(env.main_state(), &diff)) << diff;
  // A new version: the copies' properties are kept by name, a new one gets its initialiser.
  std::int64_t before = 0;
  for (const char* n : {"c1", "c2"})
    for (const char* t : {"first", "second"})
      before += child<Transition>(*p.object(n), t)->get<std::int64_t>("passed");
  std::string v2 = kCounted;
  v2.replace(v2.find("int limit = 2;"), 14, "int limit = 2;\n  string tag = \"v2\";");
  const vsd::soml::MigrationReport r = p.reload("net.soml", v2);
  EXPECT_EQ(r.migrated, 4u);  // the script object, log, c1 and c2 (the copies are parts of their nets)
  std::int64_t after = 0;
  for (const char* n : {"c1", "c2"})
    for (const char* t : {"first", "second"}) {
      auto* copy = child<Transition>(*p.object(n), t);
      after += copy->get<std::int64_t>("passed");
      EXPECT_EQ(copy->get<std::string>("tag"), "v2");
    }
  EXPECT_EQ(after, before);
  EXPECT_EQ(p.run_until_quiet(), 8u - 3u);
}

TEST_F(Nets, WhatPortNetsCannotDoIsAnErrorWithItsPosition) {
  auto error_of = [&](const std::string& text) {
    try {
      vsd::Registry r;  // a refused load may leave its classes defined: a registry per case
      vsd::Environment e(0, r);
      vsd::soml::RunOptions o;
      o.out = &out;
      e.use<vsd::soml::Module>().load(e.main_state(), "net.soml", text, o);
    } catch (const vsd::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string ports = "place a = 1;\nplace b;\ntransition move = Relay(a, b);\n";
  // A property with the name of one of soml::Transition (the copy's node is one).
  EXPECT_THAT(
      error_of("net Relay(place in, place out) {\n  int firings = 0;\n  transition t;\n"
               "  arrow in -> t;\n  arrow t -> out;\n}\n" +
               ports),
      HasSubstr("net.soml:2:7: error: duplicate definition of 'firings' (already a member of built-in "
                "class 'soml::Transition')"));
  // A port net nested in a class does not reach the class's instance (its depth varies per copy).
  EXPECT_THAT(error_of("class C : Node {\n  int k = 0;\n  net Relay(place in, place out) {\n"
                       "    transition t { do { k += 1; } }\n    arrow in -> t;\n    arrow t -> out;\n  }\n"
                       "  place a = 1;\n  place b;\n  transition move = Relay(a, b);\n}\nobject o : C;\n"),
              HasSubstr("net.soml:4:25: error: reaching the enclosing instance"));
}

// ---- invocation --------------------------------------------------------------------------------------

constexpr const char* kDouble = R"(
class Job : Node { int n = 0; start desk.todo; Job(int v) { n = v; } }
net int twice(int x) {
  place go;
  start go;
  transition t { do { finish x * 2; } }
  arrow go -> t;
}
object desk {
  place<Job> todo;
  place<Job> done;
  int calls = 0;
  transition call {
    invoke twice(mark.n + 1);
    do { mark.n = result; calls += 1; }
  }
  arrow todo -> call;
  arrow call -> done;
}
object j : Job(20);
)";

TEST_F(Nets, AnInvocationIsANetInstanceUnderTheInvokingTransitionUntilItFinishes) {
  Program& p = load(kDouble);
  std::vector<vsd::soml::Firing> trace;
  p.on_firing([&](const vsd::soml::Firing& f) { trace.push_back(f); });
  vsd::Node* desk = p.object("desk");
  vsd::Node* job = p.object("j");
  // First half: the mark leaves `todo`, a `twice` instance appears under `call` with x = 21 and the
  // invocation's token in its start place; nothing is produced yet.
  ASSERT_EQ(p.step(1), 1u);
  EXPECT_TRUE(p.place("todo", desk)->objects().empty());
  EXPECT_TRUE(p.place("done", desk)->objects().empty());
  auto* call = child<Transition>(*desk, "call");
  ASSERT_NE(call, nullptr);
  auto* inv = child<Invocation>(*call, "twice");
  ASSERT_NE(inv, nullptr);
  EXPECT_EQ(inv->meta().name(), "soml::twice");
  EXPECT_EQ(inv->get<std::int64_t>("x"), 21);
  EXPECT_EQ(inv->mark().get(), job);
  EXPECT_FALSE(inv->finished());
  ASSERT_NE(child<Place>(*inv, "go"), nullptr);
  EXPECT_EQ(child<Place>(*inv, "go")->tokens(), 1);
  const vsd::Id inv_id = inv->id();
  EXPECT_EQ(call->firings(), 1);
  ASSERT_EQ(trace.size(), 1u);
  EXPECT_EQ(trace[0].invocation, inv_id);
  EXPECT_EQ(trace[0].to, nullptr);

  // Second half: `finish 42;` ends the instance; call's action gets result = 42 and the mark moves on.
  ASSERT_EQ(p.step(1), 1u);
  EXPECT_EQ(env.main_state().find(inv_id), nullptr);
  EXPECT_EQ(child<Invocation>(*call, "twice"), nullptr);
  EXPECT_EQ(job->get<std::int64_t>("n"), 42);
  EXPECT_EQ(desk->get<std::int64_t>("calls"), 1);
  ASSERT_EQ(p.place("done", desk)->objects().size(), 1u);
  EXPECT_EQ(p.place("done", desk)->objects()[0], job);
  ASSERT_EQ(trace.size(), 3u);  // the finishing firing, then the invoking transition's completion
  EXPECT_EQ(trace[1].invocation, inv_id);
  EXPECT_EQ(trace[0].kind, vsd::soml::FiringKind::Invoke);
  EXPECT_EQ(trace[1].kind, vsd::soml::FiringKind::Finish);
  EXPECT_EQ(trace[2].kind, vsd::soml::FiringKind::Complete);
  EXPECT_EQ(trace[2].transition, call);
  EXPECT_EQ(trace[2].to, p.place("done", desk));
  EXPECT_EQ(trace[2].step, 2u);
  EXPECT_EQ(p.run_until_quiet(), 0u);
  EXPECT_EQ(p.firings(), 2u);
}

TEST_F(Nets, AnInvokedNetWaitsForTheDatabaseAndEachFiringGetsItsOwnInstance) {
  Program& p = load(R"(
class Order : Node { shared<Node> part; bool ok = false; start shop.open; }
net bool fetch(shared<Node> part, double timeout) {
  place begin;
  place asked;
  start begin;
  transition ask { do { part.name = "requested"; } }
  transition done { when part.name == "delivered"; do { finish true; } }
  arrow begin -> ask;
  arrow ask -> asked;
  arrow asked -> done;
}
object shop {
  place<Order> open;
  place<Order> closed;
  transition get {
    when mark.part != null;
    invoke fetch(mark.part, 2.5);
    do { mark.ok = result; }
  }
  arrow open -> get;
  arrow get -> closed;
}
object o1 : Order;
object o2 : Order;
)");
  vsd::SimState& s = env.main_state();
  auto& n1 = s.create<vsd::Node>();
  auto& n2 = s.create<vsd::Node>();
  s.database().add_child(n1);
  s.database().add_child(n2);
  p.object("o1")->set("part", vsd::SharedRef<vsd::Node>(&n1));
  p.object("o2")->set("part", vsd::SharedRef<vsd::Node>(&n2));
  // Both orders invoke fetch (two instances), both ask, then wait for the plant.
  EXPECT_EQ(p.run_until_quiet(), 4u);
  EXPECT_EQ(n1.name(), "requested");
  EXPECT_EQ(n2.name(), "requested");
  ASSERT_EQ(invocations(p).size(), 2u);
  EXPECT_DOUBLE_EQ(invocations(p)[0]->get<double>("timeout"), 2.5);
  // The plant delivers part 2: only that instance finishes (its condition read n2.name).
  n2.set_name("delivered");
  EXPECT_EQ(p.run_until_quiet(), 1u);
  ASSERT_EQ(invocations(p).size(), 1u);
  EXPECT_EQ(invocations(p)[0]->mark().get(), p.object("o1"));
  EXPECT_TRUE(p.object("o2")->get<bool>("ok"));
  EXPECT_FALSE(p.object("o1")->get<bool>("ok"));
  n1.set_name("delivered");
  EXPECT_EQ(p.run_until_quiet(), 1u);
  EXPECT_TRUE(invocations(p).empty());
  EXPECT_EQ(p.place("closed", p.object("shop"))->objects().size(), 2u);
}

TEST_F(Nets, NestedInvocationsFormTheInvocationHierarchy) {
  Program& p = load(R"(
net int leaf(int v) {
  place s;
  start s;
  transition t { do { finish v + 1; } }
  arrow s -> t;
}
net int middle(int v) {
  place s;
  place r;
  start s;
  int got = 0;
  transition call { invoke leaf(v * 10); do { got = result; } }
  transition t { do { finish got + 1; } }
  arrow s -> call;
  arrow call -> r;
  arrow r -> t;
}
net void quiet() {
  place s;
  start s;
  transition t { do { print("quiet"); finish; } }
  arrow s -> t;
}
int total = 0;
place go = 1;
place done;
transition top { invoke middle(4); do { total = result; } }
transition also { invoke quiet(); }
arrow go -> top;
arrow top -> done;
place go2 = 1;
arrow go2 -> also;
)");
  // top -> middle instance -> call -> leaf instance: the hierarchy is the database tree.
  EXPECT_EQ(p.step(1), 1u);  // seed 1 picks one of top, also; run until both invocations exist
  while (invocations(p).size() < 3 && p.step(1) == 1) {
  }
  std::vector<const Invocation*> all = invocations(p);
  const Invocation* mid = nullptr;
  const Invocation* leaf = nullptr;
  for (const Invocation* i : all) {
    if (i->meta().name() == "soml::middle") mid = i;
    if (i->meta().name() == "soml::leaf") leaf = i;
  }
  ASSERT_NE(mid, nullptr);
  ASSERT_NE(leaf, nullptr);
  ASSERT_NE(leaf->parent(), nullptr);
  EXPECT_EQ(leaf->parent()->name(), "call");
  EXPECT_EQ(leaf->parent()->parent(), mid);
  EXPECT_EQ(mid->parent()->name(), "top");
  p.run_until_quiet();
  EXPECT_EQ(p.root().get<std::int64_t>("total"), 42);  // leaf: 40 + 1, middle: 41 + 1
  EXPECT_EQ(p.place("done")->tokens(), 1);
  EXPECT_TRUE(invocations(p).empty());
  EXPECT_EQ(out.str(), "quiet\n");
}

TEST_F(Nets, AnErrorInTheInvokingActionUndoesTheFinishingFiring) {
  Program& p = load(R"(
int zero = 0;
net int one() {
  place s;
  start s;
  transition t { do { finish 1; } }
  arrow s -> t;
}
place go = 1;
place done;
transition call { invoke one(); do { int x = result / zero; print(x); } }
arrow go -> call;
arrow call -> done;
)");
  EXPECT_EQ(p.step(1), 1u);
  ASSERT_EQ(invocations(p).size(), 1u);
  const Invocation* inv = invocations(p)[0];
  try {
    p.step(1);
    FAIL() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("division by zero"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("at call (action) (net.soml:11:53)"));
  }
  // The instance is still there, not finished, its token back in its start place; nothing produced.
  ASSERT_EQ(invocations(p).size(), 1u);
  EXPECT_EQ(invocations(p)[0], inv);
  EXPECT_FALSE(inv->finished());
  EXPECT_EQ(child<Place>(*inv, "s")->tokens(), 1);
  EXPECT_EQ(p.place("done")->tokens(), 0);
  // Fix the cause: the invocation completes.
  p.root().set<std::int64_t>("zero", 1);
  EXPECT_EQ(p.step(1), 1u);
  EXPECT_TRUE(invocations(p).empty());
  EXPECT_EQ(p.place("done")->tokens(), 1);
}

TEST_F(Nets, AnErrorInTheArgumentsLeavesNoInstanceAndGivesTheTokensBack) {
  Program& p = load(R"(
shared<Node> missing;
net void use(string n) { place s; start s; transition t { do { finish; } } arrow s -> t; }
place go = 1;
transition call { invoke use(missing.name); }
arrow go -> call;
)");
  try {
    p.step(1);
    FAIL() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("null reference"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("call (invocation arguments) (net.soml:5:37)"));
  }
  EXPECT_TRUE(invocations(p).empty());
  EXPECT_EQ(p.place("go")->tokens(), 1);
}

TEST_F(Nets, AFinishWhoseInvokerIsGoneOrInvokesAnotherNetIsARunTimeError) {
  Program& p = load(R"(
net int a() { place s; place w; start s; transition t; transition f { do { finish 7; } }
              arrow s -> t; arrow t -> w; arrow w -> f; }
net string b() { place s; start s; transition t { do { finish "b"; } } arrow s -> t; }
place go = 1;
place gob;
place w;
transition call_a { invoke a(); do { print(result); } }
transition call_b { invoke b(); do { print(result); } }
arrow go -> call_a;
arrow gob -> call_b;
transition tick;
arrow w -> tick;
)");
  EXPECT_EQ(p.step(2), 2u);  // call_a, then a.t: the instance waits in w
  ASSERT_EQ(invocations(p).size(), 1u);
  auto* inv = const_cast<Invocation*>(invocations(p)[0]);
  // C++ moves the instance under call_b, which invokes b (a string result): its int result cannot go there.
  child<Transition>(p.root(), "call_b")->add_child(*inv);
  try {
    p.step(1);
    FAIL() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("net a finished, but transition call_b invokes net b"));
  }
  EXPECT_FALSE(inv->finished());
  // Under no transition at all: no invoker.
  p.root().add_child(*inv);
  try {
    p.step(1);
    FAIL() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("net a finished, but no transition invoked it"));
  }
  EXPECT_EQ(out.str(), "");
}

TEST_F(Nets, InvocationsAreRecordedAndReplayedOnAReplica) {
  Program& p = load(kDouble);
  vsd::SimState& replica = env.create_state("replica");
  replica.copy_from(env.main_state());
  env.main_state().start_recording();
  EXPECT_EQ(p.step(1), 1u);  // mid-invocation
  vsd::Transaction t1 = env.main_state().stop_recording();
  replica.apply(t1);
  std::string diff;
  EXPECT_TRUE(replica.equals(env.main_state(), &diff)) << diff;
  env.main_state().start_recording();
  EXPECT_EQ(p.run_until_quiet(), 1u);  // finished and completed
  vsd::Transaction t2 = env.main_state().stop_recording();
  replica.apply(t2);
  EXPECT_TRUE(replica.equals(env.main_state(), &diff)) << diff;
  EXPECT_EQ(replica.find(p.object("j")->id())->as<vsd::Node>()->get<std::int64_t>("n"), 42);
}

}  // namespace

#if VSD_SOML_TEST_IO
#include "vsd/io/snapshot.hpp"

namespace {

TEST_F(Nets, ARunningInvocationIsSavedAndLoadedByVsdIo) {
  Program& p = load(kDouble);
  EXPECT_EQ(p.step(1), 1u);
  for (auto format : {vsd::io::Format::Text, vsd::io::Format::Binary}) {
    const auto bytes = vsd::io::save_bytes(env.main_state(), format);
    vsd::SimState& copy = env.create_state(format == vsd::io::Format::Text ? "text copy" : "binary copy");
    vsd::io::load_bytes(copy, bytes);
    std::string diff;
    EXPECT_TRUE(copy.equals(env.main_state(), &diff)) << diff;
    const Invocation* inv = invocations(p).at(0);
    const auto* loaded = copy.find<Invocation>(inv->id());
    ASSERT_NE(loaded, nullptr);
    EXPECT_EQ(loaded->get<std::int64_t>("x"), 21);
    ASSERT_NE(loaded->mark().get(), nullptr);
    EXPECT_EQ(loaded->mark()->id(), p.object("j")->id());
  }
}

}  // namespace
#endif
