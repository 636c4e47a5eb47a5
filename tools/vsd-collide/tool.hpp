/** @file
 *  @brief vsd-collide: contacts and distances between the hulls of a URDF or a saved scene
 *  (`vsd-collide --help`).
 *
 *  `vsd-collide FILE [--package-path DIR]... [--no-meshes] [--visual] [--same-link] [--distances]`
 *  loads a URDF (.urdf, .xml, or XML on a pipe) or a scene saved by vsd::io (.json, .vsds), builds a
 *  CollisionWorld over its hulls and prints the pairs in contact (points, depth, normal), and with
 *  --distances the distance between every pair of hulls. Hulls left out (degenerate geometry, a mesh that
 *  was not found) are listed as warnings. FILE may be "-" (standard input). Exit codes: 0 done, 1 the file
 *  could not be loaded, 2 a usage error.
 */
#pragma once

#include <iosfwd>
#include <span>
#include <string_view>

namespace vsd::tool::vsd_collide {

/// @brief Runs vsd-collide with @p args (without the program name), printing to @p out and @p err.
/// @return the exit code.
int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);

}  // namespace vsd::tool::vsd_collide
