// Tests of vsd/core/signal.hpp: Signal<void(Args...)> and its RAII Connection.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>
#include <vsd/vsd.hpp>

namespace {

using testing::ElementsAre;
using IntSignal = vsd::Signal<void(int)>;
using VoidSignal = vsd::Signal<void()>;

struct Accumulator {
  int total = 0;
  int calls = 0;
  void add(int x) {
    total += x;
    ++calls;
  }
};

int free_function_total = 0;
void free_function(int x) { free_function_total += x; }

TEST(Signal, EmitWithoutListenersDoesNothing) {
  IntSignal sig;
  EXPECT_FALSE(sig.has_listeners());
  EXPECT_EQ(sig.size(), 0u);
  sig.emit(1);
  sig(2);
  EXPECT_FALSE(sig.has_listeners());
  EXPECT_EQ(sig.size(), 0u);
}

TEST(Signal, EmitReachesOneListenerWithItsArguments) {
  vsd::Signal<void(int, const std::string&)> sig;
  std::vector<std::pair<int, std::string>> seen;
  auto c = sig.connect([&](int n, const std::string& s) { seen.emplace_back(n, s); });
  EXPECT_TRUE(sig.has_listeners());
  EXPECT_EQ(sig.size(), 1u);
  sig.emit(7, "seven");
  sig(8, "eight");
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0], std::make_pair(7, std::string("seven")));
  EXPECT_EQ(seen[1], std::make_pair(8, std::string("eight")));
}

TEST(Signal, EmitReachesManyListenersInConnectionOrder) {
  IntSignal sig;
  std::vector<int> order;
  std::vector<vsd::Connection> connections;
  for (int i = 0; i < 5; ++i)
    connections.push_back(sig.connect([&order, i](int x) { order.push_back(i * 100 + x); }));
  EXPECT_EQ(sig.size(), 5u);
  sig.emit(1);
  EXPECT_THAT(order, ElementsAre(1, 101, 201, 301, 401));
}

TEST(Signal, ListenerArgumentsAreReferencesWhenDeclaredSo) {
  vsd::Signal<void(int&)> sig;
  auto c1 = sig.connect([](int& x) { x += 1; });
  auto c2 = sig.connect([](int& x) { x *= 10; });
  int value = 4;
  sig.emit(value);
  EXPECT_EQ(value, 50);
}

TEST(Signal, LambdaKeepsItsStateBetweenEmits) {
  IntSignal sig;
  std::vector<int> seen;
  auto c = sig.connect([count = 0, &seen](int x) mutable {
    ++count;
    seen.push_back(count * x);
  });
  sig.emit(1);
  sig.emit(1);
  sig.emit(2);
  EXPECT_THAT(seen, ElementsAre(1, 2, 6));
}

TEST(Signal, MemberFunctionConnect) {
  IntSignal sig;
  Accumulator acc;
  auto c = sig.connect<&Accumulator::add>(acc);
  EXPECT_TRUE(c.connected());
  sig.emit(3);
  sig.emit(4);
  EXPECT_EQ(acc.total, 7);
  EXPECT_EQ(acc.calls, 2);
  c.disconnect();
  sig.emit(100);
  EXPECT_EQ(acc.total, 7);
}

TEST(Signal, FunctionPointerConnect) {
  IntSignal sig;
  free_function_total = 0;
  auto c = sig.connect(&free_function);
  sig.emit(5);
  sig.emit(6);
  EXPECT_EQ(free_function_total, 11);
}

TEST(Signal, ConnectionDisconnectsOnDestruction) {
  IntSignal sig;
  int calls = 0;
  {
    auto c = sig.connect([&](int) { ++calls; });
    sig.emit(0);
    EXPECT_EQ(calls, 1);
    EXPECT_EQ(sig.size(), 1u);
  }
  EXPECT_FALSE(sig.has_listeners());
  EXPECT_EQ(sig.size(), 0u);
  sig.emit(0);
  EXPECT_EQ(calls, 1);
}

