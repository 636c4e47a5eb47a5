// JointController: trajectory following, velocity control and Cartesian motion by differential IK.
#include "vsd/robotics/controller.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "vsd/core/error.hpp"
#include "vsd/core/meta_property.hpp"
#include "vsd/robotics/hardware_binding.hpp"

namespace vsd::robotics {

KinematicTree* JointController::tree() const noexcept {
  NamedModelInstance* o = owner();
  return o != nullptr ? o->find_extension<KinematicTree>() : nullptr;
}

namespace {

// True when clamping changed any value of @p q (compared with @p before).
bool clamped(const Model& m, std::vector<double>& q) {
  const std::vector<double> before = q;
  m.clamp(q.data());
  return q != before;
}

}  // namespace

// Connected by the SimState's robotics tracker (kinematic_tree.cpp), so every way of setting a target
// clears `done` at once, not only this class's setters.
void on_controller_changed(SimStateInstance& inst, const MetaProperty& p) {
  auto& c = static_cast<JointController&>(inst);
  if (&p == &JointController::vsd_prop_target() || &p == &JointController::vsd_prop_target_pose() ||
      &p == &JointController::vsd_prop_tip() ||
      (&p == &JointController::vsd_prop_mode() && (c.mode() == ControlMode::Position || c.mode() == ControlMode::Cartesian)))
    c.set_done(false);
}

void JointController::stop(std::string why) {
  trajectory_.reset();
  set_fault(std::move(why));
  set_mode(ControlMode::Idle);
}

void JointController::limits(const Model& m, std::vector<double>& v, std::vector<double>& a) const {
  v.clear();
  a.clear();
  for (const DofInfo& d : m.layout()) {
    v.push_back(d.velocity_limit > 0 ? d.velocity_limit : default_velocity());
    a.push_back(d.acceleration_limit > 0 ? d.acceleration_limit : default_acceleration());
  }
}

void JointController::step(double dt) {
  if (mode() == ControlMode::Idle || !(dt > 0)) return;
  KinematicTree* t = tree();
  if (t == nullptr) return stop("no KinematicTree on the controller's node");
  // Bound to hardware: hold while the adapters do not deliver (the binding sends hold commands), and
  // replan from the measured positions once they do again.
  HardwareBinding* hw = owner()->find_extension<HardwareBinding>();
  if (hw != nullptr && !hw->active()) hw = nullptr;
  if (hw != nullptr) {
    if (hw->holding()) {
      // Whether the target is reached is not known while the robot does not report.
      if (mode() == ControlMode::Position || mode() == ControlMode::Cartesian) set_done(false);
      return;
    }
    if (hw->synchronisations() != seen_synchronisations_) {
      seen_synchronisations_ = hw->synchronisations();
      trajectory_.reset();
    }
  }
  const Model& m = t->model();
  const auto n = static_cast<std::size_t>(m.dof());
  std::vector<double> q = t->positions();
  std::vector<double> qd(n, 0.0);
  std::vector<double> vmax, amax;
  limits(m, vmax, amax);

  switch (mode()) {
    case ControlMode::Idle:
      return;
    case ControlMode::Position: {
      if (target().size() != n)
        return stop("target has " + std::to_string(target().size()) + " values; the tree has " +
                    std::to_string(n));
      if (!trajectory_ || planned_for_ != target() || trajectory_->size() != n) {
        std::vector<double> goal = target();
        set_limited(clamped(m, goal));
        trajectory_ = JointTrajectory::plan(interpolation(), q, goal, vmax, amax);
        planned_for_ = target();
        elapsed_ = 0.0;
        set_done(false);
      }
      elapsed_ += dt;
      trajectory_->sample(elapsed_, q.data(), qd.data());
      if (elapsed_ >= trajectory_->duration()) set_done(true);
      break;
    }
    case ControlMode::Velocity: {
      if (target_velocity().size() != n)
        return stop("target_velocity has " + std::to_string(target_velocity().size()) +
                    " values; the tree has " + std::to_string(n));
      std::vector<double> before = q;
      for (std::size_t i = 0; i < n; ++i) q[i] += std::clamp(target_velocity()[i], -vmax[i], vmax[i]) * dt;
      set_limited(clamped(m, q));
      for (std::size_t i = 0; i < n; ++i) qd[i] = (q[i] - before[i]) / dt;
      break;
    }
    case ControlMode::Cartesian: {
      const int body = m.find_body(tip());
      if (body < 0) return stop("no body '" + tip() + "' in the tree");
      Model::Data data = m.make_data();
      m.forward(q.data(), data);
      const Frame& f = m.pose(data, body);
      Eigen::Matrix<double, 6, 1> e;
      e.head<3>() = target_pose().translation() - f.translation;
      const Eigen::AngleAxisd aa(target_pose().linear() * f.rotation.transpose());
      e.tail<3>() = aa.angle() * aa.axis();
      if (e.head<3>().norm() <= cartesian_tolerance() && e.tail<3>().norm() <= cartesian_tolerance()) {
        set_done(true);
        set_limited(false);
        break;
      }
      set_done(false);
      Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, static_cast<Eigen::Index>(n));
      m.jacobian(data, body, j);
      Eigen::Matrix<double, 6, 6> a = j * j.transpose();
      a.diagonal().array() += 1e-4;  // damping near singularities
      const Eigen::VectorXd v = j.transpose() * a.llt().solve(cartesian_gain() * e);
      // Scale the whole step so that no joint exceeds its speed: the path stays straight in task space.
      double scale = 1.0;
      for (std::size_t i = 0; i < n; ++i)
        scale = std::min(scale, vmax[i] / std::max(std::abs(v[static_cast<Eigen::Index>(i)]), 1e-300));
      std::vector<double> before = q;
      for (std::size_t i = 0; i < n; ++i) q[i] += scale * v[static_cast<Eigen::Index>(i)] * dt;
      set_limited(clamped(m, q));
      for (std::size_t i = 0; i < n; ++i) qd[i] = (q[i] - before[i]) / dt;
      break;
    }
  }
  if (hw != nullptr) return hw->command(q, qd);  // the binding writes what the robot measures
  t->set_positions(q);
  const std::vector<DofInfo> layout(m.layout().begin(), m.layout().end());
  for (std::size_t i = 0; i < n; ++i)
    if (layout[i].axis_index == 0) const_cast<KinematicJoint*>(layout[i].joint)->set_velocity(qd[i]);
}

}  // namespace vsd::robotics
