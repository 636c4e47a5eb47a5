// PNML nets imported into the database as SOML++ nets: the places hold the initial marking, and the SOML++
// executor plays the same firing rule as PtNet — every firing it makes is checked against a PtNet mirror,
// and both agree on when a dead marking is reached.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/analysis/pnml.hpp"
#include "vsd/analysis/soml_net.hpp"
#include "vsd/soml/module.hpp"
#include "vsd/soml/net_classes.hpp"
#include "vsd/soml/runtime.hpp"

namespace an = vsd::analysis;

namespace {

const std::string kImportData = VSD_ANALYSIS_TEST_DATA_DIR;

class Import : public ::testing::TestWithParam<const char*> {};

TEST_P(Import, TheExecutorPlaysThePtNetFiringRule) {
  const an::PnmlImport pnml = an::read_pnml_file(kImportData + "/" + GetParam() + ".pnml");
  // The mirror has the ids the database nodes are named by (ids that are not identifiers are renamed),
  // in the same order as the PNML net.
  const an::PtNet mirror = an::read_soml_net(an::write_soml(pnml.net)).net;

  vsd::Registry registry;
  vsd::Environment env(0, registry);
  auto& soml = env.use<vsd::soml::Module>();
  vsd::soml::Program& program = an::import_net(soml, env.main_state(), pnml.net);

  std::vector<vsd::soml::Place*> places;
  for (const auto& p : mirror.places()) {
    places.push_back(program.place(p.id));
    ASSERT_NE(places.back(), nullptr) << p.id;
  }
  auto database_marking = [&] {
    std::vector<std::uint32_t> m;
    for (const auto* p : places) m.push_back(static_cast<std::uint32_t>(p->tokens()));
    return m;
  };
  std::vector<std::uint32_t> marking = mirror.initial_marking();
  ASSERT_EQ(database_marking(), marking);

  std::size_t checked = 0;
  program.on_firing([&](const vsd::soml::Firing& f) {
    const auto t = mirror.find_transition(f.transition->name());
    ASSERT_TRUE(t) << f.transition->name();
    ASSERT_TRUE(mirror.enabled(*t, marking)) << "step " << f.step << ": " << f.transition->name();
    mirror.fire(*t, marking);
    ASSERT_EQ(database_marking(), marking) << "step " << f.step << ": " << f.transition->name();
    ++checked;
  });
  const std::uint64_t fired = program.step(400);
  EXPECT_EQ(fired, checked);
  EXPECT_GT(fired, 0u);  // every one of these nets starts with an enabled transition
  bool any = false;
  for (std::uint32_t t = 0; t < mirror.transition_count(); ++t) any = any || mirror.enabled(t, marking);
  EXPECT_EQ(program.enabled_any(), any);
  if (fired < 400) {
    EXPECT_FALSE(any);  // quiet before the budget: a dead marking in both
  }
}

INSTANTIATE_TEST_SUITE_P(MccNets, Import,
                         ::testing::Values("ResAllocation-PT-R002C002", "Eratosthenes-PT-010", "TokenRing-PT-005",
                                           "Philosophers-PT-000005", "SharedMemory-PT-000005", "FMS-PT-00002",
                                           "Dekker-PT-010", "Peterson-PT-2"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n)
                             if (c == '-') c = '_';
                           return n;
                         });

TEST(ImportNet, IdsThatAreNotIdentifiersAndInhibitorsAndWeights) {
  an::PtNet net("odd");
  const auto a = net.add_place("a-1", {}, 3);
  const auto b = net.add_place("b", {}, 0);
  const auto t = net.add_transition("move.2");
  net.add_input(t, a, 2);
  net.add_output(t, b, 1);
  net.add_inhibitor(t, b, 2);
  std::vector<std::string> notes;
  vsd::Registry registry;
  vsd::Environment env(0, registry);
  auto& soml = env.use<vsd::soml::Module>();
  vsd::soml::Program& program = an::import_net(soml, env.main_state(), net, &notes);
  EXPECT_EQ(notes.size(), 2u);
  ASSERT_NE(program.place("a_1"), nullptr);
  EXPECT_EQ(program.place("a_1")->tokens(), 3);
  EXPECT_EQ(program.run_until_quiet(), 1u);  // 3 -> 1 token: a needs 2 again
  EXPECT_EQ(program.place("a_1")->tokens(), 1);
  EXPECT_EQ(program.place("b")->tokens(), 1);
  // The module runs it in the environment's steps like any script.
  EXPECT_EQ(soml.programs().size(), 1u);
}

}  // namespace
