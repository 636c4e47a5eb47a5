// URDF loading (limits, inputs, mesh paths, validation), save/load through vsd::io, replication.
#include "vsd/scene/urdf_loader.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>

#include "files.hpp"
#include "vsd/core.hpp"
#include "vsd/io.hpp"
#include "vsd/scene.hpp"

namespace vsd::scene {
namespace {

using namespace test;

const fs::path data_dir = VSD_SCENE_TEST_DATA_DIR;

class UrdfTest : public ::testing::Test {
 protected:
  void SetUp() override { env.use<Module>(); }
  Environment env;
  SimState& s = env.main_state();
};

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
    <inertial><origin xyz="0 0 0.5"/><mass value="2"/><inertia ixx="2" ixy="0.1" ixz="0.2" iyy="2.5" iyz="0.3" izz="3"/></inertial>
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


// ---- limits, inputs, paths, validation ----------------------------------------------------------------

std::string load_error(SimState& s, std::string_view xml, const fs::path& base = ".") {
  try {
    (void)load_urdf_text(s.database(), xml, "t.urdf", base);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// `depth` elements nested inside <robot> (which has one link), starting on line 2.
std::string nested_urdf(int depth) {
  std::string xml = "<robot name=\"r\"><link name=\"a\"/>\n";
  xml.reserve(xml.size() + 8 * static_cast<std::size_t>(depth));
  for (int i = 0; i < depth; ++i) xml += "<x>";
  for (int i = 0; i < depth; ++i) xml += "</x>";
  return xml + "</robot>\n";
}

// 100,000 levels crashed in urdfdom's XML parser (it recurses per level) and 20,000 took 3.5 s: the text
// is refused before urdfdom sees it, at the element that crosses the limit.
TEST_F(UrdfTest, DeeplyNestedXmlIsRefusedBeforeParsing) {
  const std::string what = load_error(s, nested_urdf(100000));
  EXPECT_NE(what.find("t.urdf:2:2998: URDF nests elements deeper than 1000 levels"), std::string::npos) << what;
  // The limit itself is fine (<robot> is level 1): the unknown elements are a warning.
  const SceneReport r = load_urdf_text(s.database(), nested_urdf(999), "ok.urdf", ".");
  EXPECT_TRUE(any_contains(r.warnings, "<x>", "not supported"));
  EXPECT_NE(load_error(s, nested_urdf(1000)).find("deeper than 1000"), std::string::npos);
}

TEST_F(UrdfTest, TooManyElementsOrBytesAreRefusedBeforeParsing) {
  std::string many = "<robot name=\"r\"><link name=\"a\"/>";
  for (std::size_t i = 0; i < max_urdf_elements; ++i) many += "<x/>";
  many += "</robot>";
  EXPECT_NE(load_error(s, many).find("URDF has more than 1000000 elements"), std::string::npos);
  std::string big(max_urdf_bytes + 1, ' ');
  EXPECT_NE(load_error(s, big).find("URDF of 67108865 bytes is larger than the limit of 67108864 bytes"),
            std::string::npos);
}

// Markup inside comments, CDATA, processing instructions, declarations and attribute values is not
// nesting: a document full of it loads.
TEST_F(UrdfTest, MarkupInCommentsAndAttributesIsNotNesting) {
  std::string xml = "<?xml version=\"1.0\"?>\n<!DOCTYPE robot>\n";
  xml += "<robot name=\"r\">";
  for (int i = 0; i < 2000; ++i) xml += "<!-- <a><a> --><?pi <a>?>";
  xml += "<link name=\"a\"><visual name=\"<a><a>\"><geometry><box size=\"1 1 1\"/></geometry></visual></link>";
  xml += "<x><![CDATA[<a><a><a>]]></x></robot>";
  const SceneReport r = load_urdf_text(s.database(), xml, "ok.urdf", ".");
  EXPECT_EQ(r.links, 1u);
}

TEST_F(UrdfTest, ADirectoryIsADirectory) {
  TempDir dir;
  try {
    (void)load_urdf(s.database(), dir.path());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory, not a URDF file"), std::string::npos) << e.what();
  }
  try {
    (void)load_urdf(s.database(), dir.path() / "absent.urdf");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open the URDF file: No such file"), std::string::npos)
        << e.what();
  }
}

const char* small_urdf = R"(<robot name="small"><link name="a"/><link name="b"/>
  <joint name="j" type="continuous"><parent link="a"/><child link="b"/></joint></robot>)";

// The text is read whole before urdfdom parses it, so anything that reads like a file works: a FIFO
// (a pipe, `<(...)` in a shell) and standard input as "-".
TEST_F(UrdfTest, PipesAndStandardInputAreRead) {
  TempDir dir;
  const fs::path fifo = dir.path() / "robot.urdf";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] { std::ofstream(fifo) << small_urdf; });
  const SceneReport r = load_urdf(s.database(), fifo);
  writer.join();
  EXPECT_EQ(r.joints, 1u);
  std::istringstream in(small_urdf);
  std::streambuf* old = std::cin.rdbuf(in.rdbuf());
  const SceneReport r2 = load_urdf(s.database(), "-");
  std::cin.rdbuf(old);
  EXPECT_EQ(r2.links, 2u);
  EXPECT_EQ(r2.scene->source(), "standard input");
}

std::string mesh_urdf(const std::vector<std::string>& files) {
  std::string xml = "<robot name=\"r\"><link name=\"a\">";
  for (const auto& f : files) xml += "<visual><geometry><mesh filename=\"" + f + "\"/></geometry></visual>";
  return xml + "</link></robot>";
}

// Mesh references were opened wherever they pointed. Now each must lead (after `..` and symbolic links)
// into the URDF's folder or a package path, to a regular file; otherwise it is not read, with a warning.
TEST_F(UrdfTest, MeshReferencesStayInsideTheUrdfFolderAndThePackagePaths) {
  TempDir dir;
  const fs::path robot = dir.path() / "robot";
  write(dir.path() / "outside.stl", binary_stl());
  write(robot / "inside.stl", binary_stl());
  write(dir.path() / "pkgs" / "p" / "m.stl", binary_stl());
  fs::create_symlink(dir.path() / "outside.stl", robot / "link.stl");
  ASSERT_EQ(::mkfifo((robot / "fifo.stl").c_str(), 0600), 0);
  const std::string out = (dir.path() / "outside.stl").string();
  const std::vector<std::string> refused = {"../outside.stl",    out,
                                            "file://" + out,     "link.stl",
                                            "/etc/passwd",       "/proc/self/environ",
                                            "package://p/../../outside.stl"};
  std::vector<std::string> refs = refused;
  refs.insert(refs.end(), {"fifo.stl", "http://example.com/m.stl", "inside.stl", "package://p/m.stl",
                           "absent.stl"});
  UrdfOptions o;
  o.package_paths = {dir.path() / "pkgs"};
  const SceneReport r = load_urdf_text(s.database(), mesh_urdf(refs), "r.urdf", robot, o);
  EXPECT_EQ(r.meshes_loaded, 2u);  // inside.stl, package://p/m.stl
  for (const auto& ref : refused)
    EXPECT_TRUE(any_contains(r.warnings, "mesh '" + ref + "' not read: ", "is outside the folders")) << ref;
  EXPECT_TRUE(any_contains(r.warnings, "mesh 'fifo.stl' not read: ", "is not a regular file"));
  EXPECT_TRUE(any_contains(r.warnings, "mesh 'http://example.com/m.stl' not read: URI scheme 'http'"));
  EXPECT_TRUE(any_contains(r.warnings, "mesh 'absent.stl' not found"));
  EXPECT_TRUE(any_contains(r.warnings, "UrdfOptions::allow_paths_outside permits it"));
  // The caller may allow it (regular files only, still).
  o.allow_paths_outside = true;
  const SceneReport all = load_urdf_text(s.database(), mesh_urdf({"../outside.stl", out, "link.stl", "fifo.stl"}),
                                         "r.urdf", robot, o);
  EXPECT_EQ(all.meshes_loaded, 3u);
  EXPECT_TRUE(any_contains(all.warnings, "mesh 'fifo.stl' not read: ", "is not a regular file"));
  // The files a mesh pulls in obey the same rule.
  write(dir.path() / "secret.mtl", "newmtl red\nKd 1 0 0\n");
  write(robot / "cube.obj", "mtllib ../secret.mtl\nusemtl red\n" + obj_cube());
  const SceneReport obj = load_urdf_text(s.database(), mesh_urdf({"cube.obj"}), "r.urdf", robot);
  EXPECT_EQ(obj.meshes_loaded, 1u);
  EXPECT_TRUE(any_contains(obj.warnings, "mesh 'cube.obj': ", "secret.mtl' is outside the folders"));
}

// What no body, joint or shape can be is an error naming the link or joint and the field (all of them at
// once, and nothing is created); what is legal but cannot be simulated as written is a warning.
TEST_F(UrdfTest, ValuesAreValidated) {
  const std::size_t before = s.size();
  const std::string bad = R"(<robot name="bad">
  <link name="heavy"><inertial><mass value="-1"/><inertia ixx="-0.1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><geometry><cylinder radius="-0.5" length="1"/></geometry></collision>
    <visual><geometry><box size="1 -2 1"/></geometry></visual>
    <visual><geometry><sphere radius="-1"/></geometry></visual></link>
  <link name="b"/><link name="c"/><link name="d"/>
  <joint name="j1" type="revolute"><parent link="heavy"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="1" upper="-1" effort="1" velocity="1"/><mimic joint="j2"/></joint>
  <joint name="j2" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="j1"/></joint>
  <joint name="j3" type="continuous"><parent link="c"/><child link="d"/><mimic joint="j3"/></joint>
</robot>)";
  const std::string what = load_error(s, bad);
  for (const char* expected :
       {"t.urdf: not a valid URDF", "link 'heavy' <inertial> <mass>: -1 kg is negative",
        "link 'heavy' <inertial> <inertia> ixx: -0.1 kg m^2 is negative",
        "link 'heavy' collision <cylinder>: radius -0.5 is negative", "link 'heavy' visual <box>: size y -2 is negative",
        "link 'heavy' visual 1 <sphere>: radius -1 is negative", "joint 'j1' <limit>: lower 1 is above upper -1",
        "joint 'j2' <axis>: the axis is zero", "<mimic>: a mimic cycle 'j1' -> 'j2' -> 'j1'",
        "joint 'j3' <mimic>: a mimic cycle 'j3' -> 'j3'"})
    EXPECT_NE(what.find(expected), std::string::npos) << expected << "\n" << what;
  EXPECT_EQ(s.size(), before);
  const std::string odd = R"(<robot name="odd">
  <link name="flat"><inertial><mass value="1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
    <collision><geometry><box size="1 0 1"/></geometry></collision></link>
  <link name="rod"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="3"/></inertial>
    <collision><geometry><sphere radius="0"/></geometry></collision></link>
  <joint name="j" type="prismatic"><parent link="flat"/><child link="rod"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="1" effort="-1" velocity="1"/><dynamics damping="-2"/></joint>
</robot>)";
  const SceneReport r = load_urdf_text(s.database(), odd, "odd.urdf", ".");
  EXPECT_TRUE(any_contains(r.warnings, "link 'flat' <inertial> <inertia>: not positive definite"));
  EXPECT_TRUE(any_contains(r.warnings, "link 'rod' <inertial> <inertia>: principal moment 3 exceeds"));
  EXPECT_TRUE(any_contains(r.warnings, "link 'flat' collision <box>: size y is 0"));
  EXPECT_TRUE(any_contains(r.warnings, "link 'rod' collision <sphere>: radius is 0"));
  EXPECT_TRUE(any_contains(r.warnings, "joint 'j' <limit> effort: -1 is negative"));
  EXPECT_TRUE(any_contains(r.warnings, "joint 'j' <dynamics> damping: -2 is negative"));
}

