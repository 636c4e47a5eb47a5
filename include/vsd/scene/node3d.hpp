/** @file
 *  @brief Node3D: a Node with a frame relative to its parent and a cached world frame.
 *
 *  The frame of a Node3D is relative to its nearest Node3D ancestor (plain Nodes in between are
 *  transparent: they group without moving). world_frame() is a plain load while the cache is clean.
 *
 *  Keeping the cache current is lazy: a change of `frame` (through the setter, MetaProperty::set, a
 *  loaded file or an applied Transaction alike) and every re-parenting mark the node and the clean part
 *  of its subtree dirty; the next read recomputes the dirty chain from the nearest clean ancestor down.
 *  Lazy, not eager, because a simulation step typically moves many bodies before anyone reads a world
 *  frame, and many nodes (hidden hulls, far-away parts) are not read every step: an eager update would
 *  recompute a deep subtree once per change instead of once per read. Marking stops at nodes that are
 *  already dirty (a clean node's ancestors are always clean), so a burst of changes costs O(1) per
 *  change amortised, and nothing above or beside the moved node is touched.
 *
 *  How the changes are seen: the first time a world frame is computed in a SimState, vsd::scene
 *  connects three listeners to that SimState (property changes of Node3D and its subclasses, child
 *  added, child removed). A node's cache is only ever clean after those listeners exist, so no change can
 *  slip past them. The listeners only cost the Node3D setters their slow path (the signal); setters of
 *  other classes return to their fast path after one change.
 */
#pragma once

#include <Eigen/Geometry>
#include <cstdint>

#include "vsd/core/meta_type_eigen.hpp"
#include "vsd/core/node.hpp"
#include "vsd/scene/namespace.hpp"

namespace vsd::scene {

struct WorldFrameWatch;

class Node3D : public vsd::Node {
  VSD_INSTANCE(Node3D, vsd::Node)
  /// Frame relative to the nearest Node3D ancestor (the world when there is none).
  VSD_PROPERTY(Eigen::Isometry3d, frame, Eigen::Isometry3d::Identity())

 public:
  /// @brief The frame in world coordinates: the product of the frames from the top Node3D down to this
  /// one. A plain load while the cache is clean; never stale.
  [[nodiscard]] const Eigen::Isometry3d& world_frame() const {
    if (VSD_LIKELY(world_clean_)) return world_;
    return update_world_frame();
  }
  /// @brief Moves the node so that its world frame becomes @p world (sets `frame` accordingly).
  void set_world_frame(const Eigen::Isometry3d& world);
  /// @brief The nearest Node3D ancestor (through plain Nodes), or nullptr for a top-level Node3D.
  [[nodiscard]] Node3D* frame_parent() const noexcept;
  /// @brief True while the cached world frame is current (for tests and diagnostics).
  [[nodiscard]] bool world_frame_clean() const noexcept { return world_clean_; }
  /// @brief How often this node's world frame was recomputed (for tests and diagnostics).
  [[nodiscard]] std::uint64_t world_frame_updates() const noexcept { return world_updates_; }

  /// @brief Marks @p node (when it is a Node3D) and the clean Node3Ds below it dirty. Called by the
  /// state's world-frame watch; stops below nodes that are already dirty.
  static void invalidate_below(vsd::Node& node);

 private:
  const Eigen::Isometry3d& update_world_frame() const;

  mutable Eigen::Isometry3d world_ = Eigen::Isometry3d::Identity();
  mutable std::uint64_t world_updates_ = 0;
  mutable bool world_clean_ = false;
  mutable bool tracked_ = false;  // the world-frame watch of this node's SimState is known to exist
  friend struct WorldFrameWatch;
};

}  // namespace vsd::scene