TEST(Signal, DisconnectFreesTheListenerAndIsIdempotent) {
  IntSignal sig;
  auto token = std::make_shared<int>(0);
  std::weak_ptr<int> watch = token;
  auto c = sig.connect([token](int) { ++*token; });
  token.reset();
  EXPECT_FALSE(watch.expired()) << "the signal holds the listener";
  c.disconnect();
  EXPECT_TRUE(watch.expired()) << "disconnecting outside an emit frees the listener at once";
  EXPECT_FALSE(c.connected());
  c.disconnect();  // a second disconnect is a no-op
  EXPECT_FALSE(c.connected());
  EXPECT_EQ(sig.size(), 0u);
}

TEST(Signal, DefaultConnectionIsNotConnected) {
  vsd::Connection c;
  EXPECT_FALSE(c.connected());
  c.disconnect();
  c.release();
  EXPECT_FALSE(c.connected());
}

TEST(Signal, MovedConnectionKeepsTheListener) {
  IntSignal sig;
  int calls = 0;
  vsd::Connection a = sig.connect([&](int) { ++calls; });
  vsd::Connection b(std::move(a));
  EXPECT_FALSE(a.connected());  // NOLINT(bugprone-use-after-move): a moved-from Connection is empty
  EXPECT_TRUE(b.connected());
  a.disconnect();  // disconnecting the moved-from one does nothing
  sig.emit(0);
  EXPECT_EQ(calls, 1);

  vsd::Connection c;
  c = std::move(b);
  EXPECT_FALSE(b.connected());  // NOLINT(bugprone-use-after-move)
  EXPECT_TRUE(c.connected());
  sig.emit(0);
  EXPECT_EQ(calls, 2);
  { vsd::Connection d(std::move(c)); }  // d goes out of scope: the listener is gone
  sig.emit(0);
  EXPECT_EQ(calls, 2);
  EXPECT_FALSE(sig.has_listeners());
}

TEST(Signal, MoveAssignmentOverAConnectedConnectionDisconnectsTheOldListener) {
  IntSignal sig;
  int first = 0;
  int second = 0;
  vsd::Connection c = sig.connect([&](int) { ++first; });
  c = sig.connect([&](int) { ++second; });
  EXPECT_EQ(sig.size(), 1u);
  sig.emit(0);
  EXPECT_EQ(first, 0);
  EXPECT_EQ(second, 1);
}

TEST(Signal, ReleaseLetsTheListenerLiveAsLongAsTheSignal) {
  auto token = std::make_shared<int>(0);
  std::weak_ptr<int> watch = token;
  int calls = 0;
  {
    IntSignal sig;
    {
      auto c = sig.connect([&calls, token](int) { ++calls; });
      c.release();
      EXPECT_FALSE(c.connected());
    }  // the released connection's destruction does not disconnect
    token.reset();
    EXPECT_EQ(sig.size(), 1u);
    sig.emit(0);
    sig.emit(0);
    EXPECT_EQ(calls, 2);
    EXPECT_FALSE(watch.expired());
  }
  EXPECT_TRUE(watch.expired()) << "the signal frees released listeners when it dies";
}

TEST(Signal, HasListenersAndSizeFollowConnectAndDisconnect) {
  VoidSignal sig;
  auto a = sig.connect([] {});
  auto b = sig.connect([] {});
  auto c = sig.connect([] {});
  EXPECT_EQ(sig.size(), 3u);
  EXPECT_TRUE(sig.has_listeners());
  b.disconnect();
  EXPECT_EQ(sig.size(), 2u);
  a.disconnect();
  EXPECT_EQ(sig.size(), 1u);
  EXPECT_TRUE(sig.has_listeners());
  c.disconnect();
  EXPECT_EQ(sig.size(), 0u);
  EXPECT_FALSE(sig.has_listeners());
  auto d = sig.connect([] {});
  EXPECT_TRUE(sig.has_listeners());
  EXPECT_EQ(sig.size(), 1u);
}

