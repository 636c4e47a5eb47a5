// Synchronised trapezoidal and quintic point-to-point motions.
#include "vsd/robotics/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "vsd/core/error.hpp"

namespace vsd::robotics {

JointTrajectory JointTrajectory::plan(Interpolation shape, std::span<const double> start,
                                      std::span<const double> goal, std::span<const double> vmax,
                                      std::span<const double> amax) {
  const std::size_t n = start.size();
  if (goal.size() != n || vmax.size() != n || amax.size() != n)
    throw vsd::Error("JointTrajectory: " + std::to_string(n) + " start values but " +
                     std::to_string(goal.size()) + " goal values, " + std::to_string(vmax.size()) +
                     " speed and " + std::to_string(amax.size()) + " acceleration limits");
  for (std::size_t i = 0; i < n; ++i) {
    if (!(vmax[i] > 0) || !(amax[i] > 0) || !std::isfinite(vmax[i]) || !std::isfinite(amax[i]))
      throw vsd::Error("JointTrajectory: joint " + std::to_string(i) +
                       " needs positive, finite speed and acceleration limits");
    if (!std::isfinite(start[i]) || !std::isfinite(goal[i]))
      throw vsd::Error("JointTrajectory: joint " + std::to_string(i) + " needs a finite start and goal");
  }
  JointTrajectory t;
  t.shape_ = shape;
  t.start_.assign(start.begin(), start.end());
  t.goal_.assign(goal.begin(), goal.end());
  // The slowest joint sets the duration.
  double T = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = std::abs(goal[i] - start[i]);
    double ti;
    if (shape == Interpolation::Trapezoidal) {
      // Triangle when the speed limit is not reached, else accelerate, cruise, decelerate.
      ti = d * amax[i] <= vmax[i] * vmax[i] ? 2.0 * std::sqrt(d / amax[i]) : d / vmax[i] + vmax[i] / amax[i];
    } else {
      // Peak speed 15 d / (8 T), peak acceleration 10 d / (sqrt(3) T^2).
      ti = std::max(15.0 * d / (8.0 * vmax[i]), std::sqrt(10.0 * d / (std::sqrt(3.0) * amax[i])));
    }
    T = std::max(T, ti);
  }
  t.duration_ = T;
  if (shape == Interpolation::Trapezoidal) {
    t.cruise_.resize(n);
    t.accel_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double d = std::abs(goal[i] - start[i]);
      if (d == 0.0 || T == 0.0) continue;
      // Keep this joint's acceleration and find the cruise speed that arrives at T:
      // d = v T - v^2 / a  =>  v = (a T - sqrt(a^2 T^2 - 4 a d)) / 2.
      const double a = amax[i];
      const double disc = std::max(0.0, a * a * T * T - 4.0 * a * d);
      const double v = 0.5 * (a * T - std::sqrt(disc));
      t.cruise_[i] = goal[i] > start[i] ? v : -v;
      t.accel_[i] = v > 0 ? a : 0.0;
      if (disc == 0.0) t.accel_[i] = 4.0 * d / (T * T);  // exactly a triangle
    }
  }
  return t;
}

void JointTrajectory::sample(double t, double* q, double* qd) const noexcept {
  const std::size_t n = start_.size();
  const double T = duration_;
  if (T <= 0.0 || t >= T) {
    for (std::size_t i = 0; i < n; ++i) {
      q[i] = t <= 0.0 && T > 0.0 ? start_[i] : goal_[i];
      qd[i] = 0.0;
    }
    return;
  }
  if (t < 0.0) t = 0.0;
  if (shape_ == Interpolation::Quintic) {
    const double s = t / T;
    const double p = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    const double dp = 30.0 * s * s * (1.0 - s) * (1.0 - s) / T;
    for (std::size_t i = 0; i < n; ++i) {
      const double d = goal_[i] - start_[i];
      q[i] = start_[i] + d * p;
      qd[i] = d * dp;
    }
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double v = cruise_[i];
    const double a = accel_[i];
    if (v == 0.0 || a == 0.0) {
      q[i] = goal_[i];  // this joint does not move (start == goal)
      qd[i] = 0.0;
      continue;
    }
    const double sign = v > 0 ? 1.0 : -1.0;
    const double speed = std::abs(v);
    const double ta = speed / a;  // acceleration phase
    double s, ds;
    if (t < ta) {
      s = 0.5 * a * t * t;
      ds = a * t;
    } else if (t < T - ta) {
      s = 0.5 * a * ta * ta + speed * (t - ta);
      ds = speed;
    } else {
      const double r = T - t;
      s = std::abs(goal_[i] - start_[i]) - 0.5 * a * r * r;
      ds = a * r;
    }
    q[i] = start_[i] + sign * s;
    qd[i] = sign * ds;
  }
}

}  // namespace vsd::robotics
