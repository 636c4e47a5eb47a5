// Ray casts against FCL shapes (FCL 0.7 has no ray query): closed forms in the shape's frame for the
// primitives, Moeller-Trumbore on the triangles of a mesh's FCL bounding-volume tree (OBBRSS) that the ray
// enters (private to vsd::collision).
#pragma once

#include <fcl/geometry/collision_geometry.h>

#include <Eigen/Geometry>
#include <optional>

namespace vsd::collision {

struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;  // unit length
  double max_distance;
};

struct ShapeHit {
  double distance;
  Eigen::Vector3d point;   // world
  Eigen::Vector3d normal;  // world, outward
};

/// True when the ray meets the box [lo, hi] at a distance in [0, limit].
bool ray_enters_box(const Ray& ray, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double limit);

/// The first point where @p ray meets @p shape placed at @p pose within ray.max_distance; a ray that
/// starts inside a solid shape hits it at distance 0 (normal: against the ray).
std::optional<ShapeHit> ray_hit_shape(const Ray& ray, const fcl::CollisionGeometryd& shape,
                                      const Eigen::Isometry3d& pose);

}  // namespace vsd::collision
