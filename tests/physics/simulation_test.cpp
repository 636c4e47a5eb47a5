// vsd::physics and the database: bodies and joints follow the database through signals, the step writes
// poses back through the setters, changes made by others reach ODE, and bad input is a vsd::Error.
#include <gmock/gmock.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string_view>
#include <vector>

#include "fixture.hpp"
#include "vsd/io.hpp"

// Only to check that ODE's handlers are redirected (process wide, installed by the first Simulation).
#include <ode/ode.h>

namespace vsd::physics::test {
namespace {

using scene::GeometryKind;
using ::testing::HasSubstr;

class SimulationTest : public PhysicsTest {};

TEST_F(SimulationTest, ModuleRegistersClassesAndRunsAsASchedulerTask) {
  EXPECT_EQ(RigidBody::static_meta().name(), "physics::RigidBody");
  EXPECT_NE(env.registry().find_class("physics::World"), nullptr);
  EXPECT_NE(env.module<scene::Module>(), nullptr);  // used by the physics module
  auto& box = hull(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), at(0, 0, 10));
  body(box);
  env.scheduler().set_base_step(0.01);
  env.step();
  EXPECT_LT(box.frame().translation().z(), 10.0);
  EXPECT_NEAR(world->time(), 0.01, 1e-12);
  EXPECT_EQ(sim().stats().steps, 10u);  // World.step 1 ms: ten ODE steps per scheduler step
}

TEST_F(SimulationTest, EveryListenerSeesTheMotion) {
  auto& box = hull(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), at(0, 0, 10));
  auto& rb = body(box);
  int frames = 0;
  int velocities = 0;
  auto c1 = box.on_changed().connect([&](SimStateInstance&, const MetaProperty& p) {
    if (p.name() == "frame") ++frames;
  });
  auto c2 = rb.on_changed().connect([&](SimStateInstance&, const MetaProperty& p) {
    if (p.name() == "linear_velocity") ++velocities;
  });
  env.step();
  env.step();
  EXPECT_EQ(frames, 2);
  EXPECT_EQ(velocities, 2);
  EXPECT_LT(rb.linear_velocity().z(), 0.0);
  // The world frame cache of the node (and of its children) is current.
  EXPECT_NEAR(box.world_frame().translation().z(), box.frame().translation().z(), 1e-15);
}

TEST_F(SimulationTest, BodiesAndJointsAppearAndDisappearThroughSignals) {
  auto& g = geometry(GeometryKind::Sphere, Eigen::Vector3d::Zero(), 0.5);
  auto& a = hull(g, at(0, 0, 5), nullptr, nullptr, "a");
  auto& ra = body(a);
  sim().sync();
  EXPECT_EQ(sim().stats().bodies, 1u);
  EXPECT_EQ(sim().stats().geoms, 1u);
  auto& b = hull(g, at(2, 0, 5), nullptr, nullptr, "b");
  auto& rb = body(b);
  auto& j = s.create<Joint>();
  j.set_kind(JointKind::Ball);
  j.set_other(&a);
  b.add_extension(j);
  sim().sync();
  EXPECT_EQ(sim().stats().bodies, 2u);
  EXPECT_EQ(sim().stats().joints, 1u);
  EXPECT_TRUE(sim().simulates(rb));
  // Deleting the node deletes its extensions: the body and its joint leave ODE at once.
  s.destroy(b);
  EXPECT_EQ(sim().stats().bodies, 1u);
  EXPECT_EQ(sim().stats().joints, 0u);
  // Removing the RigidBody makes the hull static scenery: still a geom, no body.
  a.remove_extension(ra);
  sim().sync();
  EXPECT_EQ(sim().stats().bodies, 0u);
  EXPECT_EQ(sim().stats().geoms, 1u);
  const auto z = a.frame().translation().z();
  env.step();
  EXPECT_EQ(a.frame().translation().z(), z);
}

