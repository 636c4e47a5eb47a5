// vsd-web, run in-process: it loads each kind of input, serves it for a moment and stops; its errors and
// its refusals (a non-loopback address without a token).
#include "vsd-web/tool.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "tool_run.hpp"

namespace vsd_web_tool_test {
namespace {

using testing::HasSubstr;
using vsd_tool_test::TempDir;
using vsd_tool_test::ToolRun;

ToolRun run(const std::vector<std::string>& args) { return vsd_tool_test::run_tool(vsd::tool::vsd_web::run, args); }

const std::string iiwa = std::string(VSD_TOOLS_SCENE_DATA_DIR) + "/iiwa14.urdf";

TEST(VsdWeb, ServesAUrdfForAMomentAndStops) {
  const ToolRun r = run({iiwa, "--port", "0", "--seconds", "0.2"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("loaded 11 links"));
  EXPECT_THAT(r.out, testing::ContainsRegex("vsd-web: serving http://127\\.0\\.0\\.1:[0-9]+/"));
  EXPECT_THAT(r.out, testing::ContainsRegex("vsd-web: write token: [0-9a-f]{32}"));
  EXPECT_THAT(r.out, HasSubstr("vsd-web: stopped"));
}

TEST(VsdWeb, ServesAScriptAndRunsIt) {
  TempDir tmp("vsd_web_tool");
  const std::string path = tmp.path("turn.soml");
  std::ofstream(path) << "object counter { place a = 3; place b; transition t; arrow a -> t; arrow t -> b; }\n";
  const ToolRun r = run({path, "--port", "0", "--seconds", "0.2", "--run", "--token", "secret-token-1"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("write token: secret-token-1"));
}

TEST(VsdWeb, ReportsBadInputAndUsage) {
  TempDir tmp("vsd_web_tool");
  const std::string bad = tmp.path("bad.soml");
  std::ofstream(bad) << "object x { place a = ; }\n";
  const ToolRun script = run({bad, "--port", "0", "--seconds", "0.1"});
  EXPECT_EQ(script.code, 1);
  EXPECT_THAT(script.err, HasSubstr("bad.soml:1:"));
  EXPECT_EQ(run({tmp.path("missing.json"), "--port", "0"}).code, 1);
  EXPECT_EQ(run({iiwa, "--port", "70000"}).code, 2);
  EXPECT_EQ(run({iiwa, "--token", "short"}).code, 2);
  EXPECT_EQ(run({iiwa, "--dt", "0"}).code, 2);
  EXPECT_EQ(run({}).code, 2);
  const ToolRun open = run({iiwa, "--port", "0", "--bind", "0.0.0.0", "--seconds", "0.1"});
  EXPECT_EQ(open.code, 1);
  EXPECT_THAT(open.err, HasSubstr("needs a token"));
  const ToolRun help = run({"--help"});
  EXPECT_EQ(help.code, 0);
  EXPECT_THAT(help.out, HasSubstr("Usage:"));
}

}  // namespace
}  // namespace vsd_web_tool_test
