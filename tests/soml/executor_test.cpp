// SOML++ net execution: the firing rule (weights, inhibitors, conditions, marks, arrow conditions),
// seeded choice, dependency-driven re-testing, markings as database state (recording and replicas),
// and the Module's scheduler task.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "script_fixture.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace exec_test {

// A plant whose state a C++ method interprets: the script cannot see what full() reads.
class MethodTank : public vsd::Node {
  VSD_INSTANCE(MethodTank, vsd::Node)
  VSD_PROPERTY(double, level, 0.0)
  VSD_PROPERTY(double, limit, 0.8)
 public:
  bool full() { return level() > limit(); }
  VSD_METHOD(full)
};

}  // namespace exec_test

namespace {

using ::testing::HasSubstr;
using vsd::soml::Program;

struct Exec : soml_test::ScriptTest {
  Exec() { script_file = "net.soml"; }
};

// Every invocation makes a net instance and deletes it when it finishes. The executor drops the entries
// of deleted nets once they are the majority (between steps), without changing the run: stepping one
// firing at a time (compacting often) and all at once (never) give the same trace.
constexpr const char* invoking = R"(
net int work(int n) {
  place s;
  start s;
  transition t { do { finish n * 2; } }
  arrow s -> t;
}
class Worker : Node {
  int done = 0;
  int sum = 0;
  place ticks = 150;
  transition go { invoke work(done); do { done += 1; sum += result; } }
  arrow ticks -> go;
}
object a : Worker;
object b : Worker;
object c : Worker;
)";

std::string trace_of(Program& p, std::uint64_t chunk, std::size_t* most_entries) {
  std::string trace;
  p.on_firing([&](const vsd::soml::Firing& f) {
    trace += std::to_string(f.step) + " " + f.transition->name() + " " + std::to_string(f.invocation) + "\n";
  });
  while (p.step(chunk) != 0) *most_entries = std::max(*most_entries, p.executor_entries());
  return trace;
}

TEST_F(Exec, FinishedInvocationsDoNotGrowTheExecutor) {
  Program& p = load(invoking, 7);
  std::size_t most = 0;
  const std::string one_by_one = trace_of(p, 1, &most);
  for (const char* w : {"a", "b", "c"}) EXPECT_EQ(p.object(w)->get<std::int64_t>("done"), 150) << w;
  EXPECT_EQ(p.firings(), 3u * 150u * 2u);  // per tick: go invokes; work.t finishes (and go completes)
  EXPECT_LT(most, 3u * 150u) << "one dead entry per invocation would reach 450";
  EXPECT_LE(p.executor_entries(), 3u + 64u);

  vsd::Registry reg2;
  vsd::Environment env2{0, reg2};
  auto& soml2 = env2.use<vsd::soml::Module>();
  vsd::soml::RunOptions o;
  o.out = &out;
  o.seed = 7;
  Program& q = soml2.load(env2.main_state(), "net.soml", invoking, o);
  std::size_t most_q = 0;
  EXPECT_EQ(trace_of(q, 1'000'000, &most_q), one_by_one);
  EXPECT_GE(most_q, 3u * 150u) << "one step() compacts only before it starts";
  for (const char* w : {"a", "b", "c"})
    EXPECT_EQ(q.object(w)->get<std::int64_t>("sum"), p.object(w)->get<std::int64_t>("sum")) << w;
}

TEST_F(Exec, WeightsConsumeAndProduce) {
  Program& p = load(R"(
place a = 5;
place b;
transition t;
arrow a -> t * 2;
arrow t -> b * 3;
)");
  EXPECT_EQ(p.run_until_quiet(), 2u);
  EXPECT_EQ(p.place("a")->tokens(), 1);
  EXPECT_EQ(p.place("b")->tokens(), 6);
  EXPECT_EQ(p.root().find_child("t")->get<std::int64_t>("firings"), 2);
}