TEST_F(SimulationTest, AFrameSetByTheUserTeleportsTheBodyAndKeepsItsVelocity) {
  auto& box = hull(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), at(0, 0, 10));
  auto& rb = body(box);
  world->set_gravity(Eigen::Vector3d::Zero());
  rb.set_linear_velocity(Eigen::Vector3d(1, 0, 0));
  env.step();
  EXPECT_NEAR(box.frame().translation().x(), 0.01, 1e-12);
  box.set_frame(at(5, 5, 5));
  env.step();
  EXPECT_NEAR(box.frame().translation().x(), 5.01, 1e-12);
  EXPECT_NEAR(box.frame().translation().y(), 5.0, 1e-12);
  EXPECT_EQ(sim().stats().rebuilds, 1u);  // a teleport is no rebuild
  // Moving an ancestor moves the body with it.
  auto& group = s.create<scene::Node3D>();
  scene_root().add_child(group);
  group.add_child(box);
  env.step();
  group.set_frame(at(0, 100, 0));
  env.step();
  EXPECT_NEAR(box.world_frame().translation().y(), 105.0, 1e-9);
}

TEST_F(SimulationTest, MassAndVelocityChangesReachOde) {
  auto& box = hull(geometry(GeometryKind::Box, Eigen::Vector3d(1, 2, 4)), at(0, 0, 10));
  auto& rb = body(box);
  sim().sync();
  EXPECT_NEAR(sim().mass_of(rb).mass, 8000.0, 1e-9);  // 8 m^3 of the default density 1000 kg/m^3
  EXPECT_NEAR(sim().mass_of(rb).inertia(0, 0), 8000.0 * (4 + 16) / 12.0, 1e-6);
  rb.set_mass(2.0);
  sim().sync();
  EXPECT_NEAR(sim().mass_of(rb).mass, 2.0, 1e-12);
  EXPECT_NEAR(sim().mass_of(rb).inertia(0, 0), 2.0 * (4 + 16) / 12.0, 1e-12);
  // A force of 2 N on 2 kg against no gravity: 1 m/s^2 for one scheduler step, then the accumulator is clear.
  world->set_gravity(Eigen::Vector3d::Zero());
  rb.add_force(Eigen::Vector3d(2, 0, 0));
  env.step();
  EXPECT_NEAR(rb.linear_velocity().x(), 0.01, 1e-12);
  EXPECT_TRUE(rb.force().isZero());
  env.step();
  EXPECT_NEAR(rb.linear_velocity().x(), 0.01, 1e-12);
  rb.set_linear_velocity(Eigen::Vector3d(0, -3, 0));
  env.step();
  EXPECT_NEAR(rb.linear_velocity().y(), -3.0, 1e-12);
  EXPECT_NEAR(rb.linear_velocity().x(), 0.0, 1e-12);
  // A force off the centre of mass also turns the body.
  sim().add_force_at(rb, Eigen::Vector3d(0, 1, 0), box.world_frame() * Eigen::Vector3d(0.5, 0, 0));
  EXPECT_NEAR(rb.torque().z(), 0.5, 1e-12);
  env.step();
  EXPECT_GT(rb.angular_velocity().z(), 0.0);
}

TEST_F(SimulationTest, ExplicitInertiaAndAnOffCentreHull) {
  // A body node with a hull placed off its origin: the centre of mass is the hull's centre.
  auto& n = s.create<scene::Node3D>();
  n.set_frame(at(0, 0, 3));
  scene_root().add_child(n);
  auto& rb = s.create<RigidBody>();
  n.add_extension(rb);
  hull(geometry(GeometryKind::Sphere, Eigen::Vector3d::Zero(), 0.1), at(1, 0, 0), nullptr, &n);
  sim().sync();
  EXPECT_TRUE(sim().mass_of(rb).center.isApprox(Eigen::Vector3d(1, 0, 0)));
  rb.set_mass(3.0);
  rb.set_inertia_diagonal(Eigen::Vector3d(1, 2, 2.5));
  rb.set_center_of_mass(Eigen::Vector3d(0.5, 0, 0));
  sim().sync();
  EXPECT_EQ(sim().mass_of(rb).mass, 3.0);
  EXPECT_EQ(sim().mass_of(rb).inertia(1, 1), 2.0);
  EXPECT_TRUE(sim().mass_of(rb).center.isApprox(Eigen::Vector3d(0.5, 0, 0)));
  // Free fall of the whole node: its frame keeps its orientation, the node origin falls with the body.
  env.step();
  EXPECT_LT(n.frame().translation().z(), 3.0);
  EXPECT_NEAR(n.frame().translation().x(), 0.0, 1e-12);
}

