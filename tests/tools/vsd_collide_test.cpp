// vsd-collide, run in-process: contacts and distances of a URDF and of a saved scene; usage and file
// errors.
#include "vsd-collide/tool.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tool_run.hpp"
#include "vsd/collision.hpp"
#include "vsd/core.hpp"
#include "vsd/io.hpp"

namespace vsd_collide_tool_test {
namespace {

using vsd_tool_test::has;
using vsd_tool_test::ToolRun;
namespace collision = vsd::collision;
namespace scene = vsd::scene;
namespace io = vsd::io;
using vsd::Environment;
using vsd::SimState;

const std::string data_dir = VSD_TOOLS_COLLISION_DATA_DIR;

ToolRun run(const std::vector<std::string>& args) { return vsd_tool_test::run_tool(vsd::tool::vsd_collide::run, args); }

TEST(VsdCollide, ListsTheContactsOfAUrdf) {
  const std::string file = data_dir + "/table_and_arm.urdf";
  ToolRun r = run({file});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "5 hulls, 4 shapes, 1 left out")) << r.out;
  EXPECT_TRUE(has(r.out, "1 pairs in contact")) << r.out;
  // the block sinks 1 cm into the table top; the normal points from the table up into the block
  EXPECT_TRUE(has(r.out, "contact table/top - block/body\n")) << r.out;
  EXPECT_TRUE(has(r.out, "normal [0, 0, 1] depth 0.01")) << r.out;
  EXPECT_FALSE(has(r.out, "table/leg")) << r.out;  // same link as the top
  // the missing mesh: the loader's warning and the left-out hull
  EXPECT_TRUE(has(r.err, "warning: left out: hull 'housing'")) << r.err;
  EXPECT_TRUE(has(r.err, "its mesh has no vertices")) << r.err;
}

TEST(VsdCollide, OptionsSelectSameLinkPairsVisualHullsAndDistances) {
  const std::string file = data_dir + "/table_and_arm.urdf";
  ToolRun r = run({file, "--same-link"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "2 pairs in contact")) << r.out;
  EXPECT_TRUE(has(r.out, "contact table/top - table/leg")) << r.out;

  r = run({file, "--visual"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "6 hulls")) << r.out;
  // the big visual sphere (r 0.5 at 1.09 m) reaches the block, the top and the leg's upper end
  EXPECT_TRUE(has(r.out, "4 pairs in contact")) << r.out;
  EXPECT_TRUE(has(r.out, "contact table/top - gripper/look")) << r.out;
  EXPECT_TRUE(has(r.out, "contact table/leg - gripper/look")) << r.out;
  EXPECT_TRUE(has(r.out, "contact block/body - gripper/look")) << r.out;
  EXPECT_FALSE(has(r.out, "gripper/finger - gripper/look")) << r.out;  // same link

  // every pair, the concentric finger and look spheres included (FCL's signed distance asserts there)
  r = run({file, "--visual", "--same-link", "--distances"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "distance gripper/look - gripper/finger: -0.55")) << r.out;

  r = run({file, "--distances"});
  ASSERT_EQ(r.code, 0) << r.err;
  // the finger's sphere (r 5 cm at 1.09 m) hangs 5 cm above the block's top face (0.99 m)
  EXPECT_TRUE(has(r.out, "distance block/body - gripper/finger: 0.05 between")) << r.out;
  EXPECT_TRUE(has(r.out, "distance table/top - block/body: -")) << r.out;  // overlapping: negative
}

TEST(VsdCollide, ReadsASavedScene) {
  const auto file = std::filesystem::temp_directory_path() / "vsd_collide_tool_test.json";
  {
    Environment env;
    env.use<collision::Module>();
    SimState& s = env.main_state();
    auto& g = s.create<scene::Geometry>();
    g.set_kind(scene::GeometryKind::Sphere);
    g.set_radius(1);
    auto& holder = s.create<scene::Scene>();
    s.database().add_child(holder);
    holder.edit_geometries().push_back(g);
    for (int i = 0; i < 3; ++i) {
      auto& h = s.create<scene::Hull>();
      h.set_name("ball" + std::to_string(i));
      h.set_role(scene::HullRole::Collision);
      h.set_geometry(&g);
      Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
      f.translation().x() = 1.5 * i * i;  // 0, 1.5, 6: only the first two touch
      h.set_frame(f);
      holder.add_child(h);
    }
    io::save(s, file);
  }
  ToolRun r = run({file.string()});
  std::filesystem::remove(file);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "3 hulls, 1 shapes, 0 left out")) << r.out;
  EXPECT_TRUE(has(r.out, "contact ball0 - ball1\n  at ")) << r.out;
  EXPECT_TRUE(has(r.out, "depth 0.5")) << r.out;
  EXPECT_FALSE(has(r.out, "ball2")) << r.out;
}

TEST(VsdCollide, UsageAndFileErrors) {
  EXPECT_EQ(run({}).code, 2);
  EXPECT_EQ(run({"--frobnicate", "x.urdf"}).code, 2);
  EXPECT_EQ(run({"a.urdf", "b.urdf"}).code, 2);
  EXPECT_EQ(run({"a.urdf", "--package-path"}).code, 2);
  ToolRun help = run({"--help"});
  EXPECT_EQ(help.code, 0);
  EXPECT_TRUE(has(help.out, "Usage:")) << help.out;
  ToolRun missing = run({data_dir + "/no_such_file.urdf"});
  EXPECT_EQ(missing.code, 1);
  EXPECT_TRUE(has(missing.err, "no_such_file.urdf")) << missing.err;
  ToolRun bad = run({data_dir + "/table_and_arm.urdf.json"});
  EXPECT_EQ(bad.code, 1);
}

TEST(VsdCollide, ReadsStandardInputAndSaysADirectoryIsOne) {
  const std::string urdf = vsd_tool_test::TempDir::read(data_dir + "/table_and_arm.urdf");
  const ToolRun r = vsd_tool_test::run_tool_with_stdin(vsd::tool::vsd_collide::run, {"-"}, urdf);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "1 pairs in contact")) << r.out;
  const ToolRun dir = run({data_dir});
  EXPECT_EQ(dir.code, 1);
  EXPECT_TRUE(has(dir.err, "is a directory")) << dir.err;
}

}  // namespace
}  // namespace vsd_collide_tool_test
