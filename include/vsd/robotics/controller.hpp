/** @file
 *  @brief JointController: the extension of a KinematicTree's base node that moves the tree each step —
 *  to a joint target along a trapezoidal or quintic trajectory, at joint velocities, or to a Cartesian pose
 *  of a body by differential IK. Run by the Scheduler (the robotics Module adds the task) or by step().
 *
 *  Targets are properties, so a supervisory control (a SOML++ net, a user interface in another process)
 *  commands the robot by setting them; a changed target replans from where the joints are. Limits: each
 *  joint's velocity and acceleration limits, or the controller's defaults where a joint has none; positions
 *  stay within the joint limits, and `limited` says when that cut a command or a target short. A target of
 *  the wrong size stops the controller with `fault` set.
 *
 *  With an active HardwareBinding on the same node the step's result goes to the binding as the command
 *  (the binding writes the measured state into the joints); while the binding holds, the controller does
 *  not advance, and after it held it replans from the measured positions.
 */
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vsd/core/extension.hpp"
#include "vsd/core/meta_type_eigen.hpp"
#include "vsd/robotics/kinematic_tree.hpp"
#include "vsd/robotics/trajectory.hpp"

namespace vsd::robotics {

/// @brief What a JointController does.
enum class ControlMode : std::uint8_t {
  Idle,      ///< nothing
  Position,  ///< follow a trajectory to `target`
  Velocity,  ///< move at `target_velocity` (limited), holding position at the joint limits
  Cartesian  ///< move body `tip` to `target_pose` (base frame) by damped least-squares differential IK
};
VSD_ENUM(ControlMode, Idle, Position, Velocity, Cartesian)

class JointController : public vsd::Extension {
  VSD_INSTANCE(JointController, vsd::Extension)
  VSD_PROPERTY(ControlMode, mode, ControlMode::Idle)
  VSD_PROPERTY(Interpolation, interpolation, Interpolation::Trapezoidal)
  /// Joint positions to reach (Position mode), in the tree model's layout.
  VSD_PROPERTY(std::vector<double>, target, {})
  /// Joint velocities (Velocity mode), in the layout.
  VSD_PROPERTY(std::vector<double>, target_velocity, {})
  /// Pose of body `tip` to reach (Cartesian mode), in the base frame.
  VSD_PROPERTY(Eigen::Isometry3d, target_pose, Eigen::Isometry3d::Identity())
  VSD_PROPERTY(std::string, tip, "")
  /// Speed and acceleration used for joints that give none (rad/s or m/s, and per second).
  VSD_PROPERTY(double, default_velocity, 1.0)
  VSD_PROPERTY(double, default_acceleration, 4.0)
  /// Cartesian mode: proportional gain on the pose error (1/s).
  VSD_PROPERTY(double, cartesian_gain, 10.0)
  /// Cartesian mode: done within this position (m) and orientation (rad) error.
  VSD_PROPERTY(double, cartesian_tolerance, 1e-4)
  /// True once the target is reached (Position, Cartesian). Cleared as soon as a new target is set —
  /// `target`, `target_pose` or `tip` changes, or `mode` becomes Position or Cartesian — by whatever sets
  /// it (C++, a SOML++ net, a replica, a file): "wait until done" never sees the previous target's done.
  /// Setting the same value again is no change and leaves it as it is.
  VSD_PROPERTY(bool, done, true)
  /// True while the joint limits cut the command short: in Cartesian and Velocity mode the last step
  /// clamped a joint at its limit (the tip then leaves the straight path and may never reach
  /// `target_pose`, so `done` may stay false), in Position mode the target lies outside the limits and the
  /// plan goes to the nearest position within them. False otherwise; a property, so listeners see it.
  VSD_PROPERTY(bool, limited, false)
  /// Why the controller stopped (empty while fine).
  VSD_PROPERTY(std::string, fault, "")

 public:
  /// @brief The KinematicTree on the same node, or nullptr.
  [[nodiscard]] KinematicTree* tree() const noexcept;
  /// @brief One control step of @p dt seconds: reads the joints, computes, writes positions and velocities.
  void step(double dt);
  /// @brief Seconds of the current trajectory (Position mode; 0 before planning).
  [[nodiscard]] double trajectory_duration() const noexcept {
    return trajectory_ ? trajectory_->duration() : 0.0;
  }

 private:
  void stop(std::string why);
  void limits(const Model& m, std::vector<double>& v, std::vector<double>& a) const;

  std::optional<JointTrajectory> trajectory_;
  std::vector<double> planned_for_;
  double elapsed_ = 0.0;
  std::uint64_t seen_synchronisations_ = 0;
};

}  // namespace vsd::robotics
