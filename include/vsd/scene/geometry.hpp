/** @file
 *  @brief Geometry: a primitive (box, sphere, cylinder, capsule, plane) or a triangle mesh, shared by
 *  many hulls (Hull::geometry is a shared reference).
 */
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "vsd/core/meta_type_eigen.hpp"
#include "vsd/core/named_model_instance.hpp"
#include "vsd/scene/namespace.hpp"

namespace vsd::scene {

/// @brief What a Geometry is.
enum class GeometryKind : std::uint8_t {
  Mesh,      ///< vertices and triangle facets (scaled by `scale`)
  Box,       ///< `size` is the full extent along x, y, z, centred at the origin
  Sphere,    ///< `radius`
  Cylinder,  ///< `radius`, `length` along z, centred at the origin
  Capsule,   ///< a cylinder of `radius` and `length` (between the sphere centres) capped by half spheres
  Plane      ///< the plane through the origin with normal `normal` (unbounded)
};
VSD_ENUM(GeometryKind, Mesh, Box, Sphere, Cylinder, Capsule, Plane)

class Geometry : public vsd::NamedModelInstance {
  VSD_INSTANCE(Geometry, vsd::NamedModelInstance)
  VSD_PROPERTY(GeometryKind, kind, GeometryKind::Mesh)
  VSD_PROPERTY(Eigen::Vector3d, size, Eigen::Vector3d::Zero())
  VSD_PROPERTY(double, radius, 0.0)
  VSD_PROPERTY(double, length, 0.0)
  VSD_PROPERTY(Eigen::Vector3d, normal, Eigen::Vector3d::UnitZ())
  /// Scale applied to the mesh vertices (URDF's mesh scale); vertices are stored unscaled.
  VSD_PROPERTY(Eigen::Vector3d, scale, Eigen::Vector3d::Ones())
  /// Where a mesh came from, as written in the description (e.g. "package://robot/meshes/a.stl").
  VSD_PROPERTY(std::string, source, "")
  VSD_PROPERTY(std::vector<Eigen::Vector3d>, vertices, {})
  /// One normal per vertex (empty when unknown).
  VSD_PROPERTY(std::vector<Eigen::Vector3d>, normals, {})
  /// Triangles: three vertex indices each.
  VSD_PROPERTY(std::vector<std::int32_t>, facets, {})
  /// One texture coordinate per vertex (empty when the mesh has none).
  VSD_PROPERTY(std::vector<Eigen::Vector2d>, texture_coordinates, {})

 public:
  /// @brief Number of triangles.
  [[nodiscard]] std::size_t facet_count() const noexcept { return facets_.size() / 3; }
  /// @brief True for a mesh that has vertices (a mesh whose file was missing has none).
  [[nodiscard]] bool has_mesh_data() const noexcept { return !vertices_.empty(); }
  /// @brief A short description: "box 1 x 2 x 3", "mesh a.stl: 8 vertices, 12 facets", ...
  [[nodiscard]] std::string describe() const;
};

}  // namespace vsd::scene
