// Mesh files through assimp: the formats, and the checks in front of assimp (formats, sizes, nesting, the
// files a mesh pulls in).
#include "vsd/scene/mesh_loader.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <string>

#include "files.hpp"
#include "vsd/core.hpp"
#include "vsd/scene.hpp"

namespace vsd::scene {
namespace {

using namespace test;

class MeshLoaderTest : public ::testing::Test {
 protected:
  void SetUp() override { env.use<Module>(); }
  Environment env;
  SimState& s = env.main_state();
};

std::string error_of(Geometry& g, const fs::path& p, const MeshOptions& o = {}) {
  try {
    (void)load_mesh(g, p, o);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST_F(MeshLoaderTest, StlAsciiBinaryAndObjGiveTheCube) {
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

TEST_F(MeshLoaderTest, ColladaMeshWithNodeTransform) {
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

TEST_F(MeshLoaderTest, BadMeshFilesAreErrorsNamingTheFile) {
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

// A COLLADA file whose nodes nest 100,000 deep crashed inside assimp (its reader recurses per level);
// it is refused before assimp sees it, naming line and column.
TEST_F(MeshLoaderTest, DeeplyNestedColladaIsRefusedBeforeAssimp) {
  TempDir dir;
  std::string dae = "<?xml version=\"1.0\"?>\n<COLLADA version=\"1.4.1\"><library_visual_scenes><visual_scene id=\"s\">\n";
  const int depth = 100000;
  dae.reserve(20 * depth);
  for (int i = 0; i < depth; ++i) dae += "<node id=\"n\">";
  for (int i = 0; i < depth; ++i) dae += "</node>";
  dae += "</visual_scene></library_visual_scenes></COLLADA>\n";
  write(dir.path() / "deep.dae", dae);
  Geometry& g = s.create<Geometry>();
  const std::string what = error_of(g, dir.path() / "deep.dae");
  EXPECT_NE(what.find("deep.dae:3:"), std::string::npos) << what;  // the node that crosses the limit
  EXPECT_NE(what.find("COLLADA mesh nests elements deeper than 1000 levels"), std::string::npos) << what;
  EXPECT_FALSE(g.has_mesh_data());
  // Markup in a declaration's internal subset, comments and CDATA is not nesting.
  std::string busy = collada_tetrahedron;
  std::string noise = "<!DOCTYPE COLLADA [ <!ENTITY e \"<node><node>\"> <!-- <node> --> ]>\n";
  for (int i = 0; i < 2000; ++i) noise += "<!-- <node><node> --><![CDATA[<node>]]>";
  busy.insert(busy.find("<COLLADA"), noise);
  write(dir.path() / "busy.dae", busy);
  (void)load_mesh(g, dir.path() / "busy.dae");
  EXPECT_EQ(g.facet_count(), 4u);
}

// assimp follows <instance_node> by recursion and copies what it instances: a node that instances itself
// crashed it (SIGSEGV), and 40 nodes each instancing the one before twice (2^40 copies) never ended. Both
// are refused before assimp sees them; instancing within bounds loads.
TEST_F(MeshLoaderTest, ColladaInstancingIsBoundedBeforeAssimp) {
  TempDir dir;
  auto with_nodes = [&](const std::string& library, const std::string& in_scene) {
    std::string dae = collada_tetrahedron;
    dae.insert(dae.find("<library_visual_scenes>"), "<library_nodes>" + library + "</library_nodes>\n");
    const std::string old_node = "<node id=\"n\"><translate>10 0 0</translate><instance_geometry url=\"#tet\"/></node>";
    dae.replace(dae.find(old_node), old_node.size(), "<node id=\"n\">" + in_scene + "</node>");
    return dae;
  };
  Geometry& g = s.create<Geometry>();
  write(dir.path() / "self.dae",
        with_nodes("<node id=\"a\"><instance_geometry url=\"#tet\"/><instance_node url=\"#a\"/></node>",
                   "<instance_node url=\"#a\"/>"));
  std::string what = error_of(g, dir.path() / "self.dae");
  EXPECT_NE(what.find("self.dae:"), std::string::npos) << what;
  EXPECT_NE(what.find("node 'a' contains itself through <instance_node> references"), std::string::npos) << what;
  // A ring through nested nodes: b holds c, c instances b.
  write(dir.path() / "ring.dae",
        with_nodes("<node id=\"b\"><node id=\"c\"><instance_node url=\"#b\"/></node></node>",
                   "<instance_node url=\"#b\"/>"));
  what = error_of(g, dir.path() / "ring.dae");
  EXPECT_NE(what.find("node 'b' contains itself"), std::string::npos) << what;
  std::string doubling = "<node id=\"d0\"><instance_geometry url=\"#tet\"/></node>";
  for (int k = 1; k <= 40; ++k)
    doubling += "<node id=\"d" + std::to_string(k) + "\"><instance_node url=\"#d" + std::to_string(k - 1) +
                "\"/><instance_node url=\"#d" + std::to_string(k - 1) + "\"/></node>";
  write(dir.path() / "doubling.dae", with_nodes(doubling, "<instance_node url=\"#d40\"/>"));
  what = error_of(g, dir.path() / "doubling.dae");
  EXPECT_NE(what.find("its scene expands to 2199023255552 nodes"), std::string::npos) << what;
  EXPECT_FALSE(g.has_mesh_data());
  // Four levels of doubling: 16 tetrahedra at one place, joined into one.
  std::string small = "<node id=\"d0\"><instance_geometry url=\"#tet\"/></node>";
  for (int k = 1; k <= 4; ++k)
    small += "<node id=\"d" + std::to_string(k) + "\"><instance_node url=\"#d" + std::to_string(k - 1) +
             "\"/><instance_node url=\"#d" + std::to_string(k - 1) + "\"/></node>";
  write(dir.path() / "small.dae", with_nodes(small, "<instance_node url=\"#d4\"/>"));
  (void)load_mesh(g, dir.path() / "small.dae");
  EXPECT_EQ(g.facet_count(), 64u);
}

TEST_F(MeshLoaderTest, OnlyStlObjColladaAndPlyAreRead) {
  TempDir dir;
  write(dir.path() / "cube.3ds", binary_stl());
  write(dir.path() / "cube", binary_stl());
  Geometry& g = s.create<Geometry>();
  EXPECT_NE(error_of(g, dir.path() / "cube.3ds").find("format '.3ds' is not read"), std::string::npos);
  EXPECT_NE(error_of(g, dir.path() / "cube").find("format '' is not read"), std::string::npos);
  // Upper-case extensions are common in robot packages.
  write(dir.path() / "CUBE.STL", binary_stl());
  (void)load_mesh(g, dir.path() / "CUBE.STL");
  EXPECT_EQ(g.facet_count(), 12u);
}

TEST_F(MeshLoaderTest, FilesLargerThanTheLimitAndNonRegularFilesAreRefused) {
  TempDir dir;
  write(dir.path() / "cube.stl", binary_stl());  // 684 bytes
  Geometry& g = s.create<Geometry>();
  MeshOptions small;
  small.max_file_bytes = 600;
  const std::string what = error_of(g, dir.path() / "cube.stl", small);
  EXPECT_NE(what.find("684 bytes is larger than the limit of 600 bytes"), std::string::npos) << what;
  // A FIFO would block the reader forever; a directory is no mesh.
  ASSERT_EQ(::mkfifo((dir.path() / "fifo.stl").c_str(), 0600), 0);
  EXPECT_NE(error_of(g, dir.path() / "fifo.stl").find("not a regular file"), std::string::npos);
  fs::create_directories(dir.path() / "dir.stl");
  EXPECT_NE(error_of(g, dir.path() / "dir.stl").find("not a regular file"), std::string::npos);
  EXPECT_FALSE(g.has_mesh_data());
}

// An OBJ pulls in its material library (`mtllib`): that file obeys the mesh's folder rule, after `..` and
// symbolic links are resolved, and a refused one is reported, not read.
TEST_F(MeshLoaderTest, FilesAMeshPullsInStayInsideTheAllowedFolders) {
  TempDir dir;
  write(dir.path() / "secret.mtl", "newmtl red\nKd 1 0 0\n");
  write(dir.path() / "m" / "up.obj", "mtllib ../secret.mtl\nusemtl red\n" + obj_cube());
  fs::create_symlink(dir.path() / "secret.mtl", dir.path() / "m" / "link.mtl");
  write(dir.path() / "m" / "linked.obj", "mtllib link.mtl\nusemtl red\n" + obj_cube());
  ASSERT_EQ(::mkfifo((dir.path() / "m" / "fifo.mtl").c_str(), 0600), 0);
  write(dir.path() / "m" / "fifo.obj", "mtllib fifo.mtl\n" + obj_cube());
  write(dir.path() / "m" / "own.mtl", "newmtl red\nKd 1 0 0\n");
  write(dir.path() / "m" / "own.obj", "mtllib own.mtl\nusemtl red\n" + obj_cube());
  for (const char* name : {"up.obj", "linked.obj"}) {
    Geometry& g = s.create<Geometry>();
    const MeshReport r = load_mesh(g, dir.path() / "m" / name);
    EXPECT_EQ(g.facet_count(), 12u) << name;  // the mesh loads without its materials
    ASSERT_EQ(r.warnings.size(), 1u) << name << ": " << ::testing::PrintToString(r.warnings);
    EXPECT_NE(r.warnings[0].find("secret.mtl' is outside the folders models may read from"), std::string::npos)
        << r.warnings[0];
  }
  {
    Geometry& g = s.create<Geometry>();
    const MeshReport r = load_mesh(g, dir.path() / "m" / "fifo.obj");
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("fifo.mtl' is not a regular file"), std::string::npos) << r.warnings[0];
  }
  {
    Geometry& g = s.create<Geometry>();
    EXPECT_TRUE(load_mesh(g, dir.path() / "m" / "own.obj").warnings.empty());
  }
  // Wider folders, or none at all, when the caller says so.
  MeshOptions wider;
  wider.allowed_roots = {dir.path()};
  MeshOptions anywhere;
  anywhere.allow_paths_outside = true;
  for (const MeshOptions* o : {&wider, &anywhere}) {
    Geometry& g = s.create<Geometry>();
    EXPECT_TRUE(load_mesh(g, dir.path() / "m" / "up.obj", *o).warnings.empty());
  }
  // The mesh itself obeys the folders given.
  MeshOptions elsewhere;
  elsewhere.allowed_roots = {dir.path() / "m"};
  Geometry& g = s.create<Geometry>();
  write(dir.path() / "cube.stl", binary_stl());
  EXPECT_NE(error_of(g, dir.path() / "cube.stl", elsewhere).find("is outside the folders"), std::string::npos);
}

}  // namespace
}  // namespace vsd::scene
