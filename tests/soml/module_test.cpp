// vsd::soml::Module on the states of an Environment: programs belong to their state, nets fire only
// where the module steps the state, Service::none drops the programs (their content stays), and a
// loaded program watches only the class properties its conditions read.
#include "vsd/soml/module.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../core/test_util.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace {

using testing::ElementsAre;
using testing::HasSubstr;
using vsd::Service;
using vsd::soml::Program;
using vsd_test::error_of;

// One token moves from `a` to `b` once `n` reaches the limit.
const char* const kNet = R"(
object c {
  int n = 0;
  place a = 1;
  place b;
  transition t { when n >= 2; }
  arrow a -> t;
  arrow t -> b;
}
)";

struct SomlModuleTest : testing::Test {
  vsd::Registry reg;
  vsd::Environment env{0, reg};
  vsd::soml::Module& soml = env.use<vsd::soml::Module>();
  static void open(Program& p) { p.object("c")->set("n", vsd::Value(std::int64_t{2})); }
  static std::int64_t done(Program& p) { return p.place("b", p.object("c"))->count(); }
};

TEST_F(SomlModuleTest, NetsFireOnlyOnTheStatesTheModuleSteps) {
  vsd::SimState& what_if = env.create_state("what-if");  // served as `derived` by default
  EXPECT_EQ(env.service(soml, what_if), Service::derived);
  Program& main_program = soml.load(env.main_state(), "cell.soml", kNet);
  Program& copy_program = soml.load(what_if, "cell.soml", kNet);  // the same script: the same classes
  EXPECT_THAT(soml.programs(env.main_state()), ElementsAre(&main_program));
  EXPECT_THAT(soml.programs(what_if), ElementsAre(&copy_program));
  EXPECT_THAT(soml.programs(), ElementsAre(&main_program, &copy_program));
  open(main_program);
  open(copy_program);
  env.step();
  EXPECT_EQ(done(main_program), 1);
  EXPECT_EQ(done(copy_program), 0) << "a derived state's nets do not fire";
  env.set_service(soml, what_if, Service::stepped);
  env.step();
  EXPECT_EQ(done(copy_program), 1) << "stepped now: the test that waited runs";
}

TEST_F(SomlModuleTest, ServiceNoneDropsTheProgramsAndKeepsTheirContent) {
  vsd::SimState& other = env.create_state("other");
  env.set_service(soml, other, Service::stepped);
  Program& p = soml.load(other, "cell.soml", kNet);
  const vsd::Id c = p.object("c")->id();
  env.set_service(soml, other, Service::none);
  EXPECT_TRUE(soml.programs(other).empty());
  ASSERT_NE(other.find(c), nullptr) << "the run stays in the database";
  EXPECT_THAT(error_of([&] { soml.load(other, "cell.soml", kNet); }), HasSubstr("does not serve the state 'other'"));
  // Served again: the run continues where it stood.
  env.set_service(soml, other, Service::stepped);
  Program& again = soml.adopt(other, "cell.soml", kNet);
  EXPECT_EQ(again.object("c")->id(), c);
  open(again);
  env.step();
  EXPECT_EQ(done(again), 1);
}

TEST_F(SomlModuleTest, RemovingAStateTakesItsPrograms) {
  vsd::SimState& doomed = env.create_state("doomed");
  env.set_service(soml, doomed, Service::stepped);
  open(soml.load(doomed, "cell.soml", kNet));
  Program& kept = soml.load(env.main_state(), "cell.soml", kNet);
  env.remove_state(doomed);
  EXPECT_THAT(soml.programs(), ElementsAre(&kept));
  open(kept);
  env.step();
  EXPECT_EQ(done(kept), 1);
}

TEST_F(SomlModuleTest, AStateOfAnotherEnvironmentIsRefused) {
  vsd::Environment elsewhere{1, reg};
  EXPECT_THAT(error_of([&] { soml.load(elsewhere.main_state(), "cell.soml", kNet); }),
              HasSubstr("not of the Environment that uses this module"));
}

// The executor hears the class properties its conditions read, and nothing else: instances of other
// classes keep the setter's one-branch fast path while the program is loaded.
TEST_F(SomlModuleTest, AProgramWatchesOnlyWhatItsConditionsRead) {
  vsd::SimState& s = env.main_state();
  auto& bystander = s.create<vsd::Node>();
  s.database().add_child(bystander);
  Program& p = soml.load(s, "cell.soml", kNet);
  EXPECT_EQ(p.run_until_quiet(), 0u);
  EXPECT_TRUE(p.object("c")->observed()) << "its condition read c.n";
  auto& later = s.create<vsd::Node>();
  EXPECT_FALSE(later.observed());
  const auto tests = p.condition_tests();
  // The load's savepoint recorded for a while: an instance made before finds out on its next set that
  // nobody listens any more, and is back on the fast path.
  bystander.set_name("renamed");  // not read by any test
  EXPECT_FALSE(bystander.observed());
  EXPECT_EQ(p.run_until_quiet(), 0u);
  EXPECT_EQ(p.condition_tests(), tests);
  open(p);  // read: re-tested and fires
  EXPECT_EQ(p.run_until_quiet(), 1u);
  EXPECT_EQ(done(p), 1);
}

}  // namespace

namespace {

// A program that goes while its instances stay (its state lives on) leaves its classes defined, and with
// them the enums their methods name: the Registry checks properties, not method signatures. Once the
// instances are gone, the module sweeps both when it goes.
TEST(SomlModuleLifetime, EnumsNamedByMethodsOfClassesThatStayStayToo) {
  vsd::Registry reg;
  {
    vsd::Environment env{0, reg};
    auto& soml = env.use<vsd::soml::Module>();
    vsd::SimState& other = env.create_state("other");
    env.set_service(soml, other, Service::stepped);
    soml.load(other, "modes.soml", R"(
enum Mode { Idle, Busy }
object m {
  int n = 0;
  Mode flip(Mode x) { if (x == Mode::Idle) return Mode::Busy; return Mode::Idle; }
}
)");
    env.set_service(soml, other, Service::none);  // the program goes, its objects stay
    ASSERT_NE(reg.find_class_exact("soml::m"), nullptr);
    EXPECT_NE(reg.find_type("soml::Mode"), nullptr) << "the class that stays names it in flip()";
  }
  EXPECT_EQ(reg.find_class_exact("soml::m"), nullptr) << "swept when the module went";
  EXPECT_EQ(reg.find_type("soml::Mode"), nullptr);
}

}  // namespace
