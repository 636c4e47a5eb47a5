/** @file
 *  @brief Link: a rigid body of a robot or mechanism — a Node3D with mass and inertia, whose hulls
 *  (visual and collision) are its children.
 */
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "vsd/scene/node3d.hpp"

namespace vsd::scene {

class Link : public Node3D {
  VSD_INSTANCE(Link, Node3D)
  /// kg; 0 when the description gives no inertial data.
  VSD_PROPERTY(double, mass, 0.0)
  /// Frame of the centre of mass (and of the inertia axes), relative to the link.
  VSD_PROPERTY(Eigen::Isometry3d, inertial_frame, Eigen::Isometry3d::Identity())
  /// Ixx, Iyy, Izz in kg m^2, about the inertial frame.
  VSD_PROPERTY(Eigen::Vector3d, inertia_diagonal, Eigen::Vector3d::Zero())
  /// Ixy, Ixz, Iyz in kg m^2, about the inertial frame.
  VSD_PROPERTY(Eigen::Vector3d, inertia_products, Eigen::Vector3d::Zero())

 public:
  /// @brief The symmetric inertia tensor about the inertial frame.
  [[nodiscard]] Eigen::Matrix3d inertia() const;
};

}  // namespace vsd::scene
