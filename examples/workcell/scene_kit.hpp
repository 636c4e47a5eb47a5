// What both work cells (examples/workcell/main.cpp, examples/workcell/two_robots/cell.cpp) build their
// scenery with: positions, script files, and collision hulls of one material under one cell node.
#pragma once

#include <fstream>
#include <sstream>
#include <string>
#include <utility>

#include "vsd/core/error.hpp"
#include "vsd/scene.hpp"

namespace vsd_example {

/// A pure translation.
inline Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translation() = Eigen::Vector3d(x, y, z);
  return f;
}

/// The whole text of @p path. @throws vsd::Error when it cannot be read.
inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw vsd::Error("cannot read " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Geometries and hulls of a cell: they live in the lists of @p cell, every hull of one material ("wood":
/// friction 0.8, no bounce, 600 kg/m³).
class SceneKit {
 public:
  SceneKit(vsd::SimState& s, vsd::scene::Scene& cell)
      : s_(s), cell_(cell), wood_(s.create<vsd::scene::Material>()) {
    wood_.set_name("wood");
    wood_.set_friction(0.8);
    wood_.set_restitution(0.0);
    wood_.set_density(600);
    cell_.edit_materials().push_back(wood_);
  }
  /// A geometry of @p kind (@p size for boxes, @p radius for spheres).
  vsd::scene::Geometry& geometry(vsd::scene::GeometryKind kind, const Eigen::Vector3d& size,
                                 double radius = 0) {
    auto& g = s_.create<vsd::scene::Geometry>();
    g.set_kind(kind);
    g.set_size(size);
    g.set_radius(radius);
    cell_.edit_geometries().push_back(g);
    return g;
  }
  /// Makes @p h a collision hull named @p name of geometry @p g at @p f, a child of @p parent.
  vsd::scene::Hull& hull(vsd::scene::Hull& h, std::string name, vsd::scene::Geometry& g,
                         const Eigen::Isometry3d& f, vsd::Node& parent) {
    h.set_name(std::move(name));
    h.set_role(vsd::scene::HullRole::Collision);
    h.set_geometry(&g);
    h.set_material(&wood_);
    h.set_frame(f);
    parent.add_child(h);
    return h;
  }

 private:
  vsd::SimState& s_;
  vsd::scene::Scene& cell_;
  vsd::scene::Material& wood_;
};

}  // namespace vsd_example
