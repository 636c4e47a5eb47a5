/** @file
 *  @brief vsd-scene: load a URDF or a saved scene and print its tree (`vsd-scene --help`).
 *
 *  `vsd-scene FILE [--package-path DIR]... [--no-meshes] [--json]` loads a URDF (.urdf, .xml, or XML on a
 *  pipe) or a saved scene (.json / .vsds through vsd::io) and prints its tree — links with masses, joints
 *  with types and limits, hulls with their geometry — and the warnings of the load. --json prints the
 *  loaded state as a vsd-text file instead. FILE may be "-" (standard input). Exit codes: 0 loaded, 1 the
 *  file could not be loaded, 2 a usage error.
 */
#pragma once

#include <iosfwd>
#include <span>
#include <string_view>

namespace vsd::tool::vsd_scene {

/// @brief Runs vsd-scene with @p args (without the program name), printing to @p out and @p err.
/// @return the exit code.
int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);

}  // namespace vsd::tool::vsd_scene
