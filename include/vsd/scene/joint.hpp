/** @file
 *  @brief Joint: the kinematic data of a joint between two links, kept for the robotics module
 *  (chains, forward kinematics, dynamics). The child link's `frame` is the joint origin at position 0.
 */
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>

#include "vsd/core/named_model_instance.hpp"
#include "vsd/core/reference.hpp"
#include "vsd/scene/link.hpp"

namespace vsd::scene {

/// @brief The joint types of URDF.
enum class JointType : std::uint8_t { Unknown, Revolute, Continuous, Prismatic, Floating, Planar, Fixed };
VSD_ENUM(JointType, Unknown, Revolute, Continuous, Prismatic, Floating, Planar, Fixed)

class Joint : public vsd::NamedModelInstance {
  VSD_INSTANCE(Joint, vsd::NamedModelInstance)
  VSD_PROPERTY(JointType, type, JointType::Fixed)
  /// Frame of the joint (and of the child link at position 0) relative to the parent link.
  VSD_PROPERTY(Eigen::Isometry3d, origin, Eigen::Isometry3d::Identity())
  /// Axis in the joint frame (unit vector).
  VSD_PROPERTY(Eigen::Vector3d, axis, Eigen::Vector3d::UnitX())
  VSD_PROPERTY(vsd::SharedRef<Link>, parent_link, nullptr)
  VSD_PROPERTY(vsd::SharedRef<Link>, child_link, nullptr)
  /// True when lower/upper/effort/velocity come from a <limit> element.
  VSD_PROPERTY(bool, has_limits, false)
  /// rad or m.
  VSD_PROPERTY(double, lower, 0.0)
  VSD_PROPERTY(double, upper, 0.0)
  /// N m or N.
  VSD_PROPERTY(double, effort, 0.0)
  /// rad/s or m/s.
  VSD_PROPERTY(double, velocity, 0.0)
  VSD_PROPERTY(double, damping, 0.0)
  VSD_PROPERTY(double, friction, 0.0)
  /// The joint this one mimics (position = multiplier * theirs + offset), or null.
  VSD_PROPERTY(vsd::SharedRef<Joint>, mimic, nullptr)
  VSD_PROPERTY(double, mimic_multiplier, 1.0)
  VSD_PROPERTY(double, mimic_offset, 0.0)
  /// The position (rad or m) the description starts in (a URDF has none: 0). vsd::robotics copies it into
  /// the KinematicJoint it builds; from then on that KinematicJoint's `position` is the joint's value, the
  /// one property a joint set writes (this one is not kept in step).
  VSD_PROPERTY(double, position, 0.0)
};

}  // namespace vsd::scene