TEST(Signal, ListenerDisconnectsItselfDuringEmit) {
  IntSignal sig;
  std::vector<std::string> calls;
  auto token = std::make_shared<int>(0);
  std::weak_ptr<int> watch = token;
  vsd::Connection self;
  auto before = sig.connect([&](int) { calls.emplace_back("before"); });
  self = sig.connect([&calls, &self, token](int) {
    calls.emplace_back("self");
    self.disconnect();
    // The running functor must stay alive until it returns: its captures are still usable here.
    calls.push_back("self-after-" + std::to_string(*token));
  });
  auto after = sig.connect([&](int) { calls.emplace_back("after"); });
  token.reset();

  sig.emit(0);
  EXPECT_THAT(calls, ElementsAre("before", "self", "self-after-0", "after"));
  EXPECT_FALSE(self.connected());
  EXPECT_EQ(sig.size(), 2u);
  EXPECT_TRUE(watch.expired()) << "the functor is freed once the emit returns";

  calls.clear();
  sig.emit(0);
  EXPECT_THAT(calls, ElementsAre("before", "after"));
}

TEST(Signal, OnlyListenerDisconnectingItselfLeavesNoListeners) {
  VoidSignal sig;
  int calls = 0;
  vsd::Connection self;
  self = sig.connect([&] {
    ++calls;
    self.disconnect();
  });
  sig.emit();
  EXPECT_FALSE(sig.has_listeners());
  EXPECT_EQ(sig.size(), 0u);
  sig.emit();
  EXPECT_EQ(calls, 1);
}

TEST(Signal, ListenerDisconnectingALaterListenerDuringEmitPreventsItsCall) {
  IntSignal sig;
  std::vector<int> order;
  vsd::Connection second;
  auto first = sig.connect([&](int) {
    order.push_back(1);
    second.disconnect();
  });
  second = sig.connect([&](int) { order.push_back(2); });
  auto third = sig.connect([&](int) { order.push_back(3); });
  sig.emit(0);
  EXPECT_THAT(order, ElementsAre(1, 3));
  EXPECT_FALSE(second.connected());
  EXPECT_EQ(sig.size(), 2u);
  order.clear();
  sig.emit(0);
  EXPECT_THAT(order, ElementsAre(1, 3));
}

// Listeners of one type (the same lambda, the same member function) run inline, one after the other,
// without an indirect call each; these check that such runs keep order and still see disconnections.
struct Recorder {
  std::vector<int>* order;
  int tag;
  std::vector<vsd::Connection>* to_cut = nullptr;  // disconnected by this listener when set
  void on(int) {
    order->push_back(tag);
    if (to_cut != nullptr)
      for (auto& c : *to_cut) c.disconnect();
  }
};

TEST(Signal, SameTypedListenersKeepConnectionOrderBetweenOtherTypes) {
  IntSignal sig;
  std::vector<int> order;
  std::vector<Recorder> rs;
  for (int i = 0; i < 6; ++i) rs.push_back(Recorder{&order, i});
  std::vector<vsd::Connection> cs;
  cs.push_back(sig.connect<&Recorder::on>(rs[0]));
  cs.push_back(sig.connect<&Recorder::on>(rs[1]));
  cs.push_back(sig.connect([&](int) { order.push_back(100); }));  // another type breaks the run
  for (int i = 2; i < 6; ++i) cs.push_back(sig.connect<&Recorder::on>(rs[static_cast<std::size_t>(i)]));
  sig.emit(0);
  EXPECT_THAT(order, ElementsAre(0, 1, 100, 2, 3, 4, 5));
}

