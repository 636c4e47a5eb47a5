// vsd-dist, run in-process: its usage errors (no DDS is touched before the arguments are right).
// (Serving and watching a domain drive the executables: tests/tools/CMakeLists.txt.)
#include "vsd-dist/tool.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tool_run.hpp"

namespace vsd_dist_tool_test {
namespace {

using testing::HasSubstr;
using vsd_tool_test::ToolRun;

ToolRun run(const std::vector<std::string>& args) { return vsd_tool_test::run_tool(vsd::tool::vsd_dist::run, args); }

TEST(VsdDist, DomainAndDurationAreStrict) {
  const ToolRun abc = run({"watch", "--domain", "abc"});
  EXPECT_EQ(abc.code, 2);
  EXPECT_THAT(abc.err, HasSubstr("--domain: 'abc' is not an integer"));
  const ToolRun huge = run({"watch", "--domain", "99999999999"});
  EXPECT_EQ(huge.code, 2);
  EXPECT_THAT(huge.err, HasSubstr("--domain: '99999999999' is out of range (0 to 230)"));
  EXPECT_EQ(run({"watch", "--domain", "231"}).code, 2);
  EXPECT_EQ(run({"watch", "--domain", "-1"}).code, 2);
  EXPECT_EQ(run({"watch", "--domain", ""}).code, 2);
  const ToolRun for_abc = run({"watch", "--domain", "7", "--for", "abc"});
  EXPECT_EQ(for_abc.code, 2);
  EXPECT_THAT(for_abc.err, HasSubstr("--for: 'abc' is not a number"));
  EXPECT_EQ(run({"watch", "--domain", "7", "--for", "-1"}).code, 2);
  EXPECT_EQ(run({"watch", "--domain", "7", "--for", "inf"}).code, 2);
  EXPECT_EQ(run({"watch"}).code, 2);  // --domain is required
  EXPECT_EQ(run({"serve", "--domain", "7"}).code, 2);  // serve needs a FILE
  EXPECT_EQ(run({"watch", "x.json", "--domain", "7"}).code, 2);
  EXPECT_EQ(run({"frob"}).code, 2);
  EXPECT_EQ(run({}).code, 2);
  EXPECT_EQ(run({"--help"}).code, 0);
}

TEST(VsdDist, AFileThatCannotBeServedIsAFailure) {
  const ToolRun dir = run({"serve", "/tmp", "--domain", "7", "--for", "0"});
  EXPECT_EQ(dir.code, 1);
  EXPECT_THAT(dir.err, HasSubstr("/tmp: is a directory"));
}

}  // namespace
}  // namespace vsd_dist_tool_test
