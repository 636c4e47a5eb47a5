// Kinematics as database content: joint values move link frames (signals fire), mimics follow, the tree
// recompiles only on topology changes, and everything saves and loads through vsd::io.
#include <gtest/gtest.h>

#include <filesystem>
#include <numbers>

#include "test_util.hpp"
#include "vsd/io.hpp"
#include "vsd/robotics.hpp"

namespace vsd::robotics {
namespace {

using vsd_test::robot_file;

struct Robot {
  Environment env;
  scene::SceneReport report;
  KinematicTree* tree = nullptr;
  explicit Robot(const std::string& file) {
    env.use<Module>();
    scene::UrdfOptions o;
    o.load_meshes = false;
    report = scene::load_urdf(env.main_state().database(), robot_file(file), o);
    tree = &build_kinematics(*report.scene);
  }
  scene::Link& link(std::string_view n) const { return *report.scene->find_link(n); }
};

TEST(Kinematics, BuiltFromUrdf) {
  Robot r("iiwa14.urdf");
  EXPECT_EQ(r.tree->base(), r.report.scene);
  EXPECT_EQ(r.tree->joints().size(), 10u);  // 7 revolute + 3 fixed
  KinematicJoint* j2 = r.tree->find_joint("iiwa_joint_2");
  ASSERT_NE(j2, nullptr);
  EXPECT_EQ(j2->type(), KinematicJointType::Rotary);
  EXPECT_TRUE(j2->has_limits());
  EXPECT_NEAR(j2->upper(), 2.0944, 1e-4);
  EXPECT_EQ(j2->owner(), &r.link("iiwa_link_2"));
  EXPECT_EQ(j2->description().get(), r.report.scene->find_joint("iiwa_joint_2"));
  EXPECT_EQ(r.tree->find_joint("iiwa_joint_ee")->type(), KinematicJointType::Fixed);
  EXPECT_EQ(r.tree->model().dof(), 7);
  EXPECT_EQ(&build_kinematics(*r.report.scene), r.tree);  // a second call returns the same tree
}

TEST(Kinematics, JointValueMovesLinkFramesAndSignalsFire) {
  Robot r("iiwa14.urdf");
  scene::Link& l2 = r.link("iiwa_link_2");
  scene::Link& ee = r.link("iiwa_link_ee");
  const Eigen::Vector3d ee_before = ee.world_frame().translation();
  int frame_signals = 0;
  Connection c = l2.on_changed().connect([&](SimStateInstance&, const MetaProperty& p) {
    if (p.name() == "frame") ++frame_signals;
  });
  KinematicJoint* j2 = r.tree->find_joint("iiwa_joint_2");
  j2->set_position(0.5);
  EXPECT_EQ(frame_signals, 1);
  EXPECT_TRUE(l2.frame().isApprox(j2->origin() * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ())));
  EXPECT_GT((ee.world_frame().translation() - ee_before).norm(), 0.3);
  // One owner of the value: the URDF description's joint keeps the value it started with, and setting
  // it moves nothing.
  EXPECT_EQ(r.report.scene->find_joint("iiwa_joint_2")->position(), 0.0);
  r.report.scene->find_joint("iiwa_joint_2")->set_position(-0.25);
  EXPECT_EQ(j2->position(), 0.5);
  EXPECT_EQ(frame_signals, 1);
  // Through the generic path as well.
  j2->set("position", Value(0.0));
  EXPECT_TRUE(ee.world_frame().translation().isApprox(ee_before, 1e-12));
}

TEST(Kinematics, MimicJointsFollowAndAreNeverDropped) {
  Robot r("iiwa14.urdf");
  KinematicJoint* j1 = r.tree->find_joint("iiwa_joint_1");
  KinematicJoint* j3 = r.tree->find_joint("iiwa_joint_3");
  j3->set_mimic_multiplier(-2.0);
  j3->set_mimic_offset(0.1);
  j3->set_mimic(j1);
  EXPECT_DOUBLE_EQ(j3->position(), 0.1);  // takes its master's value at once
  j1->set_position(0.3);
  EXPECT_DOUBLE_EQ(j3->position(), -2.0 * 0.3 + 0.1);
  EXPECT_TRUE(r.link("iiwa_link_3").frame().isApprox(j3->motion_frame()));
  j3->set_position(1.0);  // a follower's value is its master's
  EXPECT_DOUBLE_EQ(j3->position(), -0.5);
  const Model& m = r.tree->model();
  EXPECT_EQ(m.dof(), 6);
  std::vector<std::string> names;
  for (const auto& d : m.layout()) names.push_back(d.name);
  EXPECT_EQ(std::find(names.begin(), names.end(), "iiwa_joint_3"), names.end());
  // On a chain that does not hold the master, the master still drives the follower.
  const Model chain = Model::compile(r.link("iiwa_link_2"), &r.link("iiwa_link_4"));
  ASSERT_EQ(chain.dof(), 2);  // iiwa_joint_4 and the master iiwa_joint_1 (value only)
  EXPECT_EQ(chain.layout()[0].name, "iiwa_joint_4");
  EXPECT_EQ(chain.layout()[1].name, "iiwa_joint_1");
}

TEST(Kinematics, MimicFromUrdfIsKept) {
  const std::string xml = R"(<robot name="gripper">
    <link name="palm"/><link name="left"/><link name="right"/>
    <joint name="l" type="prismatic"><parent link="palm"/><child link="left"/><axis xyz="0 1 0"/>
      <limit lower="0" upper="0.04" effort="10" velocity="0.1"/></joint>
    <joint name="r" type="prismatic"><parent link="palm"/><child link="right"/><axis xyz="0 1 0"/>
      <limit lower="-0.04" upper="0" effort="10" velocity="0.1"/><mimic joint="l" multiplier="-1" offset="0"/></joint>
  </robot>)";
  Environment env;
  env.use<Module>();
  auto rep = scene::load_urdf_text(env.main_state().database(), xml, "gripper.urdf", ".");
  KinematicTree& t = build_kinematics(*rep.scene);
  ASSERT_EQ(t.model().dof(), 1);
  t.set_positions(std::vector<double>{0.03});
  EXPECT_DOUBLE_EQ(t.find_joint("r")->position(), -0.03);
  EXPECT_NEAR(rep.scene->find_link("right")->frame().translation().y(), -0.03, 1e-15);
}

