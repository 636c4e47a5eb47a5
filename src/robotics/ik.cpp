// Inverse kinematics: damped least squares with Levenberg–Marquardt damping and random restarts.
#include "vsd/robotics/ik.hpp"

#include <Eigen/Cholesky>
#include <chrono>
#include <limits>
#include <cmath>
#include <numbers>

#include "vsd/core/error.hpp"

namespace vsd::robotics {

IkSolver::IkSolver(const Model& model, int body, IkOptions options)
    : model_(model),
      body_(body),
      options_(options),
      data_(model.make_data()),
      jac_(6, model.dof()),
      rng_(options.random_seed) {
  if (body < 0 || body >= model.body_count())
    throw vsd::Error("IkSolver: body index " + std::to_string(body) + " out of range (the model has " +
                     std::to_string(model.body_count()) + " bodies)");
  if (model.dof() == 0) throw vsd::Error("IkSolver: the model has no degrees of freedom");
}

void IkSolver::error_of(const Eigen::Isometry3d& target, Eigen::Matrix<double, 6, 1>& e) {
  const Frame& f = model_.pose(data_, body_);
  e.head<3>() = target.translation() - f.translation;
  const Eigen::Matrix3d r = target.linear() * f.rotation.transpose();
  const Eigen::AngleAxisd aa(r);
  e.tail<3>() = aa.angle() * aa.axis();
}

bool IkSolver::attempt(const Eigen::Isometry3d& target, Eigen::VectorXd& q, int& iterations, double& pos_err,
                       double& rot_err) {
  const int n = model_.dof();
  Eigen::Matrix<double, 6, 1> e, en;
  Eigen::VectorXd qn(n);
  model_.clamp(q.data());
  model_.forward(q.data(), data_);
  error_of(target, e);
  double err = e.squaredNorm();
  double lambda = options_.initial_damping;
  for (int it = 0;; ++it) {
    // stableNorm: a target 1e200 m away is that far, not infinitely (norm() squares and overflows).
    pos_err = e.head<3>().stableNorm();
    rot_err = e.tail<3>().stableNorm();
    if (pos_err <= options_.position_tolerance && rot_err <= options_.orientation_tolerance) return true;
    if (it >= options_.max_iterations || lambda > 1e12) return false;
    ++iterations;
    model_.jacobian(data_, body_, jac_);
    Eigen::Matrix<double, 6, 6> a = jac_ * jac_.transpose();
    a.diagonal().array() += lambda;
    const Eigen::Matrix<double, 6, 1> y = a.llt().solve(e);
    qn.noalias() = q + jac_.transpose() * y;
    model_.clamp(qn.data());
    model_.forward(qn.data(), data_);
    error_of(target, en);
    const double errn = en.squaredNorm();
    if (errn < err) {
      q.swap(qn);
      e = en;
      err = errn;
      lambda = std::max(lambda * 0.1, 1e-12);
    } else {
      lambda *= 10.0;
      model_.forward(q.data(), data_);  // the Jacobian of the next try is taken at q again
    }
  }
}

IkResult IkSolver::solve(const Eigen::Isometry3d& target, std::span<const double> seed) {
  const int n = model_.dof();
  if (seed.size() != static_cast<std::size_t>(n))
    throw vsd::Error("IkSolver: the seed has " + std::to_string(seed.size()) + " values; the model has " +
                     std::to_string(n));
  if (!target.matrix().allFinite()) throw vsd::Error("IkSolver: the target pose is not finite");
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(seed[static_cast<std::size_t>(i)]))
      throw vsd::Error("IkSolver: the seed value of '" + model_.layout()[static_cast<std::size_t>(i)].name +
                       "' is not finite");
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(options_.time_budget));
  ++calls_;
  IkResult r;
  Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(seed.data(), n);
  Eigen::VectorXd best = q;
  double best_err = std::numeric_limits<double>::infinity();
  for (int attempt_no = 0;; ++attempt_no) {
    double pe = 0, re = 0;
    const bool ok = attempt(target, q, r.iterations, pe, re);
    // The first attempt always counts: its errors are the real ones even when they are huge (an error of
    // infinity compared with the initial best of infinity used to leave the reported errors at 0).
    if (ok || attempt_no == 0 || pe + re < best_err) {
      best = q;
      best_err = pe + re;
      r.position_error = pe;
      r.orientation_error = re;
    }
    if (ok) {
      r.success = true;
      break;
    }
    if (attempt_no >= options_.max_restarts || Clock::now() >= deadline) break;
    ++r.restarts;
    for (int i = 0; i < n; ++i) {
      const DofInfo& d = model_.layout()[static_cast<std::size_t>(i)];
      double lo = d.lower, hi = d.upper;
      if (!d.has_limits) {
        lo = d.type == KinematicJointType::Prismatic ? -1.0 : -std::numbers::pi;
        hi = -lo;
      }
      q[i] = std::uniform_real_distribution<double>(lo, hi)(rng_);
    }
  }
  if (r.success) ++successes_;
  r.q.assign(best.data(), best.data() + n);
  return r;
}

}  // namespace vsd::robotics