TEST(Signal, SameTypedListenerDisconnectingTheNextOnesDuringEmitPreventsTheirCalls) {
  IntSignal sig;
  std::vector<int> order;
  std::vector<Recorder> rs;
  for (int i = 0; i < 5; ++i) rs.push_back(Recorder{&order, i});
  std::vector<vsd::Connection> before;
  std::vector<vsd::Connection> cut;  // listeners 2 and 3, cut by listener 1 in the middle of the run
  before.push_back(sig.connect<&Recorder::on>(rs[0]));
  before.push_back(sig.connect<&Recorder::on>(rs[1]));
  cut.push_back(sig.connect<&Recorder::on>(rs[2]));
  cut.push_back(sig.connect<&Recorder::on>(rs[3]));
  before.push_back(sig.connect<&Recorder::on>(rs[4]));
  rs[1].to_cut = &cut;
  sig.emit(0);
  EXPECT_THAT(order, ElementsAre(0, 1, 4));
  EXPECT_EQ(sig.size(), 3u);
  order.clear();
  rs[1].to_cut = nullptr;
  sig.emit(0);
  EXPECT_THAT(order, ElementsAre(0, 1, 4));
}

TEST(Signal, ListenerDisconnectingAnEarlierListenerDuringEmit) {
  IntSignal sig;
  std::vector<int> order;
  vsd::Connection first = sig.connect([&](int) { order.push_back(1); });
  auto second = sig.connect([&](int) {
    order.push_back(2);
    first.disconnect();
  });
  auto third = sig.connect([&](int) { order.push_back(3); });
  sig.emit(0);
  EXPECT_THAT(order, ElementsAre(1, 2, 3));
  order.clear();
  sig.emit(0);
  EXPECT_THAT(order, ElementsAre(2, 3));
}

TEST(Signal, ListenerDisconnectingEveryoneDuringEmit) {
  IntSignal sig;
  std::vector<int> order;
  std::vector<vsd::Connection> all;
  all.push_back(sig.connect([&](int) {
    order.push_back(0);
    for (auto& c : all) c.disconnect();
  }));
  for (int i = 1; i < 4; ++i) all.push_back(sig.connect([&order, i](int) { order.push_back(i); }));
  sig.emit(0);
  EXPECT_THAT(order, ElementsAre(0));
  EXPECT_FALSE(sig.has_listeners());
  sig.emit(0);
  EXPECT_THAT(order, ElementsAre(0));
}

TEST(Signal, ListenerConnectedDuringEmitIsCalledFromTheNextEmit) {
  IntSignal sig;
  int outer = 0;
  int inner = 0;
  std::vector<vsd::Connection> added;
  auto c = sig.connect([&](int) {
    ++outer;
    if (added.empty()) added.push_back(sig.connect([&](int) { ++inner; }));
  });
  sig.emit(0);
  EXPECT_EQ(outer, 1);
  EXPECT_EQ(inner, 0) << "a listener connected during an emit waits for the next emit";
  EXPECT_EQ(sig.size(), 2u);
  sig.emit(0);
  EXPECT_EQ(outer, 2);
  EXPECT_EQ(inner, 1);
}

TEST(Signal, ManyListenersConnectedDuringEmitDoNotDisturbIt) {
  // Connecting enough listeners to grow the slot array while it is being walked.
  IntSignal sig;
  std::vector<int> order;
  std::vector<vsd::Connection> added;
  auto first = sig.connect([&](int) {
    order.push_back(1);
    if (added.empty())
      for (int i = 0; i < 100; ++i) added.push_back(sig.connect([&order](int) { order.push_back(100); }));
  });
  auto second = sig.connect([&](int x) { order.push_back(x); });
  sig.emit(2);
  EXPECT_THAT(order, ElementsAre(1, 2));
  EXPECT_EQ(sig.size(), 102u);
  order.clear();
  sig.emit(2);
  EXPECT_EQ(order.size(), 102u);
}

TEST(Signal, ListenerConnectedAfterTheOnlyListenerLeftDuringEmit) {
  VoidSignal sig;
  int replaced = 0;
  int replacement = 0;
  vsd::Connection slot;
  slot = sig.connect([&] {
    ++replaced;
    slot = sig.connect([&] { ++replacement; });  // disconnects the running listener, connects a new one
  });
  sig.emit();
  EXPECT_EQ(replaced, 1);
  EXPECT_EQ(replacement, 0);
  EXPECT_TRUE(sig.has_listeners());
  EXPECT_EQ(sig.size(), 1u);
  sig.emit();
  EXPECT_EQ(replaced, 1);
  EXPECT_EQ(replacement, 1);
}