TEST(Kinematics, RecompilesOnlyOnTopologyChanges) {
  Robot r("ur5_robot.urdf");
  const Model* m = &r.tree->model();
  EXPECT_EQ(r.tree->compilations(), 1u);
  r.tree->set_positions(std::vector<double>{0.1, 0.2, 0.3, 0.4, 0.5, 0.6});
  for (KinematicJoint* j : r.tree->joints()) j->set_velocity(1.0);
  (void)r.tree->model();
  EXPECT_EQ(r.tree->compilations(), 1u);
  EXPECT_EQ(&r.tree->model(), m);
  r.tree->find_joint("elbow_joint")->set_upper(1.0);
  EXPECT_EQ(r.tree->model().layout()[2].upper, 1.0);
  EXPECT_EQ(r.tree->compilations(), 2u);
  auto& extra = r.env.main_state().create<scene::Link>();
  extra.set_name("camera");
  r.link("tool0").add_child(extra);
  EXPECT_EQ(r.tree->model().find_body("camera"), r.tree->model().body_count() - 1);
  EXPECT_EQ(r.tree->compilations(), 3u);
  EXPECT_EQ(r.tree->positions(), (std::vector<double>{0.1, 0.2, 0.3, 0.4, 0.5, 0.6}));
  EXPECT_THROW(r.tree->set_positions(std::vector<double>{1, 2}), vsd::Error);
}

TEST(Kinematics, NodesOutsideEveryTreeDoNotRecompileIt) {
  Robot r("ur5_robot.urdf");
  vsd::SimState& s = r.env.main_state();
  (void)r.tree->model();
  // A part moving beside the robot, gaining and losing an extension: no model depends on it.
  auto& part = s.create<scene::Node3D>();
  s.database().add_child(part);  // any reparenting counts (the old parent is not known any more)
  (void)r.tree->model();
  const std::uint64_t before = topology_version(s);
  const std::uint64_t compiled = r.tree->compilations();
  for (int i = 0; i < 10; ++i) part.set_frame(Eigen::Isometry3d(Eigen::Translation3d(0.01 * i, 0, 0)));
  auto& joint = s.create<KinematicJoint>();
  part.add_extension(joint);
  part.remove_extension(joint);
  (void)r.tree->model();
  EXPECT_EQ(topology_version(s), before);
  EXPECT_EQ(r.tree->compilations(), compiled);
  // A fixed link inside the tree is part of the model: moving it compiles it again.
  auto& camera = s.create<scene::Link>();
  r.link("tool0").add_child(camera);  // a new node in the tree (reparented: a new version)
  (void)r.tree->model();
  const std::uint64_t with_camera = r.tree->compilations();
  camera.set_frame(Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.1)));
  EXPECT_GT(topology_version(s), before);
  (void)r.tree->model();
  EXPECT_EQ(r.tree->compilations(), with_camera + 1);
}

