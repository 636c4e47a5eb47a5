/** @file
 *  @brief vsd-physics: simulate a URDF or a saved scene and print the final poses (`vsd-physics --help`).
 *
 *  `vsd-physics FILE [--steps N] [--dt SECONDS] [--package-path DIR]... [--free-base]` loads a URDF
 *  (.urdf, .xml, or XML on a pipe; made dynamic with make_dynamic()) or a saved scene (.json / .vsds
 *  through vsd::io; a World is added on the Database when it has none), simulates N scheduler steps of dt
 *  seconds and prints the final pose and speed of every body. --steps is 1 to 10^8, --dt 10^-6 to 1 s, and
 *  a run of more than 10^7 steps of one world is refused before it starts; a simulation that diverges
 *  (a pose that is no longer finite) is an error. Exit codes: 0 simulated, 1 the file could not be loaded
 *  or simulated, 2 a usage error.
 */
#pragma once

#include <iosfwd>
#include <span>
#include <string_view>

namespace vsd::tool::vsd_physics {

/// @brief Runs vsd-physics with @p args (without the program name), printing to @p out and @p err.
/// @return the exit code.
int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);

}  // namespace vsd::tool::vsd_physics
