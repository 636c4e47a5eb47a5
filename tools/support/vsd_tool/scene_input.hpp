/** @file
 *  @brief The input of the scene tools (vsd-scene, vsd-collide, vsd-physics, vsd-robot): a URDF or a saved
 *  scene, from a file, a pipe or standard input.
 */
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/core/fwd.hpp"
#include "vsd/io/snapshot.hpp"
#include "vsd/scene/urdf_loader.hpp"

namespace vsd::tool {

/// @brief What load_scene_input() loaded.
struct SceneInput {
  std::optional<scene::SceneReport> urdf;  ///< set when the input was a URDF
  std::optional<io::LoadReport> saved;     ///< set when it was a saved state (vsd-text or VSDS)
  std::vector<std::string> warnings;       ///< the load's warnings, either way
};

/// @brief Loads @p path ("-": standard input) into @p state: a URDF (a name ending in .urdf or .xml, or
/// content that starts with '<') as a new Scene under the Database, anything else as a saved state
/// through load_vsd() (@p state must be empty then). Relative mesh paths of a URDF are resolved against
/// its folder (the current one for standard input). @throws vsd::Error naming the input.
SceneInput load_scene_input(SimState& state, std::string_view path, const scene::UrdfOptions& options);

/// @brief Loads @p path ("-": standard input) as a URDF, whatever its name, as a new Scene under the
/// Database of @p state. @throws vsd::Error naming the input.
scene::SceneReport load_urdf_input(SimState& state, std::string_view path, const scene::UrdfOptions& options);

}  // namespace vsd::tool
