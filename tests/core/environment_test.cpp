#include "vsd/core/environment.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <thread>

#include "test_classes.hpp"

using testing::ElementsAre;
using testing::HasSubstr;

namespace {

// A test module: registers a class and a periodic algorithm that works on the database's instances.
class TCounter : public vsd::Node {
  VSD_INSTANCE(TCounter, vsd::Node)
  VSD_PROPERTY(int, ticks, 0)
};

class CountingModule : public vsd::Module {
 public:
  std::string_view name() const override { return "counting"; }
  void register_types(vsd::Registry& r) override {
    r.add<TCounter>();
    ++registered;
  }
  void attach(vsd::Environment& env) override {
    task = env.scheduler().add_periodic("count", 0.02, [&env](const vsd::StepInfo&) {
      for (TCounter* c : env.main_state().index().of<TCounter>()) c->set_ticks(c->ticks() + 1);
    });
    ++attached;
  }
  void detach(vsd::Environment&) override { ++*detached; }
  int registered = 0;
  int attached = 0;
  int* detached = nullptr;
  vsd::Scheduler::TaskId task = 0;
};

class OtherModule : public vsd::Module {
 public:
  std::string_view name() const override { return "other"; }
  void attach(vsd::Environment& env) override { env.use<CountingModule>(); }  // modules may use modules
};

TEST(Environment, OwnsAMainStateAndMore) {
  vsd::Environment env;
  EXPECT_EQ(env.main_state().name(), "main");
  auto& extra = env.create_state("loader");
  EXPECT_EQ(env.states().size(), 2u);
  env.remove_state(extra);
  EXPECT_EQ(env.states().size(), 1u);
  EXPECT_THAT([&] { env.remove_state(env.main_state()); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("main")));
}

TEST(Environment, IdsAreUniqueAcrossStatesAndThreads) {
  vsd::Environment env;
  auto& a = env.create_state("a");
  auto& b = env.create_state("b");
  std::vector<vsd::Id> ia, ib;
  std::thread ta([&] {
    for (int i = 0; i < 2000; ++i) ia.push_back(a.create<vsd::Node>().id());
  });
  std::thread tb([&] {
    for (int i = 0; i < 2000; ++i) ib.push_back(b.create<vsd::Node>().id());
  });
  ta.join();
  tb.join();
  std::set<vsd::Id> all(ia.begin(), ia.end());
  all.insert(ib.begin(), ib.end());
  EXPECT_EQ(all.size(), 4000u);
}

TEST(Environment, SiteNumbersSeparateIdSpaces) {
  vsd::Environment here(1), there(2);
  const vsd::Id a = here.main_state().create<vsd::Node>().id();
  const vsd::Id b = there.main_state().create<vsd::Node>().id();
  EXPECT_EQ(a >> 48, 1u);
  EXPECT_EQ(b >> 48, 2u);
}

TEST(Environment, ModulesRegisterAttachOnceAndDetach) {
  int detached = 0;
  {
    vsd::Environment env;
    auto& m = env.use<CountingModule>();
    m.detached = &detached;
    EXPECT_EQ(&env.use<CountingModule>(), &m) << "use is idempotent";
    EXPECT_EQ(m.registered, 1);
    EXPECT_EQ(m.attached, 1);
    EXPECT_EQ(env.module<CountingModule>(), &m);
    EXPECT_EQ(env.module<OtherModule>(), nullptr);
    EXPECT_NE(vsd::Registry::global().find_class("TCounter"), nullptr);

    auto& c = env.main_state().create<TCounter>();
    env.run_for(0.1);  // 10 steps of 10 ms, the task runs every 2
    EXPECT_EQ(c.ticks(), 5);
    EXPECT_EQ(env.scheduler().steps(), 10u);
    EXPECT_NEAR(env.time(), 0.1, 1e-12);
  }
  EXPECT_EQ(detached, 1);
}

TEST(Environment, ModulesMayUseOtherModules) {
  int detached = 0;
  vsd::Environment env;
  env.use<OtherModule>();
  ASSERT_NE(env.module<CountingModule>(), nullptr);
  env.module<CountingModule>()->detached = &detached;
  EXPECT_EQ(env.modules().size(), 2u);
}

TEST(Environment, IsAnInstanceWithCallableMethods) {
  vsd::Environment env;
  EXPECT_TRUE(env.is_a(vsd::Instance::static_meta()));
  env.call("step");
  env.call("run_for", {vsd::Value(0.05)});
  EXPECT_EQ(env.scheduler().steps(), 6u);
  EXPECT_THROW(env.call("run_for", {vsd::Value("soon")}), vsd::Error);
}

// ---- how modules serve states --------------------------------------------------------------------------

// A module that logs every change of service and keeps a per-state entry in the state's context.
struct ServingLog {
  std::vector<std::string> lines;
};

class ServingModule : public vsd::Module {
 public:
  explicit ServingModule(ServingLog& log, std::string name = "serving") : log_(&log), name_(std::move(name)) {}
  std::string_view name() const override { return name_; }
  struct PerState {
    PerState(ServingLog& log, std::string tag) : log(&log), tag(std::move(tag)) {}
    ~PerState() { log->lines.push_back(tag + " data gone"); }
    ServingLog* log;
    std::string tag;
  };
  void serve(vsd::SimState& state, vsd::Service from, vsd::Service to) override {
    if (fail_on == state.name()) throw vsd::Error("cannot serve " + state.name());
    log_->lines.push_back(name_ + " " + state.name() + " " + vsd::service_name(from) + "->" +
                          vsd::service_name(to));
    if (from == vsd::Service::none) state.context().emplace<PerState>(*log_, name_ + " " + state.name());
    if (to == vsd::Service::none) state.context().erase<PerState>();
  }
  std::string fail_on;

