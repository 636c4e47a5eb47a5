// Builds an Orocos KDL chain from a URDF through urdfdom, the way ROS's kdl_parser does (Debian ships no
// kdl_parser): each segment's joint sits at the joint origin, with the axis rotated into the parent frame.
// Used by the robotics tests and benchmarks only; KDL is never a dependency of vsd::robotics itself.
#pragma once

#include <urdf_parser/urdf_parser.h>

#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace vsd_test {

inline KDL::Frame to_kdl(const urdf::Pose& p) {
  return KDL::Frame(KDL::Rotation::Quaternion(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w),
                    KDL::Vector(p.position.x, p.position.y, p.position.z));
}

inline KDL::Joint to_kdl(const urdf::Joint& j) {
  const KDL::Frame f = to_kdl(j.parent_to_joint_origin_transform);
  const KDL::Vector axis(j.axis.x, j.axis.y, j.axis.z);
  switch (j.type) {
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS:
      return KDL::Joint(j.name, f.p, f.M * axis, KDL::Joint::RotAxis);
    case urdf::Joint::PRISMATIC:
      return KDL::Joint(j.name, f.p, f.M * axis, KDL::Joint::TransAxis);
    default:
      return KDL::Joint(j.name, KDL::Joint::None);
  }
}

/// The KDL chain from link @p base to link @p tip of the URDF text @p xml.
inline KDL::Chain kdl_chain(const std::string& xml, const std::string& base, const std::string& tip) {
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(xml);
  if (!model) throw std::runtime_error("urdfdom could not parse the URDF");
  std::vector<urdf::JointConstSharedPtr> joints;
  for (urdf::LinkConstSharedPtr l = model->getLink(tip); l && l->name != base; l = l->getParent()) {
    if (!l->parent_joint) throw std::runtime_error(tip + " is not below " + base);
    joints.insert(joints.begin(), l->parent_joint);
  }
  KDL::Chain chain;
  for (const auto& j : joints)
    chain.addSegment(
        KDL::Segment(j->child_link_name, to_kdl(*j), to_kdl(j->parent_to_joint_origin_transform)));
  return chain;
}

}  // namespace vsd_test
