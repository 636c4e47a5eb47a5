// KinematicJoint: placement of every joint kind as pre * motion(q) * post.
#include "vsd/robotics/joint.hpp"

#include <cmath>

namespace vsd::robotics {

namespace {

Eigen::Isometry3d rot_x(double a) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()));
}
Eigen::Isometry3d rot_z(double a) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()));
}
Eigen::Isometry3d trans(double x, double y, double z) {
  return Eigen::Isometry3d(Eigen::Translation3d(x, y, z));
}

Eigen::Isometry3d move(KinematicJointType type, const Eigen::Vector3d& axis, double q) {
  if (type == KinematicJointType::Prismatic) return Eigen::Isometry3d(Eigen::Translation3d(axis * q));
  return Eigen::Isometry3d(Eigen::AngleAxisd(q, axis.normalized()));
}

}  // namespace

int KinematicJoint::dof() const noexcept {
  switch (type()) {
    case KinematicJointType::Fixed:
      return 0;
    case KinematicJointType::Universal:
      return 2;
    default:
      return 1;
  }
}

JointPlacement KinematicJoint::placement() const {
  JointPlacement p;
  const bool prismatic = type() == KinematicJointType::Prismatic;
  switch (dh()) {
    case DhConvention::None:
      p.pre = origin();
      p.axis = axis();
      break;
    case DhConvention::Standard:
      // Rz(theta + q) Tz(d + q') Tx(a) Rx(alpha): the variable sits between Rz(theta) and the rest.
      if (prismatic) {
        p.pre = rot_z(dh_theta()) * trans(0, 0, dh_d());
        p.post = trans(dh_a(), 0, 0) * rot_x(dh_alpha());
      } else {
        p.pre = rot_z(dh_theta());
        p.post = trans(0, 0, dh_d()) * trans(dh_a(), 0, 0) * rot_x(dh_alpha());
      }
      break;
    case DhConvention::Modified:
      // Rx(alpha) Tx(a) Rz(theta + q) Tz(d + q').
      if (prismatic) {
        p.pre = rot_x(dh_alpha()) * trans(dh_a(), 0, 0) * rot_z(dh_theta()) * trans(0, 0, dh_d());
      } else {
        p.pre = rot_x(dh_alpha()) * trans(dh_a(), 0, 0) * rot_z(dh_theta());
        p.post = trans(0, 0, dh_d());
      }
      break;
  }
  return p;
}

Eigen::Isometry3d KinematicJoint::motion_frame(double q1, double q2) const {
  const JointPlacement p = placement();
  Eigen::Isometry3d f = p.pre;
  if (p.axis.norm() > 0.0) {
    switch (type()) {
      case KinematicJointType::Fixed:
        break;
      case KinematicJointType::Universal:
        f = f * move(KinematicJointType::Rotary, p.axis, q1);
        if (axis2().norm() > 0.0) f = f * move(KinematicJointType::Rotary, axis2(), q2);
        break;
      default:
        f = f * move(type(), p.axis.normalized(), q1);
        break;
    }
  }
  f = f * p.post;
  f.makeAffine();
  return f;
}

namespace {

// The angle of the rotation @p r about the unit axis @p a: the rotation of a vector perpendicular to the
// axis, projected onto the plane perpendicular to it (exact for a rotation about @p a).
double angle_about(const Eigen::Matrix3d& r, const Eigen::Vector3d& a) {
  Eigen::Vector3d b = a.unitOrthogonal();
  const Eigen::Vector3d c = a.cross(b);
  const Eigen::Vector3d rb = r * b;
  return std::atan2(c.dot(rb), b.dot(rb));
}

// @p q moved by whole turns to the one nearest @p near.
double nearest_turn(double q, double near) {
  if (!std::isfinite(near)) return q;
  constexpr double turn = 2.0 * 3.14159265358979323846;
  return q + turn * std::round((near - q) / turn);
}

}  // namespace

std::pair<double, double> KinematicJoint::values_of(const Eigen::Isometry3d& frame) const {
  const JointPlacement p = placement();
  if (type() == KinematicJointType::Fixed || p.axis.norm() == 0.0) return {position(), position2()};
  const Eigen::Isometry3d m = p.pre.inverse() * frame * p.post.inverse();
  const Eigen::Vector3d a = p.axis.normalized();
  switch (type()) {
    case KinematicJointType::Prismatic:
      return {a.dot(m.translation()), position2()};
    case KinematicJointType::Universal: {
      if (axis2().norm() == 0.0 || a.cross(axis2().normalized()).norm() < 1e-12)
        return {nearest_turn(angle_about(m.linear(), a), position()), 0.0};
      // R = Rot(a, q1) Rot(a2, q2) turns a2 like Rot(a, q1) does: q1 from where a2 went, then q2.
      const Eigen::Vector3d a2 = axis2().normalized();
      const Eigen::Vector3d b = (a2 - a * a.dot(a2)).normalized();
      const Eigen::Vector3d c = a.cross(b);
      const Eigen::Vector3d ra2 = m.linear() * a2;
      const double q1 = nearest_turn(std::atan2(c.dot(ra2), b.dot(ra2)), position());
      const Eigen::Matrix3d rest = Eigen::AngleAxisd(q1, a).toRotationMatrix().transpose() * m.linear();
      return {q1, nearest_turn(angle_about(rest, a2), position2())};
    }
    default:
      return {nearest_turn(angle_about(m.linear(), a), position()), position2()};
  }
}

void KinematicJoint::set_dh_parameters(DhConvention convention, const DhParameters& p) {
  set_dh(convention);
  set_dh_a(p.a);
  set_dh_alpha(p.alpha);
  set_dh_d(p.d);
  set_dh_theta(p.theta);
}

}  // namespace vsd::robotics
