/** @file
 *  @brief vsd-robot: kinematics of a robot description (`vsd-robot --help`).
 *
 *  @code
 *  vsd-robot chain    ROBOT.urdf --base LINK --tip LINK [--json]
 *  vsd-robot fk       ROBOT.urdf --base LINK --tip LINK --q v1,v2,...
 *  vsd-robot jacobian ROBOT.urdf --base LINK --tip LINK --q v1,v2,...
 *  vsd-robot ik       ROBOT.urdf --base LINK --tip LINK --target x,y,z,qx,qy,qz,qw [--seed v1,...]
 *                     [--timeout SECONDS]
 *  @endcode
 *  Joint values are in the order `chain` prints (metres and radians; `--q ""` for a chain without joints).
 *  fk prints `{"position": [x, y, z], "quaternion": [x, y, z, w]}` (the tip in the base frame, w >= 0);
 *  jacobian `{"jacobian": [[...], ...]}` (6 rows, linear first, base frame); ik the joint values found with
 *  the position and orientation error of that solution. Output is valid JSON: names are escaped, and a
 *  result that is not finite is an error, never printed. ROBOT.urdf may be "-" (standard input).
 *  Exit codes: 0 done, 1 a bad file, an unknown link, a wrong number of values, a result that is not finite
 *  or no IK solution (with a message on the error stream), 2 a usage error (numbers included).
 */
#pragma once

#include <iosfwd>
#include <span>
#include <string_view>

namespace vsd::tool::vsd_robot {

/// @brief Runs vsd-robot with @p args (without the program name), printing to @p out and @p err.
/// @return the exit code.
int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);

}  // namespace vsd::tool::vsd_robot
