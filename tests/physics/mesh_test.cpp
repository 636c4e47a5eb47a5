// Mesh hulls in ODE: trimeshes built from the scene Geometry's vertex and facet lists, shared by the hulls of
// one Geometry and rebuilt when it changes; bodies resting on a mesh floor and a mesh body falling onto a
// plane at the heights the geometry gives; degenerate meshes as errors naming the hull.
#include <gmock/gmock.h>

#include <cmath>
#include <string>
#include <vector>

#include "fixture.hpp"

namespace vsd::physics::test {
namespace {

using scene::GeometryKind;
using ::testing::AllOf;
using ::testing::HasSubstr;

// The closed triangle mesh of a box of full extents @p size centred at @p centre (12 facets wound counter-
// clockwise seen from outside). Vertex i has the signs of bits x = 1, y = 2, z = 4.
void set_box_mesh(scene::Geometry& g, const Eigen::Vector3d& size,
                  const Eigen::Vector3d& centre = Eigen::Vector3d::Zero()) {
  std::vector<Eigen::Vector3d> v;
  for (int i = 0; i < 8; ++i)
    v.push_back(centre + 0.5 * Eigen::Vector3d((i & 1) ? size.x() : -size.x(), (i & 2) ? size.y() : -size.y(),
                                               (i & 4) ? size.z() : -size.z()));
  g.set_kind(GeometryKind::Mesh);
  g.set_vertices(v);
  g.set_facets({0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5});
}

class MeshTest : public PhysicsTest {
 public:
  scene::Geometry& box_mesh(const Eigen::Vector3d& size,
                            const Eigen::Vector3d& centre = Eigen::Vector3d::Zero()) {
    auto& g = geometry(GeometryKind::Mesh);
    set_box_mesh(g, size, centre);
    return g;
  }
  // A static mesh floor, 4 m x 4 m x 0.2 m, its top face at z = 0.
  scene::Hull& mesh_floor() {
    return hull(box_mesh(Eigen::Vector3d(4, 4, 0.2)), at(0, 0, -0.1), nullptr, nullptr, "floor");
  }
  static double z(const scene::Node3D& n) { return n.world_frame().translation().z(); }
};

TEST_F(MeshTest, BoxAndSphereComeToRestOnAMeshFloorAtTheRightHeight) {
  mesh_floor();
  auto& box = hull(geometry(GeometryKind::Box, Eigen::Vector3d(0.2, 0.2, 0.2)), at(0, 0, 0.5), nullptr,
                   nullptr, "box");
  auto& ball = hull(geometry(GeometryKind::Sphere, Eigen::Vector3d::Zero(), 0.1), at(1, 0, 0.5), nullptr,
                    nullptr, "ball");
  auto& rb = body(box);
  auto& rs = body(ball);
  sim().sync();
  EXPECT_EQ(sim().stats().geoms, 3u);
  EXPECT_EQ(sim().stats().meshes, 1u);
  EXPECT_TRUE(sim().warnings().empty());
  env.run_for(2.0);
  // Half their height above the floor's top face (ODE's contacts let them sink by a fraction of a mm).
  EXPECT_NEAR(z(box), 0.1, 2e-3);
  EXPECT_NEAR(z(ball), 0.1, 2e-3);
  EXPECT_NEAR(box.world_frame().translation().x(), 0.0, 1e-3);  // no drift on the flat top
  EXPECT_LT(rb.linear_velocity().norm(), 1e-2);
  EXPECT_LT(rs.linear_velocity().norm(), 1e-2);
  EXPECT_GT(sim().stats().contacts, 0u);
}

TEST_F(MeshTest, AMeshBoxFallsOntoAPlaneWithTheMassOfItsVolume) {
  ground();
  // The mesh's vertices are off its node's origin: the centre of mass is the volume's centroid.
  auto& g = box_mesh(Eigen::Vector3d(0.2, 0.4, 0.2), Eigen::Vector3d(0.1, 0, 0));
  auto& box = hull(g, at(0, 0, 1.0), nullptr, nullptr, "crate");
  auto& rb = body(box);
  sim().sync();
  const MassProperties m = sim().mass_of(rb);
  EXPECT_NEAR(m.mass, 1000.0 * 0.2 * 0.4 * 0.2, 1e-9);  // density 1000 (no material) times the volume
  EXPECT_TRUE(m.center.isApprox(Eigen::Vector3d(0.1, 0, 0), 1e-12));
  EXPECT_NEAR(m.inertia(0, 0), m.mass * (0.4 * 0.4 + 0.2 * 0.2) / 12, 1e-9);
  EXPECT_NEAR(m.inertia(1, 1), m.mass * (0.2 * 0.2 + 0.2 * 0.2) / 12, 1e-9);
  EXPECT_NEAR(m.inertia(2, 2), m.mass * (0.2 * 0.2 + 0.4 * 0.4) / 12, 1e-9);
  EXPECT_NEAR(m.inertia(0, 1), 0.0, 1e-12);
  // The same fall as a primitive box of that size (free fall until it touches), then rest at z = 0.1.
  for (int i = 0; i < 20; ++i) env.step();
  EXPECT_NEAR(z(box), 1.0 - 0.5 * 9.81 * 0.2 * 0.2, 0.01);
  env.run_for(2.0);
  EXPECT_NEAR(z(box), 0.1, 2e-3);
  EXPECT_LT(rb.linear_velocity().norm(), 1e-2);
  EXPECT_NEAR(Eigen::AngleAxisd(box.world_frame().rotation()).angle(), 0.0, 1e-3);  // flat on its face
}

TEST_F(MeshTest, HullsSharingAGeometryShareOneTrimeshThatFollowsTheGeometry) {
  auto& g = box_mesh(Eigen::Vector3d(1, 1, 0.2));
  hull(g, at(0, 0, -0.1), nullptr, nullptr, "tile1");
  hull(g, at(2, 0, -0.1), nullptr, nullptr, "tile2");
  auto& box = hull(geometry(GeometryKind::Box, Eigen::Vector3d(0.2, 0.2, 0.2)), at(2, 0, 0.5), nullptr,
                   nullptr, "box");
  body(box);
  env.run_for(1.0);
  EXPECT_EQ(sim().stats().meshes, 1u);
  EXPECT_EQ(sim().stats().geoms, 3u);
  EXPECT_NEAR(z(box), 0.1, 2e-3);
  // The geometry grows to 0.3 m high about the tile centres (top at z = 0.05): both tiles get the new
  // trimesh through the geometry's signals; the box, now 5 cm into it, is pushed up onto the new top.
  // (Not more: a trimesh sees only triangles, so a box entirely inside it would fall through.)
  const auto rebuilds = sim().stats().rebuilds;
  g.set_scale(Eigen::Vector3d(1, 1, 1.5));
  env.run_for(1.0);
  EXPECT_GT(sim().stats().rebuilds, rebuilds);
  EXPECT_EQ(sim().stats().meshes, 1u);
  EXPECT_NEAR(z(box), 0.15, 3e-3);
  // Back to the old vertices through the list property: down again.
  g.set_scale(Eigen::Vector3d::Ones());
  set_box_mesh(g, Eigen::Vector3d(1, 1, 0.2), Eigen::Vector3d(0, 0, -0.1));  // top at z = -0.1
  env.run_for(1.0);
  EXPECT_NEAR(z(box), 0.0, 3e-3);
  // Deleting the geometry nulls the hulls' references: nothing is left colliding with the box.
  s.destroy(g);
  env.run_for(0.1);
  EXPECT_EQ(sim().stats().meshes, 0u);
  EXPECT_EQ(sim().stats().geoms, 1u);
  EXPECT_LT(z(box), -0.01);  // falling
}

TEST_F(MeshTest, DegenerateMeshesAreErrorsNamingTheHullNeverACrash) {
  auto& g = geometry(GeometryKind::Mesh);
  g.set_source("broken.stl");
  auto& wreck = hull(g, at(0, 0, 0), nullptr, nullptr, "wreck");
  auto fails = [&](const std::string& what) {
    EXPECT_THAT([&] { sim().sync(); },
                ::testing::ThrowsMessage<vsd::Error>(
                    AllOf(HasSubstr("/scene/wreck"), HasSubstr("broken.stl"), HasSubstr(what))))
        << what;
  };
  // Vertices without facets.
  g.set_vertices({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)});
  fails("facet list is empty");
  g.set_facets({0, 1});
  fails("not a multiple of 3");
  g.set_facets({0, 1, 3});
  fails("facet 0 refers to vertex 3, but there are 3 vertices");
  g.set_facets({0, 1, 2, 0, -1, 2});
  fails("facet 1 refers to vertex -1");
  g.set_facets({0, 1, 2});
  g.set_vertices({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, std::nan(""), 0)});
  fails("vertex 2 is not finite");
  g.set_vertices({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)});
  g.set_scale(Eigen::Vector3d(1, 0, 1));
  fails("scale must be finite and non-zero");
  g.set_scale(Eigen::Vector3d::Ones());
  sim().sync();  // one triangle is fine as static scenery
  EXPECT_EQ(sim().stats().meshes, 1u);
  // ... but an open surface on a body has no volume, hence no mass.
  auto& rb = body(wreck);
  fails("encloses no positive volume");
  rb.set_mass(2.0);
  rb.set_inertia_diagonal(Eigen::Vector3d(0.1, 0.1, 0.1));
  env.run_for(0.1);  // with explicit mass properties it is simulated
  EXPECT_TRUE(sim().simulates(rb));
  // An inside-out closed mesh is refused as well, and a mirroring scale is not inside-out.
  rb.set_mass(0.0);
  rb.set_inertia_diagonal(Eigen::Vector3d::Zero());
  set_box_mesh(g, Eigen::Vector3d(1, 1, 1));
  auto f = g.facets();
  for (std::size_t i = 0; i < f.size(); i += 3) std::swap(f[i + 1], f[i + 2]);
  g.set_facets(f);
  fails("encloses no positive volume");
  set_box_mesh(g, Eigen::Vector3d(1, 1, 1));
  g.set_scale(Eigen::Vector3d(-1, 1, 1));
  sim().sync();
  EXPECT_NEAR(sim().mass_of(rb).mass, 1000.0, 1e-9);
}

