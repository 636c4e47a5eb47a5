/** @file
 *  @brief Node: a NamedModelInstance with children — the building block of the database graph.
 *
 *  Children are composite references: a node keeps its children alive, deleting a node deletes the
 *  children that nothing else holds, and moving a child to a new parent never lets it die on the way.
 */
#pragma once

#include <string_view>
#include <vector>

#include "vsd/core/named_model_instance.hpp"

namespace vsd {

class Node : public NamedModelInstance {
  VSD_INSTANCE(Node, NamedModelInstance)
  VSD_PROPERTY(RefList<Node>, children, {}, Savable | Distributed)

 public:
  /// @brief The parent node (the first node holding this one as a child), or nullptr.
  [[nodiscard]] Node* parent() const noexcept;
  /// @brief Appends @p child, moving it from its former parent.
  /// @throws vsd::Error when the child is this node or one of its ancestors, or lives in another SimState.
  Node& add_child(Node& child);
  /// @brief Inserts @p child at @p index (moving it from its former parent).
  Node& insert_child(std::size_t index, Node& child);
  /// @brief Removes @p child; it is deleted when nothing else holds it compositely.
  /// @throws vsd::Error when @p child is not a child of this node.
  void remove_child(Node& child);
  /// @brief The first child named @p name, or nullptr.
  [[nodiscard]] Node* find_child(std::string_view name) const noexcept;
  /// @brief Names from the root down, joined by '/': "/robot/arm".
  [[nodiscard]] std::string path() const;
  /// @brief Calls @p fn for this node and every descendant, depth first, parents before children. A loop,
  /// not a recursion: a tree of any depth fits the stack.
  template <class F>
  void visit(F&& fn) {
    std::vector<Node*> todo{this};
    while (!todo.empty()) {
      Node* n = todo.back();
      todo.pop_back();
      fn(*n);
      for (std::size_t i = n->children_.size(); i-- > 0;) todo.push_back(n->children_[i]);
    }
  }
};

}  // namespace vsd
