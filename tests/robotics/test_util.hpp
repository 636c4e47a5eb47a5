// Helpers of the robotics tests: robot files, random joint vectors, URDF text of a DH table.
#pragma once

#include <Eigen/Geometry>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "vsd/robotics/model.hpp"

namespace vsd_test {

inline std::string robot_file(const std::string& name) {
  return std::string(VSD_ROBOTICS_TEST_DATA_DIR) + "/" + name;
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A joint vector within the limits (unlimited joints in [-pi, pi] or [-1, 1] m).
inline std::vector<double> random_q(const vsd::robotics::Model& m, std::mt19937_64& rng) {
  std::vector<double> q;
  for (const auto& d : m.layout()) {
    double lo =
        d.has_limits ? d.lower : (d.type == vsd::robotics::KinematicJointType::Prismatic ? -1.0 : -3.14159);
    double hi = d.has_limits ? d.upper : -lo;
    q.push_back(std::uniform_real_distribution<double>(lo, hi)(rng));
  }
  return q;
}

inline std::string num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

/// "xyz=... rpy=..." of a transform, for URDF text.
inline std::string urdf_origin(const Eigen::Isometry3d& f) {
  const Eigen::Vector3d ypr = f.linear().eulerAngles(2, 1, 0);
  const Eigen::Vector3d t = f.translation();
  return "<origin xyz=\"" + num(t.x()) + " " + num(t.y()) + " " + num(t.z()) + "\" rpy=\"" + num(ypr[2]) +
         " " + num(ypr[1]) + " " + num(ypr[0]) + "\"/>";
}

}  // namespace vsd_test
