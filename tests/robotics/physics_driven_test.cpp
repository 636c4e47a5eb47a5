// Joints driven by physics: when ODE moves a robot's bodies, the kinematic joint values follow the links'
// frames, so FK, Jacobians and controllers see the joints where the bodies are. And the inverse of a
// joint's motion frame that this relies on, for every kind of joint.
#include <gtest/gtest.h>

#include <random>

#include "test_util.hpp"
#include "vsd/physics.hpp"
#include "vsd/robotics.hpp"

namespace vsd::robotics {
namespace {

TEST(JointValues, AreRecoveredFromTheirMotionFrameForEveryKind) {
  Environment env;
  env.use<Module>();
  SimState& s = env.main_state();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  auto unit = [&] { return Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized(); };
  for (int i = 0; i < 200; ++i) {
    auto& j = s.create<KinematicJoint>();
    const int kind = i % 5;
    j.set_type(kind == 0 ? KinematicJointType::Prismatic
                         : kind == 1 ? KinematicJointType::Universal : KinematicJointType::Rotary);
    Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
    origin.translate(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    origin.rotate(Eigen::AngleAxisd(u(rng), unit()));
    j.set_origin(origin);
    j.set_axis(unit() * 2.0);  // not normalised on purpose
    j.set_axis2(unit());
    if (kind == 3) j.set_dh_parameters(DhConvention::Standard, {u(rng), u(rng), u(rng), u(rng)});
    if (kind == 4) j.set_dh_parameters(DhConvention::Modified, {u(rng), u(rng), u(rng), u(rng)});
    const double q1 = kind == 0 ? u(rng) : 0.9 * u(rng);  // within one turn of the current 0
    const double q2 = kind == 1 ? 0.45 * u(rng) : 0.0;    // a universal joint's second angle within +-pi/2
    const auto [r1, r2] = j.values_of(j.motion_frame(q1, q2));
    EXPECT_NEAR(r1, q1, 1e-9) << "joint kind " << kind;
    EXPECT_NEAR(r2, q2, 1e-9) << "joint kind " << kind;
  }
  // A continuous joint keeps counting turns: the value nearest the current one.
  auto& c = s.create<KinematicJoint>();
  c.set_position(6.0);
  EXPECT_NEAR(c.values_of(c.motion_frame(6.2)).first, 6.2, 1e-9);
  // A frame off the joint's motion projects onto it: the rotation about the axis.
  auto& r = s.create<KinematicJoint>();
  const Eigen::Isometry3d off(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(1e-3, Eigen::Vector3d::UnitX()));
  EXPECT_NEAR(r.values_of(off).first, 0.4, 1e-6);
}

TEST(PhysicsDrivenJoints, KeepTheKinematicJointValuesCurrent) {
  Environment env;
  env.use<Module>();
  env.use<physics::Module>();
  SimState& s = env.main_state();
  scene::UrdfOptions o;
  o.load_meshes = false;
  auto report = scene::load_urdf(s.database(), vsd_test::robot_file("iiwa14.urdf"), o);
  KinematicTree& tree = build_kinematics(*report.scene);
  // Start bent, so that gravity swings the arm; the bodies take the pose of the joint values.
  std::vector<double> q0{0.3, 0.8, -0.2, -1.0, 0.4, 0.6, 0.0};
  tree.set_positions(q0);
  auto& world = s.create<physics::World>();
  s.database().add_extension(world);
  ASSERT_GT(physics::make_dynamic(*report.scene), 0u);
  SimState& replica = env.create_state("ui");  // robotics derives there, physics does not run there
  replica.copy_from(s);
  s.start_recording();
  env.run_for(0.3);
  const Transaction t = s.stop_recording();
  const std::vector<double> q = tree.positions();
  double moved = 0.0;
  for (std::size_t i = 0; i < q.size(); ++i) moved = std::max(moved, std::abs(q[i] - q0[i]));
  EXPECT_GT(moved, 0.05) << "gravity swung the arm, and the joint values followed";
  // FK of the followed values puts every link where physics put it (up to ODE's joint error).
  const Model& m = tree.model();
  Model::Data d = m.make_data();
  m.forward(std::span<const double>(q), d);
  const Eigen::Isometry3d base_world = tree.base()->world_frame();
  for (int b = 0; b < m.body_count(); ++b) {
    const scene::Link* link = report.scene->find_link(m.body_name(b));
    if (link == nullptr) continue;
    EXPECT_TRUE((base_world * m.pose(d, b).isometry()).isApprox(link->world_frame(), 1e-4)) << m.body_name(b);
  }
  // The joint values were derived, not recorded: the bundle carries the poses physics wrote, and a
  // replica derives the same values from them.
  const std::string ops = t.describe();
  EXPECT_NE(ops.find(".frame"), std::string::npos);
  for (KinematicJoint* j : tree.joints())
    EXPECT_EQ(ops.find("set #" + std::to_string(j->id()) + ".position"), std::string::npos) << j->name();
  replica.apply(t);
  std::string diff;
  EXPECT_TRUE(replica.equals(s, &diff)) << diff;
}

}  // namespace
}  // namespace vsd::robotics
