/** @file
 *  @brief Inverse kinematics on a compiled Model: damped least squares with Levenberg–Marquardt damping,
 *  joint limits respected, random restarts within a time budget; the success rate is counted.
 *
 *  Each iteration solves `(J Jᵀ + λ I) y = e`, steps `Δq = Jᵀ y`, clamps into the limits and keeps the step
 *  only when the weighted error shrank (then λ falls; otherwise it grows and the step is retried). The
 *  error `e` is the position error and the rotation error (angle times axis of target · currentᵀ), in the
 *  base frame. An attempt ends when both are within tolerance, after max_iterations, or when λ has grown
 *  past use; then the solver restarts from a random vector within the limits until the time budget is
 *  spent.
 */
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "vsd/robotics/model.hpp"

namespace vsd::robotics {

/// @brief How IK searches.
struct IkOptions {
  double position_tolerance = 1e-6;     ///< m
  double orientation_tolerance = 1e-6;  ///< rad
  int max_iterations = 100;             ///< per attempt
  double time_budget = 0.005;           ///< s, for all attempts together (the first attempt always runs)
  int max_restarts = 1000;              ///< random restarts at most
  double initial_damping = 1e-3;        ///< λ of the first iteration
  std::uint64_t random_seed = 1;        ///< of the restart generator
};

/// @brief What IK found.
struct IkResult {
  bool success = false;
  std::vector<double> q;           ///< the best joint vector found (model layout)
  int iterations = 0;              ///< over all attempts
  int restarts = 0;                ///< attempts after the first
  double position_error = 0.0;     ///< m, of q
  double orientation_error = 0.0;  ///< rad, of q
};

class IkSolver {
 public:
  /// @brief A solver for body @p body of @p model (which must outlive the solver).
  /// @throws vsd::Error when @p body is out of range or the model has no degrees of freedom.
  IkSolver(const Model& model, int body, IkOptions options = {});

  /// @brief Solves for @p target (the body's pose in the base frame), starting from @p seed.
  /// @throws vsd::Error when @p seed does not have model.dof() values.
  IkResult solve(const Eigen::Isometry3d& target, std::span<const double> seed);

  [[nodiscard]] const IkOptions& options() const noexcept { return options_; }
  void set_options(const IkOptions& o) { options_ = o; }
  /// @brief solve() calls so far, and how many succeeded.
  [[nodiscard]] std::uint64_t calls() const noexcept { return calls_; }
  [[nodiscard]] std::uint64_t successes() const noexcept { return successes_; }
  /// @brief successes() / calls() (0 before the first call).
  [[nodiscard]] double success_rate() const noexcept {
    return calls_ == 0 ? 0.0 : static_cast<double>(successes_) / static_cast<double>(calls_);
  }

 private:
  bool attempt(const Eigen::Isometry3d& target, Eigen::VectorXd& q, int& iterations, double& pos_err,
               double& rot_err);
  void error_of(const Eigen::Isometry3d& target, Eigen::Matrix<double, 6, 1>& e);

  const Model& model_;
  int body_;
  IkOptions options_;
  Model::Data data_;
  Eigen::Matrix<double, 6, Eigen::Dynamic> jac_;
  std::mt19937_64 rng_;
  std::uint64_t calls_ = 0;
  std::uint64_t successes_ = 0;
};

}  // namespace vsd::robotics
