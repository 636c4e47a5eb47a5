// Trajectories (trapezoidal, quintic) and the JointController run by the Scheduler: position, velocity and
// Cartesian control, limits kept, bad targets reported.
#include "vsd/robotics/controller.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "test_util.hpp"
#include "vsd/robotics.hpp"

namespace vsd::robotics {
namespace {

TEST(Trajectory, TrapezoidalKeepsLimitsAndArrivesTogether) {
  const std::vector<double> start{0.0, 1.0, -0.5}, goal{2.0, 0.5, -0.5}, v{1.0, 0.2, 1.0}, a{2.0, 1.0, 1.0};
  const JointTrajectory t = JointTrajectory::plan(Interpolation::Trapezoidal, start, goal, v, a);
  // Joint 0: 2 rad at 1 rad/s, 2 rad/s^2: 2/1 + 1/2 = 2.5 s; joint 1: 0.5 at 0.2, 1: 2.5 + 0.2 = 2.7 s.
  EXPECT_NEAR(t.duration(), 2.7, 1e-12);
  double q[3], qd[3], prev[3] = {0, 1, -0.5}, prev_v[3] = {0, 0, 0};
  const double dt = 1e-3;
  for (double time = dt; time <= t.duration() + 1e-9; time += dt) {
    t.sample(time, q, qd);
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(std::abs(qd[i]), v[static_cast<std::size_t>(i)] + 1e-9);
      EXPECT_LE(std::abs(qd[i] - prev_v[i]) / dt, a[static_cast<std::size_t>(i)] + 1e-6);
      EXPECT_NEAR((q[i] - prev[i]) / dt, 0.5 * (qd[i] + prev_v[i]), 1e-3);  // velocity is the derivative
      prev[i] = q[i];
      prev_v[i] = qd[i];
    }
  }
  t.sample(t.duration(), q, qd);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(q[i], goal[static_cast<std::size_t>(i)], 1e-12);
    EXPECT_EQ(qd[i], 0.0);
  }
  t.sample(-1.0, q, qd);
  EXPECT_EQ(q[0], 0.0);
}

TEST(Trajectory, QuinticStartsAndEndsAtRest) {
  const std::vector<double> start{0.0, 0.0}, goal{1.0, -3.0}, v{1.0, 2.0}, a{10.0, 10.0};
  const JointTrajectory t = JointTrajectory::plan(Interpolation::Quintic, start, goal, v, a);
  EXPECT_NEAR(t.duration(), 15.0 * 3.0 / (8.0 * 2.0), 1e-12);  // the speed limit of joint 1 decides
  double q[2], qd[2];
  double peak = 0;
  for (double time = 0; time <= t.duration(); time += 1e-3) {
    t.sample(time, q, qd);
    peak = std::max(peak, std::abs(qd[1]));
  }
  EXPECT_NEAR(peak, 2.0, 1e-3);
  t.sample(1e-6, q, qd);
  EXPECT_NEAR(qd[0], 0.0, 1e-9);
  t.sample(t.duration() - 1e-6, q, qd);
  EXPECT_NEAR(qd[1], 0.0, 1e-9);
  EXPECT_NEAR(q[1], -3.0, 1e-9);
}

TEST(Trajectory, BadLimitsAreErrors) {
  const std::vector<double> one{0.0}, two{0.0, 1.0}, zero{0.0};
  EXPECT_THROW(JointTrajectory::plan(Interpolation::Quintic, one, two, one, one), vsd::Error);
  EXPECT_THROW(JointTrajectory::plan(Interpolation::Trapezoidal, one, one, zero, std::vector<double>{1.0}),
               vsd::Error);
  // Start and goal must be finite too (a NaN goal made every sample NaN).
  const std::vector<double> nan{std::nan("")}, inf{INFINITY};
  EXPECT_THROW(JointTrajectory::plan(Interpolation::Quintic, one, nan, one, one), vsd::Error);
  EXPECT_THROW(JointTrajectory::plan(Interpolation::Trapezoidal, inf, one, one, one), vsd::Error);
}

struct Cell {
  Environment env;
  KinematicTree* tree = nullptr;
  JointController* ctrl = nullptr;
  Cell() {
    env.use<Module>();
    scene::UrdfOptions o;
    o.load_meshes = false;
    auto rep = scene::load_urdf(env.main_state().database(), vsd_test::robot_file("iiwa14.urdf"), o);
    tree = &build_kinematics(*rep.scene);
    ctrl = &env.main_state().create<JointController>();
    rep.scene->add_extension(*ctrl);
    env.scheduler().set_base_step(0.001);
  }
};

