/** @file
 *  @brief KinematicJoint: the extension of a 3D node (normally a scene::Link) that makes it the child
 *  side of a joint — rotary, prismatic, universal, fixed, or given by Denavit–Hartenberg parameters
 *  (standard or modified) — with limits, velocities and an optional mimic relation.
 *
 *  The joint's values (`position`, `position2` for the second axis of a universal joint) are ordinary
 *  properties. Changing one (by the setter, MetaProperty::set, a loaded file or an applied bundle) sets
 *  the owner node's `frame` to `motion_frame()` and the positions of the joints that mimic it, so the
 *  link frames in the scene follow and their signals fire. This is done by listeners that vsd::robotics
 *  keeps per SimState (see track() in kinematic_tree.hpp).
 *
 *  Every joint kind has the same form, which is what the compiled Model evaluates:
 *  `frame = pre * motion(q) * post` with `motion` a rotation about, or a translation along, `axis`.
 *  - URDF-like (`dh` = None): pre = `origin`, post = identity; a universal joint rotates about `axis`,
 *    then about `axis2` (expressed in the frame after the first rotation).
 *  - DH standard: `frame = Rz(theta + q) Tz(d) Tx(a) Rx(alpha)` (a prismatic joint adds q to d).
 *  - DH modified (Craig): `frame = Rx(alpha) Tx(a) Rz(theta + q) Tz(d)`.
 */
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <utility>
#include <cstdint>
#include <limits>

#include "vsd/core/extension.hpp"
#include "vsd/core/meta_type_eigen.hpp"
#include "vsd/core/reference.hpp"
#include "vsd/robotics/namespace.hpp"
#include "vsd/scene/joint.hpp"

namespace vsd::robotics {

/// @brief What a joint lets move.
enum class KinematicJointType : std::uint8_t {
  Rotary,     ///< one rotation about `axis` (rad)
  Prismatic,  ///< one translation along `axis` (m)
  Universal,  ///< a rotation about `axis`, then one about `axis2` (two values: position, position2)
  Fixed       ///< no motion
};
VSD_ENUM(KinematicJointType, Rotary, Prismatic, Universal, Fixed)

/// @brief How the joint's placement is given.
enum class DhConvention : std::uint8_t {
  None,      ///< `origin` and `axis` (as URDF)
  Standard,  ///< classic Denavit–Hartenberg: Rz(theta) Tz(d) Tx(a) Rx(alpha)
  Modified   ///< Craig's modified DH: Rx(alpha) Tx(a) Rz(theta) Tz(d)
};
VSD_ENUM(DhConvention, None, Standard, Modified)

/// @brief One row of a DH table.
struct DhParameters {
  double a = 0.0;      ///< link length (m)
  double alpha = 0.0;  ///< link twist (rad)
  double d = 0.0;      ///< link offset (m); the variable of a prismatic joint is added to it
  double theta = 0.0;  ///< joint angle offset (rad); the variable of a rotary joint is added to it
};

/// @brief A rigid transform as the pair pre/post of a joint (see the file comment).
struct JointPlacement {
  Eigen::Isometry3d pre = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d post = Eigen::Isometry3d::Identity();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
};

class KinematicJoint : public vsd::Extension {
  VSD_INSTANCE(KinematicJoint, vsd::Extension)
  VSD_PROPERTY(KinematicJointType, type, KinematicJointType::Rotary)
  VSD_PROPERTY(DhConvention, dh, DhConvention::None)
  /// Placement of the joint frame in the parent frame (dh None).
  VSD_PROPERTY(Eigen::Isometry3d, origin, Eigen::Isometry3d::Identity())
  /// Axis of motion in the joint frame (dh None; a unit vector). DH joints move about/along z.
  VSD_PROPERTY(Eigen::Vector3d, axis, Eigen::Vector3d::UnitZ())
  /// Second axis of a universal joint, in the frame after the first rotation.
  VSD_PROPERTY(Eigen::Vector3d, axis2, Eigen::Vector3d::UnitY())
  VSD_PROPERTY(double, dh_a, 0.0)
  VSD_PROPERTY(double, dh_alpha, 0.0)
  VSD_PROPERTY(double, dh_d, 0.0)
  VSD_PROPERTY(double, dh_theta, 0.0)
  /// False: the joint is unbounded (continuous); lower/upper are ignored.
  VSD_PROPERTY(bool, has_limits, false)
  /// rad or m (both values of a universal joint).
  VSD_PROPERTY(double, lower, 0.0)
  VSD_PROPERTY(double, upper, 0.0)
  /// Largest speed, rad/s or m/s (0: not given).
  VSD_PROPERTY(double, velocity_limit, 0.0)
  /// Largest acceleration, rad/s^2 or m/s^2 (0: not given).
  VSD_PROPERTY(double, acceleration_limit, 0.0)
  /// Largest effort, N m or N (0: not given).
  VSD_PROPERTY(double, effort_limit, 0.0)
  /// The joint this one follows (position = mimic_multiplier * theirs + mimic_offset), or null.
  VSD_PROPERTY(vsd::SharedRef<KinematicJoint>, mimic, nullptr)
  VSD_PROPERTY(double, mimic_multiplier, 1.0)
  VSD_PROPERTY(double, mimic_offset, 0.0)
  /// The joint's value, rad or m (the first axis of a universal joint).
  VSD_PROPERTY(double, position, 0.0)
  /// The second value of a universal joint (rad).
  VSD_PROPERTY(double, position2, 0.0)
  /// The current speed, rad/s or m/s (set by controllers and adapters).
  VSD_PROPERTY(double, velocity, 0.0)
  /// The scene::Joint it was built from (a URDF joint), or null; its `position` follows this joint's and
  /// the other way round.
  VSD_PROPERTY(vsd::SharedRef<scene::Joint>, description, nullptr)

 public:
  /// @brief Number of values the joint has: 0 (fixed), 1, or 2 (universal).
  [[nodiscard]] int dof() const noexcept;
  /// @brief The joint's pre/post transforms and axis (see the file comment).
  [[nodiscard]] JointPlacement placement() const;
  /// @brief The child frame relative to the parent for values @p q1 and @p q2.
  [[nodiscard]] Eigen::Isometry3d motion_frame(double q1, double q2 = 0.0) const;
  /// @brief The child frame for the current values.
  [[nodiscard]] Eigen::Isometry3d motion_frame() const { return motion_frame(position(), position2()); }
  /// @brief The joint values whose motion frame comes closest to @p frame (the child frame relative to
  /// the parent): the inverse of motion_frame() where @p frame is one of its values, otherwise the
  /// projection onto the joint's motion (the rotation about the axis, the translation along it). A
  /// rotary value is taken in the turn nearest the current position (continuous joints keep counting).
  /// For a fixed joint the current values.
  [[nodiscard]] std::pair<double, double> values_of(const Eigen::Isometry3d& frame) const;
  /// @brief Sets the DH convention and parameters at once.
  void set_dh_parameters(DhConvention convention, const DhParameters& p);
  /// @brief True when @p q is within the limits (always, without limits).
  [[nodiscard]] bool within_limits(double q) const noexcept {
    return !has_limits() || (q >= lower() && q <= upper());
  }
};

}  // namespace vsd::robotics
