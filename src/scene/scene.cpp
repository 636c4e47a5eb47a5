#include "vsd/scene/scene.hpp"

#include "vsd/scene/link.hpp"

namespace vsd::scene {

Eigen::Matrix3d Link::inertia() const {
  const Eigen::Vector3d& d = inertia_diagonal();
  const Eigen::Vector3d& o = inertia_products();  // xy, xz, yz
  Eigen::Matrix3d m;
  m << d.x(), o.x(), o.y(),  //
      o.x(), d.y(), o.z(),   //
      o.y(), o.z(), d.z();
  return m;
}

Joint* Scene::find_joint(std::string_view name) const noexcept {
  for (Joint* j : joints())
    if (j->name() == name) return j;
  return nullptr;
}

std::vector<Link*> Scene::links() const {
  std::vector<Link*> out;
  // visit() is non-const; the walk does not change anything.
  const_cast<Scene*>(this)->visit([&](vsd::Node& n) {
    if (auto* l = n.as<Link>()) out.push_back(l);
  });
  return out;
}

Link* Scene::find_link(std::string_view name) const {
  for (Link* l : links())
    if (l->name() == name) return l;
  return nullptr;
}

}  // namespace vsd::scene