TEST_F(SimulationTest, ErrorsAreVsdErrorsNamingTheCulprit) {
  auto& n = s.create<scene::Node3D>();
  n.set_name("lonely");
  scene_root().add_child(n);
  auto& rb = s.create<RigidBody>();
  n.add_extension(rb);
  EXPECT_THAT([&] { env.step(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("/scene/lonely")));
  EXPECT_THAT([&] { sim().sync(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("no mass")));
  rb.set_mass(-1.0);
  EXPECT_THAT([&] { sim().sync(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("mass must be >= 0")));
  rb.set_mass(1.0);
  rb.set_inertia_diagonal(Eigen::Vector3d(1, 1, 5));  // violates the triangle inequality
  EXPECT_THAT([&] { sim().sync(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("not physical")));
  rb.set_inertia_diagonal(Eigen::Vector3d(1, 1, 1));
  sim().sync();
  EXPECT_TRUE(sim().simulates(rb));
  // NaN from outside: frame, velocity, force.
  n.set_frame(at(std::nan(""), 0, 0));
  EXPECT_THAT([&] { env.step(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("non-finite frame")));
  n.set_frame(at(0, 0, 0));
  rb.set_linear_velocity(Eigen::Vector3d(INFINITY, 0, 0));
  EXPECT_THAT([&] { env.step(); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("velocities must be finite")));
  rb.set_linear_velocity(Eigen::Vector3d::Zero());
  rb.set_force(Eigen::Vector3d(0, std::nan(""), 0));
  EXPECT_THAT([&] { env.step(); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("force and torque must be finite")));
  rb.set_force(Eigen::Vector3d::Zero());
  env.step();  // fixed: runs again
  EXPECT_LT(n.frame().translation().z(), 0.0);
  // A plane on a body, a World with a bad step.
  auto& plane = hull(geometry(GeometryKind::Plane), at(0, 0, 0), nullptr, &n, "floor");
  EXPECT_THAT([&] { sim().sync(); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("cannot belong to a rigid body")));
  s.destroy(plane);
  world->set_step(0.0);
  EXPECT_THAT([&] { sim().sync(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("step must be > 0")));
  world->set_step(0.001);
  sim().sync();
}

TEST_F(SimulationTest, ABodyOrJointOutsideEveryWorldAndAJointAcrossWorldsAreErrors) {
  auto& g = geometry(GeometryKind::Sphere, Eigen::Vector3d::Zero(), 0.5);
  // A second world below its own node.
  auto& other_root = s.create<scene::Node3D>();
  other_root.set_name("elsewhere");
  s.database().add_child(other_root);
  auto& w2 = s.create<World>();
  other_root.add_extension(w2);
  auto& a = hull(g, at(0, 0, 0), nullptr, nullptr, "a");
  body(a);
  auto& b = hull(g, at(3, 0, 0), nullptr, &other_root, "b");
  body(b);
  sim().sync();
  EXPECT_EQ(sim().stats().worlds, 2u);
  auto& j = s.create<Joint>();
  j.set_other(&a);
  b.add_extension(j);
  EXPECT_THAT([&] { env.step(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("different worlds")));
  b.remove_extension(j);
  sim().sync();
  // Removing the second world puts b into the root's world.
  other_root.remove_extension(w2);
  sim().sync();
  EXPECT_EQ(sim().stats().worlds, 1u);
  EXPECT_EQ(sim().stats().bodies, 2u);
  s.destroy(b);
  // A joint on a node without a body, a joint to itself, a ball with limits.
  auto& k = s.create<Joint>();
  scene_root().add_extension(k);
  EXPECT_THAT([&] { sim().sync(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("has no RigidBody")));
  scene_root().remove_extension(k);
  auto& self = s.create<Joint>();
  self.set_other(&a);
  a.add_extension(self);
  EXPECT_THAT([&] { sim().sync(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("two different bodies")));
  self.set_other(nullptr);
  self.set_kind(JointKind::Ball);
  self.set_has_limits(true);
  EXPECT_THAT([&] { sim().sync(); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("limits and motors apply")));
  self.set_has_limits(false);
  sim().sync();
  EXPECT_EQ(sim().stats().joints, 1u);
  // Without any World the body is an error, not silently ignored.
  s.database().remove_extension(*world);
  EXPECT_THAT([&] { sim().sync(); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("is in no physics world")));
  EXPECT_EQ(sim().stats().worlds, 0u);
  EXPECT_EQ(sim().stats().bodies, 0u);
}

TEST_F(SimulationTest, RunawayForcesAndVelocitiesAreRefusedAndTheDatabaseKeepsItsState) {
  auto& box = hull(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), at(0, 0, 5));
  auto& rb = body(box);
  env.step();
  const Eigen::Isometry3d before = box.frame();
  rb.set_force(Eigen::Vector3d(1e308, 1e308, 0));
  EXPECT_THAT([&] { env.step(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("more than 1e8")));
  EXPECT_TRUE(box.frame().isApprox(before));
  rb.set_force(Eigen::Vector3d::Zero());
  rb.set_angular_velocity(Eigen::Vector3d(0, 0, 1e9));
  EXPECT_THAT([&] { env.step(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("below 1e8")));
  rb.set_angular_velocity(Eigen::Vector3d::Zero());
  env.step();
  EXPECT_TRUE(box.frame().matrix().allFinite());
  EXPECT_LT(box.frame().translation().z(), before.translation().z());
}

TEST_F(SimulationTest, OdeErrorHandlerThrowsAVsdErrorInsteadOfAborting) {
  sim().sync();  // ODE is initialised and its handlers are ours while a Simulation lives
  EXPECT_THAT([] { dError(7, "bad thing %d", 3); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("ODE error: ODE 7: bad thing 3")));
  EXPECT_THAT(
      [] { dDebug(8, "broken %s", "invariant"); },
      ::testing::ThrowsMessage<vsd::Error>(HasSubstr("ODE internal check failed: ODE 8: broken invariant")));
  // Messages are warnings of the simulation that runs into them (here: none is running, so they are kept
  // aside).
  dMessage(9, "just saying");
  SUCCEED();
}

TEST_F(SimulationTest, BodiesSaveAndLoadThroughVsdIoAndGoOnIdentically) {
  auto& g = geometry(GeometryKind::Box, Eigen::Vector3d(0.2, 0.3, 0.4));
  auto& box = hull(g, at(0, 0, 10));
  auto& rb = body(box);
  rb.set_angular_velocity(Eigen::Vector3d(0, 0, 2));
  for (int i = 0; i < 5; ++i) env.step();
  const auto bytes = vsd::io::save_bytes(s, vsd::io::Format::Binary);
  for (int i = 0; i < 5; ++i) env.step();

  vsd::Environment env2;
  env2.use<Module>();
  vsd::io::load_bytes(env2.main_state(), bytes);
  auto bodies = env2.main_state().index().all<RigidBody>();
  ASSERT_EQ(bodies.size(), 1u);
  EXPECT_TRUE(bodies[0]->angular_velocity().isApprox(Eigen::Vector3d(0, 0, 2)));
  EXPECT_NEAR(bodies[0]->linear_velocity().z(), rb.linear_velocity().z() + 9.81 * 0.05,
              1e-9);  // 5 steps earlier
  for (int i = 0; i < 5; ++i) env2.step();
  const auto* box2 = bodies[0]->node();
  ASSERT_NE(box2, nullptr);
  EXPECT_TRUE(box2->frame().isApprox(box.frame(), 1e-12));
  EXPECT_TRUE(bodies[0]->linear_velocity().isApprox(rb.linear_velocity(), 1e-12));
}

std::string two_link_urdf(const char* type) {
  return std::string(R"(<robot name="r">
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type=")") +
         type + R"("><parent link="base"/><child link="arm"/><origin xyz="0 0 1"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>)";
}

TEST_F(SimulationTest, MakeDynamicTurnsAUrdfIntoBodiesAndJoints) {
  auto r = scene::load_urdf_text(s.database(), two_link_urdf("revolute"), "two.urdf", ".");
  EXPECT_EQ(make_dynamic(*r.scene), 2u);
  sim().sync();
  EXPECT_EQ(sim().stats().bodies, 2u);
  EXPECT_EQ(sim().stats().joints, 2u);  // the hinge and the base held to the world
  auto* hinge = r.scene->find_link("arm")->find_extension<Joint>();
  ASSERT_NE(hinge, nullptr);
  EXPECT_EQ(hinge->kind(), JointKind::Hinge);
  EXPECT_TRUE(hinge->has_limits());
  EXPECT_NEAR(sim().mass_of(*r.scene->find_link("arm")->find_extension<RigidBody>()).center.x(), 0.5, 1e-12);
  env.run_for(3.0);  // the arm falls about y until it rests on its limit; the base stays
  EXPECT_NEAR(std::abs(hinge->position()), 1.0, 0.02);
  EXPECT_NEAR(r.scene->find_link("base")->world_frame().translation().norm(), 0.0, 1e-3);
  // A planar joint: an error naming it, and nothing made.
  auto bad = scene::load_urdf_text(s.database(), two_link_urdf("planar"), "planar.urdf", ".");
  EXPECT_THAT([&] { make_dynamic(*bad.scene); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("joint 'j'")));
  EXPECT_EQ(bad.scene->find_link("arm")->find_extension<RigidBody>(), nullptr);
}

// A negative link mass used to make make_dynamic() skip the link silently (it then moved with its parent
// as a massless frame). The URDF loader refuses it; set in the database, it is an error naming the link.
TEST_F(SimulationTest, ANegativeLinkMassIsAnErrorNamingTheLink) {
  auto r = scene::load_urdf_text(s.database(), two_link_urdf("revolute"), "two.urdf", ".");
  scene::Link* arm = r.scene->find_link("arm");
  arm->set_mass(-1.0);
  EXPECT_THAT([&] { make_dynamic(*r.scene); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("link 'arm' of scene 'r' has a mass of -1")));
  EXPECT_EQ(r.scene->find_link("base")->find_extension<RigidBody>(), nullptr);  // nothing made
  arm->set_mass(1.0);
  ASSERT_EQ(make_dynamic(*r.scene), 2u);
  sim().sync();
  arm->set_mass(-1.0);  // after the fact: the next sync names it
  EXPECT_THAT([&] { sim().sync(); }, ::testing::ThrowsMessage<vsd::Error>(HasSubstr("has a mass of -1")));
}

// `vsd-physics --dt 1e6` hung (1e9 ODE steps per scheduler step) and `--dt 1e17` "simulated" after 0 steps
// (the step count overflowed its integer): an interval that needs more than max_steps_per_advance steps
// is an error, and nothing moves.
TEST_F(SimulationTest, AnAbsurdIntervalIsAnErrorAndNothingMoves) {
  auto& box = hull(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), at(0, 0, 5));
  body(box);
  const auto refused = [&](double seconds, double time) {
    EXPECT_THAT([&] { sim().advance(seconds); },
                ::testing::ThrowsMessage<vsd::Error>(HasSubstr("steps of 0.001 s in physics::World")))
        << seconds;
    EXPECT_TRUE(box.frame().isApprox(at(0, 0, 5 - 0.5 * 9.81 * time * time), 1e-3)) << seconds;
    EXPECT_DOUBLE_EQ(world->time(), time);
  };
  refused(1e6, 0.0);  // the first call, before ODE holds anything
  EXPECT_EQ(sim().stats().steps, 0u);
  sim().advance(0.01);
  for (double seconds : {1e6, 1e17, 1e300}) refused(seconds, 0.01);
  EXPECT_EQ(sim().stats().steps, 10u);
  // The limit is in steps: a larger World step allows a longer interval.
  world->set_step(1.0);
  sim().advance(1e4);
  EXPECT_DOUBLE_EQ(world->time(), 0.01 + 1e4);
}

// Hulls overlapping en masse: the contact points of one step are bounded (each is an ODE contact joint);
// beyond the bound the step is an error, never an exhausted memory or an exception through ODE's C frames.
TEST_F(SimulationTest, TooManyContactPointsInOneStepAreAnError) {
  auto& geo = geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1));
  std::vector<scene::Hull*> boxes;
  for (int i = 0; i < 400; ++i) {  // 79,800 overlapping pairs, up to 8 contact points each
    boxes.push_back(&hull(geo, at(0.001 * i, 0, 0)));
    body(*boxes.back());
  }
  EXPECT_THAT([&] { sim().advance(0.001); },
              ::testing::ThrowsMessage<vsd::Error>(HasSubstr("more than 100000 contact points in one step")));
  EXPECT_TRUE(boxes[7]->frame().isApprox(at(0.007, 0, 0)));
  // Fewer of them step again.
  for (std::size_t i = 10; i < boxes.size(); ++i) s.destroy(*boxes[i]);
  sim().advance(0.001);
  EXPECT_GT(sim().stats().contacts, 0u);
}

// The example model with primitive hulls (tests/scene/data/iiwa14_primitives.urdf): its inertials are the
// original's, its hulls collide. Unpowered, the arm falls from upright onto its floor plate and comes to
// rest on it — neither through it nor (as without hulls) through itself.
TEST_F(SimulationTest, ThePrimitiveIiwaFallsOntoItsFloorAndRests) {
  auto r = scene::load_urdf(s.database(), std::string(VSD_SCENE_TEST_DATA_DIR) + "/iiwa14_primitives.urdf");
  EXPECT_TRUE(r.warnings.empty());
  EXPECT_EQ(make_dynamic(*r.scene), 8u);
  env.run_for(4.0);
  EXPECT_EQ(sim().stats().geoms, 11u);
  double lowest = 1e9;
  for (const scene::Link* l : r.scene->links()) {
    const RigidBody* b = l->find_extension<RigidBody>();
    if (b == nullptr) continue;
    EXPECT_LT(b->linear_velocity().norm(), 0.1) << l->name();  // settling: contact order varies by run
    if (l->name() != "iiwa_link_0") lowest = std::min(lowest, l->world_frame().translation().z());
  }
  const double tip = r.scene->find_link("iiwa_link_7")->world_frame().translation().z();
  EXPECT_LT(tip, 0.15);  // it lies down (1.27 m when upright)
  EXPECT_GT(lowest, 0.02);  // every moving link's origin above the floor (the thinnest hull is 9 cm across)
  EXPECT_GT(sim().stats().contacts, 0u);
}

TEST_F(SimulationTest, JointsWithLimitsAndMotors) {
  world->set_gravity(Eigen::Vector3d::Zero());
  auto& g = geometry(GeometryKind::Box, Eigen::Vector3d(1, 0.1, 0.1));
  auto& arm = hull(g, at(0.5, 0, 1), nullptr, nullptr, "arm");
  body(arm, 1.0);
  auto& hinge = s.create<Joint>();
  hinge.set_kind(JointKind::Hinge);
  hinge.set_anchor(Eigen::Vector3d(-0.5, 0, 0));  // at the arm's end, about z
  hinge.set_axis(Eigen::Vector3d::UnitZ());
  hinge.set_motor_velocity(1.0);
  hinge.set_motor_max_force(100.0);
  hinge.set_has_limits(true);
  hinge.set_lower(-0.5);
  hinge.set_upper(0.3);
  arm.add_extension(hinge);
  env.step();
  EXPECT_NEAR(hinge.rate(), 1.0, 1e-3);  // the motor reaches its velocity at once (100 N m on 0.33 kg m^2)
  for (int i = 0; i < 100; ++i) env.step();
  EXPECT_NEAR(hinge.position(), 0.3, 0.01);  // held at the upper limit
  EXPECT_NEAR(hinge.rate(), 0.0, 1e-2);
  // The arm turned about the anchor, which stayed where it was.
  const Eigen::Vector3d anchor = arm.world_frame() * Eigen::Vector3d(-0.5, 0, 0);
  EXPECT_TRUE(anchor.isApprox(Eigen::Vector3d(0, 0, 1), 1e-3));
  // Reverse the motor: it runs to the lower limit.
  hinge.set_motor_velocity(-2.0);
  for (int i = 0; i < 100; ++i) env.step();
  EXPECT_NEAR(hinge.position(), -0.5, 0.01);

  // A slider with a motor, a fixed joint and a universal joint between two bodies.
  auto& cart = hull(g, at(0, 5, 1), nullptr, nullptr, "cart");
  body(cart, 2.0);
  auto& slider = s.create<Joint>();
  slider.set_kind(JointKind::Slider);
  slider.set_axis(Eigen::Vector3d::UnitX());
  slider.set_motor_velocity(0.5);
  slider.set_motor_max_force(50.0);
  cart.add_extension(slider);
  auto& rider = hull(g, at(0, 5, 2), nullptr, nullptr, "rider");
  body(rider, 1.0);
  auto& weld = s.create<Joint>();
  weld.set_kind(JointKind::Fixed);
  weld.set_other(&cart);
  rider.add_extension(weld);
  for (int i = 0; i < 100; ++i) env.step();  // one second
  EXPECT_NEAR(slider.position(), 0.5, 0.01);
  EXPECT_NEAR(rider.world_frame().translation().x() - cart.world_frame().translation().x(), 0.0, 1e-3);
  EXPECT_NEAR(rider.world_frame().translation().z(), 2.0, 1e-3);
  weld.set_kind(JointKind::Universal);
  weld.set_axis(Eigen::Vector3d::UnitX());
  weld.set_axis2(Eigen::Vector3d::UnitY());
  env.step();
  EXPECT_EQ(sim().stats().joints, 3u);
  // Deleting a joint releases the body.
  s.destroy(slider);
  EXPECT_EQ(sim().stats().joints, 2u);
}

// A universal joint holding a rod to the static world at its end: axis 1 (x) is fixed in the rod, axis 2
// (y) in the world. Without gravity only the motors act, so each angle follows its motor and stops at
// its limit; the rod's pose is then the rotation about y by the second angle, checkable by hand.
TEST_F(SimulationTest, UniversalJointSecondAxisHasLimitsAndAMotor) {
  world->set_gravity(Eigen::Vector3d::Zero());
  auto& g = geometry(GeometryKind::Box, Eigen::Vector3d(0.1, 0.1, 1));
  auto& rod = hull(g, at(0, 0, 0.5), nullptr, nullptr, "rod");
  body(rod, 1.0);
  auto& u = s.create<Joint>();
  u.set_kind(JointKind::Universal);
  u.set_anchor(Eigen::Vector3d(0, 0, -0.5));  // the rod's lower end, at the world origin
  u.set_axis(Eigen::Vector3d::UnitX());
  u.set_axis2(Eigen::Vector3d::UnitY());
  u.set_motor_velocity2(0.5);
  u.set_motor_max_force2(100.0);
  u.set_has_limits2(true);
  u.set_lower2(-0.2);
  u.set_upper2(0.4);
  rod.add_extension(u);
  env.step();
  EXPECT_NEAR(u.rate2(), 0.5, 1e-3);  // 100 N m on about 0.34 kg m^2: the motor's velocity at once
  EXPECT_NEAR(u.rate(), 0.0, 1e-6);   // nothing drives the first axis
  for (int i = 0; i < 40; ++i) env.step();
  EXPECT_NEAR(u.position2(), 0.5 * 0.41, 0.01);  // 41 scheduler steps of 10 ms at 0.5 rad/s
  for (int i = 0; i < 100; ++i) env.step();
  EXPECT_NEAR(u.position2(), 0.4, 0.01);  // held at the upper stop
  EXPECT_NEAR(u.rate2(), 0.0, 1e-2);
  EXPECT_NEAR(u.position(), 0.0, 1e-6);
  // The rod turned about the world's y axis through the anchor by the second angle (ODE's sign).
  const Eigen::AngleAxisd turned(rod.world_frame().rotation());
  EXPECT_NEAR(turned.angle(), 0.4, 0.01);
  EXPECT_NEAR(std::abs(turned.axis().y()), 1.0, 1e-6);
  EXPECT_TRUE((rod.world_frame() * Eigen::Vector3d(0, 0, -0.5)).isZero(1e-3));
  // Reversed, the motor runs to the lower stop; the first axis, with a motor of its own, turns meanwhile.
  u.set_motor_velocity2(-1.0);
  u.set_motor_velocity(0.3);
  u.set_motor_max_force(100.0);
  for (int i = 0; i < 150; ++i) env.step();
  EXPECT_NEAR(u.position2(), -0.2, 0.01);
  EXPECT_NEAR(u.rate(), 0.3, 1e-2);
  // Without the stop the motor keeps its velocity past the old limit.
  u.set_has_limits2(false);
  u.set_motor_velocity(0.0);
  u.set_motor_velocity2(-0.5);
  for (int i = 0; i < 60; ++i) env.step();
  EXPECT_NEAR(u.rate2(), -0.5, 1e-2);
  EXPECT_LT(u.position2(), -0.45);

  // The new properties save, load and replicate like the others.
  SimState& replica = env.create_state("replica");
  replica.copy_from(s);
  s.start_recording();
  u.set_has_limits2(true);
  u.set_lower2(-0.7);
  u.set_upper2(0.1);
  u.set_motor_max_force2(7.0);
  replica.apply(s.stop_recording());
  const auto* ru = replica.find(u.id())->as<Joint>();
  ASSERT_NE(ru, nullptr);
  EXPECT_TRUE(ru->has_limits2());
  EXPECT_EQ(ru->lower2(), -0.7);
  EXPECT_EQ(ru->upper2(), 0.1);
  EXPECT_EQ(ru->motor_velocity2(), -0.5);
  EXPECT_EQ(ru->motor_max_force2(), 7.0);
  vsd::Environment env2;
  env2.use<Module>();
  vsd::io::load_bytes(env2.main_state(), vsd::io::save_bytes(s, vsd::io::Format::Text));
  auto joints = env2.main_state().index().all<Joint>();
  ASSERT_EQ(joints.size(), 1u);
  EXPECT_TRUE(joints[0]->has_limits2());
  EXPECT_EQ(joints[0]->lower2(), -0.7);
  EXPECT_EQ(joints[0]->upper2(), 0.1);
  EXPECT_EQ(joints[0]->motor_velocity2(), -0.5);
  EXPECT_EQ(joints[0]->motor_max_force2(), 7.0);
  env.remove_state(replica);
}

TEST_F(SimulationTest, SecondAxisLimitsAndMotorsAreCheckedAndNameTheJoint) {
  auto& g = geometry(GeometryKind::Box, Eigen::Vector3d(0.1, 0.1, 1));
  auto& rod = hull(g, at(0, 0, 0.5), nullptr, nullptr, "rod");
  body(rod, 1.0);
  auto& j = s.create<Joint>();
  j.set_name("wrist");
  j.set_kind(JointKind::Hinge);
  j.set_has_limits2(true);
  rod.add_extension(j);
  auto fails = [&](const char* what) {
    EXPECT_THAT([&] { sim().sync(); }, ::testing::ThrowsMessage<vsd::Error>(
                                           ::testing::AllOf(HasSubstr("'wrist'"), HasSubstr(what))));
  };
  fails("apply to universal joints only");
  j.set_has_limits2(false);
  j.set_motor_max_force2(1.0);
  fails("apply to universal joints only");
  j.set_kind(JointKind::Universal);
  j.set_axis(Eigen::Vector3d::UnitX());
  j.set_axis2(Eigen::Vector3d::UnitY());
  j.set_motor_max_force2(-1.0);
  fails("motor_max_force2 >= 0");
  j.set_motor_max_force2(1.0);
  j.set_motor_velocity2(std::nan(""));
  fails("must be finite");
  j.set_motor_velocity2(0.0);
  j.set_has_limits2(true);
  j.set_lower2(0.5);
  j.set_upper2(0.1);
  fails("lower2 limit above upper2");
  j.set_lower2(-2.0);
  fails("[-pi/2, pi/2]");
  j.set_lower2(-1.0);
  sim().sync();  // now valid
  EXPECT_EQ(sim().stats().joints, 1u);
}

// Physics runs where it is asked to: the main state by default; a replica only shows what it is sent; a
// what-if copy simulates once it is stepped, on its own, and states come and go in any order.
TEST_F(SimulationTest, OnlySteppedStatesAreSimulatedEachOnItsOwn) {
  auto& box = hull(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), at(0, 0, 10));
  body(box);
  Module& m = *env.module<Module>();
  SimState& replica = env.create_state("replica");
  replica.copy_from(s);
  SimState& what_if = env.create_state("what-if");
  what_if.copy_from(s);
  EXPECT_EQ(env.service(m, replica), Service::none);
  EXPECT_THROW((void)m.simulation(replica), vsd::Error);
  env.set_service(m, what_if, Service::stepped);
  auto* w_box = what_if.find<scene::Hull>(box.id());
  auto* w_body = w_box->find_extension<RigidBody>();
  w_body->set_linear_velocity(Eigen::Vector3d(0, 0, 20));  // the copy throws the box up
  s.start_recording();
  env.run_for(0.1);
  replica.apply(s.stop_recording());
  std::string diff;
  EXPECT_TRUE(replica.equals(s, &diff)) << diff;
  EXPECT_LT(box.frame().translation().z(), 10.0);
  EXPECT_GT(w_box->frame().translation().z(), 10.0) << "the copy simulated its own throw";
  EXPECT_EQ(m.simulation(what_if).stats().bodies, 1u);
  env.remove_state(replica);
  env.set_service(m, what_if, Service::none);
  const double z = w_box->frame().translation().z();
  env.run_for(0.05);
  EXPECT_EQ(w_box->frame().translation().z(), z) << "no longer simulated";
  env.remove_state(what_if);
  env.run_for(0.05);
}

}  // namespace
}  // namespace vsd::physics::test
