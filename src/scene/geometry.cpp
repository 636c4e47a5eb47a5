#include "vsd/scene/geometry.hpp"

#include <sstream>

namespace vsd::scene {

std::string Geometry::describe() const {
  std::ostringstream s;
  switch (kind_) {
    case GeometryKind::Box:
      s << "box " << size_.x() << " x " << size_.y() << " x " << size_.z();
      break;
    case GeometryKind::Sphere:
      s << "sphere r " << radius_;
      break;
    case GeometryKind::Cylinder:
      s << "cylinder r " << radius_ << " l " << length_;
      break;
    case GeometryKind::Capsule:
      s << "capsule r " << radius_ << " l " << length_;
      break;
    case GeometryKind::Plane:
      s << "plane n [" << normal_.x() << ", " << normal_.y() << ", " << normal_.z() << "]";
      break;
    case GeometryKind::Mesh:
      s << "mesh " << (source_.empty() ? std::string("(inline)") : source_);
      if (has_mesh_data()) {
        s << ": " << vertices_.size() << " vertices, " << facet_count() << " facets";
      } else {
        s << " (not loaded)";
      }
      if (scale_ != Eigen::Vector3d::Ones())
        s << ", scale [" << scale_.x() << ", " << scale_.y() << ", " << scale_.z() << "]";
      break;
  }
  return s.str();
}

}  // namespace vsd::scene
