// State-space exploration: the eight MCC nets against the published figures, exactly, and hand-made nets
// whose state spaces are known (closed forms, unbounded, inhibitor arcs, dead markings).
#include "vsd/analysis/explorer.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <optional>
#include <set>
#include <sstream>

#include "nets.hpp"
#include "vsd/core/error.hpp"
#include "vsd/analysis/pnml.hpp"
#include "../sanitized.hpp"

namespace an = vsd::analysis;
using an::ExploreOptions;
using an::ExploreResult;
using an::PtNet;

namespace {

struct Expected {
  std::string model;
  std::size_t places, transitions, arcs;
  std::uint64_t states, edges;
  bool deadlock;
};

std::vector<Expected> expected_rows() {
  std::ifstream in(std::string(VSD_ANALYSIS_TEST_DATA_DIR) + "/expected.tsv");
  std::vector<Expected> rows;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::istringstream ls(line);
    Expected e;
    std::string dead;
    ls >> e.model >> e.places >> e.transitions >> e.arcs >> e.states >> e.edges >> dead;
    e.deadlock = dead == "TRUE";
    rows.push_back(e);
  }
  return rows;
}

// Small levels are split among the threads too, so that the multi-threaded path runs on these small nets.
ExploreOptions quiet(unsigned threads = 1) {
  ExploreOptions o;
  o.threads = threads;
  o.progress = ExploreOptions::Progress::never;
  o.split_small_levels = true;
  return o;
}

// Every (marking, firing) by a naive search over std::vector markings: the reference the explorer's
// packed, incremental, multi-threaded search must agree with.
struct Naive {
  std::uint64_t states = 0, edges = 0;
  bool deadlock = false;
};
Naive naive(const PtNet& net) {
  std::set<std::vector<std::uint32_t>> seen{net.initial_marking()};
  std::vector<std::vector<std::uint32_t>> todo{net.initial_marking()};
  Naive r;
  while (!todo.empty()) {
    auto m = todo.back();
    todo.pop_back();
    bool any = false;
    for (std::uint32_t t = 0; t < net.transition_count(); ++t) {
      if (!net.enabled(t, m)) continue;
      any = true;
      ++r.edges;
      auto m2 = m;
      net.fire(t, m2);
      if (seen.insert(m2).second) todo.push_back(m2);
    }
    r.deadlock = r.deadlock || !any;
  }
  r.states = seen.size();
  return r;
}

class MccNets : public ::testing::TestWithParam<unsigned> {};

TEST(MccNetsData, AllEightRowsArePresent) { EXPECT_EQ(expected_rows().size(), 8u); }