TEST_F(Exec, InhibitorArrowBlocksWhileItsPlaceHoldsTokens) {
  Program& p = load(R"(
place a = 3;
place stop;
place done;
transition t;
arrow a -> t;
arrow stop -o t;
arrow t -> done;
)");
  p.place("stop")->set_tokens(1);  // C++ changes the marking through the setter
  EXPECT_EQ(p.run_until_quiet(), 0u);
  p.place("stop")->set_tokens(0);
  EXPECT_EQ(p.run_until_quiet(), 3u);
  EXPECT_EQ(p.place("done")->tokens(), 3);
}

TEST_F(Exec, ObjectTokensMarksConditionsAndArrowConditions) {
  Program& p = load(R"(
class Job : Node {
  double speed = 1.0;
  bool ready = true;
  int visits = 0;
  Job(double s, bool r) { speed = s; ready = r; }
}
object cell {
  int served = 0;
  place<Job> waiting;
  place<Job> fast;
  place<Job> slow;
  transition go {
    when mark.ready;
    do { served += 1; mark.visits += 1; }
  }
  arrow waiting -> go;
  arrow go -> fast when mark.speed > 1.5;
  arrow go -> slow;
  void add(double s, bool r) { waiting.put(new Job(s, r)); }
}
)");
  vsd::Node* cell = p.object("cell");
  cell->call("add", {vsd::Value(2.0), vsd::Value(true)});
  cell->call("add", {vsd::Value(1.0), vsd::Value(true)});
  cell->call("add", {vsd::Value(3.0), vsd::Value(false)});
  std::vector<std::string> trace;
  p.on_firing([&](const vsd::soml::Firing& f) {
    trace.push_back(f.transition->name() + ":" + (f.from ? f.from->name() : "") + "->" +
                    (f.to ? f.to->name() : "-"));
  });
  EXPECT_EQ(p.run_until_quiet(), 2u);
  EXPECT_EQ(cell->get<std::int64_t>("served"), 2);
  EXPECT_EQ(p.place("fast", cell)->objects().size(), 1u);
  EXPECT_EQ(p.place("slow", cell)->objects().size(), 1u);
  ASSERT_EQ(p.place("waiting", cell)->objects().size(), 1u) << "the job that is not ready waits";
  vsd::Node* idle = p.place("waiting", cell)->objects()[0];
  EXPECT_DOUBLE_EQ(idle->get<double>("speed"), 3.0);
  EXPECT_EQ(p.place("fast", cell)->objects()[0]->get<std::int64_t>("visits"), 1);
  EXPECT_THAT(trace, ::testing::ElementsAre("go:waiting->fast", "go:waiting->slow"));
  // The waiting job's property changes: its transition is re-tested and fires.
  idle->set("ready", vsd::Value(true));
  EXPECT_EQ(p.run_until_quiet(), 1u);
  EXPECT_EQ(p.place("fast", cell)->objects().size(), 2u);
}

TEST_F(Exec, ConditionsOnDatabasePropertiesAreRetestedOnlyWhenTheyChange) {
  Program& p = load(R"(
shared<Node> plant;
int alarms = 0;
place armed = 1;
place fired;
transition alarm {
  when plant != null && plant.name == "hot";
  do { alarms += 1; plant.name = "cooling"; }
}
arrow armed -> alarm;
arrow alarm -> armed;
)");
  vsd::Node& plant = env.main_state().create<vsd::Node>();
  env.main_state().database().add_child(plant);
  vsd::Node& other = env.main_state().create<vsd::Node>();
  p.root().set("plant", vsd::Value(vsd::SharedRef<vsd::Node>(&plant)));
  EXPECT_EQ(p.run_until_quiet(), 0u);
  const auto tests = p.condition_tests();
  for (int i = 0; i < 50; ++i) other.set_name("x" + std::to_string(i));  // not read by the condition
  EXPECT_EQ(p.run_until_quiet(), 0u);
  EXPECT_EQ(p.condition_tests(), tests) << "no polling: unrelated changes test nothing";
  plant.set_name("warm");
  EXPECT_EQ(p.run_until_quiet(), 0u);
  EXPECT_EQ(p.condition_tests(), tests + 1);
  plant.set_name("hot");  // the event sigma
  EXPECT_EQ(p.run_until_quiet(), 1u);
  EXPECT_EQ(plant.name(), "cooling");  // the command gamma
  EXPECT_EQ(p.root().get<std::int64_t>("alarms"), 1);
}

