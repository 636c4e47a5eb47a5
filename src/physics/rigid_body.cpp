#include "vsd/physics/rigid_body.hpp"

#include "vsd/scene/node3d.hpp"

namespace vsd::physics {

scene::Node3D* RigidBody::node() const noexcept {
  vsd::NamedModelInstance* o = owner();
  return o != nullptr ? o->as<scene::Node3D>() : nullptr;
}

void RigidBody::add_force(const Eigen::Vector3d& f) { set_force(force() + f); }
void RigidBody::add_torque(const Eigen::Vector3d& t) { set_torque(torque() + t); }

}  // namespace vsd::physics
