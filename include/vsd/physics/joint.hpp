/** @file
 *  @brief physics::Joint: a dynamic joint (hinge, slider, universal, ball, fixed) between the body it is
 *  attached to (its owner, an extension of a Node3D with a RigidBody) and another body, or the static
 *  world. Anchor and axes are in the owner node's frame; joint positions are measured from the pose the
 *  bodies have when the joint is built (created, loaded, or changed). A universal joint has limits and a
 *  motor on each of its two axes (`..2` for `axis2`).
 *
 *  scene::Joint is the kinematic description a URDF gives; physics::Joint is what ODE simulates. The
 *  function make_dynamic() (vsd/physics/simulation.hpp) turns a loaded URDF scene into bodies and joints.
 */
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "vsd/core/extension.hpp"
#include "vsd/core/meta_type_eigen.hpp"
#include "vsd/core/reference.hpp"
#include "vsd/physics/namespace.hpp"
#include "vsd/scene/node3d.hpp"

namespace vsd::physics {

/// @brief The joint types of vsd::physics (ODE's hinge, slider, universal, ball and fixed joints).
enum class JointKind : std::uint8_t {
  Hinge,      ///< rotation about `axis` through `anchor`
  Slider,     ///< translation along `axis`
  Universal,  ///< rotation about `axis` and `axis2` (perpendicular) through `anchor`
  Ball,       ///< rotation about `anchor`, no limits or motor
  Fixed       ///< no relative motion
};
VSD_ENUM(JointKind, Hinge, Slider, Universal, Ball, Fixed)

class Joint : public vsd::Extension {
  VSD_INSTANCE(Joint, vsd::Extension)
  VSD_PROPERTY(JointKind, kind, JointKind::Hinge)
  /// The other body's node; null: the joint holds the owner to the static world.
  VSD_PROPERTY(vsd::SharedRef<scene::Node3D>, other, nullptr)
  /// Point of the joint in the owner node's frame (hinge, universal, ball).
  VSD_PROPERTY(Eigen::Vector3d, anchor, Eigen::Vector3d::Zero())
  /// First axis in the owner node's frame (hinge, slider, universal).
  VSD_PROPERTY(Eigen::Vector3d, axis, Eigen::Vector3d::UnitZ())
  /// Second axis of a universal joint, perpendicular to `axis`.
  VSD_PROPERTY(Eigen::Vector3d, axis2, Eigen::Vector3d::UnitY())
  /// True: `lower` and `upper` bound the position about/along `axis` (rad or m).
  VSD_PROPERTY(bool, has_limits, false)
  VSD_PROPERTY(double, lower, 0.0)
  VSD_PROPERTY(double, upper, 0.0)
  /// Motor along `axis`: target velocity (rad/s or m/s) reached with at most `motor_max_force`
  /// (N m or N); a max force of 0 switches the motor off.
  VSD_PROPERTY(double, motor_velocity, 0.0)
  VSD_PROPERTY(double, motor_max_force, 0.0)
  /// Universal joints only: limits of the angle about `axis2` (rad, in [-pi/2, pi/2]: ODE measures the
  /// second angle as an elevation), like `has_limits`, `lower` and `upper` for `axis`.
  VSD_PROPERTY(bool, has_limits2, false)
  VSD_PROPERTY(double, lower2, 0.0)
  VSD_PROPERTY(double, upper2, 0.0)
  /// Universal joints only: the motor about `axis2` (rad/s, N m), like `motor_velocity` and
  /// `motor_max_force` for `axis`.
  VSD_PROPERTY(double, motor_velocity2, 0.0)
  VSD_PROPERTY(double, motor_max_force2, 0.0)
  /// Position (rad or m) and its rate about/along `axis`, written after each step (not saved).
  VSD_PROPERTY(double, position, 0.0, vsd::Distributed)
  VSD_PROPERTY(double, rate, 0.0, vsd::Distributed)
  /// Universal joints only: angle (rad) and rate about `axis2`, written after each step (not saved).
  VSD_PROPERTY(double, position2, 0.0, vsd::Distributed)
  VSD_PROPERTY(double, rate2, 0.0, vsd::Distributed)
};

}  // namespace vsd::physics
