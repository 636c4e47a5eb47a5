// URDF and mesh loading, save/load through vsd::io, replication.
#include "vsd/scene/urdf_loader.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "vsd/core.hpp"
#include "vsd/io.hpp"
#include "vsd/scene.hpp"

namespace vsd::scene {
namespace {

namespace fs = std::filesystem;
const fs::path data_dir = VSD_SCENE_TEST_DATA_DIR;

bool any_contains(const std::vector<std::string>& v, std::string_view a, std::string_view b = {}) {
  for (const auto& s : v)
    if (s.find(a) != std::string::npos && s.find(b) != std::string::npos) return true;
  return false;
}

class TempDir {
 public:
  TempDir()
      : path_(fs::temp_directory_path() /
              ("vsd_scene_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++))) {
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  static inline int counter_ = 0;
  fs::path path_;
};

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

// A unit cube as 12 triangles, corners at 0 and 1.
const int cube_faces[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                               {2, 3, 7}, {2, 7, 6}, {1, 2, 6}, {1, 6, 5}, {0, 4, 7}, {0, 7, 3}};
Eigen::Vector3d cube_corner(int i) {
  return {double((i & 1) ^ ((i >> 1) & 1)), double((i >> 1) & 1), double(i >> 2)};
}

std::string ascii_stl() {
  std::string s = "solid cube\n";
  for (const auto& f : cube_faces) {
    s += " facet normal 0 0 0\n  outer loop\n";
    for (int i : f) {
      const auto c = cube_corner(i);
      s += "   vertex " + std::to_string(c.x()) + " " + std::to_string(c.y()) + " " + std::to_string(c.z()) +
           "\n";
    }
    s += "  endloop\n endfacet\n";
  }
  return s + "endsolid cube\n";
}

std::string binary_stl() {
  std::string s(80, ' ');
  s.replace(0, 10, "binary cub");  // must not start with "solid"
  auto put_u32 = [&](std::uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); };
  auto put_f = [&](float v) { s.append(reinterpret_cast<const char*>(&v), 4); };
  put_u32(12);
  for (const auto& f : cube_faces) {
    for (int k = 0; k < 3; ++k) put_f(0);
    for (int i : f) {
      const auto c = cube_corner(i);
      put_f(float(c.x()));
      put_f(float(c.y()));
      put_f(float(c.z()));
    }
    s.append(2, '\0');
  }
  return s;
}

// A cube with quads (triangulated on load) and texture coordinates.
std::string obj_cube() {
  std::string s = "# cube\n";
  for (int i = 0; i < 8; ++i) {
    const auto c = cube_corner(i);
    s += "v " + std::to_string(c.x()) + " " + std::to_string(c.y()) + " " + std::to_string(c.z()) + "\n";
  }
  s += "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n";
  return s;
}

class UrdfTest : public ::testing::Test {
 protected:
  void SetUp() override { env.use<Module>(); }
  Environment env;
  SimState& s = env.main_state();
};

TEST_F(UrdfTest, StlAsciiBinaryAndObjGiveTheCube) {
  TempDir dir;
  write(dir.path() / "a.stl", ascii_stl());
  write(dir.path() / "b.stl", binary_stl());
  write(dir.path() / "c.obj", obj_cube());
  for (const char* name : {"a.stl", "b.stl", "c.obj"}) {
    Geometry& g = s.create<Geometry>();
    load_mesh(g, dir.path() / name);
    EXPECT_EQ(g.kind(), GeometryKind::Mesh);
    EXPECT_EQ(g.vertices().size(), 8u) << name;
    EXPECT_EQ(g.facet_count(), 12u) << name;
    EXPECT_EQ(g.normals().size(), 8u) << name;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
    for (const auto& v : g.vertices()) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    EXPECT_TRUE(lo.isApprox(Eigen::Vector3d::Zero())) << name;
    EXPECT_TRUE(hi.isApprox(Eigen::Vector3d::Ones())) << name;
    for (std::int32_t i : g.facets()) {
      EXPECT_GE(i, 0);
      EXPECT_LT(i, 8);
    }
  }
}

// A COLLADA file (what URDFs use for visual meshes): a tetrahedron in a node moved by 10 along x.
const char* collada_tetrahedron = R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="tet" name="tet"><mesh>
      <source id="tet-pos"><float_array id="tet-pos-array" count="12">0 0 0 1 0 0 0 1 0 0 0 1</float_array>
        <technique_common><accessor source="#tet-pos-array" count="4" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <vertices id="tet-vtx"><input semantic="POSITION" source="#tet-pos"/></vertices>
      <triangles count="4"><input semantic="VERTEX" source="#tet-vtx" offset="0"/><p>0 2 1 0 1 3 0 3 2 1 2 3</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene"><node id="n"><translate>10 0 0</translate><instance_geometry url="#tet"/></node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";

TEST_F(UrdfTest, ColladaMeshWithNodeTransform) {
  TempDir dir;
  write(dir.path() / "tet.dae", collada_tetrahedron);
  Geometry& g = s.create<Geometry>();
  load_mesh(g, dir.path() / "tet.dae");
  EXPECT_EQ(g.vertices().size(), 4u);
  EXPECT_EQ(g.facet_count(), 4u);
  double min_x = 1e9;
  for (const auto& v : g.vertices()) min_x = std::min(min_x, v.x());
  EXPECT_NEAR(min_x, 10.0, 1e-9);  // the node's transform is baked in
}

TEST_F(UrdfTest, BadMeshFilesAreErrorsNamingTheFile) {
  TempDir dir;
  Geometry& g = s.create<Geometry>();
  try {
    load_mesh(g, dir.path() / "missing.stl");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.stl"), std::string::npos) << e.what();
  }
  write(dir.path() / "junk.stl", "solid x\n facet normal 0 0 garbage\n");
  write(dir.path() / "empty.obj", "# nothing\n");
  for (const char* name : {"junk.stl", "empty.obj"}) {
    try {
      load_mesh(g, dir.path() / name);
      FAIL() << name;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(g.vertices().empty());
}

TEST_F(UrdfTest, Iiwa14LoadsWithoutItsMeshes) {
  const SceneReport r = load_urdf(s.database(), data_dir / "iiwa14.urdf");
  ASSERT_NE(r.scene, nullptr);
  // Counted in the file: 11 <link>, 10 <joint> at the top level (the 7 inside <transmission> are not joints).
  EXPECT_EQ(r.links, 11u);
  EXPECT_EQ(r.joints, 10u);
  EXPECT_EQ(r.scene->links().size(), 11u);
  EXPECT_EQ(r.scene->joints().size(), 10u);
  EXPECT_EQ(r.scene->name(), "iiwa14");
  EXPECT_EQ(r.meshes_loaded, 0u);
  // 16 <mesh> elements; each missing one is a warning naming the link.
  EXPECT_TRUE(any_contains(r.warnings, "link 'iiwa_link_0' visual", "not found"));
  EXPECT_TRUE(any_contains(r.warnings, "link 'iiwa_link_7' collision", "package://iiwa_description/meshes"));
  // What urdfdom does not read is named too.
  EXPECT_TRUE(any_contains(r.warnings, "<transmission>", "not supported"));
  EXPECT_TRUE(any_contains(r.warnings, "<gazebo>"));
  EXPECT_TRUE(any_contains(r.warnings, "link 'iiwa_link_0'", "<self_collision_checking>"));
  const Joint* j1 = r.scene->find_joint("iiwa_joint_1");
  ASSERT_NE(j1, nullptr);
  EXPECT_EQ(j1->type(), JointType::Revolute);
  EXPECT_TRUE(j1->has_limits());
  EXPECT_NEAR(j1->upper(), 170.0 * M_PI / 180.0, 1e-3);
  EXPECT_TRUE(j1->axis().isApprox(Eigen::Vector3d::UnitZ()));
  ASSERT_NE(j1->parent_link().get(), nullptr);
  EXPECT_EQ(j1->parent_link()->name(), "iiwa_link_0");
  EXPECT_EQ(j1->child_link()->name(), "iiwa_link_1");
  // The child link sits at the joint origin (0 0 0.1575 in the file).
  const Link* l1 = r.scene->find_link("iiwa_link_1");
  ASSERT_NE(l1, nullptr);
  EXPECT_TRUE(l1->frame().translation().isApprox(Eigen::Vector3d(0, 0, 0.1575)));
  EXPECT_NEAR(l1->mass(), 4.0, 1e-12);
  // Fixed-joint frames stay addressable: the end-effector link is a node with its own world frame.
  const Link* ee = r.scene->find_link("iiwa_link_ee");
  ASSERT_NE(ee, nullptr);
  EXPECT_EQ(r.scene->find_joint("iiwa_joint_ee")->type(), JointType::Fixed);
  EXPECT_GT(ee->world_frame().translation().z(), 1.0);
  // Hulls: the mesh geometry is kept (source set, no vertices) for a later fix of the search path.
  std::size_t hulls = 0;
  r.scene->visit([&](Node& n) {
    if (auto* h = n.as<Hull>()) {
      ++hulls;
      ASSERT_NE(h->geometry().get(), nullptr);
      EXPECT_EQ(h->geometry()->kind(), GeometryKind::Mesh);
      EXPECT_FALSE(h->geometry()->source().empty());
      EXPECT_FALSE(h->geometry()->has_mesh_data());
    }
  });
  EXPECT_EQ(hulls, 16u);
  EXPECT_EQ(r.hulls, 16u);
}

TEST_F(UrdfTest, Ur5LoadsWithoutItsMeshes) {
  const SceneReport r = load_urdf(s.database(), data_dir / "ur5_robot.urdf");
  ASSERT_NE(r.scene, nullptr);
  EXPECT_EQ(r.links, 11u);
  EXPECT_EQ(r.joints, 10u);
  EXPECT_EQ(r.scene->find_joint("shoulder_pan_joint")->type(), JointType::Revolute);
  EXPECT_TRUE(any_contains(r.warnings, "mesh 'package://", "not found"));
  double mass = 0;
  for (const Link* l : r.scene->links()) mass += l->mass();
  EXPECT_GT(mass, 10.0);
}

TEST_F(UrdfTest, PackagePathsResolveMeshes) {
  TempDir dir;
  write(dir.path() / "pkgs" / "cuberobot" / "meshes" / "cube.stl", binary_stl());
  write(dir.path() / "robot" / "local.obj", obj_cube());
  const std::string urdf = R"(<robot name="cuberobot">
  <material name="red"><color rgba="1 0 0 1"/></material>
  <link name="base">
    <inertial><origin xyz="0 0 0.5"/><mass value="2"/><inertia ixx="1" ixy="0.1" ixz="0.2" iyy="2" iyz="0.3" izz="3"/></inertial>
    <visual><origin xyz="0 0 1"/><geometry><mesh filename="package://cuberobot/meshes/cube.stl" scale="2 2 2"/></geometry><material name="red"/></visual>
    <collision><geometry><mesh filename="package://cuberobot/meshes/cube.stl" scale="2 2 2"/></geometry></collision>
  </link>
  <link name="arm">
    <visual><geometry><mesh filename="local.obj"/></geometry></visual>
    <collision><geometry><box size="1 2 3"/></geometry></collision>
    <collision><geometry><cylinder radius="0.5" length="2"/></geometry></collision>
    <collision><geometry><mesh filename="nowhere.stl"/></geometry></collision>
  </link>
  <joint name="j" type="prismatic"><parent link="base"/><child link="arm"/><origin xyz="1 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-0.5" upper="0.5" effort="10" velocity="1"/></joint>
</robot>)";
  write(dir.path() / "robot" / "cube.urdf", urdf);
  UrdfOptions options;
  options.package_paths = {dir.path() / "elsewhere", dir.path() / "pkgs"};
  const SceneReport r = load_urdf(s.database(), dir.path() / "robot" / "cube.urdf", options);
  EXPECT_EQ(r.links, 2u);
  EXPECT_EQ(r.joints, 1u);
  EXPECT_EQ(r.meshes_loaded, 2u);  // cube.stl once (shared by visual and collision), local.obj
  ASSERT_EQ(r.warnings.size(), 1u) << r.warnings[0];
  EXPECT_NE(r.warnings[0].find("link 'arm' collision 2: mesh 'nowhere.stl' not found"), std::string::npos)
      << r.warnings[0];
  const Link* base = r.scene->find_link("base");
  ASSERT_NE(base, nullptr);
  EXPECT_DOUBLE_EQ(base->mass(), 2.0);
  EXPECT_TRUE(base->inertial_frame().translation().isApprox(Eigen::Vector3d(0, 0, 0.5)));
  EXPECT_DOUBLE_EQ(base->inertia()(0, 1), 0.1);
  EXPECT_DOUBLE_EQ(base->inertia()(2, 1), 0.3);
  const auto* visual = base->children()[0]->as<Hull>();
  const auto* collision = base->children()[1]->as<Hull>();
  ASSERT_TRUE(visual != nullptr && collision != nullptr);
  EXPECT_EQ(visual->geometry().get(), collision->geometry().get());  // shared
  EXPECT_EQ(visual->geometry()->vertices().size(), 8u);
  EXPECT_TRUE(visual->geometry()->scale().isApprox(Eigen::Vector3d::Constant(2)));
  EXPECT_EQ(visual->material()->name(), "red");
  EXPECT_TRUE(visual->material()->color().isApprox(Eigen::Vector4d(1, 0, 0, 1)));
  EXPECT_TRUE(visual->world_frame().translation().isApprox(Eigen::Vector3d(0, 0, 1)));
  const Link* arm = r.scene->find_link("arm");
  EXPECT_TRUE(arm->world_frame().translation().isApprox(Eigen::Vector3d(1, 0, 0)));
  const auto* box = arm->children()[1]->as<Hull>();
  EXPECT_EQ(box->geometry()->kind(), GeometryKind::Box);
  EXPECT_TRUE(box->geometry()->size().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_EQ(arm->children()[2]->as<Hull>()->geometry()->kind(), GeometryKind::Cylinder);
  const Joint* j = r.scene->find_joint("j");
  EXPECT_EQ(j->type(), JointType::Prismatic);
  EXPECT_DOUBLE_EQ(j->lower(), -0.5);
  EXPECT_TRUE(j->axis().isApprox(Eigen::Vector3d::UnitY()));
}

TEST_F(UrdfTest, MalformedUrdfIsAnErrorNamingTheFileAndCreatesNothing) {
  TempDir dir;
  const std::size_t before = s.size();
  write(dir.path() / "broken.urdf",
        "<robot name=\"x\"><link name=\"a\"/><joint name=\"j\" type=\"revolute\">");
  write(dir.path() / "nochild.urdf",
        "<robot name=\"x\"><link name=\"a\"/><joint name=\"j\" type=\"fixed\"><parent link=\"a\"/>"
        "<child link=\"zz\"/></joint></robot>");
  write(dir.path() / "badnumber.urdf",
        "<robot name=\"x\"><link name=\"a\"><inertial><mass value=\"heavy\"/></inertial></link></robot>");
  for (const char* name : {"broken.urdf", "nochild.urdf", "badnumber.urdf"}) {
    try {
      (void)load_urdf(s.database(), dir.path() / name);
      FAIL() << name;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(name), std::string::npos) << what;
      EXPECT_NE(what.find("not a valid URDF"), std::string::npos) << what;
    }
  }
  // urdfdom's own reason is in the message.
  try {
    (void)load_urdf(s.database(), dir.path() / "nochild.urdf");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("zz"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)load_urdf(s.database(), dir.path() / "absent.urdf"), Error);
  EXPECT_EQ(s.size(), before);
}

TEST_F(UrdfTest, SceneSavesAndLoadsInBothFormats) {
  TempDir dir;
  write(dir.path() / "m" / "cube.obj", obj_cube());
  const std::string urdf = R"(<robot name="r">
  <material name="blue"><color rgba="0 0 1 1"/><texture filename="tex.png"/></material>
  <link name="a"><visual><geometry><mesh filename="m/cube.obj"/></geometry><material name="blue"/></visual></link>
  <link name="b"><visual><geometry><sphere radius="0.3"/></geometry></visual></link>
  <joint name="j" type="continuous"><parent link="a"/><child link="b"/><origin xyz="0 0 1" rpy="0 0.5 0"/></joint>
</robot>)";
  const SceneReport r = load_urdf_text(s.database(), urdf, "inline", dir.path());
  EXPECT_TRUE(r.warnings.empty());
  Geometry& g = *r.scene->geometries()[0];
  ASSERT_EQ(g.vertices().size(), 8u);
  g.set_texture_coordinates(std::vector<Eigen::Vector2d>(8, Eigen::Vector2d(0.25, 0.75)));
  const Hull* textured = r.scene->find_link("a")->children()[0]->as<Hull>();
  ASSERT_EQ(textured->maps().size(), 1u);
  EXPECT_EQ(textured->maps()[0]->url(), "tex.png");
  for (io::Format f : {io::Format::Text, io::Format::Binary}) {
    const auto bytes = io::save_bytes(s, f);
    SimState& copy = env.create_state(f == io::Format::Text ? "text" : "binary");
    (void)io::load_bytes(copy, bytes);
    std::string diff;
    EXPECT_TRUE(copy.equals(s, &diff)) << diff;
    const auto* b = copy.find(r.scene->find_link("b")->id())->as<Link>();
    ASSERT_NE(b, nullptr);
    EXPECT_TRUE(b->world_frame().isApprox(r.scene->find_link("b")->world_frame()));
    const auto* cg = copy.find(g.id())->as<Geometry>();
    EXPECT_EQ(cg->texture_coordinates().size(), 8u);
    env.remove_state(copy);
  }
}

TEST_F(UrdfTest, ReplicationThroughARecordedTransaction) {
  SimState& replica = env.create_state("replica");
  s.start_recording();
  const SceneReport r = load_urdf(s.database(), data_dir / "ur5_robot.urdf");
  const Transaction t = s.stop_recording();
  replica.apply(t);
  std::string diff;
  EXPECT_TRUE(replica.equals(s, &diff)) << diff;
  // A moved base moves the replica's tool frame too.
  const Link* tool = r.scene->find_link("ee_link");
  ASSERT_NE(tool, nullptr);
  const auto* rtool = replica.find(tool->id())->as<Link>();
  EXPECT_TRUE(rtool->world_frame().isApprox(tool->world_frame()));
  s.start_recording();
  Eigen::Isometry3d moved = Eigen::Isometry3d::Identity();
  moved.translate(Eigen::Vector3d(0, 3, 0));
  r.scene->set_frame(moved);
  replica.apply(s.stop_recording());
  EXPECT_TRUE(rtool->world_frame().isApprox(tool->world_frame()));
  EXPECT_NEAR(rtool->world_frame().translation().y() - tool->frame().translation().y(), 3.0, 1.0);
  EXPECT_TRUE(replica.equals(s, &diff)) << diff;
}

}  // namespace
}  // namespace vsd::scene
