// vsd-robot: chain, fk, jacobian and ik output, and its errors.
#include "vsd/robotics/tool.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace vsd::robotics {
namespace {

struct ToolRun {
  int code;
  std::string out, err;
};

ToolRun run(std::vector<std::string> args) {
  std::vector<std::string_view> v(args.begin(), args.end());
  std::ostringstream out, err;
  const int code = run_tool(v, out, err);
  return {code, out.str(), err.str()};
}

const std::string iiwa = vsd_test::robot_file("iiwa14.urdf");
const std::string ur5 = vsd_test::robot_file("ur5_robot.urdf");

TEST(RobotTool, Chain) {
  const ToolRun r = run({"chain", ur5, "--base", "base_link", "--tip", "tool0"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("chain base_link -> tool0: 6 joint values"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 shoulder_pan_joint rotary [-6.28"), std::string::npos) << r.out;
  const ToolRun j = run({"chain", ur5, "--base", "base_link", "--tip", "tool0", "--json"});
  EXPECT_NE(j.out.find("{\"name\": \"shoulder_pan_joint\", \"type\": \"rotary\", \"lower\": -6.28"),
            std::string::npos)
      << j.out;
}

TEST(RobotTool, ForwardKinematicsIsJsonWithNonNegativeW) {
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

TEST(RobotTool, Jacobian) {
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

TEST(RobotTool, InverseKinematics) {
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

TEST(RobotTool, Errors) {
  ToolRun r = run({"fk", iiwa, "--base", "iiwa_link_0", "--tip", "iiwa_link_ee", "--q", "0,0,0"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--q has 3 values; the chain iiwa_link_0 -> iiwa_link_ee has 7"), std::string::npos)
      << r.err;
  r = run({"fk", iiwa, "--base", "iiwa_link_0", "--tip", "iiwa_link_ee", "--q", "0,0,x,0,0,0,0"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("'x' is not a number"), std::string::npos) << r.err;
  r = run({"chain", iiwa, "--base", "iiwa_link_0", "--tip", "nowhere"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("unknown link 'nowhere'"), std::string::npos) << r.err;
  r = run({"chain", iiwa, "--base", "iiwa_link_5", "--tip", "iiwa_link_2"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("is not below"), std::string::npos) << r.err;
  r = run({"chain", vsd_test::robot_file("README.md"), "--base", "a", "--tip", "b"});
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

}  // namespace
}  // namespace vsd::robotics
