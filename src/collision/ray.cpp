// Ray casts against FCL shapes (see ray.hpp).
#include "ray.hpp"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/halfspace.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace vsd::collision {

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

// Where a ray (in the shape's frame) is inside a convex part: [t0, t1], with the outward normal at t0.
struct Span {
  double t0 = -inf, t1 = inf;
  Eigen::Vector3d n0 = Eigen::Vector3d::Zero();
  [[nodiscard]] bool empty() const { return t0 > t1; }
};

// Intersects s with the slab lo <= o[axis] + t d[axis] <= hi; the normal is -/+ the axis at the entry.
void clip_slab(Span& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d, int axis, double lo, double hi) {
  if (std::abs(d[axis]) < 1e-300) {
    if (o[axis] < lo || o[axis] > hi) s.t0 = inf, s.t1 = -inf;
    return;
  }
  double a = (lo - o[axis]) / d[axis], b = (hi - o[axis]) / d[axis];
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  n[axis] = -1;
  if (a > b) {
    std::swap(a, b);
    n[axis] = 1;
  }
  if (a > s.t0) {
    s.t0 = a;
    s.n0 = n;
  }
  s.t1 = std::min(s.t1, b);
}

Span sphere_span(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& c, double r) {
  Span s;
  const Eigen::Vector3d oc = o - c;
  const double b = oc.dot(d), q = oc.squaredNorm() - r * r, disc = b * b - q;
  if (disc < 0) return Span{inf, -inf, Eigen::Vector3d::Zero()};
  const double root = std::sqrt(disc);
  s.t0 = -b - root;
  s.t1 = -b + root;
  s.n0 = (oc + s.t0 * d) / r;
  return s;
}

Span cylinder_span(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r, double half) {
  Span s;
  const double a = d.x() * d.x() + d.y() * d.y();
  const double q = o.x() * o.x() + o.y() * o.y() - r * r;
  if (a < 1e-300) {
    if (q > 0) return Span{inf, -inf, Eigen::Vector3d::Zero()};
  } else {
    const double b = o.x() * d.x() + o.y() * d.y(), disc = b * b - a * q;
    if (disc < 0) return Span{inf, -inf, Eigen::Vector3d::Zero()};
    const double root = std::sqrt(disc);
    s.t0 = (-b - root) / a;
    s.t1 = (-b + root) / a;
    const Eigen::Vector3d p = o + s.t0 * d;
    s.n0 = Eigen::Vector3d(p.x(), p.y(), 0) / r;
  }
  clip_slab(s, o, d, 2, -half, half);
  return s;
}

std::optional<double> triangle_hit(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                   const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-14 * e1.norm() * e2.norm()) return std::nullopt;  // parallel or degenerate
  const Eigen::Vector3d s = o - a;
  const double u = s.dot(p) / det;
  if (u < 0 || u > 1) return std::nullopt;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (v < 0 || u + v > 1) return std::nullopt;
  const double t = e2.dot(q) / det;
  if (t < 0) return std::nullopt;
  return t;
}

}  // namespace

bool ray_enters_box(const Ray& ray, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double limit) {
  Span s;
  for (int k = 0; k < 3; ++k) clip_slab(s, ray.origin, ray.direction, k, lo[k], hi[k]);
  return !s.empty() && s.t1 >= 0 && s.t0 <= limit;
}