TEST(Signal, NestedEmitWithDisconnect) {
  IntSignal sig;
  std::vector<int> order;
  vsd::Connection last;
  auto first = sig.connect([&](int depth) {
    order.push_back(depth);
    if (depth == 0) sig.emit(1);  // re-entrant emit
  });
  auto second = sig.connect([&](int depth) {
    order.push_back(10 + depth);
    if (depth == 1) last.disconnect();  // during the inner emit
  });
  last = sig.connect([&](int depth) { order.push_back(20 + depth); });
  sig.emit(0);
  // outer: first(0) -> inner: first(1), second(1) disconnects last; inner skips last
  // outer continues: second(0); last is gone.
  EXPECT_THAT(order, ElementsAre(0, 1, 11, 10));
  EXPECT_EQ(sig.size(), 2u);
}

TEST(Signal, DestroyingTheSignalInsideItsOwnListener) {
  auto sig = std::make_unique<IntSignal>();
  auto token = std::make_shared<int>(0);
  std::weak_ptr<int> watch = token;
  int before = 0;
  vsd::Connection c1 = sig->connect([&](int) { ++before; });
  vsd::Connection c2 = sig->connect([&sig, token](int) { sig.reset(); });
  vsd::Connection c3 = sig->connect([token](int) {});
  token.reset();
  IntSignal* raw = sig.get();
  raw->emit(1);  // the signal dies in the middle of its emit
  EXPECT_EQ(sig, nullptr);
  EXPECT_EQ(before, 1);
  EXPECT_FALSE(c1.connected());
  EXPECT_FALSE(c2.connected());
  EXPECT_FALSE(c3.connected());
  c1.disconnect();  // no-ops after the signal is gone
  c2.disconnect();
  EXPECT_FALSE(watch.expired()) << "c3 still shares the signal's state";
  c3.disconnect();
  EXPECT_TRUE(watch.expired()) << "the listeners are freed once the last connection lets go";
}

TEST(Signal, DestroyingTheSignalInsideTheOnlyListenerWithReleasedConnection) {
  auto sig = std::make_unique<VoidSignal>();
  int calls = 0;
  sig->connect([&] {
       ++calls;
       sig.reset();
     })
      .release();
  sig->emit();
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(sig, nullptr);
}

TEST(Signal, ConnectionOutlivingItsSignal) {
  int calls = 0;
  auto token = std::make_shared<int>(0);
  std::weak_ptr<int> watch = token;
  vsd::Connection c;
  {
    IntSignal sig;
    c = sig.connect([&calls, token](int) { ++calls; });
    token.reset();
    EXPECT_TRUE(c.connected());
    sig.emit(0);
  }
  EXPECT_EQ(calls, 1);
  EXPECT_FALSE(c.connected());
  c.disconnect();  // a no-op, and no access to the dead signal (ASan)
  EXPECT_FALSE(c.connected());
  EXPECT_TRUE(watch.expired());
}

TEST(Signal, ConnectionOutlivingItsSignalIsDestroyedSafely) {
  auto c = std::make_unique<vsd::Connection>();
  {
    VoidSignal sig;
    *c = sig.connect([] {});
  }
  EXPECT_FALSE(c->connected());
  c.reset();  // destructor after the signal is gone
  SUCCEED();
}

TEST(Signal, ConnectionsOfDifferentSignalsAreIndependent) {
  IntSignal a;
  IntSignal b;
  int from_a = 0;
  int from_b = 0;
  auto ca = a.connect([&](int x) { from_a += x; });
  auto cb = b.connect([&](int x) { from_b += x; });
  a.emit(1);
  b.emit(10);
  ca.disconnect();
  a.emit(1);
  b.emit(10);
  EXPECT_EQ(from_a, 1);
  EXPECT_EQ(from_b, 20);
  EXPECT_TRUE(cb.connected());
}

}  // namespace
