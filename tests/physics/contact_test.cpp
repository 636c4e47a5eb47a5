// Contacts from ODE's own collider: none between jointed bodies, deep and near-touching box/box and
// box/cylinder pairs without a crash, resting contact, and contact properties and shapes that follow the
// database.
#include <gmock/gmock.h>

#include <cmath>

#include "fixture.hpp"

namespace vsd::physics::test {
namespace {

using scene::GeometryKind;

class ContactTest : public PhysicsTest {
 public:
  ContactTest() { world->set_gravity(Eigen::Vector3d::Zero()); }

  // Two bodies: a unit box at the origin and @p other at @p where (rotated about z by @p angle).
  void pair(scene::Geometry& other, const Eigen::Vector3d& where, double angle) {
    auto& a = hull(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), at(0, 0, 0), nullptr, nullptr, "a");
    Eigen::Isometry3d f = at(where.x(), where.y(), where.z());
    f.rotate(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()));
    auto& b = hull(other, f, nullptr, nullptr, "b");
    body(a);
    body(b);
    first = &a;
    second = &b;
  }
  double gap() const {  // centre distance along x
    return second->world_frame().translation().x() - first->world_frame().translation().x();
  }
  scene::Hull* first = nullptr;
  scene::Hull* second = nullptr;
};

// Bodies joined by a joint do not collide with each other (a robot's neighbouring links overlap at their
// joints); the test is a lookup in the joint records, not ODE's walk over every joint of a body.
TEST_F(ContactTest, JointedBodiesDoNotCollide) {
  pair(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), Eigen::Vector3d(0.5, 0, 0), 0.0);
  auto& ball = s.create<Joint>();
  ball.set_kind(JointKind::Ball);
  ball.set_other(first);
  second->add_extension(ball);
  env.step();
  EXPECT_EQ(sim().stats().contacts, 0u);
  s.destroy(ball);
  env.step();
  EXPECT_GT(sim().stats().contacts, 0u);
}

// Friction and restitution are used inside ODE's collision callback, where nothing can be refused: a
// material outside their ranges is an error naming the hull when the hull enters the simulation (it was
// clamped silently).
TEST_F(ContactTest, MaterialValuesOutsideTheirRangesAreErrors) {
  pair(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), Eigen::Vector3d(2, 0, 0), 0.0);
  scene::Material& m = material(-0.3, 0.5);
  second->set_material(&m);
  EXPECT_THAT([&] { env.step(); },
              ::testing::ThrowsMessage<vsd::Error>(::testing::HasSubstr("material friction must be finite and >= 0")));
  m.set_friction(0.3);
  m.set_restitution(1.5);
  EXPECT_THAT([&] { env.step(); },
              ::testing::ThrowsMessage<vsd::Error>(::testing::HasSubstr("restitution must lie in [0, 1], got 1.5")));
  m.set_restitution(0.5);
  env.step();
  EXPECT_GT(sim().stats().steps, 0u);
}

TEST_F(ContactTest, DeepBoxBoxPenetrationIsResolvedWithoutACrash) {
  // Almost fully inside each other (centres 1 cm apart), rotated: a degenerate case for box/box.
  pair(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), Eigen::Vector3d(0.01, 0, 0), 0.3);
  for (int i = 0; i < 300; ++i) env.step();
  EXPECT_GT(sim().stats().steps, 0u);
  EXPECT_TRUE(first->world_frame().matrix().allFinite());
  EXPECT_TRUE(second->world_frame().matrix().allFinite());
  EXPECT_GT(std::abs(gap()), 0.01);  // pushed apart (at the contact's max correcting velocity)
}

TEST_F(ContactTest, NearTouchingBoxBoxMakesAContactAndNoMotion) {
  // Faces 1e-9 m apart / 1e-9 m deep: neither explodes nor drifts.
  for (double d : {1.0 + 1e-9, 1.0 - 1e-9}) {
    pair(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), Eigen::Vector3d(d, 0, 0), 0.0);
    for (int i = 0; i < 100; ++i) env.step();
    EXPECT_NEAR(gap(), d, 1e-6) << d;
    EXPECT_TRUE(second->world_frame().matrix().allFinite());
    s.destroy(*first);
    s.destroy(*second);
  }
}

