// The paper's 8-axis robot as URDF text: the iiwa14's fixed world joint made a prismatic linear axis.
// Shared by examples/robotics/eight_axis.cpp and the two-robot work cell (examples/workcell/two_robots).
#pragma once

#include <optional>
#include <string>

namespace vsd_example {

/// The URDF @p xml of the iiwa14 with its joint `world_iiwa_joint` turned into a linear axis along
/// @p axis (in the robot's base frame, text "x y z") limited to [@p lower, @p upper] m at 1 m/s; nullopt
/// when @p xml has no fixed joint of that name.
inline std::optional<std::string> eight_axis_urdf(std::string xml, const std::string& axis = "0.6 0.8 0",
                                                  double lower = -2, double upper = 3) {
  const std::string fixed = R"(<joint name="world_iiwa_joint" type="fixed">)";
  const auto at = xml.find(fixed);
  if (at == std::string::npos) return std::nullopt;
  xml.replace(at, fixed.size(),
              R"(<joint name="world_iiwa_joint" type="prismatic">
    <axis xyz=")" +
                  axis + R"("/><limit lower=")" + std::to_string(lower) + R"(" upper=")" +
                  std::to_string(upper) + R"(" effort="1000" velocity="1"/>)");
  return xml;
}

}  // namespace vsd_example