TEST(Kinematics, UniversalAndDhJointsInTheDatabase) {
  Environment env;
  env.use<Module>();
  SimState& s = env.main_state();
  auto& base = s.create<scene::Node3D>();
  s.database().add_child(base);
  auto& link = s.create<scene::Link>();
  link.set_name("cardan");
  auto& u = s.create<KinematicJoint>();
  u.set_type(KinematicJointType::Universal);
  u.set_axis(Eigen::Vector3d::UnitX());
  u.set_axis2(Eigen::Vector3d::UnitY());
  link.add_extension(u);
  base.add_child(link);
  auto& tree = s.create<KinematicTree>();
  base.add_extension(tree);
  ASSERT_EQ(tree.model().dof(), 2);
  u.set_position(0.4);
  u.set_position2(-0.7);
  const Eigen::Isometry3d want(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(link.frame().isApprox(want));
  EXPECT_EQ(tree.positions(), (std::vector<double>{0.4, -0.7}));
  // A DH joint: standard convention Rz(theta + q) Tz(d) Tx(a) Rx(alpha).
  u.set_type(KinematicJointType::Rotary);
  u.set_dh_parameters(DhConvention::Standard, {0.5, std::numbers::pi / 2, 0.2, 0.1});
  const Eigen::Isometry3d dh = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                               Eigen::Translation3d(0, 0, 0.2) * Eigen::Translation3d(0.5, 0, 0) *
                               Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX());
  EXPECT_TRUE(link.frame().isApprox(dh, 1e-12));
  u.set_type(KinematicJointType::Universal);  // DH universal: rejected when compiled
  EXPECT_THROW((void)tree.model(), vsd::Error);
}

TEST(Kinematics, SavedAndLoadedLikeAnyContent) {
  const auto file = std::filesystem::temp_directory_path() / "vsd_robotics_save_test.json";
  {
    Robot r("iiwa14.urdf");
    r.tree->find_joint("iiwa_joint_3")->set_mimic(r.tree->find_joint("iiwa_joint_1"));
    r.tree->set_positions(std::vector<double>{0.2, -0.3, 0.5, 0.6, -0.1, 0.7});
    io::save(r.env.main_state(), file);
  }
  Environment env;
  env.use<Module>();
  io::load(env.main_state(), file);
  std::filesystem::remove(file);
  auto trees = env.main_state().index().of<KinematicTree>();
  ASSERT_EQ(trees.size(), 1u);
  KinematicTree& t = *trees[0];
  EXPECT_EQ(t.positions(), (std::vector<double>{0.2, -0.3, 0.5, 0.6, -0.1, 0.7}));
  KinematicJoint* j3 = t.find_joint("iiwa_joint_3");
  ASSERT_NE(j3->mimic().get(), nullptr);
  EXPECT_EQ(j3->mimic()->name(), "iiwa_joint_1");
  EXPECT_DOUBLE_EQ(j3->position(), 0.2);
  // The loaded state is live: a joint value moves its link.
  auto* l2 = static_cast<scene::Node3D*>(t.find_joint("iiwa_joint_2")->owner());
  t.find_joint("iiwa_joint_2")->set_position(1.0);
  EXPECT_TRUE(l2->frame().isApprox(t.find_joint("iiwa_joint_2")->motion_frame()));
  t.find_joint("iiwa_joint_1")->set_position(-0.4);
  EXPECT_DOUBLE_EQ(j3->position(), -0.4);
}

TEST(Kinematics, ReplicatedThroughTransactions) {
  Robot r("ur5_robot.urdf");
  SimState& replica = r.env.create_state("replica");
  replica.copy_from(r.env.main_state());
  track(replica);
  r.env.main_state().start_recording();
  r.tree->set_positions(std::vector<double>{0.1, -0.2, 0.3, -0.4, 0.5, -0.6});
  replica.apply(r.env.main_state().stop_recording());
  auto trees = replica.index().of<KinematicTree>();
  ASSERT_EQ(trees.size(), 1u);
  EXPECT_EQ(trees[0]->positions(), (std::vector<double>{0.1, -0.2, 0.3, -0.4, 0.5, -0.6}));
  auto* wrist = static_cast<scene::Node3D*>(trees[0]->find_joint("wrist_3_joint")->owner());
  EXPECT_TRUE(wrist->world_frame().isApprox(r.link("wrist_3_link").world_frame(), 1e-12));
  // The replica is as active as its source: its own joint values move its links.
  trees[0]->find_joint("wrist_3_joint")->set_position(1.0);
  EXPECT_TRUE(wrist->frame().isApprox(trees[0]->find_joint("wrist_3_joint")->motion_frame()));
}

