/** @file
 *  @brief The vsd-scene command-line tool as a library function (the executable is a thin main).
 *
 *  `vsd-scene FILE [--package-path DIR]... [--json]` loads a URDF (.urdf, .xml) or a saved scene
 *  (.json / .vsds through vsd::io) and prints its tree — links with masses, joints with types and limits,
 *  hulls with their geometry — and the warnings of the load. --json prints the loaded scene as a
 *  vsd-text file instead. Exit codes: 0 loaded, 1 the file could not be loaded, 2 usage error.
 */
#pragma once

#include <iosfwd>
#include <span>
#include <string_view>

#include "vsd/scene/fwd.hpp"

namespace vsd::scene {

/// @brief Runs the tool with @p args (without the program name), printing to @p out and @p err.
/// @return the exit code.
int run_tool(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);

/// @brief Prints the tree of @p scene: links, joints, hulls and geometry, masses.
void print_tree(const Scene& scene, std::ostream& out);

}  // namespace vsd::scene
