// vsd-io, run in-process: convert, tree, info and check; files of classes it does not know; standard
// input, pipes, directories, failed writes and hostile names.
#include "vsd-io/tool.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include "../io/io_model.hpp"  // TRobot, TTool, TSensor, IoRich: linked into this program, so its tool knows them
#include "tool_run.hpp"
#include "vsd/io/file.hpp"
#include "vsd/io/snapshot.hpp"

namespace vsd_io_tool_test {
namespace {

using testing::HasSubstr;
using vsd_tool_test::TempDir;
using vsd_tool_test::ToolRun;

ToolRun tool(const std::vector<std::string>& args) { return vsd_tool_test::run_tool(vsd::tool::vsd_io::run, args); }

std::string golden(const std::string& name) { return std::string(VSD_TOOLS_IO_GOLDEN_DIR) + "/" + name; }

class VsdIo : public testing::Test {
 protected:
  // The classes of this program that the golden files use, registered as a program does it (inline
  // registration is dropped when nothing else names them): the tool knows what its program links.
  void SetUp() override {
    for (const vsd::MetaInstance* c : {&vsd_test::TRobot::static_meta(), &vsd_test::TTool::static_meta(),
                                       &vsd_test::TSensor::static_meta(), &vsd_test::IoRich::static_meta()})
      vsd::Registry::global().add(*c);
  }
  TempDir tmp{"vsd_io_tool_test"};
  std::string path(const std::string& name) const { return tmp.path(name); }
};

TEST_F(VsdIo, HelpAndUsageErrors) {
  const ToolRun help = tool({"--help"});
  EXPECT_EQ(help.code, 0);
  EXPECT_THAT(help.out, HasSubstr("vsd-io convert <in> <out>"));
  EXPECT_THAT(help.out, HasSubstr("Exit status"));
  EXPECT_EQ(tool({}).code, 2);
  const ToolRun unknown = tool({"frobnicate"});
  EXPECT_EQ(unknown.code, 2);
  EXPECT_THAT(unknown.err, HasSubstr("unknown command 'frobnicate'"));
  EXPECT_THAT(unknown.err, HasSubstr("Try 'vsd-io --help'."));
  EXPECT_EQ(tool({"convert", "only-one"}).code, 2);
  EXPECT_EQ(tool({"convert", "a", "b", "--to", "xml"}).code, 2);
  EXPECT_EQ(tool({"tree", "a", "--colour"}).code, 2);
  EXPECT_EQ(tool({"help"}).code, 0);
}

TEST_F(VsdIo, ConvertsBothWaysToTheSameFile) {
  const ToolRun to_binary = tool({"convert", golden("model.json"), path("model.vsds")});
  ASSERT_EQ(to_binary.code, 0) << to_binary.err;
  EXPECT_THAT(to_binary.out, HasSubstr("(binary)"));
  EXPECT_EQ(vsd::io::format_of(vsd::io::read_file(path("model.vsds"))), vsd::io::Format::Binary);
  ASSERT_EQ(tool({"convert", path("model.vsds"), path("back.json")}).code, 0);
  EXPECT_EQ(vsd::io::read_file(path("back.json")), vsd::io::read_file(golden("model.json")));
  // --to wins over the name; a subtree stays a subtree.
  ASSERT_EQ(tool({"convert", golden("handwritten.json"), path("sub.bin"), "--to", "text"}).code, 0);
  vsd::Environment env;
  const auto report = vsd::io::load(env.main_state(), path("sub.bin"));
  EXPECT_EQ(report.format, vsd::io::Format::Text);
  EXPECT_TRUE(report.subtree);
  EXPECT_EQ(report.instances, 3u);
}

TEST_F(VsdIo, PrintsATree) {
  const ToolRun plain = tool({"tree", golden("runtime.json")});
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_EQ(plain.out,
            "#1 Database \"plant\"\n"
            "└─ #2 Node \"hall\"\n"
            "   ├─ #3 Conveyor \"belt 1\"\n"
            "   └─ #4 Node \"press\"\n");
  const ToolRun values = tool({"tree", golden("model.json"), "--values"});
  ASSERT_EQ(values.code, 0) << values.err;
  EXPECT_THAT(values.out, HasSubstr("├─ #3 TRobot \"arm\"\n"));
  EXPECT_THAT(values.out, HasSubstr("   │     speed: 2.5\n"));
  EXPECT_THAT(values.out, HasSubstr("+ extension #6 TSensor"));
  EXPECT_THAT(values.out, HasSubstr("held by references only:\n  #4 TTool"));
}

// model.json with the test classes renamed to names no program has: a user's file read by the stock tool.
std::string unknown_model(const TempDir& tmp) {
  std::string text = TempDir::read(golden("model.json"));
  for (const std::string from : {"TRobot", "TTool", "TSensor"})
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + 1)) text[at] = 'X';
  return tmp.write("user.json", text);
}

