/** @file
 *  @brief The vsd-physics command-line tool as a library function (the executable is a thin main).
 *
 *  `vsd-physics FILE [--steps N] [--dt SECONDS] [--package-path DIR]... [--free-base]` loads a URDF
 *  (.urdf, .xml; made dynamic with make_dynamic()) or a saved scene (.json / .vsds through vsd::io; a
 *  World is added on the Database when it has none), simulates N scheduler steps of dt seconds and prints
 *  the final pose and speed of every body. Exit codes: 0 simulated, 1 the file could not be loaded or
 *  simulated (the vsd::Error is printed), 2 usage error.
 */
#pragma once

#include <iosfwd>
#include <span>
#include <string_view>

namespace vsd::physics {

/// @brief Runs the tool with @p args (without the program name), printing to @p out and @p err.
/// @return the exit code.
int run_tool(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);

}  // namespace vsd::physics
