/** @file
 *  @brief Reading triangle meshes (STL ASCII and binary, OBJ, COLLADA and whatever else assimp reads)
 *  into a Geometry.
 */
#pragma once

#include <filesystem>

#include "vsd/scene/geometry.hpp"

namespace vsd::scene {

/// @brief Reads the mesh file @p path into @p geometry: kind Mesh, vertices (identical positions
/// joined), per-vertex normals, triangle facets and texture coordinates (when the file has them). All
/// meshes of the file are merged with their node transforms applied. Other properties (source, scale,
/// name) are left as they are. Sets the properties through their setters (recorded and signalled).
/// @throws vsd::Error naming the file when it cannot be read or holds no triangles; @p geometry is
/// unchanged then.
void load_mesh(Geometry& geometry, const std::filesystem::path& path);

}  // namespace vsd::scene
