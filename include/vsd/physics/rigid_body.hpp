/** @file
 *  @brief RigidBody: the extension that makes a scene::Node3D a dynamic rigid body simulated by
 *  vsd::physics. Its collision hulls are the Hulls of role Collision below the node (down to the next
 *  node with a RigidBody of its own), the node itself included when it is a Hull.
 *
 *  Mass: on a scene::Link whose mass is not 0, the link's inertial data (mass, centre of mass, inertia —
 *  a URDF's <inertial>) is what the body is, whatever collision hulls the link has (they only collide);
 *  a negative or non-finite link mass is an error. Otherwise mass and inertia are derived from the
 *  collision hulls (volume times the density of their Material). `mass` > 0 scales either to that mass.
 *  `inertia_diagonal` and `inertia_products` (about `center_of_mass`, in node axes), when non-zero,
 *  override both (with `mass` > 0). A body whose mass cannot be found this way is an error (vsd::Error
 *  from the next step).
 *
 *  The velocities are written back after each step (world coordinates; the linear one is that of the
 *  centre of mass); a velocity set by anyone else is given to ODE before the next step. `force` and `torque`
 * are accumulators: what they hold when a step starts acts during the step (as constant force and torque
 * about the centre of mass) and is then cleared to zero, as ODE's own accumulators are.
 */
#pragma once

#include <Eigen/Core>

#include "vsd/core/extension.hpp"
#include "vsd/core/meta_type_eigen.hpp"
#include "vsd/physics/namespace.hpp"

namespace vsd::scene {
class Node3D;
}

namespace vsd::physics {

class RigidBody : public vsd::Extension {
  VSD_INSTANCE(RigidBody, vsd::Extension)
  /// kg; 0: derived (see the file comment).
  VSD_PROPERTY(double, mass, 0.0)
  /// Centre of mass in the node's frame (used with an explicit inertia; derived otherwise).
  VSD_PROPERTY(Eigen::Vector3d, center_of_mass, Eigen::Vector3d::Zero())
  /// Ixx, Iyy, Izz in kg m^2 about the centre of mass, node axes; zero: derived.
  VSD_PROPERTY(Eigen::Vector3d, inertia_diagonal, Eigen::Vector3d::Zero())
  /// Ixy, Ixz, Iyz in kg m^2.
  VSD_PROPERTY(Eigen::Vector3d, inertia_products, Eigen::Vector3d::Zero())
  /// m/s of the centre of mass, world coordinates.
  VSD_PROPERTY(Eigen::Vector3d, linear_velocity, Eigen::Vector3d::Zero())
  /// rad/s, world coordinates.
  VSD_PROPERTY(Eigen::Vector3d, angular_velocity, Eigen::Vector3d::Zero())
  /// N, world coordinates, acting at the centre of mass during the next step, then cleared.
  VSD_PROPERTY(Eigen::Vector3d, force, Eigen::Vector3d::Zero())
  /// N m, world coordinates, during the next step, then cleared.
  VSD_PROPERTY(Eigen::Vector3d, torque, Eigen::Vector3d::Zero())
  /// False: gravity does not act on this body.
  VSD_PROPERTY(bool, gravity, true)

 public:
  /// @brief The Node3D this body is attached to, or nullptr (not attached, or not to a Node3D).
  [[nodiscard]] scene::Node3D* node() const noexcept;
  /// @brief Adds @p f (N, world) acting at the centre of mass to the accumulator (a force acting
  /// elsewhere: Simulation::add_force_at, which knows the derived centre of mass).
  void add_force(const Eigen::Vector3d& f);
  /// @brief Adds @p t (N m, world) to the torque accumulator.
  void add_torque(const Eigen::Vector3d& t);
};

}  // namespace vsd::physics
