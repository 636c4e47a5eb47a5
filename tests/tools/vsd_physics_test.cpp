// vsd-physics, run in-process: a saved scene simulated, its errors, and the bounds of --steps and --dt.
#include "vsd-physics/tool.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "../physics/fixture.hpp"
#include "tool_run.hpp"
#include "vsd/io/snapshot.hpp"

namespace vsd_physics_tool_test {
namespace {

using testing::HasSubstr;
using vsd::physics::RigidBody;
using vsd::physics::test::at;
using vsd::scene::GeometryKind;
using vsd_tool_test::TempDir;
using vsd_tool_test::ToolRun;

ToolRun run(const std::vector<std::string>& args) { return vsd_tool_test::run_tool(vsd::tool::vsd_physics::run, args); }

const std::string iiwa = std::string(VSD_TOOLS_SCENE_DATA_DIR) + "/iiwa14.urdf";

class VsdPhysics : public vsd::physics::test::PhysicsTest {
 protected:
  TempDir tmp{"vsd_physics_tool"};
};

TEST_F(VsdPhysics, SimulatesASavedSceneAndReportsErrors) {
  auto& box = hull(geometry(GeometryKind::Box, Eigen::Vector3d(0.2, 0.2, 0.2)), at(1, 2, 3), nullptr, nullptr, "crate");
  body(box);
  ground();
  const std::string path = tmp.path("scene.json");
  vsd::io::save(s, path, vsd::io::Format::Text);
  const ToolRun r = run({path, "--steps", "2000", "--dt", "0.001"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("simulated 2 s (2000 steps of 0.001 s): 1 bodies"));
  EXPECT_THAT(r.out, HasSubstr("/scene/crate: position 1.000000 2.000000 0.09"));  // resting on the ground
  // A body without mass in the file: the error, exit code 1.
  auto& n = s.create<vsd::scene::Node3D>();
  n.set_name("ghost");
  scene_root().add_child(n);
  n.add_extension(s.create<RigidBody>());
  vsd::io::save(s, path, vsd::io::Format::Text);
  const ToolRun ghost = run({path, "--steps", "2000", "--dt", "0.001"});
  EXPECT_EQ(ghost.code, 1);
  EXPECT_THAT(ghost.err, HasSubstr("/scene/ghost"));
  EXPECT_EQ(run({"--steps", "x"}).code, 2);
}

TEST_F(VsdPhysics, StepsAndDtAreBounded) {
  for (const char* dt : {"0", "-1", "abc", "1e6", "1e17", "inf", "nan", "2", "1e-7", "0.001x", " 0.001"}) {
    const ToolRun r = run({iiwa, "--dt", dt});
    EXPECT_EQ(r.code, 2) << dt << ": " << r.out << r.err;
    EXPECT_THAT(r.err, HasSubstr("--dt")) << dt;
  }
  EXPECT_THAT(run({iiwa, "--dt", "1e6"}).err, HasSubstr("out of range (1e-06 to 1)"));
  for (const char* steps : {"0", "-3", "1.5", "1e3", "100000001", "99999999999999999999"}) {
    const ToolRun r = run({iiwa, "--steps", steps});
    EXPECT_EQ(r.code, 2) << steps << ": " << r.out << r.err;
  }
  // Within the bounds but too much work for the world's 1 ms step: refused before it starts.
  const ToolRun r = run({iiwa, "--steps", "100000000", "--dt", "1"});
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_THAT(r.err, HasSubstr("would take 100000000000 steps of 0.001 s"));
  EXPECT_THAT(r.out, testing::Not(HasSubstr("simulated")));
}

TEST_F(VsdPhysics, DtAtItsBoundSimulatesWhatItSays) {
  const ToolRun r = run({iiwa, "--steps", "2", "--dt", "1"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("simulated 2 s (2 steps of 1 s)"));
  EXPECT_THAT(r.out, HasSubstr("2000 ODE steps"));
}

}  // namespace
}  // namespace vsd_physics_tool_test