TEST_F(VsdIo, ShowsClassesItDoesNotKnowThroughStandIns) {
  const ToolRun values = tool({"tree", unknown_model(tmp), "--values"});
  ASSERT_EQ(values.code, 0) << values.err;
  EXPECT_THAT(values.out, HasSubstr("├─ #3 XRobot \"arm\"\n"));
  EXPECT_THAT(values.out, HasSubstr("   │     speed: 2.5\n"));
  EXPECT_THAT(values.out, HasSubstr("+ extension #6 XSensor"));
  EXPECT_THAT(values.out, HasSubstr("held by references only:\n  #4 XTool"));
  EXPECT_THAT(values.err, HasSubstr("warning: class 'XRobot' is not known to this program: its instances are "
                                    "shown through a stand-in derived from Node with the file's saved values"));
}

TEST_F(VsdIo, DescribesAndChecks) {
  const ToolRun info = tool({"info", golden("runtime.json")});
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_THAT(info.out, HasSubstr("format:    text"));
  EXPECT_THAT(info.out, HasSubstr("kind:      state"));
  EXPECT_THAT(info.out, HasSubstr("instances: 3"));
  EXPECT_THAT(info.out, HasSubstr("  1 Conveyor\n"));
  EXPECT_THAT(info.out, HasSubstr("run-time classes defined by the file: Conveyor"));
  const ToolRun ok = tool({"check", golden("handwritten.json")});
  EXPECT_EQ(ok.code, 0);
  EXPECT_THAT(ok.out, HasSubstr("ok, 3 instances"));
  vsd::io::write_file_atomically(path("bad.json"),
                                 std::vector<std::uint8_t>{'{', '\n', '"', 'f', 'o', 'r', 'm', 'a', 't', '"', ':', ' ', '1'});
  const ToolRun bad = tool({"check", path("bad.json")});
  EXPECT_EQ(bad.code, 1);
  EXPECT_THAT(bad.err, HasSubstr("bad.json:2:"));
  const ToolRun missing = tool({"info", path("nothing.json")});
  EXPECT_EQ(missing.code, 1);
  EXPECT_THAT(missing.err, HasSubstr("nothing.json"));
}

// A program that never defined the types (the stock tool) inspects the file and converts it unchanged.
TEST_F(VsdIo, RunTimeTypesTreeAndConvert) {
  std::vector<std::uint8_t> bytes;
  {
    vsd::Registry registry;  // the writing program's; the tool never saw these types
    const vsd::MetaType& color =
        vsd::EnumBuilder("IoRtColor").underlying(vsd::meta_type<std::int16_t>()).value("Red", -1).value("Blue", 9).define(registry);
    const vsd::MetaType& tag = vsd::StructBuilder("IoRtTag")
                                   .field<std::string>("label")
                                   .field("color", color)
                                   .field<Eigen::Vector3d>("at")
                                   .define(registry);
    const vsd::MetaType& access = vsd::EnumBuilder("IoRtAccess", vsd::TypeKind::Flags)
                                      .underlying(vsd::meta_type<std::uint8_t>())
                                      .value("Read", 1)
                                      .value("Write", 2)
                                      .define(registry);
    const vsd::MetaInstance& marker = vsd::ClassBuilder("IoRtMarker", vsd::Node::static_meta())
                                          .property("main", tag)
                                          .property("access", access)
                                          .define(registry);
    vsd::Environment env(0, registry);
    auto& m = static_cast<vsd::Node&>(env.main_state().create(marker));
    m.set_name("m");
    m.set("main", vsd::Value::from_text(tag, "{\"label\": \"first\", \"color\": \"Red\", \"at\": [1, 2, 3]}"));
    m.set("access", vsd::Value::from_text(access, "\"Read|Write\""));
    env.main_state().database().add_child(m);
    bytes = vsd::io::save_bytes(env.main_state(), vsd::io::Format::Text);
  }
  vsd::io::write_file_atomically(path("in.json"), bytes);
  ToolRun r = tool({"tree", path("in.json"), "--values"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("main: {\"label\": \"first\", \"color\": \"Red\", \"at\": [1, 2, 3]}"));
  EXPECT_THAT(r.out, HasSubstr("access: \"Read|Write\""));
  r = tool({"info", path("in.json")});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("format:    text (vsd-text 2)"));
  EXPECT_THAT(r.out, HasSubstr("run-time types defined by the file: IoRtColor IoRtTag IoRtAccess"));
  ASSERT_EQ(tool({"convert", path("in.json"), path("out.vsds")}).code, 0);
  ASSERT_EQ(tool({"convert", path("out.vsds"), path("back.json")}).code, 0);
  EXPECT_EQ(vsd::io::read_file(path("back.json")), bytes) << "text -> binary -> text: byte-identical";
  EXPECT_EQ(vsd::Registry::global().find_type("IoRtTag"), nullptr) << "each run's classes and types go with it";
}

