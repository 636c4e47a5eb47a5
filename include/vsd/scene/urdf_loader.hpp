/** @file
 *  @brief Loading a URDF robot description into a Scene: links become Link nodes (mass, inertia) whose
 *  children are the child links (frame = joint origin) and their visual and collision Hulls (frame =
 *  the element's origin); joints, materials and geometry become database objects held by the Scene.
 *
 *  Mesh URIs are resolved through a search path: "package://pkg/rest" is looked up as <dir>/pkg/rest for
 *  every package path (and as <dir>/rest when <dir> is itself named pkg), "file://" URIs and absolute
 *  paths as they are, other relative paths against the URDF's directory. What cannot be used — a mesh that
 *  is missing or unreadable, an element urdfdom does not read (<transmission>, <gazebo>, ...) — is a
 *  warning naming the element; loading goes on. A hull whose mesh is missing keeps its Geometry (kind
 *  Mesh, source set, no vertices), so the reference survives a later fix of the search path.
 */
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/core/node.hpp"
#include "vsd/scene/fwd.hpp"

namespace vsd::scene {

/// @brief How to load a URDF.
struct UrdfOptions {
  /// Directories searched for package:// URIs (a package "pkg" is <dir>/pkg or <dir> named pkg).
  std::vector<std::filesystem::path> package_paths;
  /// Read mesh files (false: geometry keeps its source only).
  bool load_meshes = true;
};

/// @brief What a load made and what it warned about.
struct SceneReport {
  Scene* scene = nullptr;
  std::size_t links = 0;
  std::size_t joints = 0;
  std::size_t hulls = 0;
  /// Mesh files read (each file once; hulls using the same file share its Geometry).
  std::size_t meshes_loaded = 0;
  /// Everything that was not used as written, each naming the element ("link 'base' visual: ...").
  std::vector<std::string> warnings;
};

/// @brief Loads URDF file @p file as a new Scene under @p parent.
/// @throws vsd::Error naming the file when it cannot be read or is not a valid URDF (urdfdom's own messages
/// included); nothing is created then.
SceneReport load_urdf(vsd::Node& parent, const std::filesystem::path& file, const UrdfOptions& options = {});

/// @brief Loads URDF text @p xml as a new Scene under @p parent; relative mesh paths are resolved against
/// @p base_dir, and errors name @p origin.
/// @throws vsd::Error as load_urdf() does.
SceneReport load_urdf_text(vsd::Node& parent, std::string_view xml, std::string_view origin,
                           const std::filesystem::path& base_dir, const UrdfOptions& options = {});

/// @brief Where mesh URI @p uri is found: the first existing candidate, or an empty path.
/// @param searched receives the candidates that were tried (for a warning), when not null.
std::filesystem::path resolve_mesh_uri(std::string_view uri, const std::filesystem::path& base_dir,
                                       const std::vector<std::filesystem::path>& package_paths,
                                       std::vector<std::filesystem::path>* searched = nullptr);

}  // namespace vsd::scene
