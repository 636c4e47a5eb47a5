// The physics benchmarks' scene in vsd (benchmarks/bench_physics.cpp, and bench_web.cpp's step with the
// inspector connected): 200 bodies — 100 boxes of 0.2 m, 100 spheres of radius 0.1 m on a 20 x 10 grid —
// resting on a plane after 500 settling steps, about 500 contact points per step.
#pragma once

#include <vector>

#include "vsd/physics.hpp"

namespace vsd_bench_physics {

constexpr int body_count = 200;
constexpr double step = 0.002;
constexpr double half = 0.1;  // half size of the boxes, radius of the spheres
constexpr double mu = 0.5;
constexpr double density = 500.0;
constexpr int settle_steps = 500;

// Grid position of body i, resting on the plane (sunk into the surface layer as a settled body is).
inline Eigen::Vector3d place(int i) { return {0.5 * (i % 20), 0.5 * (i / 20), half - 0.0004}; }

struct VsdScene {
  vsd::Environment env;
  vsd::physics::Simulation* sim = nullptr;
  std::vector<vsd::scene::Hull*> hulls;

  VsdScene() {
    env.use<vsd::physics::Module>();
    env.scheduler().set_base_step(step);
    sim = &env.module<vsd::physics::Module>()->simulation();
    auto& s = env.main_state();
    auto& root = s.create<vsd::scene::Scene>();
    s.database().add_child(root);
    auto& w = s.create<vsd::physics::World>();
    w.set_step(step);
    root.add_extension(w);
    auto& mat = s.create<vsd::scene::Material>();
    mat.set_friction(mu);
    mat.set_density(density);
    root.edit_materials().push_back(mat);
    auto geometry = [&](vsd::scene::GeometryKind k) -> vsd::scene::Geometry& {
      auto& g = s.create<vsd::scene::Geometry>();
      g.set_kind(k);
      g.set_size(Eigen::Vector3d::Constant(2 * half));
      g.set_radius(half);
      root.edit_geometries().push_back(g);
      return g;
    };
    auto& plane = geometry(vsd::scene::GeometryKind::Plane);
    auto& box = geometry(vsd::scene::GeometryKind::Box);
    auto& ball = geometry(vsd::scene::GeometryKind::Sphere);
    auto hull = [&](vsd::scene::Geometry& g, const Eigen::Vector3d& p) -> vsd::scene::Hull& {
      auto& h = s.create<vsd::scene::Hull>();
      h.set_role(vsd::scene::HullRole::Collision);
      h.set_geometry(&g);
      h.set_material(&mat);
      Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
      f.translation() = p;
      h.set_frame(f);
      root.add_child(h);
      return h;
    };
    hull(plane, Eigen::Vector3d::Zero());
    for (int i = 0; i < body_count; ++i) {
      auto& h = hull(i % 2 == 0 ? box : ball, place(i));
      h.add_extension(s.create<vsd::physics::RigidBody>());
      hulls.push_back(&h);
    }
    for (int i = 0; i < settle_steps; ++i) env.step();
  }
};

}  // namespace vsd_bench_physics
