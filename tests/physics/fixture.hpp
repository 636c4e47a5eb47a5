// Shared scaffolding of the vsd::physics tests: an environment with the module, a World on the database
// root, and helpers that make static and dynamic primitives.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "vsd/physics.hpp"

namespace vsd::physics::test {

inline Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translation() = Eigen::Vector3d(x, y, z);
  return f;
}

class PhysicsTest : public ::testing::Test {
 public:
  PhysicsTest() {
    env.use<Module>();
    world = &s.create<World>();
    s.database().add_extension(*world);
  }

  Simulation& sim() { return env.module<Module>()->simulation(); }

  scene::Geometry& geometry(scene::GeometryKind kind, Eigen::Vector3d size = Eigen::Vector3d::Zero(),
                            double radius = 0.0, double length = 0.0) {
    auto& g = s.create<scene::Geometry>();
    g.set_kind(kind);
    g.set_size(size);
    g.set_radius(radius);
    g.set_length(length);
    scene_root().edit_geometries().push_back(g);
    return g;
  }

  scene::Material& material(double friction, double restitution, double density = 1000.0) {
    auto& m = s.create<scene::Material>();
    m.set_friction(friction);
    m.set_restitution(restitution);
    m.set_density(density);
    scene_root().edit_materials().push_back(m);
    return m;
  }

  scene::Scene& scene_root() {
    if (scene_ == nullptr) {
      scene_ = &s.create<scene::Scene>();
      scene_->set_name("scene");
      s.database().add_child(*scene_);
    }
    return *scene_;
  }

  // A collision hull as a child of @p parent (the scene root when null).
  scene::Hull& hull(scene::Geometry& g, const Eigen::Isometry3d& frame, scene::Material* m = nullptr,
                    vsd::Node* parent = nullptr, std::string name = "hull") {
    auto& h = s.create<scene::Hull>();
    h.set_name(std::move(name));
    h.set_role(scene::HullRole::Collision);
    h.set_geometry(&g);
    if (m != nullptr) h.set_material(m);
    h.set_frame(frame);
    (parent != nullptr ? *parent : static_cast<vsd::Node&>(scene_root())).add_child(h);
    return h;
  }

  // A dynamic body: a Hull that carries a RigidBody (mass derived from geometry and density unless given).
  RigidBody& body(scene::Hull& h, double mass = 0.0) {
    auto& rb = s.create<RigidBody>();
    rb.set_mass(mass);
    h.add_extension(rb);
    return rb;
  }

  scene::Hull& ground(scene::Material* m = nullptr) {
    auto& g = geometry(scene::GeometryKind::Plane);
    return hull(g, Eigen::Isometry3d::Identity(), m, nullptr, "ground");
  }

  vsd::Environment env;
  vsd::SimState& s = env.main_state();
  World* world = nullptr;
  scene::Scene* scene_ = nullptr;
};

}  // namespace vsd::physics::test
