#include "vsd/core/environment.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>
#include <thread>

#include "test_classes.hpp"

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

}  // namespace
