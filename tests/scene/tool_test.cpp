// vsd-scene as a library function: URDF and saved scenes, usage errors, bad files.
#include "vsd/scene/tool.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace vsd::scene {
namespace {

namespace fs = std::filesystem;
const fs::path tool_data_dir = VSD_SCENE_TEST_DATA_DIR;

struct ToolRun {
  int code = 0;
  std::string out;
  std::string err;
};

ToolRun run(std::vector<std::string> args) {
  std::vector<std::string_view> views(args.begin(), args.end());
  std::ostringstream out, err;
  ToolRun r;
  r.code = run_tool(views, out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

TEST(SceneTool, PrintsTheTreeAndTheWarningsOfAUrdf) {
  const ToolRun r = run({(tool_data_dir / "iiwa14.urdf").string()});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("scene iiwa14: 11 links, 10 joints"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("joint iiwa_joint_4 (Revolute) axis [0, 0, 1] limits [-2.0944, 2.0944]"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("link iiwa_link_4 mass 2.7 kg"), std::string::npos) << r.out;
  EXPECT_NE(
      r.out.find("warning: link 'iiwa_link_3' collision: mesh 'package://iiwa_description/meshes/iiwa14/"
                 "collision/link_3.stl' not found"),
      std::string::npos)
      << r.out;
}

TEST(SceneTool, SavedSceneRoundTripsThroughJson) {
  const ToolRun json = run({(tool_data_dir / "ur5_robot.urdf").string(), "--no-meshes", "--json"});
  ASSERT_EQ(json.code, 0) << json.err;
  EXPECT_EQ(json.out.rfind("{", 0), 0u);
  const fs::path file =
      fs::temp_directory_path() / ("vsd_scene_tool_" + std::to_string(::getpid()) + ".json");
  std::ofstream(file) << json.out;
  const ToolRun tree = run({file.string()});
  fs::remove(file);
  EXPECT_EQ(tree.code, 0) << tree.err;
  EXPECT_NE(tree.out.find("scene ur5: 11 links, 10 joints"), std::string::npos) << tree.out;
  EXPECT_NE(tree.out.find("joint elbow_joint (Revolute)"), std::string::npos) << tree.out;
  EXPECT_NE(tree.out.find("link upper_arm_link mass 8.393 kg"), std::string::npos) << tree.out;
}

TEST(SceneTool, UsageAndFileErrors) {
  EXPECT_EQ(run({"--help"}).code, 0);
  EXPECT_NE(run({"--help"}).out.find("Usage:"), std::string::npos);
  EXPECT_EQ(run({}).code, 2);
  EXPECT_EQ(run({"a.urdf", "b.urdf"}).code, 2);
  EXPECT_EQ(run({"a.urdf", "--package-path"}).code, 2);
  EXPECT_EQ(run({"--bogus"}).code, 2);
  const ToolRun missing = run({"/nonexistent/robot.urdf"});
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("/nonexistent/robot.urdf"), std::string::npos) << missing.err;
  const ToolRun notscene = run({(tool_data_dir / "README.md").string()});
  EXPECT_EQ(notscene.code, 1);
  EXPECT_NE(notscene.err.find("README.md"), std::string::npos) << notscene.err;
}

}  // namespace
}  // namespace vsd::scene