 private:
  ServingLog* log_;
  std::string name_;
};

class DependentModule : public vsd::Module {
 public:
  explicit DependentModule(ServingLog& log) : log_(&log) {}
  std::string_view name() const override { return "dependent"; }
  void attach(vsd::Environment& env) override { env.use<ServingModule>(*log_); }
  void serve(vsd::SimState& state, vsd::Service from, vsd::Service to) override {
    log_->lines.push_back(std::string("dependent ") + state.name() + " " + vsd::service_name(from) + "->" +
                          vsd::service_name(to));
  }

 private:
  ServingLog* log_;
};

TEST(Environment, ModulesServeEveryStateExistingAndLater) {
  ServingLog log;
  {
    vsd::Environment env;
    auto& early = env.create_state("early");
    auto& m = env.use<ServingModule>(log);
    auto& late = env.create_state("late");
    EXPECT_EQ(env.service(m, env.main_state()), vsd::Service::stepped);
    EXPECT_EQ(env.service(m, early), vsd::Service::derived);
    EXPECT_EQ(env.service(m, late), vsd::Service::derived);
    EXPECT_NE(late.context().find<ServingModule::PerState>(), nullptr);
    EXPECT_THAT(env.states_served(m, vsd::Service::derived), ElementsAre(&env.main_state(), &early, &late));
    EXPECT_THAT(env.states_served(m, vsd::Service::stepped), ElementsAre(&env.main_state()));
    env.set_service<ServingModule>(late, vsd::Service::stepped);
    EXPECT_THAT(env.states_served(m, vsd::Service::stepped), ElementsAre(&env.main_state(), &late));
    env.remove_state(early);
    EXPECT_THAT(log.lines, ElementsAre("serving main none->stepped", "serving early none->derived",
                                       "serving late none->derived", "serving late derived->stepped",
                                       "serving early derived->none", "serving early data gone"));
    log.lines.clear();
  }
  EXPECT_THAT(log.lines, ElementsAre("serving late stepped->none", "serving late data gone",
                                     "serving main stepped->none", "serving main data gone"));
}

TEST(Environment, AModuleIsServedAfterTheModulesItUsesAndReleasedBefore) {
  ServingLog log;
  {
    vsd::Environment env;
    env.use<DependentModule>(log);
    env.create_state("copy");
  }
  EXPECT_THAT(log.lines, ElementsAre("serving main none->stepped", "dependent main none->stepped",
                                     "serving copy none->derived", "dependent copy none->derived",
                                     "dependent copy derived->none", "serving copy derived->none",
                                     "serving copy data gone", "dependent main stepped->none",
                                     "serving main stepped->none", "serving main data gone"));
}

TEST(Environment, AStateThatAModuleCannotServeIsNotCreated) {
  ServingLog log;
  vsd::Environment env;
  env.use<ServingModule>(log, "first");
  auto& second = static_cast<ServingModule&>(*const_cast<vsd::Module*>(env.modules().back()));
  (void)second;
  class Failing : public vsd::Module {
   public:
    std::string_view name() const override { return "failing"; }
    void serve(vsd::SimState& s, vsd::Service, vsd::Service to) override {
      if (s.name() == "bad" && to != vsd::Service::none) throw vsd::Error("no service for bad");
    }
  };
  env.use<Failing>();
  log.lines.clear();
  EXPECT_THAT([&] { env.create_state("bad"); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("no service")));
  EXPECT_EQ(env.states().size(), 1u);
  EXPECT_THAT(log.lines, ElementsAre("first bad none->derived", "first bad derived->none", "first bad data gone"));
}

TEST(Environment, ServicesOfUnknownModulesAndStatesAreRefused) {
  ServingLog log;
  vsd::Environment env, other;
  auto& m = env.use<ServingModule>(log);
  EXPECT_THAT([&] { env.set_service<CountingModule>(env.main_state(), vsd::Service::none); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("not used")));
  EXPECT_THAT([&] { env.set_service(m, other.main_state(), vsd::Service::none); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("does not belong")));
  EXPECT_EQ(env.service(m, other.main_state()), vsd::Service::none);
  env.set_service(env.main_state(), vsd::Service::none);
  EXPECT_EQ(env.service(m, env.main_state()), vsd::Service::none);
  EXPECT_TRUE(env.states_served(m, vsd::Service::derived).empty());
}

// ---- the state's context ----------------------------------------------------------------------------------

TEST(StateContext, EntriesAreTypedAndDieBeforeTheInstances) {
  struct Probe {
    explicit Probe(vsd::SimState& s, std::vector<std::string>& log) : state(&s), log(&log) {}
    ~Probe() { log->push_back("probe gone, instances " + std::to_string(state->size())); }
    vsd::SimState* state;
    std::vector<std::string>* log;
  };
  struct Other {
    int value = 7;
  };
  std::vector<std::string> log;
  {
    vsd::Environment env;
    auto& s = env.create_state("s");
    s.create<vsd::Node>();
    auto& p = s.context().emplace<Probe>(s, log);
    EXPECT_EQ(s.context().find<Probe>(), &p);
    EXPECT_EQ(s.context().find<Other>(), nullptr);
    EXPECT_THAT([&] { (void)s.context().get<Other>(); }, testing::ThrowsMessage<vsd::Error>(HasSubstr("no entry")));
    EXPECT_THAT([&] { s.context().emplace<Probe>(s, log); },
                testing::ThrowsMessage<vsd::Error>(HasSubstr("already has")));
    EXPECT_EQ(s.context().get_or_emplace<Other>().value, 7);
    EXPECT_EQ(s.context().size(), 2u);
    EXPECT_TRUE(s.context().erase<Other>());
    EXPECT_FALSE(s.context().erase<Other>());
    EXPECT_EQ(env.main_state().context().find<Probe>(), nullptr) << "per state";
  }
  EXPECT_THAT(log, ElementsAre("probe gone, instances 2"));
}

// ---- signals are connected, not emitted, by others ---------------------------------------------------------

template <class S>
concept CanEmitInstance = requires(S s, vsd::SimStateInstance& i) { s.emit(i); };
static_assert(!CanEmitInstance<decltype(std::declval<vsd::SimState&>().on_deleted())>,
              "nobody but the SimState may announce a deletion");
static_assert(!CanEmitInstance<decltype(std::declval<vsd::SimState&>().on_created())>);
static_assert(!CanEmitInstance<decltype(std::declval<vsd::ElementIndex&>().on_deleted(
                  vsd::Node::static_meta()))>);

TEST(Sink, ConnectsToTheSignalItStandsFor) {
  vsd::Environment env;
  auto& s = env.main_state();
  int created = 0;
  auto sink = s.on_created();
  EXPECT_FALSE(sink.has_listeners());
  auto c = sink.connect([&](vsd::SimStateInstance&) { ++created; });
  EXPECT_TRUE(s.on_created().has_listeners());
  EXPECT_EQ(s.on_created().size(), 1u);
  s.create<vsd::Node>();
  EXPECT_EQ(created, 1);
}

}  // namespace