// A condition that calls a C++ method is re-tested when any property of that instance changes (the
// method's reads are invisible to the VM), and not when other instances change.
TEST(ExecMethods, AConditionCallingACppMethodIsRetestedWhenItsInstanceChanges) {
  vsd::Registry reg;
  reg.add<exec_test::MethodTank>();
  vsd::Environment env{0, reg};
  auto& soml = env.use<vsd::soml::Module>();
  auto& tank = env.main_state().create<exec_test::MethodTank>();
  env.main_state().database().add_child(tank);
  auto& other = env.main_state().create<exec_test::MethodTank>();
  env.main_state().database().add_child(other);
  std::ostringstream out;
  vsd::soml::RunOptions o;
  o.out = &out;
  Program& p = soml.load(env.main_state(), "net.soml", R"(
shared<MethodTank> tank;
place watching = 1;
place alarm;
transition overflow { when tank != null && tank.full(); }
arrow watching -> overflow;
arrow overflow -> alarm;
)",
                         o);
  p.root().set("tank", vsd::Value(vsd::SharedRef<vsd::Node>(&tank)));
  EXPECT_EQ(p.run_until_quiet(), 0u);
  const auto tests = p.condition_tests();
  other.set_level(5.0);  // another instance: nothing to re-test
  EXPECT_EQ(p.run_until_quiet(), 0u);
  EXPECT_EQ(p.condition_tests(), tests);
  tank.set_level(0.5);  // read by full(): re-tested, still false
  EXPECT_EQ(p.run_until_quiet(), 0u);
  EXPECT_EQ(p.condition_tests(), tests + 1);
  tank.set_limit(0.4);  // also read by full(), never named in the script: now true
  EXPECT_EQ(p.run_until_quiet(), 1u);
  EXPECT_EQ(p.place("alarm")->count(), 1);
}

TEST_F(Exec, OnlyWhatTheLastTestReadIsWatched) {
  Program& p = load(R"(
class Tok : Node { int n = 0; }
object line {
  place<Tok> in;
  place<Tok> out;
  transition pass { when mark.n > 0; }
  arrow in -> pass;
  arrow pass -> out;
  void add(int k) { for (int i = 0; i < k; i++) { shared<Tok> t = new Tok(); t.n = 1; in.put(t); } }
}
)");
  vsd::Node* line = p.object("line");
  for (int round = 0; round < 20; ++round) {
    line->call("add", {vsd::Value(std::int64_t{5})});
    EXPECT_EQ(p.run_until_quiet(), 5u);
  }
  EXPECT_EQ(p.place("out", line)->objects().size(), 100u);
  EXPECT_LE(p.watched_properties(), 1u) << "tokens that left are not watched any more";
}

TEST_F(Exec, CommunicationArrowsDepositAndTakeTokensInOtherObjectsNets) {
  Program& p = load(R"(
class Station : Node {
  int taken = 0;
  place inbox;
  place done;
  transition take { do { taken += 1; } }
  arrow inbox -> take;
  arrow take -> done;
}
object dispatcher {
  shared<Station> target;
  place jobs = 3;
  place collected;
  transition send;
  transition collect;
  arrow jobs -> send;
  arrow send ~> target.inbox;
  arrow target.done ~> collect;
  arrow collect -> collected;
}
object s1 : Station;
object s2 : Station;
)");
  vsd::Node* dispatcher = p.object("dispatcher");
  EXPECT_EQ(p.run_until_quiet(), 0u) << "a null reference on the path disables";
  dispatcher->set("target", vsd::Value(vsd::SharedRef<vsd::Node>(p.object("s1"))));
  EXPECT_EQ(p.run_until_quiet(), 9u);  // 3 x (send, take, collect)
  EXPECT_EQ(p.object("s1")->get<std::int64_t>("taken"), 3);
  EXPECT_EQ(p.place("collected", dispatcher)->tokens(), 3);
  EXPECT_EQ(p.place("done", p.object("s1"))->tokens(), 0);
  // Re-routing through the reference property: more jobs go to s2.
  dispatcher->set("target", vsd::Value(vsd::SharedRef<vsd::Node>(p.object("s2"))));
  p.place("jobs", dispatcher)->set_tokens(2);
  EXPECT_EQ(p.run_until_quiet(), 6u);
  EXPECT_EQ(p.object("s2")->get<std::int64_t>("taken"), 2);
  EXPECT_EQ(p.place("collected", dispatcher)->tokens(), 5);
}

