/** @file
 *  @brief Scene: the root Node3D of a loaded description (a robot, a world). It holds compositely what its
 *  hulls and links share — geometries, maps, materials — and the joints, so a saved or replicated
 *  subtree carries everything it references.
 */
#pragma once

#include <string>

#include "vsd/core/reference.hpp"
#include "vsd/scene/geometry.hpp"
#include "vsd/scene/joint.hpp"
#include "vsd/scene/material.hpp"
#include "vsd/scene/node3d.hpp"
#include "vsd/scene/texture_map.hpp"

namespace vsd::scene {

class Scene : public Node3D {
  VSD_INSTANCE(Scene, Node3D)
  /// The file it was loaded from (empty when built in code).
  VSD_PROPERTY(std::string, source, "")
  VSD_PROPERTY(vsd::RefList<Geometry>, geometries, {}, vsd::Savable | vsd::Distributed)
  VSD_PROPERTY(vsd::RefList<Material>, materials, {}, vsd::Savable | vsd::Distributed)
  VSD_PROPERTY(vsd::RefList<TextureMap>, maps, {}, vsd::Savable | vsd::Distributed)
  VSD_PROPERTY(vsd::RefList<Joint>, joints, {}, vsd::Savable | vsd::Distributed)

 public:
  /// @brief The joint named @p name, or nullptr.
  [[nodiscard]] Joint* find_joint(std::string_view name) const noexcept;
  /// @brief The link named @p name anywhere below this scene, or nullptr.
  [[nodiscard]] Link* find_link(std::string_view name) const;
  /// @brief Every link below this scene, depth first.
  [[nodiscard]] std::vector<Link*> links() const;
};

}  // namespace vsd::scene
