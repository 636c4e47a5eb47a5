/** @file
 *  @brief JointTrajectory: a synchronised point-to-point motion of a joint vector, trapezoidal (bang–coast–
 *  bang in velocity) or quintic (zero velocity and acceleration at both ends), within per-joint velocity
 *  and acceleration limits. Every joint starts and arrives together: the slowest joint sets the duration,
 *  the others are slowed to it.
 */
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "vsd/core/meta_type.hpp"

namespace vsd::robotics {

/// @brief The shape of a point-to-point motion.
enum class Interpolation : std::uint8_t {
  Trapezoidal,  ///< constant acceleration, cruise, constant deceleration (minimum time within the limits)
  Quintic       ///< fifth-order polynomial: velocity and acceleration zero at both ends
};
VSD_ENUM(Interpolation, Trapezoidal, Quintic)

class JointTrajectory {
 public:
  JointTrajectory() = default;
  /// @brief Plans from @p start to @p goal with speed limits @p vmax and acceleration limits @p amax (> 0).
  /// @throws vsd::Error when the sizes differ or a limit is not positive.
  static JointTrajectory plan(Interpolation shape, std::span<const double> start,
                              std::span<const double> goal, std::span<const double> vmax,
                              std::span<const double> amax);
  /// @brief Seconds from start to goal.
  [[nodiscard]] double duration() const noexcept { return duration_; }
  [[nodiscard]] std::size_t size() const noexcept { return start_.size(); }
  [[nodiscard]] const std::vector<double>& goal() const noexcept { return goal_; }
  /// @brief Position @p q and velocity @p qd (size() values each) at time @p t (clamped to [0, duration]).
  void sample(double t, double* q, double* qd) const noexcept;

 private:
  Interpolation shape_ = Interpolation::Trapezoidal;
  std::vector<double> start_, goal_;
  std::vector<double> cruise_;  // trapezoidal: cruise speed of each joint (signed)
  std::vector<double> accel_;   // trapezoidal: acceleration of each joint (unsigned)
  double duration_ = 0.0;
};

}  // namespace vsd::robotics