// vsd::robotics has no floating or planar joint: they are kept fixed, and the caller is told so through
// the warnings of build_kinematics() (vsd-robot printed nothing).
TEST(Kinematics, FloatingAndPlanarJointsAreKeptFixedWithAWarning) {
  Environment env;
  env.use<Module>();
  const std::string xml = R"(<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
  <joint name="free" type="floating"><parent link="a"/><child link="b"/></joint>
  <joint name="flat" type="planar"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/></joint></robot>)";
  const auto rep = scene::load_urdf_text(env.main_state().database(), xml, "r.urdf", ".");
  std::vector<std::string> warnings;
  KinematicTree& tree = build_kinematics(*rep.scene, &warnings);
  EXPECT_EQ(tree.find_joint("free")->type(), KinematicJointType::Fixed);
  EXPECT_EQ(tree.find_joint("flat")->type(), KinematicJointType::Fixed);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("joint 'free': a floating joint is kept fixed"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[1].find("joint 'flat': a planar joint is kept fixed"), std::string::npos) << warnings[1];
  EXPECT_EQ(tree.model().dof(), 0);
}

TEST(Kinematics, SceneJointWithoutChildIsAnError) {
  Environment env;
  env.use<Module>();
  SimState& s = env.main_state();
  auto& sc = s.create<scene::Scene>();
  s.database().add_child(sc);
  auto& j = s.create<scene::Joint>();
  j.set_name("loose");
  sc.edit_joints().push_back(j);
  try {
    (void)build_kinematics(sc);
    FAIL();
  } catch (const vsd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("'loose' has no child link"), std::string::npos);
  }
  auto& orphan = s.create<KinematicTree>();
  EXPECT_THROW((void)orphan.model(), vsd::Error);
}

// One owner of a joint's value: a joint set records the joint value only. The link frame and a mimic
// follower's value are derived, and a replica (served by the module by default) derives them itself.
TEST(Kinematics, AJointSetRecordsOnlyTheJointValue) {
  Robot r("iiwa14.urdf");
  SimState& main = r.env.main_state();
  KinematicJoint& j1 = *r.tree->find_joint("iiwa_joint_1");
  KinematicJoint& j3 = *r.tree->find_joint("iiwa_joint_3");
  j3.set_mimic(&j1);
  j3.set_mimic_multiplier(-0.5);
  SimState& replica = r.env.create_state("replica");
  replica.copy_from(main);
  main.start_recording();
  j1.set_position(0.8);
  EXPECT_DOUBLE_EQ(j3.position(), -0.4);
  const Transaction t = main.stop_recording();
  EXPECT_EQ(t.size(), 1u) << t.describe();
  EXPECT_EQ(t.describe().find("frame"), std::string::npos) << t.describe();
  replica.apply(t);
  std::string diff;
  EXPECT_TRUE(replica.equals(main, &diff)) << diff;
  auto* rj3 = replica.find<KinematicJoint>(j3.id());
  EXPECT_DOUBLE_EQ(rj3->position(), -0.4);
  auto* rl3 = static_cast<scene::Node3D*>(rj3->owner());
  EXPECT_TRUE(rl3->world_frame().isApprox(r.link("iiwa_link_3").world_frame(), 1e-15));
}

TEST(Kinematics, UndoAndRollBackReDeriveTheLinkFrames) {
  Robot r("iiwa14.urdf");
  SimState& main = r.env.main_state();
  KinematicJoint& j2 = *r.tree->find_joint("iiwa_joint_2");
  const Eigen::Isometry3d before = r.link("iiwa_link_7").world_frame();
  main.start_recording();
  j2.set_position(0.9);
  const Transaction t = main.stop_recording();
  EXPECT_FALSE(r.link("iiwa_link_7").world_frame().isApprox(before, 1e-6));
  main.apply(t.inverted());
  EXPECT_DOUBLE_EQ(j2.position(), 0.0);
  EXPECT_TRUE(r.link("iiwa_link_7").world_frame().isApprox(before, 1e-15));
  const auto sp = main.savepoint();
  j2.set_position(-0.7);
  main.roll_back(sp);
  EXPECT_TRUE(r.link("iiwa_link_7").world_frame().isApprox(before, 1e-15));
}

TEST(Kinematics, ControllersStepOnlyTheStatesServedStepped) {
  Robot r("iiwa14.urdf");
  SimState& main = r.env.main_state();
  auto& c = main.create<JointController>();
  r.report.scene->add_extension(c);
  c.set_target(std::vector<double>(7, 0.3));
  c.set_mode(ControlMode::Position);
  SimState& copy = r.env.create_state("what-if");
  copy.copy_from(main);
  r.env.run_for(0.5);
  const double moved = r.tree->find_joint("iiwa_joint_1")->position();
  EXPECT_GT(moved, 0.0);
  auto* copy_j1 = copy.find<KinematicJoint>(r.tree->find_joint("iiwa_joint_1")->id());
  EXPECT_DOUBLE_EQ(copy_j1->position(), 0.0) << "a derived state is not stepped";
  r.env.set_service<Module>(copy, Service::stepped);
  r.env.run_for(0.5);
  EXPECT_GT(copy_j1->position(), 0.0) << "the what-if copy is simulated once it is stepped";
}

}  // namespace
}  // namespace vsd::robotics