TEST(JointController, PositionControlFollowsTheTrajectoryUnderTheScheduler) {
  for (Interpolation shape : {Interpolation::Trapezoidal, Interpolation::Quintic}) {
    Cell c;
    const std::vector<double> goal{0.5, -0.4, 0.3, -1.0, 0.2, 0.6, -0.3};
    c.ctrl->set_interpolation(shape);
    c.ctrl->set_target(goal);
    c.ctrl->set_mode(ControlMode::Position);
    c.env.run_for(0.05);
    EXPECT_FALSE(c.ctrl->done());
    const double T = c.ctrl->trajectory_duration();
    EXPECT_GT(T, 0.1);
    // The iiwa URDF gives 10 rad/s; the default acceleration (4 rad/s^2) bounds the motion.
    for (KinematicJoint* j : c.tree->joints()) EXPECT_LE(std::abs(j->velocity()), 10.0 + 1e-9);
    c.env.run_for(T);
    EXPECT_TRUE(c.ctrl->done());
    const auto q = c.tree->positions();
    for (std::size_t i = 0; i < goal.size(); ++i) EXPECT_NEAR(q[i], goal[i], 1e-12);
    EXPECT_EQ(c.ctrl->fault(), "");
  }
}

TEST(JointController, VelocityControlStopsAtTheLimits) {
  Cell c;
  c.ctrl->set_target_velocity(std::vector<double>{0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -50.0});
  c.ctrl->set_mode(ControlMode::Velocity);
  c.env.run_for(0.5);
  auto q = c.tree->positions();
  EXPECT_NEAR(q[1], 0.5, 1.1e-3);                // 1 rad/s for 0.5 s (give or take the last step of run_for)
  EXPECT_NEAR(q[6], -3.0543261909899999, 1e-9);  // 10 rad/s for 0.5 s, stopped at the lower limit
  c.env.run_for(2.0);
  q = c.tree->positions();
  EXPECT_NEAR(q[1], 2.09439510239, 1e-9);
}

TEST(JointController, CartesianMotionReachesThePose) {
  Cell c;
  c.tree->set_positions(std::vector<double>{0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0});
  const Model& m = c.tree->model();
  Model::Data d = m.make_data();
  m.forward(c.tree->positions(), d);
  const int tip = m.find_body("iiwa_link_ee");
  Eigen::Isometry3d target = m.pose(d, tip).isometry();
  target.translation() += Eigen::Vector3d(0.05, 0.1, -0.08);
  target.linear() = target.linear() * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  c.ctrl->set_tip("iiwa_link_ee");
  c.ctrl->set_target_pose(target);
  c.ctrl->set_mode(ControlMode::Cartesian);
  c.env.run_for(3.0);
  EXPECT_TRUE(c.ctrl->done());
  m.forward(c.tree->positions(), d);
  EXPECT_LT((m.pose(d, tip).translation - target.translation()).norm(), 2e-4);
}

TEST(JointController, BadTargetsStopWithAFault) {
  Cell c;
  c.ctrl->set_target(std::vector<double>{1.0, 2.0});
  c.ctrl->set_mode(ControlMode::Position);
  c.env.step();
  EXPECT_EQ(c.ctrl->mode(), ControlMode::Idle);
  EXPECT_NE(c.ctrl->fault().find("target has 2 values; the tree has 7"), std::string::npos)
      << c.ctrl->fault();
  c.ctrl->set_tip("nowhere");
  c.ctrl->set_mode(ControlMode::Cartesian);
  c.env.step();
  EXPECT_NE(c.ctrl->fault().find("no body 'nowhere'"), std::string::npos);
  auto& lone = c.env.main_state().create<JointController>();
  lone.set_mode(ControlMode::Velocity);
  lone.step(0.01);
  EXPECT_EQ(lone.mode(), ControlMode::Idle);
  EXPECT_FALSE(lone.fault().empty());
}

