/** @file
 *  @brief Hull: a placed piece of geometry (visual or collision) with its maps and material.
 *
 *  Geometry, maps and material are shared references: one mesh, texture or material serves many hulls,
 *  and deleting it nulls the references (the hulls emit property changes, so a collision or rendering
 *  module following them hears of it). Maps are shared rather than composite because a texture (a
 *  radar map, a colour atlas) is typically used by many hulls; the Scene holds them compositely.
 */
#pragma once

#include <cstdint>

#include "vsd/core/reference.hpp"
#include "vsd/scene/geometry.hpp"
#include "vsd/scene/material.hpp"
#include "vsd/scene/node3d.hpp"
#include "vsd/scene/texture_map.hpp"

namespace vsd::scene {

/// @brief What a hull is for.
enum class HullRole : std::uint8_t {
  Visual,    ///< rendering and sensors
  Collision  ///< collision detection and contact dynamics
};
VSD_ENUM(HullRole, Visual, Collision)

class Hull : public Node3D {
  VSD_INSTANCE(Hull, Node3D)
  VSD_PROPERTY(HullRole, role, HullRole::Visual)
  VSD_PROPERTY(vsd::SharedRef<Geometry>, geometry, nullptr)
  VSD_PROPERTY(vsd::SharedRefList<TextureMap>, maps, {})
  VSD_PROPERTY(vsd::SharedRef<Material>, material, nullptr)
};

}  // namespace vsd::scene