TEST_F(Exec, CommunicationArrowsCarryObjectTokensAndTestTheirConditions) {
  Program& p = load(R"(
class Job : Node {
  int client = 0;
  int size = 0;
  Job(int c, int s) { client = c; size = s; }
}
object server {
  bool open = false;
  place<Job> outbox;
  place tickets = 1;
  void add(int c, int s) { outbox.put(new Job(c, s)); }
}
class Client : Node {
  int id = 0;
  shared<server> peer;
  place<Job> mine;
  place<Job> big;
  place got;
  transition take;
  arrow peer.outbox ~> take when mark.client == id;   // the remote token is mark, id this client's
  arrow peer.tickets ~> take when peer.open;          // a black remote input with a condition
  arrow take ~> peer.tickets when mark.size > 5;      // a conditional deposit: only for big jobs
  arrow take -> big when mark.size > 10;              // the mark: the first object place that takes it
  arrow take -> mine;
  arrow take -> got;
}
object c1 : Client;
object c2 : Client;
)");
  vsd::Node* server = p.object("server");
  vsd::Node* c1 = p.object("c1");
  vsd::Node* c2 = p.object("c2");
  c1->set("id", vsd::Value(std::int64_t{1}));
  c2->set("id", vsd::Value(std::int64_t{2}));
  server->call("add", {vsd::Value(std::int64_t{2}), vsd::Value(std::int64_t{20})});
  server->call("add", {vsd::Value(std::int64_t{1}), vsd::Value(std::int64_t{7})});
  server->call("add", {vsd::Value(std::int64_t{1}), vsd::Value(std::int64_t{3})});
  EXPECT_EQ(p.run_until_quiet(), 0u) << "a null reference on the path disables";
  c1->set("peer", vsd::Value(vsd::SharedRef<vsd::Node>(server)));
  c2->set("peer", vsd::Value(vsd::SharedRef<vsd::Node>(server)));
  EXPECT_EQ(p.run_until_quiet(), 0u) << "the server is closed: the tickets' arrow condition fails";
  std::vector<std::string> trace;
  p.on_firing([&](const vsd::soml::Firing& f) {
    trace.push_back(f.transition->parent()->name() + "." + f.transition->name() + " " +
                    vsd::Value(f.mark != 0
                                   ? env.main_state().find(f.mark)->as<vsd::Node>()->get<std::int64_t>("size")
                                   : std::int64_t{0})
                        .to_text() +
                    ":" + (f.from ? f.from->parent()->name() + "." + f.from->name() : "") + "->" +
                    (f.to ? f.to->parent()->name() + "." + f.to->name() : "-"));
  });
  // Opening the server re-tests both clients (their conditions read `open`); one ticket: one firing,
  // and a job bigger than 5 gives it back.
  server->set("open", vsd::Value(true));
  EXPECT_EQ(p.run_until_quiet(), 3u);
  EXPECT_EQ(p.place("outbox", server)->objects().size(), 0u);
  ASSERT_EQ(p.place("big", c2)->objects().size(), 1u);  // the 20 of client 2
  EXPECT_EQ(p.place("big", c2)->objects()[0]->get<std::int64_t>("size"), 20);
  EXPECT_EQ(p.place("mine", c1)->objects().size(), 2u);  // client 1's 7 and 3, each only by c1
  EXPECT_EQ(p.place("got", c1)->tokens(), 2);
  EXPECT_EQ(p.place("got", c2)->tokens(), 1);
  EXPECT_EQ(p.place("tickets", server)->tokens(), 0) << "the job of size 3 kept its ticket";
  EXPECT_THAT(trace, ::testing::UnorderedElementsAre("c2.take 20:server.outbox->c2.big",
                                                     "c1.take 7:server.outbox->c1.mine",
                                                     "c1.take 3:server.outbox->c1.mine"));
  // Every change went through the setters: a replica that applies the recording ends equal.
  vsd::SimState& replica = env.create_state("replica");
  replica.copy_from(env.main_state());
  env.main_state().start_recording();
  server->call("add", {vsd::Value(std::int64_t{2}), vsd::Value(std::int64_t{9})});
  p.place("tickets", server)->set_tokens(1);
  EXPECT_EQ(p.run_until_quiet(), 1u);
  EXPECT_EQ(p.place("mine", c2)->objects().size(), 1u);
  EXPECT_EQ(p.place("tickets", server)->tokens(), 1);
  replica.apply(env.main_state().stop_recording());
  std::string diff;
  EXPECT_TRUE(replica.equals(env.main_state(), &diff)) << diff;
}