TEST_P(MccNets, StatesEdgesDeadlockMatchThePublishedFiguresExactly) {
  const unsigned threads = GetParam();
  for (const Expected& e : expected_rows()) {
    SCOPED_TRACE(e.model + ", threads " + std::to_string(threads));
    const auto imported = an::read_pnml_file(std::string(VSD_ANALYSIS_TEST_DATA_DIR) + "/" + e.model + ".pnml");
    const ExploreResult r = an::explore(imported.net, quiet(threads));
    ASSERT_TRUE(r.complete()) << r.message;
    EXPECT_EQ(r.states, e.states);
    EXPECT_EQ(r.edges, e.edges);
    EXPECT_EQ(r.deadlock, e.deadlock);
    EXPECT_EQ(r.threads, threads);
    if (r.deadlock) {
      // The sequence fires from the initial marking and ends in the reported dead marking.
      auto m = imported.net.initial_marking();
      for (std::uint32_t t : r.dead_trace) imported.net.fire(t, m);
      EXPECT_EQ(m, r.dead_marking);
      for (std::uint32_t t = 0; t < imported.net.transition_count(); ++t)
        EXPECT_FALSE(imported.net.enabled(t, m));
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Threads, MccNets, ::testing::Values(1u, 2u, 3u));

// What must not depend on the thread count (docs/analysis.md, "Threads"): the counts, the levels, the
// token bounds, whether a dead marking is reachable and the length of the shortest firing sequence to
// one. Which dead marking and which sequence may differ (shared levels number new states in the order the
// workers add them): the sequence is checked to fire from the initial marking into a dead marking.
void expect_same_results(const PtNet& net, const ExploreResult& one, const ExploreResult& other) {
  ASSERT_TRUE(other.complete()) << other.message;
  EXPECT_EQ(one.states, other.states);
  EXPECT_EQ(one.edges, other.edges);
  EXPECT_EQ(one.deadlock, other.deadlock);
  EXPECT_EQ(one.dead_trace.size(), other.dead_trace.size());
  EXPECT_EQ(one.max_tokens_place, other.max_tokens_place);
  EXPECT_EQ(one.max_tokens_marking, other.max_tokens_marking);
  EXPECT_EQ(one.levels, other.levels);
  if (!other.deadlock) return;
  auto m = net.initial_marking();
  for (std::uint32_t t : other.dead_trace) {
    ASSERT_TRUE(net.enabled(t, m));
    net.fire(t, m);
  }
  EXPECT_EQ(m, other.dead_marking);
  for (std::uint32_t t = 0; t < net.transition_count(); ++t) EXPECT_FALSE(net.enabled(t, m));
}

TEST(Explore, ResultsAreTheSameForAnyThreadCount) {
  for (const Expected& e : expected_rows()) {
    SCOPED_TRACE(e.model);
    const auto net = an::read_pnml_file(std::string(VSD_ANALYSIS_TEST_DATA_DIR) + "/" + e.model + ".pnml").net;
    const ExploreResult one = an::explore(net, quiet(1));
    for (unsigned threads : {2u, 3u, 4u}) {
      SCOPED_TRACE("threads " + std::to_string(threads));
      expect_same_results(net, one, an::explore(net, quiet(threads)));
    }
  }
}

// n independent chains of `length` steps each, one token at the head of each: (length+1)^n markings, and
// one dead marking (every token at its tail) reached by any interleaving of the n * length firings: many
// shortest sequences, all of the same length.
PtNet chains(unsigned n, unsigned length) {
  PtNet net("chains" + std::to_string(n) + "_" + std::to_string(length));
  for (unsigned c = 0; c < n; ++c) {
    std::uint32_t prev = net.add_place("c" + std::to_string(c) + "_0", {}, 1);
    for (unsigned i = 1; i <= length; ++i) {
      const auto next = net.add_place("c" + std::to_string(c) + "_" + std::to_string(i));
      const auto t = net.add_transition("t" + std::to_string(c) + "_" + std::to_string(i));
      net.add_input(t, prev);
      net.add_output(t, next);
      prev = next;
    }
  }
  return net;
}

// State spaces of more than 10^5 states, whose levels pass the size from which the threads share them by
// default (a hash set of more than 1 MiB), on 1 to 4 threads, split or not.
TEST(Explore, LargeStateSpacesAreTheSameOnEveryThreadCount) {
  const PtNet chain_net = chains(6, 6);  // 7^6 = 117 649 states, 6 * 6 * 7^5 firings
  const PtNet ring_net = an::test::ring(13, 8);  // C(20, 8) = 125 970 states
  for (const PtNet* net : {&chain_net, &ring_net}) {
    SCOPED_TRACE(net->id());
    ExploreOptions o = quiet(1);
    o.split_small_levels = false;
    const ExploreResult one = an::explore(*net, o);
    ASSERT_TRUE(one.complete());
    if (net == &chain_net) {
      EXPECT_EQ(one.states, 117649u);
      EXPECT_EQ(one.edges, 6u * 6u * 16807u);
      EXPECT_TRUE(one.deadlock);
      EXPECT_EQ(one.dead_trace.size(), 36u);
      EXPECT_EQ(one.levels, 37u);
    } else {
      EXPECT_EQ(one.states, an::test::binomial(20, 8));
      EXPECT_EQ(one.edges, 13 * an::test::binomial(19, 7));
    }
    for (const auto& [threads, split] : {std::pair{2u, false}, {2u, true}, {3u, false}, {4u, true}}) {
      SCOPED_TRACE("threads " + std::to_string(threads) + (split ? ", split" : ""));
      o.threads = threads;
      o.split_small_levels = split;
      expect_same_results(*net, one, an::explore(*net, o));
    }
  }
}

// Levels of 301 states for a while, then one of ~12 000: more new states than the hash set was sized for
// at the start of the level (from the growth of the level before), so that shared levels leave successors
// to be added after the level (the stash) and the shards grow then. Token s fans out to x1..x300 at once;
// token u walks u0 -> u1 -> u2 -> g and then fans out to y1..y40: 301 * 44 markings.
TEST(Explore, ALevelFarLargerThanTheOneBeforeIsTheSameOnEveryThreadCount) {
  PtNet net("burst");
  const auto s = net.add_place("s", {}, 1);
  for (unsigned i = 1; i <= 300; ++i) {
    const auto t = net.add_transition("a" + std::to_string(i));
    net.add_input(t, s);
    net.add_output(t, net.add_place("x" + std::to_string(i)));
  }
  std::uint32_t u = net.add_place("u0", {}, 1);
  for (const char* next : {"u1", "u2", "g"}) {
    const auto t = net.add_transition(std::string("to_") + next);
    const auto p = net.add_place(next);
    net.add_input(t, u);
    net.add_output(t, p);
    u = p;
  }
  for (unsigned j = 1; j <= 40; ++j) {
    const auto t = net.add_transition("c" + std::to_string(j));
    net.add_input(t, u);
    net.add_output(t, net.add_place("y" + std::to_string(j)));
  }
  const ExploreResult one = an::explore(net, quiet(1));
  ASSERT_TRUE(one.complete());
  EXPECT_EQ(one.states, 301u * 44u);
  EXPECT_EQ(one.edges, 300u * 44u + 301u * 43u);
  EXPECT_TRUE(one.deadlock);
  EXPECT_EQ(one.dead_trace.size(), 5u);
  for (unsigned threads : {2u, 3u}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    expect_same_results(net, one, an::explore(net, quiet(threads)));
  }
}

TEST(Explore, SmallLevelsOnOneThreadByDefaultGiveTheSameResults) {
  for (const Expected& e : expected_rows()) {
    SCOPED_TRACE(e.model);
    const auto net = an::read_pnml_file(std::string(VSD_ANALYSIS_TEST_DATA_DIR) + "/" + e.model + ".pnml").net;
    ExploreOptions o = quiet(2);
    o.split_small_levels = false;
    const ExploreResult split = an::explore(net, quiet(2));
    const ExploreResult fused = an::explore(net, o);
    EXPECT_EQ(fused.states, e.states);
    EXPECT_EQ(fused.edges, e.edges);
    EXPECT_EQ(fused.threads, 2u);
    expect_same_results(net, split, fused);
  }
}

TEST(Explore, SmallMccNetsAgreeWithANaiveSearch) {
  for (const char* model :
       {"ResAllocation-PT-R002C002", "Eratosthenes-PT-010", "Philosophers-PT-000005", "FMS-PT-00002"}) {
    SCOPED_TRACE(model);
    const auto net = an::read_pnml_file(std::string(VSD_ANALYSIS_TEST_DATA_DIR) + "/" + model + ".pnml").net;
    const Naive n = naive(net);
    const ExploreResult r = an::explore(net, quiet());
    EXPECT_EQ(r.states, n.states);
    EXPECT_EQ(r.edges, n.edges);
    EXPECT_EQ(r.deadlock, n.deadlock);
  }
}

TEST(Explore, MccTokenBounds) {
  // FMS-PT-00002 starts with 2 tokens on several places and can gather 3 on one; the others are safe.
  const auto fms = an::read_pnml_file(std::string(VSD_ANALYSIS_TEST_DATA_DIR) + "/FMS-PT-00002.pnml").net;
  const ExploreResult r = an::explore(fms, quiet());
  EXPECT_EQ(r.max_tokens_place, 3u);
  EXPECT_GE(r.max_tokens_marking, 12u);
  const auto dekker = an::read_pnml_file(std::string(VSD_ANALYSIS_TEST_DATA_DIR) + "/Dekker-PT-010.pnml").net;
  const ExploreResult d = an::explore(dekker, quiet());
  EXPECT_EQ(d.max_tokens_place, 1u);
  EXPECT_EQ(d.bits_per_place, 1u);  // a safe net is stored with one bit per place
}

TEST(Explore, RingFamilyMatchesTheClosedForm) {
  for (unsigned n : {1u, 2u, 5u, 9u}) {
    for (unsigned k : {1u, 3u, 6u}) {
      SCOPED_TRACE("n=" + std::to_string(n) + " k=" + std::to_string(k));
      const PtNet net = an::test::ring(n, k);
      const ExploreResult r = an::explore(net, quiet(2));
      ASSERT_TRUE(r.complete());
      EXPECT_EQ(r.states, an::test::binomial(n + k - 1, k));
      EXPECT_EQ(r.edges, n * an::test::binomial(n + k - 2, k - 1));
      EXPECT_FALSE(r.deadlock);
      EXPECT_EQ(r.max_tokens_place, k);
      EXPECT_EQ(r.max_tokens_marking, k);
    }
  }
}

TEST(Explore, EncodingWidensWhenAPlaceOutgrowsIt) {
  // q -> q + r while r < 20 (inhibitor): no P-semiflow covers r, so fields start at 1 bit (the initial
  // marking) and widen 1 -> 2 -> 4 -> 8 as r grows.
  PtNet grow("grow");
  const auto q = grow.add_place("q", {}, 1);
  const auto r = grow.add_place("r");
  const auto t = grow.add_transition("t");
  grow.add_input(t, q);
  grow.add_output(t, q);
  grow.add_output(t, r);
  grow.add_inhibitor(t, r, 20);
  for (unsigned threads : {1u, 2u}) {
    const ExploreResult res = an::explore(grow, quiet(threads));
    ASSERT_TRUE(res.complete()) << res.message;
    EXPECT_EQ(res.states, 21u);
    EXPECT_EQ(res.edges, 20u);
    EXPECT_EQ(res.max_tokens_place, 20u);
    EXPECT_EQ(res.bits_per_place, 8u);
    EXPECT_EQ(res.dead_trace.size(), 20u);
  }
}

TEST(Explore, EncodingFollowsTheStructuralBounds) {
  // p0 starts with 1 token, one firing puts 300 on p1: the P-semiflow 300*p0 + p1 bounds p1 by 300.
  PtNet net("widen");
  const auto p0 = net.add_place("p0", {}, 1);
  const auto p1 = net.add_place("p1");
  const auto t = net.add_transition("t");
  net.add_input(t, p0);
  net.add_output(t, p1, 300);
  const ExploreResult r = an::explore(net, quiet());
  ASSERT_TRUE(r.complete());
  EXPECT_EQ(r.states, 2u);
  EXPECT_EQ(r.edges, 1u);
  EXPECT_EQ(r.max_tokens_place, 300u);
  EXPECT_EQ(r.bits_per_place, 16u);
  EXPECT_TRUE(r.deadlock);
  EXPECT_EQ(r.dead_marking, (std::vector<std::uint32_t>{0, 300}));
}

TEST(Explore, UnboundedNetIsReportedWithTheCoveringPair) {
  // p0 -> t -> p0 + p1: p1 grows forever.
  PtNet net("pump");
  const auto p0 = net.add_place("p0", {}, 1);
  const auto p1 = net.add_place("p1");
  const auto t = net.add_transition("t");
  net.add_input(t, p0);
  net.add_output(t, p0);
  net.add_output(t, p1);
  const ExploreResult r = an::explore(net, quiet());
  EXPECT_EQ(r.status, ExploreResult::Status::unbounded);
  EXPECT_FALSE(r.complete());
  EXPECT_TRUE(r.unbounded_prefix.empty());
  EXPECT_EQ(r.unbounded_cycle, std::vector<std::uint32_t>{t});
  EXPECT_EQ(r.unbounded_covered, (std::vector<std::uint32_t>{1, 0}));
  EXPECT_EQ(r.unbounded_covering, (std::vector<std::uint32_t>{1, 1}));
  EXPECT_NE(r.message.find("unbounded"), std::string::npos);
}

TEST(Explore, UnboundedAfterAPrefixAndALongerCycle) {
  // start -> a; a -> b; b -> a + c: the cycle a->b->a adds a token to c each round.
  PtNet net("cycle");
  const auto start = net.add_place("start", {}, 1);
  const auto a = net.add_place("a");
  const auto b = net.add_place("b");
  const auto c = net.add_place("c");
  const auto go = net.add_transition("go");
  net.add_input(go, start);
  net.add_output(go, a);
  const auto ab = net.add_transition("ab");
  net.add_input(ab, a);
  net.add_output(ab, b);
  const auto ba = net.add_transition("ba");
  net.add_input(ba, b);
  net.add_output(ba, a);
  net.add_output(ba, c);
  for (unsigned threads : {1u, 2u}) {
    const ExploreResult r = an::explore(net, quiet(threads));
    ASSERT_EQ(r.status, ExploreResult::Status::unbounded);
    EXPECT_EQ(r.unbounded_prefix, std::vector<std::uint32_t>{go});
    EXPECT_EQ(r.unbounded_cycle, (std::vector<std::uint32_t>{ab, ba}));
    EXPECT_EQ(an::trace_to_string(net, r.unbounded_cycle), "ab ba");
  }
}

PtNet inhibitor_net() {
  // a=2; t1: a -> b; t2: b -> c, inhibited while a holds a token.
  PtNet net("inhib");
  const auto a = net.add_place("a", {}, 2);
  const auto b = net.add_place("b");
  const auto c = net.add_place("c");
  const auto t1 = net.add_transition("t1");
  net.add_input(t1, a);
  net.add_output(t1, b);
  const auto t2 = net.add_transition("t2");
  net.add_input(t2, b);
  net.add_output(t2, c);
  net.add_inhibitor(t2, a);
  return net;
}

TEST(Explore, InhibitorArcsRestrictTheStateSpace) {
  const PtNet net = inhibitor_net();
  const ExploreResult r = an::explore(net, quiet());
  ASSERT_TRUE(r.complete());
  // (2,0,0) (1,1,0) (0,2,0) (0,1,1) (0,0,2); without the inhibitor also (1,0,1): 6.
  EXPECT_EQ(r.states, 5u);
  EXPECT_EQ(r.edges, 4u);
  EXPECT_TRUE(r.deadlock);
  EXPECT_EQ(an::trace_to_string(net, r.dead_trace), "t1 t1 t2 t2");
  EXPECT_EQ(r.dead_marking, (std::vector<std::uint32_t>{0, 0, 2}));
  EXPECT_EQ(naive(net).states, 5u);

  PtNet plain("plain");
  for (const auto& p : net.places()) plain.add_place(p.id, p.name, p.initial);
  for (const auto& t : net.transitions()) {
    const auto i = plain.add_transition(t.id);
    for (const auto& arc : t.inputs) plain.add_input(i, arc.place, arc.weight);
    for (const auto& arc : t.outputs) plain.add_output(i, arc.place, arc.weight);
  }
  EXPECT_EQ(an::explore(plain, quiet()).states, 6u);
}

TEST(Explore, InhibitorWeightCountsTokens) {
  // t adds to q while q holds fewer than 3 tokens (inhibitor of weight 3).
  PtNet net("inh3");
  const auto p = net.add_place("p", {}, 1);
  const auto q = net.add_place("q");
  const auto t = net.add_transition("t");
  net.add_input(t, p);
  net.add_output(t, p);
  net.add_output(t, q);
  net.add_inhibitor(t, q, 3);
  // (1,1) strictly covers (1,0) but differs on the inhibitor place: not a proof of unboundedness.
  const ExploreResult r = an::explore(net, quiet());
  ASSERT_TRUE(r.complete()) << r.message;
  EXPECT_EQ(r.states, 4u);
  EXPECT_EQ(r.edges, 3u);
  EXPECT_TRUE(r.deadlock);
  EXPECT_EQ(r.dead_trace.size(), 3u);
  EXPECT_EQ(r.max_tokens_place, 3u);
  EXPECT_EQ(r.max_tokens_marking, 4u);
}

TEST(Explore, DeadMarkingWithTheShortestSequence) {
  // Two ways from `start` to `end` (3 firings and 2 firings), and a cycle that never dies.
  PtNet net("dead");
  const auto start = net.add_place("start", {}, 1);
  const auto a = net.add_place("a");
  const auto b = net.add_place("b");
  const auto x = net.add_place("x");
  const auto end = net.add_place("end");
  const auto loop = net.add_place("loop");
  auto arc = [&](const char* id, std::uint32_t from, std::uint32_t to) {
    const auto t = net.add_transition(id);
    net.add_input(t, from);
    net.add_output(t, to);
    return t;
  };
  arc("long1", start, a);
  arc("long2", a, b);
  arc("long3", b, end);
  arc("short1", start, x);
  arc("short2", x, end);
  arc("toloop", a, loop);
  arc("spin", loop, loop);
  for (unsigned threads : {1u, 2u}) {
    const ExploreResult r = an::explore(net, quiet(threads));
    ASSERT_TRUE(r.complete());
    EXPECT_EQ(r.states, 6u);  // start, a, x, b, loop, end (spin keeps the marking)
    EXPECT_TRUE(r.deadlock);
    EXPECT_EQ(an::trace_to_string(net, r.dead_trace), "short1 short2");
    EXPECT_EQ(r.dead_marking, (std::vector<std::uint32_t>{0, 0, 0, 0, 1, 0}));
  }
}

TEST(Explore, NetWithoutTransitionsIsOneDeadMarking) {
  PtNet net("still");
  net.add_place("p", {}, 4);
  const ExploreResult r = an::explore(net, quiet());
  EXPECT_EQ(r.states, 1u);
  EXPECT_EQ(r.edges, 0u);
  EXPECT_TRUE(r.deadlock);
  EXPECT_TRUE(r.dead_trace.empty());
  EXPECT_EQ(r.max_tokens_place, 4u);
}

TEST(Explore, SelfLoopIsOneStateAndOneEdge) {
  PtNet net("selfloop");
  const auto p = net.add_place("p", {}, 1);
  const auto t = net.add_transition("t");
  net.add_input(t, p);
  net.add_output(t, p);
  const ExploreResult r = an::explore(net, quiet());
  EXPECT_EQ(r.states, 1u);
  EXPECT_EQ(r.edges, 1u);
  EXPECT_FALSE(r.deadlock);
}

TEST(Explore, MemoryLimitStopsWithAMessage) {
  const PtNet net = an::test::ring(12, 6);  // 12376 states
  ExploreOptions o = quiet();
  o.memory_limit = 200 * 1024;
  const ExploreResult r = an::explore(net, o);
  EXPECT_EQ(r.status, ExploreResult::Status::memory_limit);
  EXPECT_LT(r.states, 12376u);
  EXPECT_NE(r.message.find("memory limit"), std::string::npos);
  EXPECT_NE(r.message.find("--limit-mem"), std::string::npos);
  EXPECT_EQ(r.memory_limit, 200u * 1024);
  o.memory_limit = 0;  // the default: a share of the machine's memory
  EXPECT_TRUE(an::explore(net, o).complete());
}

TEST(Explore, JsonAndSummary) {
  const PtNet net = inhibitor_net();
  const ExploreResult r = an::explore(net, quiet());
  std::ostringstream json;
  an::write_json(json, net, r);
  const std::string j = json.str();
  EXPECT_NE(j.find("\"states\": 5, \"edges\": 4, \"deadlock\": true, \"max_tokens_place\": 2, "
                   "\"max_tokens_marking\": 2"),
            std::string::npos)
      << j;
  EXPECT_NE(j.find("\"dead_trace\": [\"t1\", \"t1\", \"t2\", \"t2\"]"), std::string::npos) << j;
  EXPECT_NE(j.find("\"bounded\": true"), std::string::npos);
  EXPECT_EQ(j.back(), '\n');
  std::ostringstream text;
  an::write_summary(text, net, r);
  EXPECT_NE(text.str().find("states (reachable markings): 5"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("t1 t1 t2 t2"), std::string::npos);
}

TEST(ParseSize, UnitsAndErrors) {
  EXPECT_EQ(an::parse_size("100"), 100u);
  EXPECT_EQ(an::parse_size("4K"), 4096u);
  EXPECT_EQ(an::parse_size("512M"), 512u << 20);
  EXPECT_EQ(an::parse_size("1.5GiB"), (3u << 30) / 2);
  EXPECT_THROW(an::parse_size("lots"), vsd::Error);
  EXPECT_THROW(an::parse_size("12Q"), vsd::Error);
  EXPECT_THROW(an::parse_size("-5M"), vsd::Error);
  EXPECT_THROW(an::parse_size("0"), vsd::Error);
}

}  // namespace

namespace {

TEST(Explore, ReportsOfUnboundedAndIncompleteRuns) {
  PtNet net("pump");
  const auto p0 = net.add_place("p0", {}, 1);
  const auto p1 = net.add_place("p1");
  const auto t = net.add_transition("t");
  net.add_input(t, p0);
  net.add_output(t, p0);
  net.add_output(t, p1);
  const ExploreResult r = an::explore(net, quiet());
  std::ostringstream json, text;
  an::write_json(json, net, r);
  an::write_summary(text, net, r);
  EXPECT_NE(json.str().find("\"status\": \"unbounded\""), std::string::npos) << json.str();
  EXPECT_NE(json.str().find("\"bounded\": false"), std::string::npos);
  EXPECT_NE(json.str().find("\"unbounded_cycle\": [\"t\"]"), std::string::npos);
  EXPECT_NE(text.str().find("UNBOUNDED"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("at least"), std::string::npos);

  ExploreOptions o = quiet();
  o.memory_limit = 100 * 1024;
  const PtNet big = an::test::ring(12, 6);
  const ExploreResult m = an::explore(big, o);
  std::ostringstream json2;
  an::write_json(json2, big, m);
  EXPECT_NE(json2.str().find("\"status\": \"memory_limit\""), std::string::npos) << json2.str();
  EXPECT_NE(json2.str().find("\"bounded\": null"), std::string::npos);
  EXPECT_GE(an::default_memory_limit(), std::size_t{64} << 20);
}

// Resident memory from /proc/self/status (KiB -> bytes): "VmRSS" now, "VmHWM" the peak since the last
// reset_peak_rss(). Empty where there is no such file, and in sanitizer builds (their shadow memory and
// quarantine of freed blocks count as resident too).
std::optional<std::size_t> resident(const std::string& key) {
#ifdef VSD_TEST_SANITIZED
  (void)key;
  return std::nullopt;
#else
  std::ifstream in("/proc/self/status");
  std::string k;
  std::size_t kib = 0;
  std::string unit;
  while (in >> k) {
    if (k == key + ":" && in >> kib >> unit) return kib * 1024;
    std::getline(in, unit);
  }
  return std::nullopt;
#endif
}
bool reset_peak_rss() {
  std::ofstream f("/proc/self/clear_refs");
  f << "5";  // Linux: resets VmHWM to the current resident size
  f.close();
  return f.good() && resident("VmHWM").has_value();
}

TEST(Explore, TheMemoryLimitCoversEveryPhaseAndNothingGrowsPastIt) {
  constexpr std::size_t kLimit = std::size_t{80} << 20;
  constexpr std::size_t kSlack = std::size_t{8} << 20;  // the allocator's own bookkeeping and rounding
  ExploreOptions o = quiet();
  o.split_small_levels = false;
  o.memory_limit = kLimit;
  // 20,000 places and transitions: the place-bounds phase held dense rows, places x transitions (3.2 GB
  // under a limit of 256 MiB); they are sparse now, and the whole run stays within the limit.
  {
    const PtNet ring = an::test::ring(20'000, 1);
    const bool rss = reset_peak_rss();
    const std::size_t before = resident("VmRSS").value_or(0);
    const ExploreResult r = an::explore(ring, o);
    EXPECT_TRUE(r.complete()) << r.message;
    EXPECT_EQ(r.states, 20'000u);
    EXPECT_EQ(r.edges, 20'000u);
    EXPECT_EQ(r.bits_per_place, 1u);  // the bounds were found: one token in the ring
    EXPECT_LE(r.peak_memory, kLimit);
    if (rss) {
      EXPECT_LE(*resident("VmHWM") - before, kLimit + kSlack);
    }
  }
  // 200,000 places: a state takes 25 KB (200,000 bits); 200,000 places grew to 24 GB before. The run stops
  // in the exploration, at the limit.
  {
    const PtNet ring = an::test::ring(200'000, 1);
    const bool rss = reset_peak_rss();
    const std::size_t before = resident("VmRSS").value_or(0);
    const ExploreResult r = an::explore(ring, o);
    EXPECT_EQ(r.status, ExploreResult::Status::memory_limit);
    EXPECT_NE(r.message.find("memory limit of 80.0 MiB reached in the exploration after "), std::string::npos)
        << r.message;
    EXPECT_GT(r.states, 1000u);
    EXPECT_LT(r.states, 200'000u);
    EXPECT_LE(r.peak_memory, kLimit);
    if (rss) {
      EXPECT_LE(*resident("VmHWM") - before, kLimit + kSlack);
    }
    // A limit the compiled net alone passes: said before anything else is made.
    o.memory_limit = std::size_t{1} << 20;
    const ExploreResult tiny = an::explore(ring, o);
    EXPECT_EQ(tiny.status, ExploreResult::Status::memory_limit);
    EXPECT_NE(tiny.message.find("memory limit of 1.0 MiB reached while compiling the net (it needs at least "),
              std::string::npos)
        << tiny.message;
    EXPECT_EQ(tiny.states, 0u);
  }
  // Workers each need two markings of the net: 1024 threads of 20,000 places pass 64 MiB before any state.
  {
    const PtNet ring = an::test::ring(20'000, 1);
    o.memory_limit = std::size_t{64} << 20;
    o.threads = 1024;
    const ExploreResult r = an::explore(ring, o);
    EXPECT_EQ(r.status, ExploreResult::Status::memory_limit);
    EXPECT_NE(r.message.find("while preparing the exploration"), std::string::npos) << r.message;
    EXPECT_EQ(r.threads, 1024u);
  }
}

TEST(Explore, TransitionsSharingAPlaceNeedNoQuadraticTable) {
  // n transitions take a mutex and n give it back. The transitions to test again after each firing,
  // listed per transition, are 2n^2 entries (18 MB for n = 1500); past an eighth of the limit the list is
  // not made and every transition is tested: the figures stay the same.
  constexpr unsigned n = 1500;
  PtNet net("mutex");
  const auto m = net.add_place("m", {}, 1);
  for (unsigned i = 0; i < n; ++i) {
    const auto a = net.add_place("a" + std::to_string(i), {}, 1);
    const auto b = net.add_place("b" + std::to_string(i));
    const auto take = net.add_transition("take" + std::to_string(i));
    net.add_input(take, a);
    net.add_input(take, m);
    net.add_output(take, b);
    const auto give = net.add_transition("give" + std::to_string(i));
    net.add_input(give, b);
    net.add_output(give, a);
    net.add_output(give, m);
  }
  for (const std::size_t limit : {std::size_t{16} << 20, std::size_t{0}}) {
    SCOPED_TRACE(limit);
    ExploreOptions o = quiet();
    o.memory_limit = limit;
    const ExploreResult r = an::explore(net, o);
    EXPECT_TRUE(r.complete()) << r.message;
    EXPECT_EQ(r.states, n + 1);
    EXPECT_EQ(r.edges, 2u * n);
    EXPECT_FALSE(r.deadlock);
    if (limit != 0) {
      EXPECT_LE(r.peak_memory, limit);
    }
  }
}

}  // namespace
