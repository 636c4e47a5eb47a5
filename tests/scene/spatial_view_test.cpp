// SpatialView: grabbing and releasing keep world poses; carried objects follow their supports through
// the frame signals, whatever moved the support; objects moved by others keep their relation.
#include "vsd/scene/spatial_view.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "vsd/core.hpp"
#include "vsd/io.hpp"
#include "vsd/scene.hpp"

namespace vsd::scene {
namespace {

Eigen::Isometry3d pose(double x, double y, double z, double yaw = 0) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translation() = Eigen::Vector3d(x, y, z);
  f.rotate(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  return f;
}

void expect_pose(const Eigen::Isometry3d& actual, const Eigen::Isometry3d& expected) {
  EXPECT_TRUE(actual.isApprox(expected, 1e-12)) << "actual\n"
                                                << actual.matrix() << "\nexpected\n"
                                                << expected.matrix();
}

class SpatialViewTest : public ::testing::Test {
 protected:
  void SetUp() override { env.use<Module>(); }
  Node3D& node(const std::string& name, const Eigen::Isometry3d& frame, vsd::Node* parent = nullptr) {
    auto& n = s.create<Node3D>();
    n.set_name(name);
    n.set_frame(frame);
    (parent != nullptr ? *parent : static_cast<vsd::Node&>(s.database())).add_child(n);
    return n;
  }
  Environment env;
  SimState& s = env.main_state();
};

TEST_F(SpatialViewTest, GrabbedObjectFollowsTheGripperAndStaysWhereItIsReleased) {
  // The gripper hangs below an arm: moving the arm moves the gripper (no signal on the gripper itself).
  Node3D& arm = node("arm", pose(0, 0, 1));
  Node3D& gripper = node("gripper", pose(0.5, 0, 0, 0.3), &arm);
  Node3D& cup = node("cup", pose(0.6, 0.1, 0.9, 1.0));
  SpatialView view(s);
  std::vector<std::string> added, removed;
  auto c1 = view.on_added().connect([&](vsd::Node& n) { added.push_back(n.name()); });
  auto c2 = view.on_removed().connect([&](vsd::Node& n) { removed.push_back(n.name()); });

  const Eigen::Isometry3d at_grab = cup.world_frame();
  view.relate(cup, gripper, SpatialRelation::GrabbedBy);
  expect_pose(cup.world_frame(), at_grab);  // grabbing moves nothing
  EXPECT_EQ(added, std::vector<std::string>{"cup"});
  EXPECT_EQ(view.support_of(cup), &gripper);
  EXPECT_EQ(view.relation_of(cup), SpatialRelation::GrabbedBy);
  EXPECT_EQ(cup.parent(), &s.database());  // the spanning tree is untouched
  const Eigen::Isometry3d offset = gripper.world_frame().inverse() * at_grab;

  arm.set_frame(pose(2, 1, 1.5, -0.7));  // through the setter of an ancestor
  expect_pose(cup.world_frame(), gripper.world_frame() * offset);
  gripper.set_frame(pose(0.2, 0, -0.3, 0.9));  // the gripper itself
  expect_pose(cup.world_frame(), gripper.world_frame() * offset);

  const Eigen::Isometry3d at_release = cup.world_frame();
  EXPECT_TRUE(view.release(cup));
  expect_pose(cup.world_frame(), at_release);  // releasing moves nothing
  EXPECT_EQ(removed, std::vector<std::string>{"cup"});
  arm.set_frame(pose(-3, 0, 1));
  expect_pose(cup.world_frame(), at_release);  // no longer follows
  EXPECT_FALSE(view.release(cup));
  EXPECT_EQ(view.size(), 0u);
}

TEST_F(SpatialViewTest, ChainsFollowAndObjectsMovedByOthersKeepTheirRelation) {
  Node3D& table = node("table", pose(0, 0, 0));
  Node3D& tray = node("tray", pose(0, 0, 0.8));
  Node3D& cup = node("cup", pose(0.1, 0, 0.85));
  Node3D& gripper = node("gripper", pose(5, 5, 2));
  SpatialView view(s);
  view.relate(tray, table, SpatialRelation::LiesOn);
  view.relate(cup, tray, SpatialRelation::LiesOn);
  EXPECT_EQ(view.carried_closure(table), (std::vector<Node3D*>{&tray, &cup}));
  std::vector<vsd::Node*> order;
  view.for_each([&](vsd::Node& n) { order.push_back(&n); });
  EXPECT_EQ(order, (std::vector<vsd::Node*>{&tray, &cup}));

  // the table is carried away: tray and cup follow
  table.set_frame(pose(1, 0, 0, M_PI / 2));
  expect_pose(tray.world_frame(), pose(1, 0, 0, M_PI / 2) * pose(0, 0, 0.8));
  expect_pose(cup.world_frame(), pose(1, 0, 0, M_PI / 2) * pose(0.1, 0, 0.85));

  // the cup is pushed across the tray by someone else: it still lies on the tray, at its new place
  const Eigen::Isometry3d pushed = tray.world_frame() * pose(-0.2, 0.1, 0.05);
  cup.set_world_frame(pushed);
  EXPECT_EQ(view.support_of(cup), &tray);
  EXPECT_TRUE(view.offset_of(cup)->isApprox(pose(-0.2, 0.1, 0.05), 1e-12));

  // the gripper grabs the tray (replacing "lies on the table"): table moves stay behind
  const Eigen::Isometry3d tray_before = tray.world_frame();
  view.relate(tray, gripper, SpatialRelation::GrabbedBy);
  EXPECT_EQ(view.size(), 2u);
  table.set_frame(pose(9, 9, 0));
  expect_pose(tray.world_frame(), tray_before);
  gripper.set_frame(pose(5, 5, 3));  // up by 1: tray and cup come along
  expect_pose(tray.world_frame(), pose(0, 0, 1) * tray_before);
  expect_pose(cup.world_frame(), pose(0, 0, 1) * pushed);

  // released onto a shelf: nothing jumps, and from then on the shelf carries it
  Node3D& shelf = node("shelf", pose(4, 5, 1.9));
  const Eigen::Isometry3d tray_at_release = tray.world_frame();
  view.relate(tray, shelf, SpatialRelation::LiesOn);
  expect_pose(tray.world_frame(), tray_at_release);
  gripper.set_frame(pose(0, 0, 0));
  expect_pose(tray.world_frame(), tray_at_release);
  shelf.set_frame(pose(4, 6, 1.9));
  expect_pose(tray.world_frame(), pose(0, 1, 0) * tray_at_release);
  expect_pose(cup.world_frame(), pose(0, 1, 0) * pose(0, 0, 1) * pushed);
}

TEST_F(SpatialViewTest, ReparentingASupportMovesWhatItCarries) {
  Node3D& base = node("base", pose(3, 0, 0));
  Node3D& plate = node("plate", pose(0, 0, 1));
  Node3D& box = node("box", pose(0, 0, 1.5));
  SpatialView view(s);
  view.relate(box, plate, SpatialRelation::LiesOn);
  base.add_child(plate);  // the plate's frame is now relative to base: it moved by (3, 0, 0)
  expect_pose(plate.world_frame(), pose(3, 0, 1));
  expect_pose(box.world_frame(), pose(3, 0, 1.5));
}

TEST_F(SpatialViewTest, TheViewRecordsItsMovesLikeAnyOtherChange) {
  Node3D& gripper = node("gripper", pose(0, 0, 1));
  Node3D& part = node("part", pose(0, 0, 0.9));
  SpatialView view(s);
  view.relate(part, gripper, SpatialRelation::GrabbedBy);
  int part_changes = 0;
  auto c = part.on_changed().connect([&](SimStateInstance&, const MetaProperty&) { ++part_changes; });
  s.start_recording();
  gripper.set_frame(pose(1, 0, 1));
  Transaction t = s.stop_recording();
  EXPECT_EQ(part_changes, 1);
  expect_pose(part.world_frame(), pose(1, 0, 0.9));
  // undo restores both: the view follows the gripper back (the part's own change is undone too)
  s.apply(t.inverted());
  expect_pose(gripper.world_frame(), pose(0, 0, 1));
  expect_pose(part.world_frame(), pose(0, 0, 0.9));
  // and the relation goes on from there
  gripper.set_frame(pose(0, 2, 1));
  expect_pose(part.world_frame(), pose(0, 2, 0.9));
}

TEST_F(SpatialViewTest, DeletionRemovesRelations) {
  Node3D& gripper = node("gripper", pose(0, 0, 1));
  Node3D& a = node("a", pose(0, 0, 0.9));
  Node3D& b = node("b", pose(0, 0, 0.8));
  SpatialView view(s);
  view.relate(a, gripper, SpatialRelation::GrabbedBy);
  view.relate(b, a, SpatialRelation::AttachedTo);
  std::vector<std::string> removed;
  auto c = view.on_removed().connect([&](vsd::Node& n) { removed.push_back(n.name()); });
  s.destroy(a);  // the object of one relation and the support of another
  EXPECT_EQ(removed, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(view.size(), 0u);
  gripper.set_frame(pose(1, 1, 1));
  expect_pose(b.world_frame(), pose(0, 0, 0.8));
}

TEST_F(SpatialViewTest, BadRelationsAreRejected) {
  Node3D& a = node("a", pose(0, 0, 0));
  Node3D& b = node("b", pose(1, 0, 0), &a);
  Node3D& c = node("c", pose(2, 0, 0));
  SpatialView view(s);
  EXPECT_THROW(view.relate(a, a, SpatialRelation::LiesOn), vsd::Error);
  try {
    view.relate(a, b, SpatialRelation::GrabbedBy);  // b moves with a in the spanning tree
    ADD_FAILURE() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("'b' (id " + std::to_string(b.id()) + ") lies below 'a'"),
              std::string::npos)
        << e.what();
  }
  view.relate(c, a, SpatialRelation::LiesOn);
  EXPECT_THROW(view.relate(a, c, SpatialRelation::LiesOn), vsd::Error);  // a cycle through the view
  Environment other;
  other.use<Module>();
  auto& foreign = other.main_state().create<Node3D>();
  EXPECT_THROW(view.relate(foreign, a, SpatialRelation::LiesOn), vsd::Error);
  c.set_frame(pose(NAN, 0, 0));
  EXPECT_THROW(view.relate(c, b, SpatialRelation::LiesOn), vsd::Error);
  EXPECT_EQ(view.support_of(c), &a);  // the failed relate changed nothing
  // a support with a non-finite pose drags nothing into NaN
  c.set_frame(pose(2, 0, 0));
  view.relate(c, a, SpatialRelation::LiesOn);
  a.set_frame(pose(0, NAN, 0));
  EXPECT_TRUE(c.world_frame().matrix().allFinite());
}

// The node named @p name in @p state (the tests' names are unique).
Node3D& named(SimState& state, const std::string& name) {
  for (Node3D* n : state.index().all<Node3D>())
    if (n->name() == name) return *n;
  throw vsd::Error("no node " + name);
}

TEST_F(SpatialViewTest, RelationsAreSupportExtensionsWrittenThroughTheSetters) {
  Node3D& table = node("table", pose(0, 0, 0));
  Node3D& cup = node("cup", pose(0.1, 0, 0.8));
  SpatialView view(s);
  int changes = 0;
  auto c = s.on_property_changed(Support::static_meta(), true)
               .connect([&](SimStateInstance&, const MetaProperty&) { ++changes; });
  view.relate(cup, table, SpatialRelation::LiesOn);
  auto* sup = cup.find_extension<Support>();
  ASSERT_NE(sup, nullptr);
  EXPECT_EQ(sup->support().get(), &table);
  EXPECT_EQ(sup->relation(), SpatialRelation::LiesOn);
  EXPECT_GT(changes, 0);
  // Writing the Support through its setters is the same as relate(): another view (and this one) follow.
  Node3D& hand = node("hand", pose(0, 0, 1.5));
  sup->set_relation(SpatialRelation::GrabbedBy);
  sup->set_support(&hand);
  EXPECT_EQ(view.support_of(cup), &hand);
  EXPECT_EQ(view.relation_of(cup), SpatialRelation::GrabbedBy);
  hand.set_frame(pose(0, 1, 1.5));
  expect_pose(cup.world_frame(), pose(0, 1, 0) * pose(0.1, 0, 0.8));
  SpatialView second(s);  // made later: reads the relation from the SimState
  EXPECT_EQ(second.support_of(cup), &hand);
  EXPECT_TRUE(second.offset_of(cup)->isApprox(hand.world_frame().inverse() * cup.world_frame(), 1e-12));
  // Releasing destroys the extension; both views end the relation.
  EXPECT_TRUE(view.release(cup));
  EXPECT_EQ(cup.find_extension<Support>(), nullptr);
  EXPECT_EQ(second.support_of(cup), nullptr);
  EXPECT_EQ(s.index().all<Support>().size(), 0u);
}

TEST_F(SpatialViewTest, RelationsSaveAndLoadThroughVsdIo) {
  Node3D& table = node("table", pose(0, 0, 0));
  Node3D& tray = node("tray", pose(0, 0, 0.8));
  Node3D& cup = node("cup", pose(0.1, 0, 0.85, 0.4));
  Node3D& gripper = node("gripper", pose(5, 5, 2));
  Node3D& sensor = node("sensor", pose(5, 5, 2.2));
  {
    SpatialView view(s);
    view.relate(tray, table, SpatialRelation::LiesOn);
    view.relate(cup, tray, SpatialRelation::LiesOn);
    view.relate(sensor, gripper, SpatialRelation::AttachedTo);
    view.relate(tray, gripper, SpatialRelation::GrabbedBy);  // replaces "lies on the table"
  }
  for (const auto format : {vsd::io::Format::Text, vsd::io::Format::Binary}) {
    Environment env2;
    env2.use<Module>();
    SimState& loaded = env2.main_state();
    vsd::io::load_bytes(loaded, vsd::io::save_bytes(s, format));
    SpatialView view(loaded);
    EXPECT_TRUE(view.warnings().empty());
    EXPECT_EQ(view.size(), 3u);
    Node3D &ltray = named(loaded, "tray"), &lcup = named(loaded, "cup"), &lgripper = named(loaded, "gripper");
    EXPECT_EQ(view.support_of(ltray), &lgripper);
    EXPECT_EQ(view.relation_of(ltray), SpatialRelation::GrabbedBy);
    EXPECT_EQ(view.support_of(lcup), &ltray);
    EXPECT_EQ(view.relation_of(lcup), SpatialRelation::LiesOn);
    EXPECT_EQ(view.support_of(named(loaded, "sensor")), &lgripper);
    EXPECT_EQ(view.relation_of(named(loaded, "sensor")), SpatialRelation::AttachedTo);
    EXPECT_EQ(view.support_of(named(loaded, "table")), nullptr);
    // In force after loading: the gripper carries tray, cup and sensor; the table carries nothing.
    lgripper.set_frame(pose(5, 5, 3));
    expect_pose(lcup.world_frame(), pose(0, 0, 1) * cup.world_frame());
    expect_pose(named(loaded, "sensor").world_frame(), pose(0, 0, 1) * sensor.world_frame());
    named(loaded, "table").set_frame(pose(9, 0, 0));
    expect_pose(ltray.world_frame(), pose(0, 0, 1) * tray.world_frame());
  }
}

TEST_F(SpatialViewTest, AReplicaApplyingTheBundlesEndsWithTheSameRelations) {
  Node3D& table = node("table", pose(0, 0, 0));
  Node3D& cup = node("cup", pose(0.1, 0, 0.8));
  Node3D& gripper = node("gripper", pose(0, 0, 1.2));
  SimState& replica = env.create_state("replica");
  replica.copy_from(s);
  SpatialView view(s);
  SpatialView rview(replica);  // a view at the replica too: it holds back while bundles are applied
  auto rnode = [&](const Node3D& n) -> Node3D& { return *replica.find(n.id())->as<Node3D>(); };
  auto sync = [&] {
    replica.apply(s.stop_recording());
    std::string diff;
    EXPECT_TRUE(replica.equals(s, &diff)) << diff;
    s.start_recording();
  };
  s.start_recording();
  view.relate(cup, table, SpatialRelation::LiesOn);
  sync();
  EXPECT_EQ(rview.support_of(rnode(cup)), &rnode(table));
  EXPECT_EQ(rview.relation_of(rnode(cup)), SpatialRelation::LiesOn);
  view.relate(cup, gripper, SpatialRelation::GrabbedBy);  // grabbed: the same Support, new values
  gripper.set_frame(pose(1, 0, 1.5));                     // the cup follows (recorded at the source)
  sync();
  EXPECT_EQ(rview.support_of(rnode(cup)), &rnode(gripper));
  EXPECT_EQ(rview.relation_of(rnode(cup)), SpatialRelation::GrabbedBy);
  expect_pose(rnode(cup).world_frame(), cup.world_frame());
  // The replica's view puts the relation in force locally too, with the pose the bundle left.
  rnode(gripper).set_frame(pose(1, 0, 2.5));
  expect_pose(rnode(cup).world_frame(), pose(0, 0, 1) * cup.world_frame());
  rnode(gripper).set_frame(pose(1, 0, 1.5));
  view.release(cup);
  sync();
  EXPECT_EQ(rview.support_of(rnode(cup)), nullptr);
  EXPECT_EQ(rview.size(), 0u);
  // Undo at the source brings the relation back, at the source and the replica alike.
  view.relate(cup, table, SpatialRelation::LiesOn);
  Transaction t = s.stop_recording();
  s.apply(t.inverted());
  EXPECT_EQ(view.support_of(cup), nullptr);
  s.apply(t);
  EXPECT_EQ(view.support_of(cup), &table);
  replica.apply(t);
  EXPECT_EQ(rview.support_of(rnode(cup)), &rnode(table));
  env.remove_state(replica);
}

TEST_F(SpatialViewTest, SupportsTheViewCannotPutInForceAreWarnings) {
  Node3D& a = node("a", pose(0, 0, 0));
  Node3D& b = node("b", pose(1, 0, 0), &a);
  Node3D& c = node("c", pose(2, 0, 0));
  // Written directly (as a hand-edited file could): a cycle c <-> a, and a support below its object.
  auto support = [&](Node3D& object, Node3D& on) {
    auto& x = s.create<Support>();
    x.set_support(&on);
    object.add_extension(x);
  };
  support(c, a);
  support(a, c);
  support(a, b);  // a second Support on a: the first one counts
  SpatialView view(s);
  EXPECT_EQ(view.size(), 1u);
  EXPECT_EQ(view.support_of(c), &a);
  EXPECT_EQ(view.support_of(a), nullptr);
  ASSERT_EQ(view.warnings().size(), 1u);
  EXPECT_NE(
      view.warnings()[0].find("Support of 'a' (id " + std::to_string(a.id()) + ") is not in force: 'c'"),
      std::string::npos)
      << view.warnings()[0];
  a.set_frame(pose(0, 1, 0));  // no endless chase
  expect_pose(c.world_frame(), pose(2, 1, 0));
  // Set through a setter later: below the object in the spanning tree.
  auto& d = s.create<Support>();
  d.set_support(&b);
  b.add_extension(d);  // b's support is b itself
  EXPECT_EQ(view.support_of(b), nullptr);
  EXPECT_NE(view.warnings().back().find("cannot be its own support"), std::string::npos)
      << view.warnings().back();
  // Deleting the support nulls the reference: the relation ends, the extension stays as data.
  s.destroy(a);
  EXPECT_EQ(view.size(), 0u);
  ASSERT_NE(c.find_extension<Support>(), nullptr);
  EXPECT_EQ(c.find_extension<Support>()->support().get(), nullptr);
}

}  // namespace
}  // namespace vsd::scene