TEST_F(VsdIo, FilesOfUnknownClassesAreShownButNotConverted) {
  const std::string file = unknown_model(tmp);
  const ToolRun check = tool({"check", file});
  EXPECT_EQ(check.code, 0) << check.err;
  const ToolRun info = tool({"info", file});
  EXPECT_THAT(info.out, HasSubstr("classes this tool does not know (shown through stand-ins): XRobot XTool XSensor"));
  const ToolRun convert = tool({"convert", file, path("out.json")});
  EXPECT_EQ(convert.code, 1);
  EXPECT_THAT(convert.err, HasSubstr("not converted: this tool does not know the classes 'XRobot'"));
  EXPECT_FALSE(std::filesystem::exists(path("out.json")));
}

TEST_F(VsdIo, ReadsStandardInputAndWritesStandardOutput) {
  const std::string text = TempDir::read(golden("runtime.json"));
  const ToolRun tree = vsd_tool_test::run_tool_with_stdin(vsd::tool::vsd_io::run, {"tree", "-"}, text);
  ASSERT_EQ(tree.code, 0) << tree.err;
  EXPECT_THAT(tree.out, HasSubstr("└─ #2 Node \"hall\""));
  const ToolRun info = vsd_tool_test::run_tool_with_stdin(vsd::tool::vsd_io::run, {"info", "-"}, text);
  EXPECT_THAT(info.out, HasSubstr("file:      standard input"));
  const ToolRun out = tool({"convert", golden("runtime.json"), "-"});
  ASSERT_EQ(out.code, 0) << out.err;
  ASSERT_EQ(tool({"convert", golden("runtime.json"), path("file.json")}).code, 0);
  EXPECT_EQ(out.out, TempDir::read(path("file.json"))) << "text to standard output, as to a file";
  EXPECT_THAT(out.err, HasSubstr("wrote 3 instances to standard output (text)"));
}

TEST_F(VsdIo, ReadsAFifoAsAStream) {
  const std::string fifo = path("pipe.json");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] { std::ofstream(fifo) << TempDir::read(golden("runtime.json")); });
  const ToolRun r = tool({"check", fifo});
  writer.join();
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("ok, 3 instances"));
}

TEST_F(VsdIo, ADirectoryIsSaidToBeOne) {
  for (const char* cmd : {"check", "tree", "info"}) {
    const ToolRun r = tool({cmd, tmp.dir().string()});
    EXPECT_EQ(r.code, 1) << cmd;
    EXPECT_THAT(r.err, HasSubstr(": is a directory")) << cmd;
  }
  const ToolRun r = tool({"convert", tmp.dir().string(), path("x.json")});
  EXPECT_THAT(r.err, HasSubstr("is a directory"));
}

TEST_F(VsdIo, AFailedWriteLeavesTheOldFileWhole) {
  const std::string old = "old content\n";
  const std::string target = tmp.write("keep.json", old);
  ToolRun r;
  {
    const vsd_tool_test::FileSizeLimit full(64);  // the new file cannot be written whole
    r = tool({"convert", golden("runtime.json"), target});
  }
  EXPECT_EQ(r.code, 1);
  EXPECT_THAT(r.err, HasSubstr("keep.json"));
  EXPECT_EQ(TempDir::read(target), old);
}

// A deep tree prints in linear output and without recursion: levels below 48 say their level instead of
// being indented further.
TEST_F(VsdIo, ADeepTreePrintsFlat) {
  vsd::Environment env;
  vsd::Node* parent = &env.main_state().database();
  for (int i = 0; i < 200; ++i) {
    auto& n = env.main_state().create<vsd::Node>();
    n.set_name("n" + std::to_string(i));
    parent->add_child(n);
    parent = &n;
  }
  vsd::io::save(env.main_state(), path("deep.json"));
  const ToolRun r = tool({"tree", path("deep.json")});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("└─ #49 Node \"n47\"\n"));
  EXPECT_THAT(r.out, HasSubstr("… level 49: #50 Node \"n48\"\n"));
  EXPECT_THAT(r.out, HasSubstr("… level 200: #201 Node \"n199\"\n"));
  EXPECT_LT(r.out.size(), std::size_t{200} * 200);
}

TEST_F(VsdIo, ControlCharactersInNamesAndArgumentsAreNotEchoed) {
  // A class name with an escape sequence in a file: shown with '?' in the tree and in messages.
  const std::string text = TempDir::read(golden("runtime.json"));
  std::string evil = text;
  for (std::size_t at = evil.find("Conveyor"); at != std::string::npos; at = evil.find("Conveyor", at + 1))
    evil.replace(at, 8, "Con\\u001b[2Jveyor");
  const std::string file = tmp.write("evil.json", evil);
  const ToolRun r = tool({"tree", file});
  EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << r.out << r.err;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
  const ToolRun u = tool({"tree", "--bogus\x1b[2J"});
  EXPECT_EQ(u.code, 2);
  EXPECT_EQ(u.err.find('\x1b'), std::string::npos);
  EXPECT_THAT(u.err, HasSubstr("unknown option '--bogus?[2J'"));
}

}  // namespace
}  // namespace vsd_io_tool_test