TEST_F(ContactTest, BoxCylinderDeepAndNearTouching) {
  auto& cyl = geometry(GeometryKind::Cylinder, Eigen::Vector3d::Zero(), 0.5, 1.0);
  // Deep: the cylinder's axis (z) through the box, centres 5 cm apart.
  pair(cyl, Eigen::Vector3d(0.05, 0.0, 0.0), 0.2);
  for (int i = 0; i < 300; ++i) env.step();
  EXPECT_TRUE(second->world_frame().matrix().allFinite());
  EXPECT_GT(std::abs(gap()), 0.05);
  s.destroy(*first);
  s.destroy(*second);
  // Near touching: the cylinder's side against the box's face, 1e-9 m apart.
  pair(cyl, Eigen::Vector3d(1.0 + 1e-9, 0, 0), 0.0);
  for (int i = 0; i < 100; ++i) env.step();
  EXPECT_NEAR(gap(), 1.0, 1e-6);
  // Tilted cylinder edge on the box's corner region.
  s.destroy(*first);
  s.destroy(*second);
  auto& a = hull(geometry(GeometryKind::Box, Eigen::Vector3d(1, 1, 1)), at(0, 0, 0), nullptr, nullptr, "a");
  Eigen::Isometry3d f = at(0.7, 0.7, 0.7);
  f.rotate(Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 1, 0).normalized()));
  auto& b = hull(cyl, f, nullptr, nullptr, "b");
  body(a);
  body(b);
  for (int i = 0; i < 300; ++i) env.step();
  EXPECT_TRUE(a.world_frame().matrix().allFinite());
  EXPECT_TRUE(b.world_frame().matrix().allFinite());
}

TEST_F(ContactTest, StackComesToRestOnTheGround) {
  world->set_gravity(Eigen::Vector3d(0, 0, -9.81));
  ground();
  auto& cube = geometry(GeometryKind::Box, Eigen::Vector3d(0.2, 0.2, 0.2));
  std::vector<RigidBody*> bodies;
  for (int i = 0; i < 3; ++i)
    bodies.push_back(&body(hull(cube, at(0, 0, 0.1 + 0.2 * i + 0.01 * i), nullptr, nullptr)));
  bodies.push_back(
      &body(hull(geometry(GeometryKind::Cylinder, Eigen::Vector3d::Zero(), 0.1, 0.2), at(0, 0, 0.75))));
  env.run_for(3.0);
  for (RigidBody* b : bodies) EXPECT_LT(b->linear_velocity().norm(), 1e-2) << b->node()->path();
  EXPECT_NEAR(bodies.back()->node()->world_frame().translation().z(), 0.7,
              3e-3);  // 3 cubes + half the cylinder
  EXPECT_GT(sim().stats().contacts, 4u);
}

TEST_F(ContactTest, MaterialAndGeometryChangesApplyAtTheNextStep) {
  world->set_gravity(Eigen::Vector3d(0, 0, -9.81));
  auto& ice = material(0.0, 0.0);
  ground(&ice);
  auto& cube = geometry(GeometryKind::Box, Eigen::Vector3d(0.2, 0.2, 0.2));
  auto& box = hull(cube, at(0, 0, 0.1), &ice);
  auto& rb = body(box);
  env.run_for(0.2);
  rb.set_linear_velocity(Eigen::Vector3d(1, 0, 0));
  env.run_for(0.5);
  EXPECT_NEAR(rb.linear_velocity().x(), 1.0, 1e-3);  // no friction on ice
  ice.set_friction(1.0);                             // read at contact time: now it brakes
  env.run_for(0.5);
  EXPECT_NEAR(rb.linear_velocity().x(), 0.0, 1e-3);
  // A larger box: the geom is rebuilt, the body rises to rest on its new bottom, and its mass follows.
  const double m = sim().mass_of(rb).mass;
  cube.set_size(Eigen::Vector3d(0.4, 0.4, 0.4));
  env.run_for(1.0);
  EXPECT_NEAR(sim().mass_of(rb).mass, 8 * m, 1e-9);
  EXPECT_NEAR(box.world_frame().translation().z(), 0.2, 3e-3);
}

}  // namespace
}  // namespace vsd::physics::test
