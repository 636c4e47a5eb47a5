/** @file
 *  @brief Reading triangle meshes (STL ASCII and binary, OBJ, COLLADA, PLY) into a Geometry, through assimp.
 *
 *  Mesh files come from users' models, so nothing reaches assimp unchecked: the format must be one of
 *  the four above (by extension; assimp's other importers are not exposed), the file must be a regular
 *  file no larger than MeshOptions::max_file_bytes, a COLLADA file (XML) may nest elements at most
 *  max_mesh_xml_depth deep and hold at most max_mesh_xml_elements elements (assimp's XML reader recurses
 *  per level: 100,000 levels crash it), its nodes must not instance themselves and its scene must expand
 *  to at most max_mesh_collada_nodes nodes and max_mesh_collada_values geometry values (assimp follows
 *  <instance_node> by recursion: a cycle crashes it, a chain of doublings never ends), and every further
 *  file the format pulls in (an OBJ's `mtllib`) goes through the same rules and must lie in
 *  MeshOptions::allowed_roots. A file refused there is not read; the mesh loads without it and the report
 *  says so.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "vsd/scene/geometry.hpp"

namespace vsd::scene {

/// Size limit of a mesh file (and of every file it pulls in) unless MeshOptions say otherwise: 128 MiB.
inline constexpr std::uintmax_t default_max_mesh_bytes = std::uintmax_t{128} << 20;
/// Nesting limit of a COLLADA (XML) mesh file.
inline constexpr std::size_t max_mesh_xml_depth = 1000;
/// Element limit of a COLLADA (XML) mesh file.
inline constexpr std::size_t max_mesh_xml_elements = 4'000'000;
/// Nodes a COLLADA scene may hold once every <instance_node> is expanded.
inline constexpr std::size_t max_mesh_collada_nodes = 100'000;
/// Geometry values (the counts of the <float_array>s of every geometry instance) a COLLADA scene may hold
/// once every instance is expanded.
inline constexpr std::size_t max_mesh_collada_values = 30'000'000;

/// @brief How to read a mesh file.
struct MeshOptions {
  /// Folders the mesh file and the files it pulls in (an OBJ's material library) must lie in, after `..`
  /// and symbolic links are resolved. Empty: the folder of the mesh file itself.
  std::vector<std::filesystem::path> allowed_roots;
  /// True: files may lie anywhere (they must still be regular files within the size limit).
  bool allow_paths_outside = false;
  /// Size limit of every file read.
  std::uintmax_t max_file_bytes = default_max_mesh_bytes;
};

/// @brief What load_mesh() could not use: files the mesh pulls in that were refused or unreadable.
struct MeshReport {
  std::vector<std::string> warnings;
};

/// @brief Reads the mesh file @p path into @p geometry: kind Mesh, vertices (identical positions
/// joined), per-vertex normals, triangle facets and texture coordinates (when the file has them). All
/// meshes of the file are merged with their node transforms applied. Other properties (source, scale,
/// name) are left as they are. Sets the properties through their setters (recorded and signalled).
/// @throws vsd::Error naming the file when it is refused (format, size, nesting, outside the allowed
/// folders, not a regular file), cannot be read, or holds no triangles; @p geometry is unchanged then.
MeshReport load_mesh(Geometry& geometry, const std::filesystem::path& path, const MeshOptions& options = {});

}  // namespace vsd::scene
