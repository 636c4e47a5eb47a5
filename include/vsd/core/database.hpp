/** @file
 *  @brief Database: the root node of a SimState and the Container of its spanning tree.
 */
#pragma once

#include "vsd/core/container.hpp"
#include "vsd/core/node.hpp"

namespace vsd {

/// @brief Every SimState has exactly one Database, with id 1; every node reachable from it through
/// children is "in the database". Its added/removed signals fire for the root of each subtree that is
/// attached to or detached from the tree.
class Database : public Node, public Container {
  VSD_INSTANCE(Database, Node)

 public:
  /// @brief Number of nodes in the tree, the root included.
  [[nodiscard]] std::size_t size() const override;
  /// @brief True when @p n is the root or one of its descendants.
  [[nodiscard]] bool contains(const Node& n) const override;
  /// @brief Depth-first, parents before children.
  void for_each(const std::function<void(Node&)>& fn) const override;

 private:
  friend class SimState;
  void notify_attached(Node& parent, Node& child);
  void notify_detached(Node& parent, Node& child);
};

}  // namespace vsd
