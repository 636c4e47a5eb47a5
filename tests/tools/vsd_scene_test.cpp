// vsd-scene, run in-process: URDF and saved scenes, usage errors, bad files, standard input, deep trees.
#include "vsd-scene/tool.hpp"

#include "vsd-io/tool.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tool_run.hpp"

namespace vsd_scene_tool_test {
namespace {

using vsd_tool_test::TempDir;
using vsd_tool_test::ToolRun;

const std::string data_dir = VSD_TOOLS_SCENE_DATA_DIR;

ToolRun run(const std::vector<std::string>& args) { return vsd_tool_test::run_tool(vsd::tool::vsd_scene::run, args); }

TEST(VsdScene, PrintsTheTreeAndTheWarningsOfAUrdf) {
  const ToolRun r = run({data_dir + "/iiwa14.urdf"});
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

TEST(VsdScene, SavedSceneRoundTripsThroughJson) {
  const ToolRun json = run({data_dir + "/ur5_robot.urdf", "--no-meshes", "--json"});
  ASSERT_EQ(json.code, 0) << json.err;
  EXPECT_EQ(json.out.rfind("{", 0), 0u);
  const TempDir tmp("vsd_scene_tool");
  const ToolRun tree = run({tmp.write("ur5.json", json.out)});
  EXPECT_EQ(tree.code, 0) << tree.err;
  EXPECT_NE(tree.out.find("scene ur5: 11 links, 10 joints"), std::string::npos) << tree.out;
  EXPECT_NE(tree.out.find("joint elbow_joint (Revolute)"), std::string::npos) << tree.out;
  EXPECT_NE(tree.out.find("link upper_arm_link mass 8.393 kg"), std::string::npos) << tree.out;
  // The same text on standard input.
  const ToolRun piped = vsd_tool_test::run_tool_with_stdin(vsd::tool::vsd_scene::run, {"-"}, json.out);
  EXPECT_EQ(piped.code, 0) << piped.err;
  EXPECT_EQ(piped.out, tree.out);
}

// Every tool knows the classes of every module that was built: vsd-io reads what vsd-scene writes.
TEST(VsdScene, VsdIoReadsWhatItWrites) {
  const ToolRun json = run({data_dir + "/ur5_robot.urdf", "--no-meshes", "--json"});
  ASSERT_EQ(json.code, 0) << json.err;
  const TempDir tmp("vsd_scene_to_io");
  const ToolRun tree = vsd_tool_test::run_tool(vsd::tool::vsd_io::run, {"tree", tmp.write("ur5.json", json.out)});
  ASSERT_EQ(tree.code, 0) << tree.err;
  EXPECT_NE(tree.out.find("scene::Link \"upper_arm_link\""), std::string::npos) << tree.out;
  EXPECT_EQ(tree.err.find("not known"), std::string::npos) << tree.err;  // no stand-ins
}

TEST(VsdScene, UsageAndFileErrors) {
  EXPECT_EQ(run({"--help"}).code, 0);
  EXPECT_NE(run({"--help"}).out.find("Usage:"), std::string::npos);
  EXPECT_EQ(run({}).code, 2);
  EXPECT_EQ(run({"a.urdf", "b.urdf"}).code, 2);
  EXPECT_EQ(run({"a.urdf", "--package-path"}).code, 2);
  EXPECT_EQ(run({"--bogus"}).code, 2);
  const ToolRun missing = run({"/nonexistent/robot.urdf"});
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("/nonexistent/robot.urdf"), std::string::npos) << missing.err;
  const ToolRun notscene = run({data_dir + "/README.md"});
  EXPECT_EQ(notscene.code, 1);
  EXPECT_NE(notscene.err.find("README.md"), std::string::npos) << notscene.err;
  const ToolRun dir = run({data_dir});
  EXPECT_EQ(dir.code, 1);
  EXPECT_NE(dir.err.find("scene/data: is a directory"), std::string::npos) << dir.err;
}

TEST(VsdScene, AUrdfOnStandardInput) {
  const std::string urdf = TempDir::read(data_dir + "/iiwa14.urdf");
  const ToolRun r = vsd_tool_test::run_tool_with_stdin(vsd::tool::vsd_scene::run, {"-", "--no-meshes"}, urdf);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("scene iiwa14: 11 links, 10 joints"), std::string::npos) << r.out;
}

// A chain of links prints in linear output: levels below 48 say their depth instead of being indented
// further, and nothing recurses. (300 links: deeper chains load slowly until the core's cycle check is
// linear in the depth, issue 22.)
TEST(VsdScene, ADeepChainPrintsFlat) {
  std::string urdf = "<robot name=\"deep\">\n<link name=\"l0\"/>\n";
  constexpr int n = 300;
  for (int i = 1; i < n; ++i)
    urdf += "<link name=\"l" + std::to_string(i) + "\"/><joint name=\"j" + std::to_string(i) +
            "\" type=\"fixed\"><parent link=\"l" + std::to_string(i - 1) + "\"/><child link=\"l" + std::to_string(i) +
            "\"/></joint>\n";
  urdf += "</robot>\n";
  const TempDir tmp("vsd_scene_deep");
  const ToolRun r = run({tmp.write("deep.urdf", urdf)});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("(level 299) link l298"), std::string::npos);
  EXPECT_LT(r.out.size(), std::size_t{n} * 300);
}

TEST(VsdScene, ControlCharactersInNamesAreShownAsQuestionMarks) {
  const std::string urdf = "<robot name=\"r\x1b[31m\"><link name=\"a\x07\"/></robot>";
  const TempDir tmp("vsd_scene_evil");
  const ToolRun r = run({tmp.write("evil.urdf", urdf)});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find('\x07'), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("scene r?[31m"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace vsd_scene_tool_test
