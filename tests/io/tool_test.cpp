// The vsd-io tool, run in-process: this test program links the test classes, so its tool knows them (as a
// user's own tool would know theirs).
#include "vsd/io/tool.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>
#include <unistd.h>

#include "io_model.hpp"
#include "vsd/io/file.hpp"
#include "vsd/io/snapshot.hpp"

using testing::HasSubstr;

namespace {

struct ToolRun {
  int status;
  std::string out, err;
};

ToolRun tool(std::vector<std::string> args) {
  std::vector<std::string_view> views(args.begin(), args.end());
  std::ostringstream out, err;
  const int status = vsd::io::run_tool(views, out, err);
  return {status, out.str(), err.str()};
}

std::string golden(const std::string& name) { return std::string(VSD_TEST_GOLDEN_DIR) + "/" + name; }

class Tool : public testing::Test {
 protected:
  void SetUp() override {
    dir = std::filesystem::temp_directory_path() / ("vsd_tool_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
  }
  void TearDown() override { std::filesystem::remove_all(dir); }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  std::filesystem::path dir;
};

TEST_F(Tool, HelpAndUsageErrors) {
  const ToolRun help = tool({"--help"});
  EXPECT_EQ(help.status, 0);
  EXPECT_THAT(help.out, HasSubstr("vsd-io convert <in> <out>"));
  EXPECT_THAT(help.out, HasSubstr("Exit status"));
  EXPECT_EQ(tool({}).status, 2);
  const ToolRun unknown = tool({"frobnicate"});
  EXPECT_EQ(unknown.status, 2);
  EXPECT_THAT(unknown.err, HasSubstr("unknown command 'frobnicate'"));
  EXPECT_EQ(tool({"convert", "only-one"}).status, 2);
  EXPECT_EQ(tool({"convert", "a", "b", "--to", "xml"}).status, 2);
  EXPECT_EQ(tool({"tree", "a", "--colour"}).status, 2);
}

TEST_F(Tool, ConvertsBothWaysToTheSameFile) {
  const ToolRun to_binary = tool({"convert", golden("model.json"), path("model.vsds")});
  ASSERT_EQ(to_binary.status, 0) << to_binary.err;
  EXPECT_THAT(to_binary.out, HasSubstr("(binary)"));
  EXPECT_EQ(vsd::io::format_of(vsd::io::read_file(path("model.vsds"))), vsd::io::Format::Binary);
  ASSERT_EQ(tool({"convert", path("model.vsds"), path("back.json")}).status, 0);
  EXPECT_EQ(vsd::io::read_file(path("back.json")), vsd::io::read_file(golden("model.json")));
  // --to wins over the name; a subtree stays a subtree.
  ASSERT_EQ(tool({"convert", golden("handwritten.json"), path("sub.bin"), "--to", "text"}).status, 0);
  vsd::Environment env;
  const auto report = vsd::io::load(env.main_state(), path("sub.bin"));
  EXPECT_EQ(report.format, vsd::io::Format::Text);
  EXPECT_TRUE(report.subtree);
  EXPECT_EQ(report.instances, 3u);
}

TEST_F(Tool, PrintsATree) {
  const ToolRun plain = tool({"tree", golden("runtime.json")});
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_EQ(plain.out,
            "#1 Database \"plant\"\n"
            "└─ #2 Node \"hall\"\n"
            "   ├─ #3 Conveyor \"belt 1\"\n"
            "   └─ #4 Node \"press\"\n");
  const ToolRun values = tool({"tree", golden("model.json"), "--values"});
  ASSERT_EQ(values.status, 0) << values.err;
  EXPECT_THAT(values.out, HasSubstr("├─ #3 TRobot \"arm\"\n"));
  EXPECT_THAT(values.out, HasSubstr("   │     speed: 2.5\n"));
  EXPECT_THAT(values.out, HasSubstr("+ extension #6 TSensor"));
  EXPECT_THAT(values.out, HasSubstr("held by references only:\n  #4 TTool"));
}

TEST_F(Tool, DescribesAndChecks) {
  // Each run's state is gone when it ends; a class an earlier run defined is left in this process.
  if (const auto* c = vsd::Registry::global().find_class("Conveyor")) vsd::Registry::global().undefine(*c);
  const ToolRun info = tool({"info", golden("runtime.json")});
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_THAT(info.out, HasSubstr("format:    text"));
  EXPECT_THAT(info.out, HasSubstr("kind:      state"));
  EXPECT_THAT(info.out, HasSubstr("instances: 3"));
  EXPECT_THAT(info.out, HasSubstr("  1 Conveyor\n"));
  EXPECT_THAT(info.out, HasSubstr("run-time classes defined by the file: Conveyor"));
  const ToolRun ok = tool({"check", golden("handwritten.json")});
  EXPECT_EQ(ok.status, 0);
  EXPECT_THAT(ok.out, HasSubstr("ok, 3 instances"));
  vsd::io::write_file_atomically(path("bad.json"),
                                 std::vector<std::uint8_t>{'{', '\n', '"', 'f', 'o', 'r', 'm', 'a', 't', '"', ':', ' ', '1'});
  const ToolRun bad = tool({"check", path("bad.json")});
  EXPECT_EQ(bad.status, 1);
  EXPECT_THAT(bad.err, HasSubstr("bad.json:2:"));
  const ToolRun missing = tool({"info", path("nothing.json")});
  EXPECT_EQ(missing.status, 1);
  EXPECT_THAT(missing.err, HasSubstr("nothing.json"));
}

}  // namespace