// Regression: `done` used to be cleared only in the controller's next step after a new target, so a
// supervisor testing it right after commanding saw the previous motion's done.
TEST(JointController, DoneTurnsFalseAsSoonAsANewTargetIsSet) {
  Cell c;
  const std::vector<double> goal{0.2, -0.1, 0.1, -0.5, 0.0, 0.3, 0.0};
  c.ctrl->set_target(goal);
  EXPECT_FALSE(c.ctrl->done());  // no step yet
  c.ctrl->set_mode(ControlMode::Position);
  c.env.run_for(0.2);
  EXPECT_FALSE(c.ctrl->done());
  c.env.run_for(c.ctrl->trajectory_duration());
  ASSERT_TRUE(c.ctrl->done());
  // The same target again is no change: still done.
  c.ctrl->set_target(goal);
  EXPECT_TRUE(c.ctrl->done());
  // A new target, set in C++ or through the generic property interface (as SOML++ and replicas do).
  std::vector<double> next = goal;
  next[0] = 0.4;
  c.ctrl->set_target(next);
  EXPECT_FALSE(c.ctrl->done());
  c.env.run_for(c.ctrl->trajectory_duration() + 0.1);
  ASSERT_TRUE(c.ctrl->done());
  next[1] = 0.1;
  static_cast<SimStateInstance&>(*c.ctrl).set("target", Value(next));
  EXPECT_FALSE(c.ctrl->done());
  c.env.run_for(1.0);
  ASSERT_TRUE(c.ctrl->done());
  // Cartesian: a new pose, a new tip, or switching into the mode clears it too.
  const Model& m = c.tree->model();
  Model::Data d = m.make_data();
  m.forward(c.tree->positions(), d);
  Eigen::Isometry3d pose = m.pose(d, m.find_body("iiwa_link_ee")).isometry();
  c.ctrl->set_tip("iiwa_link_ee");
  c.ctrl->set_target_pose(pose);
  c.ctrl->set_mode(ControlMode::Cartesian);
  EXPECT_FALSE(c.ctrl->done());
  c.env.step();
  ASSERT_TRUE(c.ctrl->done());  // already there
  pose.translation().z() -= 0.02;
  c.ctrl->set_target_pose(pose);
  EXPECT_FALSE(c.ctrl->done());
  c.env.run_for(1.0);
  ASSERT_TRUE(c.ctrl->done());
  c.ctrl->set_tip("iiwa_link_7");
  EXPECT_FALSE(c.ctrl->done());
  c.ctrl->set_mode(ControlMode::Idle);
  c.ctrl->set_done(true);
  c.ctrl->set_mode(ControlMode::Velocity);  // no target to reach: left alone
  EXPECT_TRUE(c.ctrl->done());
  c.ctrl->set_mode(ControlMode::Position);
  EXPECT_FALSE(c.ctrl->done());
}

// Regression: Cartesian control clamped at the joint limits silently; `limited` reports it.
TEST(JointController, LimitedReportsClampingAtTheJointLimits) {
  Cell c;
  // Joint 4 (the elbow) sets the shoulder-wrist distance of the iiwa: a pose that needs it beyond its
  // limit (-2.094 rad) cannot be reached by the other joints.
  const std::vector<double> start{0.0, 0.5, 0.0, -2.0, 0.0, 0.6, 0.0};
  std::vector<double> beyond = start;
  beyond[3] = -2.4;
  c.tree->set_positions(start);
  const Model& m = c.tree->model();
  Model::Data d = m.make_data();
  const int tip = m.find_body("iiwa_link_ee");
  m.forward(beyond, d);
  c.ctrl->set_tip("iiwa_link_ee");
  c.ctrl->set_target_pose(m.pose(d, tip).isometry());
  c.ctrl->set_mode(ControlMode::Cartesian);
  EXPECT_FALSE(c.ctrl->limited());
  int first_limited = -1;
  for (int i = 0; i < 2000; ++i) {
    c.env.step();
    if (first_limited < 0 && c.ctrl->limited()) first_limited = i;
  }
  EXPECT_GT(first_limited, 0);  // not at once: the elbow reaches its limit on the way
  EXPECT_TRUE(c.ctrl->limited());
  EXPECT_FALSE(c.ctrl->done());
  EXPECT_NEAR(c.tree->positions()[3], -2.09439510239, 1e-9);  // held at the limit
  // A reachable pose: no longer limited, and done.
  std::vector<double> inside = start;
  inside[3] = -1.8;
  m.forward(inside, d);
  c.ctrl->set_target_pose(m.pose(d, tip).isometry());
  c.env.run_for(2.0);
  EXPECT_FALSE(c.ctrl->limited());
  EXPECT_TRUE(c.ctrl->done());

  // Position: a target outside the limits is planned to the nearest position inside, and reported.
  std::vector<double> target = inside;
  target[1] = 3.0;
  c.ctrl->set_target(target);
  c.ctrl->set_mode(ControlMode::Position);
  c.env.step();
  EXPECT_TRUE(c.ctrl->limited());
  c.env.run_for(c.ctrl->trajectory_duration());
  EXPECT_TRUE(c.ctrl->done());
  EXPECT_NEAR(c.tree->positions()[1], 2.09439510239, 1e-9);
  target[1] = 1.0;
  c.ctrl->set_target(target);
  c.env.step();
  EXPECT_FALSE(c.ctrl->limited());

  // Velocity: limited while a joint is held at a limit against the command.
  c.ctrl->set_target_velocity(std::vector<double>{0.0, 5.0, 0.0, 0.0, 0.0, 0.0, 0.0});
  c.ctrl->set_mode(ControlMode::Velocity);
  c.env.run_for(0.5);
  EXPECT_TRUE(c.ctrl->limited());
  c.ctrl->set_target_velocity(std::vector<double>{0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0});
  c.env.step();
  EXPECT_FALSE(c.ctrl->limited());
}

}  // namespace
}  // namespace vsd::robotics
