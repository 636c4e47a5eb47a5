/** @file
 *  @brief Container: a collection of nodes with added/removed signals; View: a live, filtered and
 *  ordered subset of a SimState's nodes.
 *
 *  The Database (the spanning tree) is the main Container. Views arrange all nodes or a subset in
 *  another order and stay current by listening to the SimState, so nothing polls.
 */
#pragma once

#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "vsd/core/node.hpp"
#include "vsd/core/signal.hpp"

namespace vsd {

class SimState;

class Container {
 public:
  using NodeSignal = Signal<void(Node&)>;

  Container() = default;
  Container(const Container&) = delete;
  Container& operator=(const Container&) = delete;
  virtual ~Container() = default;

  /// @brief Number of nodes in the container.
  [[nodiscard]] virtual std::size_t size() const = 0;
  [[nodiscard]] virtual bool contains(const Node& n) const = 0;
  /// @brief Calls @p fn for every node, in the container's order.
  virtual void for_each(const std::function<void(Node&)>& fn) const = 0;

  /// @brief Emitted when a node enters the container.
  NodeSignal& on_added() noexcept { return added_; }
  /// @brief Emitted when a node leaves the container (while it is still whole).
  NodeSignal& on_removed() noexcept { return removed_; }

 protected:
  NodeSignal added_;
  NodeSignal removed_;
};

/// @brief A live view onto the nodes of a SimState: those passing a filter, in a given order.
///
/// The view re-evaluates a node when it is created, deleted, or one of its properties changes. With no
/// order it keeps creation order. The view must not outlive its SimState.
class View : public Container {
 public:
  using Filter = std::function<bool(const Node&)>;
  using Order = std::function<bool(const Node&, const Node&)>;

  explicit View(SimState& state, Filter filter = {}, Order order = {});
  ~View() override;

  [[nodiscard]] std::size_t size() const override { return nodes_.size(); }
  [[nodiscard]] bool contains(const Node& n) const override;
  void for_each(const std::function<void(Node&)>& fn) const override;
  /// @brief The nodes, in order.
  [[nodiscard]] std::span<Node* const> nodes() const noexcept { return nodes_; }
  [[nodiscard]] auto begin() const noexcept { return nodes_.begin(); }
  [[nodiscard]] auto end() const noexcept { return nodes_.end(); }

 private:
  void consider(SimStateInstance& inst);
  void drop(SimStateInstance& inst);
  void place(Node& n);

  Filter filter_;
  Order order_;
  std::vector<Node*> nodes_;
  std::vector<Connection> connections_;
};

}  // namespace vsd
