// vsd-robot, run in-process: chain, fk, jacobian and ik output, its errors, and hostile input (names that
// need escaping in JSON, results that are not finite, failed IK).
#include "vsd-robot/tool.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "tool_run.hpp"

namespace vsd_robot_tool_test {
namespace {

using vsd_tool_test::TempDir;
using vsd_tool_test::ToolRun;

ToolRun run(const std::vector<std::string>& args) { return vsd_tool_test::run_tool(vsd::tool::vsd_robot::run, args); }

std::string robot_file(const std::string& name) { return std::string(VSD_TOOLS_SCENE_DATA_DIR) + "/" + name; }

const std::string iiwa = robot_file("iiwa14.urdf");
const std::string ur5 = robot_file("ur5_robot.urdf");

TEST(VsdRobot, Chain) {
  const ToolRun r = run({"chain", ur5, "--base", "base_link", "--tip", "tool0"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("chain base_link -> tool0: 6 joint values"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 shoulder_pan_joint rotary [-6.28"), std::string::npos) << r.out;
  const ToolRun j = run({"chain", ur5, "--base", "base_link", "--tip", "tool0", "--json"});
  EXPECT_NE(j.out.find("{\"name\": \"shoulder_pan_joint\", \"type\": \"rotary\", \"lower\": -6.28"),
            std::string::npos)
      << j.out;
}

TEST(VsdRobot, ForwardKinematicsIsJsonWithNonNegativeW) {
  // UR5 at zero: tool0 at (0.81725, 0.19145, -0.005491) in base_link... whatever the numbers, w >= 0 and
  // the position agrees with a rotation of 180 degrees of the first joint mirrored in x and y.
  const ToolRun a = run({"fk", ur5, "--base", "base_link", "--tip", "tool0", "--q", "0,0,0,0,0,0"});
  const ToolRun b =
      run({"fk", ur5, "--base", "base_link", "--tip", "tool0", "--q", "3.141592653589793,0,0,0,0,0"});
  ASSERT_EQ(a.code, 0) << a.err;
  ASSERT_EQ(b.code, 0) << b.err;
  double ax, ay, az, bx, by, bz, qx, qy, qz, qw;
  ASSERT_EQ(
      std::sscanf(a.out.c_str(), "{\"position\": [%lf, %lf, %lf], \"quaternion\": [%lf, %lf, %lf, %lf]}", &ax,
                  &ay, &az, &qx, &qy, &qz, &qw),
      7)
      << a.out;
  EXPECT_GE(qw, 0.0);
  EXPECT_NEAR(qx * qx + qy * qy + qz * qz + qw * qw, 1.0, 1e-12);
  ASSERT_EQ(
      std::sscanf(b.out.c_str(), "{\"position\": [%lf, %lf, %lf], \"quaternion\": [%lf, %lf, %lf, %lf]}", &bx,
                  &by, &bz, &qx, &qy, &qz, &qw),
      7)
      << b.out;
  EXPECT_GE(qw, 0.0);
  EXPECT_NEAR(bx, -ax, 1e-12);
  EXPECT_NEAR(by, -ay, 1e-12);
  EXPECT_NEAR(bz, az, 1e-12);
  EXPECT_NEAR(std::hypot(ax, ay), 0.81725 * 0 + std::hypot(0.81725, 0.19145), 1e-9);
}

TEST(VsdRobot, Jacobian) {
  const ToolRun r =
      run({"jacobian", iiwa, "--base", "iiwa_link_0", "--tip", "iiwa_link_ee", "--q", "0,0,0,0,0,0,0"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("{\"jacobian\": [[", 0), 0u) << r.out;
  // Upright at zero: the first joint turns about z (angular row 6 of column 1 is 1) and moves nothing.
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '['), 7);
  double first[7];
  ASSERT_EQ(std::sscanf(r.out.c_str(), "{\"jacobian\": [[%lf, %lf, %lf, %lf, %lf, %lf, %lf]", &first[0],
                        &first[1], &first[2], &first[3], &first[4], &first[5], &first[6]),
            7);
  EXPECT_NEAR(first[0], 0.0, 1e-9);
  EXPECT_NEAR(first[1], 1.306 - 0.36, 1e-9);  // x velocity of joint 2 (at 0.36 m): lever 0.946 m
}

TEST(VsdRobot, InverseKinematics) {
  const ToolRun r = run({"ik", iiwa, "--base", "iiwa_link_0", "--tip", "iiwa_link_ee", "--target",
                         "0.4,0.1,0.7,0,1,0,0", "--seed", "0,0.5,0,-1,0,0.5,0"});
  EXPECT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_EQ(r.out.rfind("{\"success\": true, \"q\": [", 0), 0u) << r.out;
  const ToolRun far = run({"ik", iiwa, "--base", "iiwa_link_0", "--tip", "iiwa_link_ee", "--target",
                           "4,0,0,0,0,0,1", "--timeout", "0.01"});
  EXPECT_EQ(far.code, 1);
  EXPECT_NE(far.out.find("\"success\": false"), std::string::npos) << far.out;
  EXPECT_NE(far.err.find("no solution"), std::string::npos) << far.err;
}

TEST(VsdRobot, Errors) {
  ToolRun r = run({"fk", iiwa, "--base", "iiwa_link_0", "--tip", "iiwa_link_ee", "--q", "0,0,0"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--q has 3 values; the chain iiwa_link_0 -> iiwa_link_ee has 7"), std::string::npos)
      << r.err;
  r = run({"fk", iiwa, "--base", "iiwa_link_0", "--tip", "iiwa_link_ee", "--q", "0,0,x,0,0,0,0"});
  EXPECT_EQ(r.code, 2);  // a malformed number is a usage error
  EXPECT_NE(r.err.find("'x' is not a number"), std::string::npos) << r.err;
  r = run({"chain", iiwa, "--base", "iiwa_link_0", "--tip", "nowhere"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("unknown link 'nowhere'"), std::string::npos) << r.err;
  r = run({"chain", iiwa, "--base", "iiwa_link_5", "--tip", "iiwa_link_2"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("is not below"), std::string::npos) << r.err;
  r = run({"chain", robot_file("README.md"), "--base", "a", "--tip", "b"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("README.md"), std::string::npos) << r.err;
  r = run({"chain", "/no/such/robot.urdf", "--base", "a", "--tip", "b"});
  EXPECT_EQ(r.code, 1);
  r = run({"ik", iiwa, "--base", "iiwa_link_0", "--tip", "iiwa_link_ee", "--target", "0,0,1,0,0,0,2"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("unit quaternion"), std::string::npos) << r.err;
  r = run({"frob"});
  EXPECT_EQ(r.code, 2);
  r = run({"fk", iiwa, "--base", "iiwa_link_0", "--tip", "iiwa_link_ee"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("fk needs --q"), std::string::npos);
  r = run({});
  EXPECT_EQ(r.code, 2);
  r = run({"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("Usage:"), std::string::npos);
}

// A URDF whose names need escaping in JSON: quotes, backslashes, control characters, non-ASCII.
const std::string evil_urdf = R"(<robot name="evil">
  <link name="base&quot;\"/>
  <link name="tip&#9;&#1;é"/>
  <joint name="j&quot;1\&#10;ü" type="prismatic">
    <parent link="base&quot;\"/><child link="tip&#9;&#1;é"/>
    <origin xyz="1e308 0 0"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>
)";

// Checks that @p text is one JSON value with a tiny validator (strings with escapes, numbers, literals).
bool valid_json(const std::string& text) {
  std::size_t i = 0;
  auto ws = [&] {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\n' || text[i] == '\t' || text[i] == '\r')) ++i;
  };
  std::function<bool()> value = [&]() -> bool {
    ws();
    if (i >= text.size()) return false;
    const char c = text[i];
    if (c == '"') {
      for (++i; i < text.size() && text[i] != '"'; ++i) {
        if (static_cast<unsigned char>(text[i]) < 0x20) return false;
        if (text[i] == '\\') {
          ++i;
          if (i >= text.size() || std::string("\"\\/bfnrtu").find(text[i]) == std::string::npos) return false;
        }
      }
      return i++ < text.size();
    }
    if (c == '{' || c == '[') {
      const char close = c == '{' ? '}' : ']';
      ++i;
      ws();
      if (i < text.size() && text[i] == close) return ++i, true;
      for (;;) {
        if (c == '{') {
          if (!value()) return false;
          ws();
          if (i >= text.size() || text[i++] != ':') return false;
        }
        if (!value()) return false;
        ws();
        if (i < text.size() && text[i] == ',') {
          ++i;
          continue;
        }
        return i < text.size() && text[i++] == close;
      }
    }
    const std::size_t start = i;
    while (i < text.size() && std::string("+-0123456789.eEtruefalsn").find(text[i]) != std::string::npos) ++i;
    const std::string word = text.substr(start, i - start);
    if (word == "true" || word == "false" || word == "null") return true;
    char* end = nullptr;
    std::strtod(word.c_str(), &end);
    return !word.empty() && end == word.c_str() + word.size() && word.find_first_of("in") == std::string::npos;
  };
  if (!value()) return false;
  ws();
  return i == text.size();
}

TEST(VsdRobot, ChainJsonEscapesEveryName) {
  const TempDir tmp("vsd_robot_evil");
  const std::string file = tmp.write("evil.urdf", evil_urdf);
  const ToolRun r = run({"chain", file, "--base", "base\"\\", "--tip", "tip\t\x01é", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(valid_json(r.out)) << r.out;
  EXPECT_NE(r.out.find(R"("base": "base\"\\")"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(R"("tip": "tip\t\u0001é")"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(R"("name": "j\"1\\\nü")"), std::string::npos) << r.out;
  // The text form shows control characters as '?'.
  const ToolRun text = run({"chain", file, "--base", "base\"\\", "--tip", "tip\t\x01é"});
  EXPECT_NE(text.out.find("1 j\"1\\?ü prismatic"), std::string::npos) << text.out;
}

TEST(VsdRobot, ForwardKinematicsNeverPrintsNonFiniteNumbers) {
  const TempDir tmp("vsd_robot_inf");
  const std::string file = tmp.write("evil.urdf", evil_urdf);
  // The joint sits 1e308 m out: a finite joint value that takes it past the largest double overflows the
  // pose. An error, not [inf, inf, inf].
  const ToolRun r = run({"fk", file, "--base", "base\"\\", "--tip", "tip\t\x01é", "--q", "1"});
  const ToolRun big = run({"fk", file, "--base", "base\"\\", "--tip", "tip\t\x01é", "--q", "1e308"});
  for (const ToolRun* x : {&r, &big}) {
    EXPECT_EQ(x->out.find("inf"), std::string::npos) << x->out;
    EXPECT_EQ(x->out.find("nan"), std::string::npos) << x->out;
  }
  EXPECT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_EQ(big.code, 1) << big.out;
  EXPECT_NE(big.err.find("is not finite"), std::string::npos) << big.err;
  // Non-numbers are usage errors.
  EXPECT_EQ(run({"fk", file, "--base", "base\"\\", "--tip", "tip\t\x01é", "--q", "inf"}).code, 2);
  EXPECT_EQ(run({"fk", file, "--base", "base\"\\", "--tip", "tip\t\x01é", "--q", "1e999"}).code, 2);
  EXPECT_EQ(run({"fk", file, "--base", "base\"\\", "--tip", "tip\t\x01é", "--q", "nan"}).code, 2);
}

TEST(VsdRobot, AChainWithoutJointsHasForwardKinematics) {
  const ToolRun r = run({"fk", iiwa, "--base", "iiwa_link_7", "--tip", "iiwa_link_ee", "--q", ""});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("{\"position\": [0, 0, 0.04", 0), 0u) << r.out;
  EXPECT_EQ(run({"fk", iiwa, "--base", "iiwa_link_7", "--tip", "iiwa_link_ee", "--q", "0"}).code, 1);
}

TEST(VsdRobot, FailedIkReportsTheErrorOfWhatItPrints) {
  const ToolRun far = run({"ik", iiwa, "--base", "iiwa_link_0", "--tip", "iiwa_link_ee", "--target",
                           "4,0,0,0,0,0,1", "--timeout", "0.01"});
  EXPECT_EQ(far.code, 1);
  double pe = 0;
  const std::size_t at = far.out.find("\"position_error\": ");
  ASSERT_NE(at, std::string::npos) << far.out;
  pe = std::strtod(far.out.c_str() + at + 18, nullptr);
  EXPECT_GT(pe, 2.0) << far.out;  // the arm reaches 1.3 m at most: the target is 2.7 m further
  EXPECT_EQ(run({"ik", iiwa, "--base", "iiwa_link_0", "--tip", "iiwa_link_ee", "--target", "4,0,0,0,0,0,1",
                 "--timeout", "1e9"})
                .code,
            2);  // --timeout is 0 to 60 s
}

TEST(VsdRobot, FloatingAndPlanarJointsAreReported) {
  const std::string urdf = R"(<robot name="f">
  <link name="a"/><link name="b"/>
  <joint name="float" type="floating"><parent link="a"/><child link="b"/></joint>
</robot>)";
  const TempDir tmp("vsd_robot_floating");
  const ToolRun r = run({"chain", tmp.write("f.urdf", urdf), "--base", "a", "--tip", "b"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("float"), std::string::npos) << r.err;
}

TEST(VsdRobot, ReadsStandardInput) {
  const ToolRun r = vsd_tool_test::run_tool_with_stdin(
      vsd::tool::vsd_robot::run, {"chain", "-", "--base", "iiwa_link_0", "--tip", "iiwa_link_ee"}, TempDir::read(iiwa));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("chain iiwa_link_0 -> iiwa_link_ee: 7 joint values"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace vsd_robot_tool_test
