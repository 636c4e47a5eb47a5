#include "vsd/dist/participant.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "dist_test_util.hpp"
#include "vsd/dist/module.hpp"

using namespace std::chrono_literals;
using testing::HasSubstr;
using vsd_dist_test::DArm;
using vsd_dist_test::options;
using vsd_dist_test::poll_all;

namespace {

struct SyncTest : testing::Test {
  std::uint32_t domain = vsd_dist_test::fresh_domain();
  vsd::Environment env_a{1};
  vsd::Environment env_b{2};
  vsd::SimState& a = env_a.main_state();
  vsd::SimState& b = env_b.main_state();
  std::vector<std::string> log_a, log_b;
};

TEST_F(SyncTest, AJoinerGetsTheModelAndBothSeeEachOthersChanges) {
  auto& arm = a.create<DArm>();
  arm.set_name("arm");
  arm.set_target(1.5);
  arm.set_note("robot side");
  a.database().add_child(arm);
  vsd::dist::Participant pa(a, options("robot", domain, true, &log_a));
  vsd::dist::Participant pb(b, options("ui", domain, false, &log_b));
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.synced(); })) << "no snapshot arrived";
  auto* arm_b = b.find<DArm>(arm.id());
  ASSERT_NE(arm_b, nullptr);
  EXPECT_EQ(arm_b->name(), "arm");
  EXPECT_EQ(arm_b->target(), 1.5);
  EXPECT_EQ(arm_b->note(), "");  // not Distributed
  EXPECT_EQ(b.database().children().size(), 1u);

  arm_b->set_target(2.5);  // the ui sets a target ...
  EXPECT_TRUE(pb.publish());
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return arm.target() == 2.5; }));
  arm.set_position(0.7);  // ... the robot moves
  auto& tool = a.create<vsd::Node>();
  arm.add_child(tool);
  arm.set_watched(&tool);
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return arm_b->position() == 0.7; }));
  std::string diff;
  ASSERT_NE(b.find(tool.id()), nullptr);
  EXPECT_EQ(arm_b->watched().get(), b.find(tool.id()));
  arm.set_note("");  // the only non-Distributed difference
  EXPECT_TRUE(a.equals(b, &diff)) << diff;
  EXPECT_EQ(pa.stats().bundles_applied, 1u);
  EXPECT_EQ(pb.stats().bundles_applied, 1u);
  EXPECT_TRUE(vsd_dist_test::contains(log_b, "synchronised from a snapshot of 'robot'"));
}

TEST_F(SyncTest, EveryPublishIsOneBundleAppliedInOrder) {
  auto& arm = a.create<DArm>();
  a.database().add_child(arm);
  vsd::dist::Participant pa(a, options("writer", domain, true));
  vsd::dist::Participant pb(b, options("reader", domain));
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.synced(); }));
  std::vector<int> seen;
  auto c = b.on_property_changed().connect([&](vsd::SimStateInstance& x, const vsd::MetaProperty& p) {
    if (p.name() == "counter") seen.push_back(static_cast<DArm&>(x).counter());
  });
  for (int i = 1; i <= 300; ++i) {
    arm.set_counter(i);
    arm.set_note("x" + std::to_string(i));  // not Distributed: never a bundle of its own
    ASSERT_TRUE(pa.publish());
  }
  arm.set_note("only local");
  EXPECT_FALSE(pa.publish());  // nothing Distributed changed: no sample
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return seen.size() >= 300; }));
  std::vector<int> expected(300);
  for (int i = 0; i < 300; ++i) expected[static_cast<std::size_t>(i)] = i + 1;
  EXPECT_EQ(seen, expected);
  EXPECT_EQ(pa.stats().bundles_sent, 300u);
  EXPECT_EQ(pb.stats().bundles_applied, 300u);
  EXPECT_EQ(pb.stats().duplicates, 0u);
}

TEST_F(SyncTest, ModuleStepsPublishAndApply) {
  auto& da = env_a.use<vsd::dist::Module>();
  auto& db = env_b.use<vsd::dist::Module>();
  auto& arm = a.create<DArm>();
  a.database().add_child(arm);
  auto& pa = da.join(a, options("robot", domain, true));
  auto& pb = db.join(b, options("ui", domain));
  EXPECT_EQ(da.participants().size(), 1u);
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (!pb.synced() && std::chrono::steady_clock::now() < end) {
    env_a.step();
    env_b.step();
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_TRUE(pb.synced());
  arm.set_target(9.0);
  DArm* arm_b = b.find<DArm>(arm.id());
  ASSERT_NE(arm_b, nullptr);
  while (arm_b->target() != 9.0 && std::chrono::steady_clock::now() < end) {
    env_a.step();
    env_b.step();
    std::this_thread::sleep_for(2ms);
  }
  EXPECT_EQ(arm_b->target(), 9.0);
  EXPECT_GE(pa.stats().bundles_sent, 1u);
}

TEST(ParticipantErrors, BadDomainIsAnError) {
  vsd::Environment env{3};
  auto o = options("x", 231);
  EXPECT_THAT([&] { vsd::dist::Participant p(env.main_state(), o); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("domain id 231 is out of range")));
}

// A state that records already for another reader (the web inspector's timeline) shares its recording:
// the participant publishes what changes after it joined, the other reader still sees every bundle, and
// leaving does not stop the other reader's recording.
TEST(Participant, SharesTheRecordingOfAStateWithOtherReaders) {
  const std::uint32_t domain = vsd_dist_test::fresh_domain();
  vsd::Environment ea{1}, eb{2};
  vsd::SimState& a = ea.main_state();
  vsd::SimState& b = eb.main_state();
  auto& node = a.create<vsd::Node>();
  a.database().add_child(node);
  a.start_recording();
  std::vector<std::size_t> seen;
  auto reader = a.on_bundle().connect([&](const vsd::Transaction& t) { seen.push_back(t.size()); });
  node.set_name("before joining");
  {
    vsd::dist::Participant pa(a, options("robot", domain, true));
    vsd::dist::Participant pb(b, options("ui", domain));
    ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.synced(); }));
    node.set_name("after joining");
    (void)a.take_recording();  // the other reader cuts at the end of its step: the participant still gets it
    ASSERT_TRUE(poll_all({&pa, &pb}, [&] {
      auto* n = b.find<vsd::Node>(node.id());
      return n != nullptr && n->name() == "after joining";
    }));
  }
  EXPECT_TRUE(a.recording()) << "the participant did not start the recording, so it does not stop it";
  EXPECT_GE(seen.size(), 2u) << "the other reader saw the bundle before joining and the one after";
}

TEST(ParticipantErrors, BadConfigurationIsAnError) {
  vsd::Environment env{3};
  auto o = options("x", vsd_dist_test::fresh_domain());
  o.config = "<CycloneDDS><Domain><General><NoSuchElement>1</NoSuchElement></General></Domain></CycloneDDS>";
  EXPECT_THAT([&] { vsd::dist::Participant p(env.main_state(), o); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("dist: creating the DDS domain")));
  EXPECT_FALSE(env.main_state().recording());
}

}  // namespace