TEST_F(Exec, AFailedFiringPutsARemoteObjectTokenBackWhereItWas) {
  Program& p = load(R"(
class Job : Node { int size = 0; Job(int s) { size = s; } }
int zero = 0;
object server {
  place<Job> outbox;
  void add(int s) { outbox.put(new Job(s)); }
}
object client {
  place<Job> done;
  transition take { do { mark.size = mark.size / zero; } }
  arrow server.outbox ~> take when mark.size > 1;
  arrow take -> done;
}
)");
  vsd::Node* server = p.object("server");
  server->call("add", {vsd::Value(std::int64_t{1})});
  server->call("add", {vsd::Value(std::int64_t{4})});
  server->call("add", {vsd::Value(std::int64_t{5})});
  try {
    p.step(1);
    FAIL() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("division by zero"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("at client.take (action) (net.soml:10:48)"));
  }
  // The first token that satisfies the arrow's condition was taken and is back in its position.
  const auto& outbox = p.place("outbox", server)->objects();
  ASSERT_EQ(outbox.size(), 3u);
  EXPECT_EQ(outbox[1]->get<std::int64_t>("size"), 4);
  EXPECT_EQ(outbox[2]->get<std::int64_t>("size"), 5);
  EXPECT_EQ(p.place("done", p.object("client"))->objects().size(), 0u);
}

TEST_F(Exec, DeletingANetsNodesStopsThatNetOnly) {
  Program& p = load(R"(
class Cell : Node {
  place a = 3;
  place b;
  transition t;
  arrow a -> t;
  arrow t -> b;
}
object c1 : Cell;
object c2 : Cell;
)");
  vsd::Node* c1 = p.object("c1");
  vsd::Node* c2 = p.object("c2");
  vsd::soml::Place* b2 = p.place("b", c2);
  env.main_state().destroy(*c1);  // C++ deletes a net object with its places and transitions
  EXPECT_EQ(p.run_until_quiet(), 3u);
  EXPECT_EQ(b2->tokens(), 3);
  b2->set_tokens(0);
  env.main_state().destroy(*p.place("a", c2));  // one place of the other net
  EXPECT_EQ(p.run_until_quiet(), 0u);
  EXPECT_EQ(p.places().size(), 0u);
}

TEST_F(Exec, SeededChoiceIsReproducible) {
  const std::string text = R"(
place a = 20;
place x;
place y;
transition tx;
transition ty;
arrow a -> tx;
arrow a -> ty;
arrow tx -> x;
arrow ty -> y;
)";
  auto run = [&](std::uint64_t seed) {
    vsd::Registry r;
    vsd::Environment e(0, r);
    auto& m = e.use<vsd::soml::Module>();
    vsd::soml::RunOptions o;
    o.seed = seed;
    Program& p = m.load(e.main_state(), "net.soml", text, o);
    std::string trace;
    p.on_firing([&](const vsd::soml::Firing& f) { trace += f.transition->name(); });
    p.run_until_quiet();
    EXPECT_EQ(p.place("x")->tokens() + p.place("y")->tokens(), 20);
    return trace;
  };
  EXPECT_EQ(run(7), run(7));
  EXPECT_NE(run(7), run(8));
}