std::optional<ShapeHit> ray_hit_shape(const Ray& ray, const fcl::CollisionGeometryd& shape,
                                      const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d r = pose.linear();
  const Eigen::Vector3d o = r.transpose() * (ray.origin - pose.translation());
  const Eigen::Vector3d d = r.transpose() * ray.direction;
  Span s{inf, -inf, {}};
  switch (shape.getNodeType()) {
    case fcl::GEOM_BOX: {
      const Eigen::Vector3d h = static_cast<const fcl::Boxd&>(shape).side / 2;
      s = Span{};
      for (int k = 0; k < 3; ++k) clip_slab(s, o, d, k, -h[k], h[k]);
      break;
    }
    case fcl::GEOM_SPHERE:
      s = sphere_span(o, d, Eigen::Vector3d::Zero(), static_cast<const fcl::Sphered&>(shape).radius);
      break;
    case fcl::GEOM_CYLINDER: {
      const auto& c = static_cast<const fcl::Cylinderd&>(shape);
      s = cylinder_span(o, d, c.radius, c.lz / 2);
      break;
    }
    case fcl::GEOM_CAPSULE: {
      // The union of a cylinder and two spheres: the first entry into any part (the parts overlap).
      const auto& c = static_cast<const fcl::Capsuled&>(shape);
      const Span parts[3] = {cylinder_span(o, d, c.radius, c.lz / 2),
                             sphere_span(o, d, Eigen::Vector3d(0, 0, c.lz / 2), c.radius),
                             sphere_span(o, d, Eigen::Vector3d(0, 0, -c.lz / 2), c.radius)};
      for (const Span& p : parts) {
        if (p.empty() || p.t1 < 0) continue;
        if (s.empty() || std::max(p.t0, 0.0) < std::max(s.t0, 0.0)) s = p;
      }
      break;
    }
    case fcl::GEOM_HALFSPACE: {
      const auto& h = static_cast<const fcl::Halfspaced&>(shape);
      const double dist = h.n.dot(o) - h.d, dn = h.n.dot(d);
      if (dist <= 0) {
        s = Span{-inf, inf, Eigen::Vector3d::Zero()};
      } else if (dn < 0) {
        s = Span{-dist / dn, inf, h.n};
      }
      break;
    }
    case fcl::BV_OBBRSS: {
      // Down FCL's own bounding-volume tree of the mesh (built for collision anyway): only the boxes the
      // ray enters before the best hit so far are opened, nearer child first, so a ray costs about
      // O(log n) box tests and a handful of triangle tests instead of n triangle tests.
      const auto& m = static_cast<const fcl::BVHModel<fcl::OBBRSSd>&>(shape);
      if (m.getNumBVs() <= 0 || m.num_tris <= 0) return std::nullopt;
      double best = ray.max_distance;
      bool found = false;
      Eigen::Vector3d normal = Eigen::Vector3d::Zero();
      // Where the ray enters node i's oriented box (its OBB, padded by a relative 1e-9 so that rounding in
      // the fit never loses a triangle on its surface); false when it misses it or enters beyond best.
      const auto enters = [&](int i, double& t) {
        const fcl::OBBd& b = m.getBV(i).bv.obb;
        const Eigen::Vector3d bo = b.axis.transpose() * (o - b.To);
        const Eigen::Vector3d bd = b.axis.transpose() * d;
        const Eigen::Vector3d h =
            b.extent.array() + 1e-9 * (b.extent.maxCoeff() + b.To.cwiseAbs().maxCoeff());
        Span span;
        for (int k = 0; k < 3; ++k) clip_slab(span, bo, bd, k, -h[k], h[k]);
        if (span.empty() || span.t1 < 0) return false;
        t = std::max(span.t0, 0.0);
        return t <= best;
      };
      struct Entry {
        int node;
        double t;
      };
      std::vector<Entry> stack;
      stack.reserve(64);
      if (double t = 0; enters(0, t)) stack.push_back({0, t});
      while (!stack.empty()) {
        const Entry e = stack.back();
        stack.pop_back();
        if (e.t > best) continue;  // a nearer hit was found since it was pushed
        const auto& node = m.getBV(e.node);
        if (node.isLeaf()) {
          const fcl::Triangle& tri = m.tri_indices[node.primitiveId()];
          const Eigen::Vector3d &a = m.vertices[tri[0]], &b = m.vertices[tri[1]], &c = m.vertices[tri[2]];
          if (auto hit = triangle_hit(o, d, a, b, c); hit && (*hit < best || (!found && *hit <= best))) {
            best = *hit;
            found = true;
            normal = (b - a).cross(c - a).normalized();
            if (normal.dot(d) > 0) normal = -normal;  // facing the ray
          }
          continue;
        }
        Entry first{node.leftChild(), 0}, second{node.rightChild(), 0};
        bool in_first = enters(first.node, first.t), in_second = enters(second.node, second.t);
        if (in_first && in_second && first.t < second.t) {  // the nearer one on top of the stack
          std::swap(first, second);
        }
        if (in_first) stack.push_back(first);
        if (in_second) stack.push_back(second);
      }
      if (!found) return std::nullopt;
      return ShapeHit{best, ray.origin + best * ray.direction, r * normal};
    }
    default:
      return std::nullopt;
  }
  if (s.empty() || s.t1 < 0) return std::nullopt;
  const bool inside = s.t0 < 0;
  const double t = inside ? 0.0 : s.t0;
  if (t > ray.max_distance) return std::nullopt;
  const Eigen::Vector3d n = inside ? Eigen::Vector3d(-d) : s.n0;
  return ShapeHit{t, ray.origin + t * ray.direction, r * n};
}

}  // namespace vsd::collision
