// Inverse kinematics: reachable targets are found within tolerance and limits, unreachable ones are
// reported as failures, restarts respect the time budget, bad arguments are errors.
#include "vsd/robotics/ik.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <random>

#include "test_util.hpp"
#include "vsd/robotics.hpp"

namespace vsd::robotics {
namespace {

using vsd_test::random_q;
using vsd_test::robot_file;

Model iiwa_chain(Environment& env) {
  env.use<Module>();
  scene::UrdfOptions o;
  o.load_meshes = false;
  auto rep = scene::load_urdf(env.main_state().database(), robot_file("iiwa14.urdf"), o);
  (void)build_kinematics(*rep.scene);
  return Model::compile(*rep.scene->find_link("iiwa_link_0"), rep.scene->find_link("iiwa_link_ee"));
}

bool within_limits(const Model& m, const std::vector<double>& q) {
  for (std::size_t i = 0; i < q.size(); ++i) {
    const DofInfo& d = m.layout()[i];
    if (d.has_limits && (q[i] < d.lower || q[i] > d.upper)) return false;
  }
  return true;
}

TEST(Ik, ReachesTargetsFromNearbySeeds) {
  Environment env;
  const Model m = iiwa_chain(env);
  IkOptions o;
  o.time_budget = 10.0;  // results must not depend on the machine's speed (sanitizer builds are slow)
  IkSolver ik(m, m.tip(), o);
  Model::Data d = m.make_data();
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.1);
  for (int n = 0; n < 200; ++n) {
    const std::vector<double> goal = random_q(m, rng);
    m.forward(goal, d);
    const Eigen::Isometry3d target = m.pose(d, m.tip()).isometry();
    std::vector<double> seed = goal;
    for (double& v : seed) v += noise(rng);
    m.clamp(seed.data());
    const IkResult r = ik.solve(target, seed);
    ASSERT_TRUE(r.success) << "configuration " << n;
    EXPECT_TRUE(within_limits(m, r.q));
    m.forward(r.q, d);
    EXPECT_LT((m.pose(d, m.tip()).translation - target.translation()).norm(), 1e-6);
    EXPECT_LT(r.position_error, 1e-6);
    EXPECT_LT(r.orientation_error, 1e-6);
  }
  EXPECT_EQ(ik.calls(), 200u);
  EXPECT_EQ(ik.successes(), 200u);
  EXPECT_DOUBLE_EQ(ik.success_rate(), 1.0);
}

TEST(Ik, RestartsFindFarTargets) {
  Environment env;
  const Model m = iiwa_chain(env);
  IkOptions o;
  o.time_budget = 30.0;  // bounded by max_restarts; independent of the machine's speed
  o.max_restarts = 200;
  IkSolver ik(m, m.tip(), o);
  Model::Data d = m.make_data();
  std::mt19937_64 rng(2);
  int restarted = 0;
  for (int n = 0; n < 20; ++n) {
    const std::vector<double> goal = random_q(m, rng);
    m.forward(goal, d);
    const IkResult r = ik.solve(m.pose(d, m.tip()).isometry(), random_q(m, rng));
    EXPECT_TRUE(r.success) << n;
    EXPECT_TRUE(within_limits(m, r.q));
    restarted += r.restarts > 0 ? 1 : 0;
  }
  EXPECT_GE(ik.success_rate(), 0.95);
  (void)restarted;
}

TEST(Ik, UnreachableTargetFailsWithinTheBudget) {
  Environment env;
  const Model m = iiwa_chain(env);
  IkOptions o;
  o.time_budget = 30.0;
  o.max_restarts = 5;
  IkSolver ik(m, m.tip(), o);
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() = Eigen::Vector3d(3.0, 0, 0.5);  // the arm reaches about 1.3 m
  IkResult r = ik.solve(far, std::vector<double>(7, 0.0));
  EXPECT_FALSE(r.success);
  EXPECT_GT(r.position_error, 1.0);
  EXPECT_EQ(r.restarts, 5);
  EXPECT_TRUE(within_limits(m, r.q));
  EXPECT_EQ(ik.success_rate(), 0.0);
  // The time budget ends the restarts long before max_restarts.
  o.time_budget = 0.05;
  o.max_restarts = 1000000;
  ik.set_options(o);
  const auto t0 = std::chrono::steady_clock::now();
  r = ik.solve(far, std::vector<double>(7, 0.0));
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_FALSE(r.success);
  EXPECT_LT(r.restarts, 1000000);
  EXPECT_LT(took, 2.0);  // the budget plus one attempt, generously bounded for loaded and sanitizer builds
}

// IK that fails reports the error of the best joint vector it found: it printed `position_error 0` with
// `success: false` when the error was too large to square (a target 1e200 m away).
TEST(Ik, AFailureReportsTheRealError) {
  Environment env;
  const Model m = iiwa_chain(env);
  IkOptions o;
  o.time_budget = 0.0;
  o.max_restarts = 1;
  IkSolver ik(m, m.tip(), o);
  for (double distance : {3.0, 1e200}) {
    Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
    far.translation() = Eigen::Vector3d(distance, 0, 0);
    const IkResult r = ik.solve(far, std::vector<double>(7, 0.0));
    EXPECT_FALSE(r.success);
    EXPECT_GT(r.position_error, 0.5 * distance) << distance;
    EXPECT_TRUE(std::isfinite(r.position_error)) << distance;
  }
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)ik.solve(bad, std::vector<double>(7, 0.0)), vsd::Error);
  std::vector<double> seed(7, 0.0);
  seed[3] = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)ik.solve(Eigen::Isometry3d::Identity(), seed), vsd::Error);
}

TEST(Ik, BadArgumentsAreErrors) {
  Environment env;
  const Model m = iiwa_chain(env);
  EXPECT_THROW(IkSolver(m, 99), vsd::Error);
  EXPECT_THROW(IkSolver(m, -1), vsd::Error);
  IkSolver ik(m, m.tip());
  EXPECT_THROW((void)ik.solve(Eigen::Isometry3d::Identity(), std::vector<double>(3, 0.0)), vsd::Error);
  std::vector<JointSpec> fixed(1);
  fixed[0].name = "weld";
  fixed[0].body = "b";
  fixed[0].type = KinematicJointType::Fixed;
  const Model rigid = Model::build(fixed);
  EXPECT_THROW(IkSolver(rigid, 0), vsd::Error);
}

}  // namespace
}  // namespace vsd::robotics
