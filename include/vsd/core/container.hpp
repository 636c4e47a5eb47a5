/** @file
 *  @brief Container: a collection of nodes with added/removed signals; View and TypedView<T>: a live,
 *  filtered and ordered subset of a SimState's nodes of one class.
 *
 *  The Database (the spanning tree) is the main Container. Views arrange all nodes or a subset in
 *  another order and stay current by listening to the SimState, so nothing polls.
 */
#pragma once

#include <cstddef>
#include <functional>
#include <span>
#include <type_traits>
#include <unordered_set>
#include <vector>

#include "vsd/core/node.hpp"
#include "vsd/core/signal.hpp"

namespace vsd {

class SimState;

class Container {
 public:
  using NodeSignal = Signal<void(Node&)>;
  using NodeSink = Sink<void(Node&)>;

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
  [[nodiscard]] NodeSink on_added() noexcept { return NodeSink(added_); }
  /// @brief Emitted when a node leaves the container (while it is still whole).
  [[nodiscard]] NodeSink on_removed() noexcept { return NodeSink(removed_); }

 protected:
  NodeSignal added_;
  NodeSignal removed_;
};

/// @brief A live view onto the nodes of a SimState: those of a class that pass a filter, in a given order.
///
/// The view re-evaluates a node when it is created, deleted, or one of its properties changes, listening
/// only to the viewed class (and its subclasses), so changes elsewhere in the state cost it nothing.
/// With no order it keeps creation order, which is id order: a node that leaves the view and comes back
/// takes its old place again. With an order, equal nodes keep the order in which they entered.
/// The view must not outlive its SimState. TypedView<T> is the same with filters, orders and iteration
/// typed on the viewed class.
class View : public Container {
 public:
  using Filter = std::function<bool(const Node&)>;
  using Order = std::function<bool(const Node&, const Node&)>;

  /// @brief A view of all nodes of @p state that pass @p filter (all when empty), ordered by @p order.
  explicit View(SimState& state, Filter filter = {}, Order order = {});
  /// @brief A view of the nodes of class @p cls (and its subclasses) that pass @p filter.
  /// @throws vsd::Error when @p cls is not Node or a subclass of it.
  View(SimState& state, const MetaInstance& cls, Filter filter = {}, Order order = {});
  ~View() override;

  /// @brief The class whose nodes the view holds (Node unless one was given).
  [[nodiscard]] const MetaInstance& viewed_class() const noexcept { return *cls_; }
  [[nodiscard]] std::size_t size() const override { return nodes_.size(); }
  [[nodiscard]] bool contains(const Node& n) const override { return members_.contains(&n); }
  void for_each(const std::function<void(Node&)>& fn) const override;
  /// @brief The nodes, in order.
  [[nodiscard]] std::span<Node* const> nodes() const noexcept { return nodes_; }
  [[nodiscard]] auto begin() const noexcept { return nodes_.begin(); }
  [[nodiscard]] auto end() const noexcept { return nodes_.end(); }

 private:
  void consider(SimStateInstance& inst);
  void drop(SimStateInstance& inst);
  void place(Node& n);
  void unplace(Node& n);

  const MetaInstance* cls_;
  Filter filter_;
  Order order_;
  std::vector<Node*> nodes_;
  std::unordered_set<const Node*> members_;
  std::vector<Connection> connections_;
};

/// @brief A View whose filter, order and iteration are typed on its class T (Node or a subclass).
/// @code
/// vsd::TypedView<Robot> fast(state, [](const Robot& r) { return r.speed() > 1; },
///                            [](const Robot& a, const Robot& b) { return a.speed() < b.speed(); });
/// for (Robot* r : fast) r->home();
/// @endcode
template <class T>
class TypedView : public View {
  static_assert(std::is_base_of_v<Node, T>, "a view holds nodes: T must be Node or derive from it");

 public:
  using Filter = std::function<bool(const T&)>;
  using Order = std::function<bool(const T&, const T&)>;

  /// @brief Iterates the view's nodes as T*.
  class iterator {
   public:
    using value_type = T*;
    using difference_type = std::ptrdiff_t;
    iterator() = default;
    explicit iterator(Node* const* p) noexcept : p_(p) {}
    T* operator*() const noexcept { return static_cast<T*>(*p_); }
    iterator& operator++() noexcept {
      ++p_;
      return *this;
    }
    iterator operator++(int) noexcept {
      auto c = *this;
      ++p_;
      return c;
    }
    bool operator==(const iterator& o) const noexcept { return p_ == o.p_; }

   private:
    Node* const* p_ = nullptr;
  };

  explicit TypedView(SimState& state, Filter filter = {}, Order order = {})
      : View(state, T::static_meta(), erase(std::move(filter)), erase(std::move(order))) {}

  [[nodiscard]] iterator begin() const noexcept { return iterator(nodes().data()); }
  [[nodiscard]] iterator end() const noexcept { return iterator(nodes().data() + nodes().size()); }
  /// @brief The node at position @p i of the view's order.
  [[nodiscard]] T* operator[](std::size_t i) const noexcept { return static_cast<T*>(nodes()[i]); }

 private:
  static View::Filter erase(Filter f) {
    if (!f) return {};
    return [f = std::move(f)](const Node& n) { return f(static_cast<const T&>(n)); };
  }
  static View::Order erase(Order o) {
    if (!o) return {};
    return [o = std::move(o)](const Node& a, const Node& b) {
      return o(static_cast<const T&>(a), static_cast<const T&>(b));
    };
  }
};

}  // namespace vsd
