// vsd-soml, run in-process: scripts that need their C++ host, atomic conversion, standard input,
// directories and bad numbers. (The run and debugger goldens drive the executable: tests/tools/CMakeLists.txt.)
#include "vsd-soml/tool.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "tool_run.hpp"
#include "vsd/soml/source.hpp"

namespace vsd_soml_tool_test {
namespace {

using testing::HasSubstr;
using vsd_tool_test::TempDir;
using vsd_tool_test::ToolRun;

int entry(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  std::istringstream no_commands;
  return vsd::tool::vsd_soml::run(args, no_commands, out, err);
}

ToolRun run(const std::vector<std::string>& args) { return vsd_tool_test::run_tool(entry, args); }

const std::string nets = VSD_TOOLS_ANALYSIS_DATA_DIR;
const std::string examples = VSD_TOOLS_EXAMPLES_DIR;

TEST(VsdSoml, AScriptOfCppClassesSaysItNeedsItsHost) {
  const ToolRun r = run({"run", examples + "/soml/supervisor.soml"});
  EXPECT_EQ(r.code, 1);
  EXPECT_THAT(r.err, HasSubstr("undefined class 'Tank'"));
  EXPECT_THAT(r.err, HasSubstr("note: vsd-soml knows vsd's own classes, not Tank: a script that uses the C++ "
                               "classes of its program runs in that program"));
  EXPECT_THAT(r.err, HasSubstr("examples/soml/supervisor.cpp"));
  // vsd's own module classes are known (a script may use the scene's).
  const TempDir tmp("vsd_soml_scene");
  const ToolRun scene = run({"run", tmp.write("s.soml", "shared<scene::Node3D> n;\nplace p = 1;\n")});
  EXPECT_EQ(scene.code, 0) << scene.err;
}

TEST(VsdSoml, ConvertWritesAtomically) {
  const TempDir tmp("vsd_soml_convert");
  const std::string out = tmp.write("net.soml", "old\n");
  ToolRun r;
  {
    const vsd_tool_test::FileSizeLimit full(64);
    r = run({"convert", nets + "/Philosophers-PT-000005.pnml", out});
  }
  EXPECT_EQ(r.code, 1);
  EXPECT_THAT(r.err, HasSubstr("net.soml"));
  EXPECT_EQ(TempDir::read(out), "old\n") << "a failed write leaves the old file whole";
  r = run({"convert", nets + "/Philosophers-PT-000005.pnml", out});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(TempDir::read(out), HasSubstr("place"));
  // To standard output.
  r = run({"convert", out, "-"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("place"));
}

TEST(VsdSoml, StandardInputAndDirectories) {
  const std::string pnml = TempDir::read(nets + "/Philosophers-PT-000005.pnml");
  const ToolRun r = vsd_tool_test::run_tool_with_stdin(entry, {"analyze", "-", "--json"}, pnml);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("\"states\": 243"));
  const ToolRun script = vsd_tool_test::run_tool_with_stdin(entry, {"run", "-", "--steps", "1"},
                                                             "place a = 1;\nplace b;\ntransition t;\narrow a -> t;\narrow t -> b;\n");
  EXPECT_EQ(script.code, 0) << script.err;
  EXPECT_THAT(script.out, HasSubstr("1 firing"));
  for (const char* cmd : {"analyze", "run", "convert"}) {
    std::vector<std::string> args{cmd, nets};
    if (std::string(cmd) == "convert") args.push_back("/tmp/never-written.soml");
    const ToolRun d = run(args);
    EXPECT_EQ(d.code, 1) << cmd;
    EXPECT_THAT(d.err, HasSubstr("analysis/data: is a directory")) << cmd;
  }
  EXPECT_EQ(run({"debug", "-"}).code, 2);  // debug reads its commands there
}

TEST(VsdSoml, NumbersAreStrict) {
  const std::string net = nets + "/Philosophers-PT-000005.pnml";
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"run", net, "--steps", "x"}, {"run", net, "--steps", "-1"},
        {"run", net, "--seed", "1.5"}, {"run", net, "--steps", "99999999999999999999999"},
        {"analyze", net, "--threads", "abc"}, {"analyze", net, "--threads", "2000"},
        {"analyze", net, "--limit-mem", "lots"}, {"debug", net, "--steps", "1e3"}}) {
    const ToolRun r = run(bad);
    EXPECT_EQ(r.code, 2) << bad[2] << " " << bad[3];
    EXPECT_THAT(r.err, HasSubstr("Try 'vsd-soml --help'."));
  }
}

// compile: the C++ of a native library (one module per script; functions outside the native subset left
// out), -o required, a script with errors reported with its position; run --native refuses what is not a
// native library of the script.
TEST(VsdSoml, CompileWritesTheNativeLibrarySource) {
  const TempDir tmp("vsd_soml_compile");
  const std::string a = tmp.write("a.soml", "int twice(int n) { return 2 * n; }\nstring s() { return \"x\"; }\n");
  const std::string b = tmp.write("b.soml", "double half(double x) { return x / 2.0; }\n");
  const ToolRun r = run({"compile", a, b, "-o", tmp.dir().string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("soml_native.cpp"));
  const std::string src = TempDir::read(tmp.path("soml_native.cpp"));
  EXPECT_THAT(src, HasSubstr("#include \"vsd/soml/native_abi.hpp\""));
  EXPECT_THAT(src, HasSubstr("vsd_soml_native_modules"));
  EXPECT_THAT(src, HasSubstr("// twice\n"));
  EXPECT_THAT(src, HasSubstr("// half\n"));
  EXPECT_THAT(src, testing::Not(HasSubstr("// s\n")));  // a string: stays in the VM
  EXPECT_EQ(run({"compile", a}).code, 2);                 // no -o
  const std::string bad = tmp.write("bad.soml", "int f() { return x; }\n");
  const ToolRun e = run({"compile", bad, "-o", tmp.dir().string()});
  EXPECT_EQ(e.code, 1);
  EXPECT_THAT(e.err, HasSubstr("bad.soml:1:"));
  const ToolRun n = run({"run", a, "--native", a});
  EXPECT_EQ(n.code, 1);
  EXPECT_THAT(n.err, HasSubstr("cannot load the SOML++ native library"));
  const ToolRun nodir = run({"compile", a, "-o", tmp.path("missing")});
  EXPECT_EQ(nodir.code, 1);
  EXPECT_THAT(nodir.err, HasSubstr("missing: no such directory"));
  EXPECT_FALSE(std::filesystem::exists(tmp.path("missing")));
}

// A stream without end (/dev/zero) is read up to the limit of a script, not up to the tools' 4 GiB.
TEST(VsdSoml, AScriptIsReadUpToTheSourceLimit) {
  const TempDir tmp("vsd_soml_source_limit");
  for (const ToolRun& r : {run({"disasm", "/dev/zero"}), run({"compile", "/dev/zero", "-o", tmp.dir().string()})}) {
    EXPECT_EQ(r.code, 1);
    EXPECT_THAT(r.err, HasSubstr("/dev/zero: is larger than " + std::to_string(vsd::soml::max_source_bytes) +
                                     " bytes"));
  }
}

}  // namespace
}  // namespace vsd_soml_tool_test
