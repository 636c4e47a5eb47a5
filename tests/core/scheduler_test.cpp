#include "vsd/core/scheduler.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_classes.hpp"

using testing::ElementsAre;
using testing::HasSubstr;

namespace {

TEST(Scheduler, RunsPeriodicTasksAtTheirRate) {
  vsd::Scheduler s(0.01);
  int fast = 0, slow = 0;
  double slow_dt = 0;
  s.add_periodic("fast", 0.01, [&](const vsd::StepInfo&) { ++fast; });
  s.add_periodic("slow", 0.05, [&](const vsd::StepInfo& i) {
    ++slow;
    slow_dt = i.dt;
  });
  s.run_for(0.2);
  EXPECT_EQ(fast, 20);
  EXPECT_EQ(slow, 4);
  EXPECT_NEAR(slow_dt, 0.05, 1e-12);
  EXPECT_EQ(s.steps(), 20u);
}

TEST(Scheduler, PhasesRunInOrderThenOrderNumberThenInsertionOrder) {
  vsd::Scheduler s;
  std::vector<std::string> order;
  auto log = [&](const char* name) { return [&order, name](const vsd::StepInfo&) { order.push_back(name); }; };
  s.add_periodic("sensors", 0.01, log("sensors"), vsd::Phase::sensors);
  s.add_periodic("physics", 0.01, log("physics"), vsd::Phase::dynamics);
  s.add_periodic("late physics", 0.01, log("late physics"), vsd::Phase::dynamics, 5);
  s.add_periodic("early physics", 0.01, log("early physics"), vsd::Phase::dynamics, -5);
  s.add_periodic("more physics", 0.01, log("more physics"), vsd::Phase::dynamics);
  s.add_periodic("control", 0.01, log("control"), vsd::Phase::controllers);
  s.add_periodic("input", 0.01, log("input"), vsd::Phase::inputs);
  s.step();
  EXPECT_THAT(order, ElementsAre("input", "control", "early physics", "physics", "more physics", "late physics",
                                 "sensors"));
  EXPECT_EQ(s.task_phase(1), vsd::Phase::sensors);
  EXPECT_STREQ(vsd::phase_name(vsd::Phase::nets), "nets");
}

TEST(Scheduler, EventDrivenTasksRunByPhaseAfterThePeriodicOnes) {
  vsd::Scheduler s;
  std::vector<std::string> order;
  const auto net = s.add_event_driven("net", [&](const vsd::StepInfo&) { order.push_back("net"); });
  const auto ui = s.add_event_driven("ui", [&](const vsd::StepInfo&) { order.push_back("ui"); }, vsd::Phase::outputs);
  s.add_periodic("plant", 0.01, [&](const vsd::StepInfo&) {
    order.push_back("plant");
    s.trigger(ui);
    s.trigger(net);
  }, vsd::Phase::dynamics);
  s.step();
  EXPECT_THAT(order, ElementsAre("plant", "net", "ui"));
}

TEST(Scheduler, RunForRefusesTimesItCannotStep) {
  vsd::Scheduler s(0.001);
  EXPECT_THROW(s.run_for(-1.0), vsd::Error);
  EXPECT_THROW(s.run_for(std::numeric_limits<double>::quiet_NaN()), vsd::Error);
  EXPECT_THROW(s.run_for(std::numeric_limits<double>::infinity()), vsd::Error);
  EXPECT_THROW(s.run_for(1e17), vsd::Error);  // 1e20 steps: not countable, refused instead of looping
  EXPECT_THROW(s.set_base_step(std::numeric_limits<double>::infinity()), vsd::Error);
  EXPECT_THROW(s.add_periodic("p", std::numeric_limits<double>::infinity(), [](const vsd::StepInfo&) {}),
               vsd::Error);
  s.run_for(0.0105);
  EXPECT_EQ(s.steps(), 11U);
}

TEST(Scheduler, EventDrivenTasksRunOnSignalsWithinTheStep) {
  vsd::Environment env;
  auto& state = env.main_state();
  auto& r = state.create<vsd_test::TRobot>();
  vsd::Scheduler& s = env.scheduler();
  int reactions = 0;
  const auto id = s.add_event_driven("react", [&](const vsd::StepInfo&) { ++reactions; });
  auto c = s.trigger_on(id, r.on_changed());
  s.add_periodic("plant", 0.01, [&](const vsd::StepInfo& i) {
    if (i.step % 2 == 0) {
      r.set_speed(static_cast<double>(i.step));  // two changes, one reaction in the step
      r.set_axes(static_cast<int>(i.step));
    }
  });
  s.run_for(0.1);
  EXPECT_EQ(reactions, 5);
}

TEST(Scheduler, EventCascadesSettleOrFailClearly) {
  vsd::Scheduler s;
  int a_runs = 0;
  vsd::Scheduler::TaskId a = 0, b = 0;
  a = s.add_event_driven("a", [&](const vsd::StepInfo&) {
    if (++a_runs < 3) s.trigger(b);
  });
  b = s.add_event_driven("b", [&](const vsd::StepInfo&) { s.trigger(a); });
  s.trigger(a);
  s.step();
  EXPECT_EQ(a_runs, 3);
  const auto loop = s.add_event_driven("loop", [&](const vsd::StepInfo&) {});
  const auto self = s.add_event_driven("self", [&](const vsd::StepInfo&) { s.trigger(loop); });
  s.remove(loop);
  s.trigger(self);
  EXPECT_THAT([&] { s.step(); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("no scheduler task")));
  vsd::Scheduler t;
  const auto ping = t.add_event_driven("ping", [&](const vsd::StepInfo&) {});
  vsd::Scheduler::TaskId pong = 0;
  t.remove(ping);
  pong = t.add_event_driven("pong", [&](const vsd::StepInfo&) { t.trigger(pong); });
  t.trigger(pong);
  EXPECT_THAT([&] { t.step(); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("kept triggering")));
}

TEST(Scheduler, TasksMayRemoveThemselves) {
  vsd::Scheduler s;
  int runs = 0;
  vsd::Scheduler::TaskId id = 0;
  id = s.add_periodic("once", 0.01, [&](const vsd::StepInfo&) {
    ++runs;
    s.remove(id);
  });
  s.run_for(0.05);
  EXPECT_EQ(runs, 1);
  EXPECT_EQ(s.task_count(), 0u);
}

TEST(Scheduler, RejectsBadInput) {
  EXPECT_THROW(vsd::Scheduler(0.0), vsd::Error);
  vsd::Scheduler s;
  EXPECT_THROW(s.add_periodic("p", -1.0, [](const vsd::StepInfo&) {}), vsd::Error);
  EXPECT_THROW(s.add_periodic("p", 0.1, nullptr), vsd::Error);
  const auto id = s.add_periodic("p", 0.1, [](const vsd::StepInfo&) {});
  EXPECT_THAT([&] { s.trigger(id); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("periodic")));
  EXPECT_THROW(s.trigger(999), vsd::Error);
  EXPECT_EQ(s.task_name(id), "p");
  EXPECT_THROW(s.set_base_step(-2), vsd::Error);
}

}  // namespace