TEST_F(MeshTest, AMeshWithoutVerticesIsSkippedWithAWarning) {
  auto& g = geometry(GeometryKind::Mesh);
  g.set_source("package://robot/missing.stl");
  hull(g, at(0, 0, 0), nullptr, nullptr, "statue");
  sim().sync();
  ASSERT_EQ(sim().warnings().size(), 1u);
  EXPECT_THAT(sim().warnings()[0],
              AllOf(HasSubstr("statue"), HasSubstr("missing.stl"), HasSubstr("no vertices")));
  EXPECT_EQ(sim().stats().geoms, 0u);
}

// Trimesh against trimesh: ODE (OPCODE's triangle-triangle collider) gives contacts, but few and noisy
// ones; a mesh box still comes to rest on a mesh floor near the right height (see docs/physics.md).
TEST_F(MeshTest, AMeshBoxOnAMeshFloorComesToRestNearTheRightHeight) {
  mesh_floor();
  auto& box = hull(box_mesh(Eigen::Vector3d(0.2, 0.2, 0.2)), at(0, 0, 0.3), nullptr, nullptr, "crate");
  auto& rb = body(box);
  env.run_for(2.0);
  EXPECT_TRUE(box.world_frame().matrix().allFinite());
  EXPECT_NEAR(z(box), 0.1, 5e-3);
  EXPECT_LT(rb.linear_velocity().norm(), 0.05);
}

}  // namespace
}  // namespace vsd::physics::test
