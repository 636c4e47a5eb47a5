// How vsd::collision names hulls, shapes and poses in its errors (private to the module).
#pragma once

#include <Eigen/Geometry>
#include <cstdio>
#include <string>

#include "vsd/scene/geometry.hpp"
#include "vsd/scene/hull.hpp"

namespace vsd::collision {

inline std::string describe_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v + 0.0);  // + 0.0: no "-0"
  return buf;
}

inline std::string describe_vector(const Eigen::Vector3d& v) {
  return "[" + describe_number(v.x()) + ", " + describe_number(v.y()) + ", " + describe_number(v.z()) + "]";
}

/// "position [x, y, z] rotation (w, x, y, z)"; NaN and infinities print as such.
inline std::string describe_pose(const Eigen::Isometry3d& p) {
  std::string s = "position " + describe_vector(p.translation());
  const Eigen::Matrix3d r = p.linear();
  if (!r.allFinite()) return s + " rotation not finite";
  const Eigen::Quaterniond q(r);
  return s + " rotation (w " + describe_number(q.w()) + ", " + describe_number(q.x()) + ", " +
         describe_number(q.y()) + ", " + describe_number(q.z()) + ")";
}

inline std::string describe_geometry(const scene::Geometry& g) {
  std::string s = "geometry";
  if (!g.name().empty()) s += " '" + g.name() + "'";
  return s + " (" + g.describe() + ")";
}

inline std::string describe_hull(const scene::Hull& h) {
  return "hull '" + h.name() + "' (id " + std::to_string(h.id()) + ")";
}

inline std::string describe_geometry_of(const scene::Hull& h) {
  return h.geometry().get() != nullptr ? describe_geometry(*h.geometry()) : std::string("no geometry");
}

/// Both hulls with their shapes and world poses.
inline std::string describe_pair(const scene::Hull& a, const scene::Hull& b) {
  return describe_hull(a) + " " + describe_geometry_of(a) + " at " + describe_pose(a.world_frame()) +
         " and " + describe_hull(b) + " " + describe_geometry_of(b) + " at " + describe_pose(b.world_frame());
}

}  // namespace vsd::collision
