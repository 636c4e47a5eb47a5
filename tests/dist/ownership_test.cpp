// Ownership: the robot controller owns what it commands, the user interface what it sets; a write by
// another participant is rejected whole and reported to the writer and the owner.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "three_participants.hpp"

using namespace std::chrono_literals;
using testing::HasSubstr;
using vsd_dist_test::DArm;

namespace {

struct OwnershipTest : vsd_dist_test::ThreeParticipants {
  DArm* arm = nullptr;

  void populate() override {
    arm = &r.create<DArm>();
    r.database().add_child(*arm);
    arm->set_target(1.0);
    arm->set_position(1.0);
  }
  DArm& ui_arm() { return *u.find<DArm>(arm->id()); }
  DArm& other_arm() { return *c.find<DArm>(arm->id()); }
};

TEST_F(OwnershipTest, AKnownClaimUndoesTheWholeBundleAtTheWriterAndTellsTheOwner) {
  robot->claim(*arm, "position");
  EXPECT_EQ(robot->owner(arm->id(), "position"), robot->id());
  ASSERT_TRUE(settle([&] { return ui->owner(arm->id(), "position") == robot->id(); }));
  EXPECT_EQ(ui->owner(arm->id(), "target"), 0u);

  ui_arm().set_target(2.0);    // fine on its own ...
  ui_arm().set_position(5.0);  // ... but this bundle also writes what the robot owns
  EXPECT_FALSE(ui->publish());
  EXPECT_EQ(ui_arm().position(), 1.0);  // undone whole, here
  EXPECT_EQ(ui_arm().target(), 1.0);
  ASSERT_EQ(seen_u.size(), 1u);
  EXPECT_EQ(seen_u[0].writer, ui->id());
  EXPECT_EQ(seen_u[0].owner, robot->id());
  EXPECT_EQ(seen_u[0].property, "position");
  EXPECT_EQ(seen_u[0].text, "write by 'ui' to #" + std::to_string(arm->id()) +
                                ".position, owned by 'robot', rejected (undone before it was sent)");
  ASSERT_TRUE(settle([&] { return seen_r.size() == 1; })) << "the owner was not told";
  EXPECT_EQ(seen_r[0].writer, ui->id());
  EXPECT_EQ(seen_r[0].property, "position");
  EXPECT_EQ(arm->target(), 1.0);
  EXPECT_EQ(other_arm().target(), 1.0);

  ui_arm().set_target(3.0);  // a write to what nobody owns still goes through
  ASSERT_TRUE(ui->publish());
  ASSERT_TRUE(settle([&] { return arm->target() == 3.0 && other_arm().target() == 3.0; }));
}

TEST_F(OwnershipTest, AWriteBeforeTheClaimArrivedIsRejectedEverywhereAndTheWriterResyncs) {
  robot->claim(*arm, "position");  // sent (stamp 1), but the ui has not read it yet ...
  ui_arm().set_target(2.0);        // ... and writes: bundle 1 (stamp 1) is unowned, fine everywhere;
  ASSERT_TRUE(ui->publish());
  ui_arm().set_position(7.0);  // bundle 2 (stamp 2) comes after the claim in the order every replica uses
  ASSERT_TRUE(ui->publish());
  ASSERT_TRUE(settle([&] { return !seen_r.empty() && ui->synced() && ui->stats().resyncs == 1; }));
  ASSERT_TRUE(settle([&] { return !seen_u.empty() && other_arm().position() == 1.0; }));
  EXPECT_EQ(arm->position(), 1.0);      // rejected at the owner
  EXPECT_EQ(ui_arm().position(), 1.0);  // the writer took the shared state back
  EXPECT_EQ(arm->target(), 2.0);        // its earlier bundle stands
  EXPECT_EQ(other_arm().target(), 2.0);
  EXPECT_EQ(ui_arm().target(), 2.0);
  EXPECT_EQ(seen_r[0].seq, 2u);
  EXPECT_EQ(seen_u[0].seq, 2u);
  EXPECT_EQ(seen_u[0].owner, robot->id());
  EXPECT_TRUE(vsd_dist_test::contains(log_u, "resynchronising from a snapshot of 'robot'"));
  EXPECT_TRUE(vsd_dist_test::contains(log_r, "owned by 'robot', rejected (bundle 2)"));
  std::string diff;
  EXPECT_TRUE(r.equals(u, &diff)) << diff;
  EXPECT_TRUE(r.equals(c, &diff)) << diff;
  // The owner's own writes keep flowing.
  arm->set_position(2.0);
  ASSERT_TRUE(settle([&] { return ui_arm().position() == 2.0 && other_arm().position() == 2.0; }));
}

TEST_F(OwnershipTest, AnOwnedInstanceCannotBeDeletedByAnother) {
  robot->claim(*arm);
  ASSERT_TRUE(settle([&] { return ui->owner(arm->id()) == robot->id(); }));
  EXPECT_EQ(ui->owner(arm->id(), "target"), robot->id());  // the instance's owner owns its properties
  u.destroy(ui_arm());
  EXPECT_FALSE(ui->publish());
  ASSERT_NE(u.find(arm->id()), nullptr);  // undone: the arm is back
  EXPECT_EQ(ui_arm().target(), 1.0);
  EXPECT_EQ(u.database().children().size(), 1u);
  ASSERT_EQ(seen_u.size(), 1u);
  EXPECT_EQ(seen_u[0].property, "");
  robot->release(*arm);
  ASSERT_TRUE(settle([&] { return ui->owner(arm->id()) == 0; }));
  u.destroy(ui_arm());
  ASSERT_TRUE(ui->publish());
  const vsd::Id id = arm->id();  // arm is deleted by the bundle
  ASSERT_TRUE(settle([&] { return r.find(id) == nullptr && c.find(id) == nullptr; }));
}

TEST_F(OwnershipTest, ClaimErrors) {
  EXPECT_THAT([&] { robot->claim(*arm, "nope"); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr("class 'DArm' has no property 'nope'")));
  robot->claim(*arm, "position");
  ASSERT_TRUE(settle([&] { return ui->owner(arm->id(), "position") == robot->id(); }));
  EXPECT_THAT([&] { ui->claim(ui_arm(), "position"); },
              testing::ThrowsMessage<vsd::Error>(HasSubstr(".position is owned by 'robot'")));
  ui->claim(ui_arm(), "target");  // the user interface owns the set-point
  ASSERT_TRUE(settle([&] { return robot->owner(arm->id(), "target") == ui->id(); }));
  EXPECT_EQ(robot->participant_name(ui->id()), "ui");
  arm->set_target(4.0);  // now the robot may not write it
  EXPECT_FALSE(robot->publish());
  EXPECT_EQ(arm->target(), 1.0);
}

}  // namespace
