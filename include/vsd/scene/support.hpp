/** @file
 *  @brief Support: the extension that makes a spatial relation database state — its node (the object)
 *  moves with `support` ("lies on", "grabbed by", "attached to"); see vsd/scene/spatial_view.hpp.
 *
 *  Because the relation is an ordinary extension with ordinary properties, it is saved and loaded by
 *  vsd::io, recorded in transactions and applied by replicas like any other change; a SpatialView reads
 *  it (and SpatialView::relate() / release() write it through the setters). The object's pose relative to
 *  its support is not stored: while a relation is in force the view keeps it equal to the current
 *  relative pose, so the saved frames already hold it.
 */
#pragma once

#include <cstdint>

#include "vsd/core/extension.hpp"
#include "vsd/core/reference.hpp"
#include "vsd/scene/namespace.hpp"
#include "vsd/scene/node3d.hpp"

namespace vsd::scene {

/// @brief How an object relates to its support (all of them mean "moves with it" to the view; the kind
/// tells applications what it means: a gripper releases what it grabbed, not what lies on it).
enum class SpatialRelation : std::uint8_t {
  LiesOn,     ///< resting on the support (a cup on a table)
  GrabbedBy,  ///< held by a gripper or a hand
  AttachedTo  ///< fixed to the support (a sensor on a vehicle)
};
VSD_ENUM(SpatialRelation, LiesOn, GrabbedBy, AttachedTo)

class Support : public vsd::Extension {
  VSD_INSTANCE(Support, vsd::Extension)
  /// The node the owner moves with; null (e.g. after the support was deleted): no relation.
  VSD_PROPERTY(vsd::SharedRef<Node3D>, support, nullptr)
  VSD_PROPERTY(SpatialRelation, relation, SpatialRelation::LiesOn)
};

}  // namespace vsd::scene