// The example model with primitive hulls loads without a single warning: 8 links with the original's
// inertials, 22 hulls (visual and collision alike), no mesh.
TEST_F(UrdfTest, ThePrimitiveIiwaIsCompleteWithoutMeshes) {
  const SceneReport r = load_urdf(s.database(), data_dir / "iiwa14_primitives.urdf");
  EXPECT_TRUE(r.warnings.empty()) << r.warnings[0];
  EXPECT_EQ(r.links, 11u);
  EXPECT_EQ(r.joints, 10u);
  EXPECT_EQ(r.hulls, 22u);
  EXPECT_EQ(r.meshes_loaded, 0u);
  const SceneReport original = load_urdf(s.database(), data_dir / "iiwa14.urdf");
  for (const Link* l : original.scene->links()) {
    const Link* p = r.scene->find_link(l->name());
    ASSERT_NE(p, nullptr) << l->name();
    EXPECT_EQ(p->mass(), l->mass()) << l->name();
    EXPECT_TRUE(p->inertia().isApprox(l->inertia())) << l->name();
    EXPECT_TRUE(p->world_frame().isApprox(l->world_frame())) << l->name();
  }
}

// The shipped descriptions load without a validation message.
TEST_F(UrdfTest, ShippedDescriptionsAreValid) {
  for (const char* name : {"iiwa14.urdf", "ur5_robot.urdf", "iiwa14_primitives.urdf"}) {
    UrdfOptions o;
    o.load_meshes = false;
    const SceneReport r = load_urdf(s.database(), data_dir / name, o);
    for (const auto& w : r.warnings) {
      EXPECT_EQ(w.find("<inertia>"), std::string::npos) << name << ": " << w;
      EXPECT_EQ(w.find("<limit>"), std::string::npos) << name << ": " << w;
    }
  }
}

}  // namespace
}  // namespace vsd::scene
