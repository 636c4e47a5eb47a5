/** @file
 *  @brief Loading a URDF robot description into a Scene: links become Link nodes (mass, inertia) whose
 *  children are the child links (frame = joint origin) and their visual and collision Hulls (frame =
 *  the element's origin); joints, materials and geometry become database objects held by the Scene.
 *
 *  The text is checked before urdfdom parses it (its XML parser recurses once per nesting level): at most
 *  max_urdf_bytes bytes, elements nested at most max_urdf_depth deep, at most max_urdf_elements of them —
 *  limits no real robot description comes near; beyond them the load is an error naming line and column.
 *  After parsing, the values are validated (see docs/design.md, "URDF validation"): what no body or joint
 *  can have (a negative mass or moment of inertia, a lower limit above the upper, a mimic cycle, a zero
 *  joint axis, a negative size or radius) is an error naming the link or joint and the field; what is
 *  legal but cannot be simulated as written (inertia not positive definite, a zero size) is a warning.
 *
 *  Mesh URIs: "package://pkg/rest" is looked up as <dir>/pkg/rest for every package path (and as
 *  <dir>/rest when <dir> is itself named pkg), "file://" URIs and absolute paths as they are, other
 *  relative paths against the URDF's directory. Whatever the form, the file must lie (after `..` and
 *  symbolic links are resolved) inside the URDF's directory or a package path and be a regular file,
 *  unless UrdfOptions::allow_paths_outside; the same holds for every file a mesh pulls in (an OBJ's
 *  material library). Other URI schemes (http://, ...) are not read. What cannot be used — a mesh that
 *  is missing, refused or unreadable, an element urdfdom does not read (<transmission>, <gazebo>, ...) —
 *  is a warning naming the element; loading goes on. A hull whose mesh is missing keeps its Geometry
 *  (kind Mesh, source set, no vertices), so the reference survives a later fix of the search path.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/core/node.hpp"
#include "vsd/scene/fwd.hpp"
#include "vsd/scene/mesh_loader.hpp"

namespace vsd::scene {

/// Size limit of a URDF text (64 MiB).
inline constexpr std::size_t max_urdf_bytes = std::size_t{64} << 20;
/// Nesting limit of a URDF's XML elements (a URDF needs about 5 levels).
inline constexpr std::size_t max_urdf_depth = 1000;
/// Element limit of a URDF (a robot of 10,000 links has about 100,000).
inline constexpr std::size_t max_urdf_elements = 1'000'000;

/// @brief How to load a URDF.
struct UrdfOptions {
  /// Directories searched for package:// URIs (a package "pkg" is <dir>/pkg or <dir> named pkg).
  std::vector<std::filesystem::path> package_paths;
  /// Read mesh files (false: geometry keeps its source only).
  bool load_meshes = true;
  /// True: mesh references (and files meshes pull in) may lead outside the URDF's directory and the
  /// package paths — absolute paths, file:// URIs, `..` out of the folder, symbolic links out of it.
  /// They must still be regular files. Leave false for models from untrusted sources.
  bool allow_paths_outside = false;
  /// Size limit of every mesh file read.
  std::uintmax_t max_mesh_bytes = default_max_mesh_bytes;
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

/// @brief Loads URDF file @p file ("-": standard input; pipes work too) as a new Scene under @p parent.
/// Relative mesh paths are resolved against the file's directory (the current directory for "-").
/// @throws vsd::Error naming the file when it is a directory, cannot be read, exceeds the limits above,
/// is not a valid URDF (urdfdom's own messages included) or holds invalid values (each named); nothing is
/// created then.
SceneReport load_urdf(vsd::Node& parent, const std::filesystem::path& file, const UrdfOptions& options = {});

/// @brief Loads URDF text @p xml as a new Scene under @p parent; relative mesh paths are resolved against
/// @p base_dir, and errors name @p origin.
/// @throws vsd::Error as load_urdf() does.
SceneReport load_urdf_text(vsd::Node& parent, std::string_view xml, std::string_view origin,
                           const std::filesystem::path& base_dir, const UrdfOptions& options = {});

/// @brief Where a mesh URI leads.
struct MeshUriResolution {
  /// The file to read (canonical), or empty.
  std::filesystem::path file;
  /// The candidates that were tried (for a warning), when none was found.
  std::vector<std::filesystem::path> searched;
  /// Why the reference is not followed although it may exist: outside the allowed folders, not a regular
  /// file, an unsupported URI scheme. Empty when the file was found or simply does not exist.
  std::string refused;
};

/// @brief Resolves mesh URI @p uri of a URDF in @p base_dir under the rules of the file comment, with
/// @p options' package paths and allow_paths_outside.
MeshUriResolution resolve_mesh_uri(std::string_view uri, const std::filesystem::path& base_dir,
                                   const UrdfOptions& options);

}  // namespace vsd::scene