TEST_F(Exec, FiringsRecordedAndReplayedOnAReplicaGiveTheSameMarking) {
  Program& p = load(R"(
class Phil : Node { int meals = 0; start table.thinking; }
object table {
  place<Phil> thinking;
  place<Phil> eating;
  place forks = 3;
  transition take { do { mark.meals += 1; } }
  transition put;
  arrow thinking -> take;
  arrow forks -> take * 2;
  arrow take -> eating;
  arrow eating -> put;
  arrow put -> thinking;
  arrow put -> forks * 2;
}
object p1 : Phil;
object p2 : Phil;
object p3 : Phil;
)");
  vsd::SimState& replica = env.create_state("replica");
  replica.copy_from(env.main_state());
  env.main_state().start_recording();
  EXPECT_EQ(p.step(25), 25u);
  vsd::Transaction t = env.main_state().stop_recording();
  replica.apply(t);
  std::string diff;
  EXPECT_TRUE(replica.equals(env.main_state(), &diff)) << diff;
  std::int64_t meals = 0;
  for (const char* n : {"p1", "p2", "p3"}) meals += p.object(n)->get<std::int64_t>("meals");
  EXPECT_GE(meals, 12);
}

TEST_F(Exec, AnActionErrorGivesTheTokensBackAndCarriesTheCallStack) {
  Program& p = load(R"(
int zero = 0;
place a = 1;
place b;
transition t { do { int x = 1 / zero; print(x); } }
arrow a -> t;
arrow t -> b;
)");
  try {
    p.step(1);
    FAIL() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("division by zero"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("at t (action) (net.soml:5:31)"));
  }
  EXPECT_EQ(p.place("a")->tokens(), 1);
  EXPECT_EQ(p.place("b")->tokens(), 0);
}

TEST_F(Exec, AFailingConditionCountsAsNotEnabled) {
  Program& p = load(R"(
shared<Node> missing;
place a = 1;
transition t { when missing.name == "x"; }
arrow a -> t;
)");
  EXPECT_EQ(p.run_until_quiet(), 0u);
  ASSERT_EQ(p.condition_errors().size(), 1u);
  EXPECT_THAT(p.condition_errors()[0], HasSubstr("null reference"));
}

TEST_F(Exec, TheModuleRunsNetsInTheSchedulersSteps) {
  Program& p = load(R"(
place a = 4;
place b;
transition t;
arrow a -> t;
arrow t -> b;
)");
  env.step();
  EXPECT_EQ(p.place("b")->tokens(), 4);
  p.place("a")->set_tokens(2);  // C++ puts tokens: the task is triggered again
  env.step();
  EXPECT_EQ(p.place("b")->tokens(), 6);
}

}  // namespace

#if VSD_SOML_TEST_IO
#include "vsd/io/snapshot.hpp"

namespace {

TEST_F(Exec, MarkingsMidRunAreSavedAndLoadedByVsdIo) {
  Program& p = load(R"(
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
object j3 : Job;
)");
  EXPECT_EQ(p.run_until_quiet(), 2u);
  for (auto format : {vsd::io::Format::Text, vsd::io::Format::Binary}) {
    const auto bytes = vsd::io::save_bytes(env.main_state(), format);
    vsd::SimState& copy = env.create_state(format == vsd::io::Format::Text ? "text copy" : "binary copy");
    vsd::io::load_bytes(copy, bytes);
    std::string diff;
    EXPECT_TRUE(copy.equals(env.main_state(), &diff)) << diff;
    // The loaded places hold the same marking.
    const auto* q = copy.find<vsd::soml::Place>(p.place("queue", p.object("line"))->id());
    ASSERT_NE(q, nullptr);
    ASSERT_EQ(q->objects().size(), 1u);
    EXPECT_EQ(q->objects()[0]->id(), p.object("j3")->id());
    EXPECT_EQ(copy.find<vsd::soml::Place>(p.place("credits", p.object("line"))->id())->tokens(), 0);
  }
}

}  // namespace
#endif
