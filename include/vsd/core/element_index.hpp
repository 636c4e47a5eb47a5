/** @file
 *  @brief ElementIndex: for every MetaInstance, the live instances of that type — the table view of
 *  the database graph, kept current on create and delete.
 */
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "vsd/core/instance.hpp"
#include "vsd/core/signal.hpp"

namespace vsd {

class ElementIndex {
 public:
  using InstanceSignal = Signal<void(SimStateInstance&)>;
  using InstanceSink = Sink<void(SimStateInstance&)>;

  /// @brief Instances of exactly class @p m (no subclasses), in no particular order.
  [[nodiscard]] std::span<SimStateInstance* const> exact(const MetaInstance& m) const noexcept;
  /// @brief Number of instances of @p m, with or without subclasses.
  [[nodiscard]] std::size_t count(const MetaInstance& m, bool include_subtypes = true) const;
  /// @brief Calls @p fn for every instance of @p m and, when asked, of its subclasses.
  template <class F>
  void for_each(const MetaInstance& m, bool include_subtypes, F&& fn) const {
    for (SimStateInstance* i : exact(m)) fn(*i);
    if (include_subtypes)
      for (const MetaInstance* d : m.derived()) for_each(*d, true, fn);
  }
  /// @brief Typed view of the instances of exactly T.
  template <class T>
  [[nodiscard]] std::vector<T*> of() const {
    std::vector<T*> out;
    for (SimStateInstance* i : exact(T::static_meta())) out.push_back(static_cast<T*>(i));
    return out;
  }
  /// @brief All instances of T, subclasses (built-in and run-time) included.
  template <class T>
  [[nodiscard]] std::vector<T*> all() const {
    std::vector<T*> out;
    for_each(T::static_meta(), true, [&](SimStateInstance& i) { out.push_back(static_cast<T*>(&i)); });
    return out;
  }

  /// @brief Emitted when an instance of @p m (or, with @p include_subtypes, of a subclass) is created.
  [[nodiscard]] InstanceSink on_created(const MetaInstance& m, bool include_subtypes = true);
  /// @brief Emitted when an instance of @p m (or a subclass) is about to be deleted.
  [[nodiscard]] InstanceSink on_deleted(const MetaInstance& m, bool include_subtypes = true);

 private:
  friend class SimState;
  struct Bucket {
    std::vector<SimStateInstance*> items;
    std::unique_ptr<InstanceSignal> created_exact, created_tree, deleted_exact, deleted_tree;
  };
  Bucket& bucket(const MetaInstance& m);
  [[nodiscard]] bool has_signals() const noexcept { return signals_ != 0; }
  void add(SimStateInstance& i) {
    const std::size_t k = i.meta().index();
    auto& items = (VSD_LIKELY(k < buckets_.size()) ? buckets_[k] : bucket(i.meta())).items;
    i.index_pos_ = static_cast<std::uint32_t>(items.size());
    items.push_back(&i);
  }
  void remove(SimStateInstance& i) noexcept {
    auto& items = buckets_[i.meta().index()].items;
    SimStateInstance* last = items.back();
    items[i.index_pos_] = last;  // swap-remove keeps every operation O(1)
    last->index_pos_ = i.index_pos_;
    items.pop_back();
  }
  /// Makes room for @p count more instances of exactly @p m.
  void reserve(const MetaInstance& m, std::size_t count) {
    auto& items = bucket(m).items;
    items.reserve(items.size() + count);
  }
  template <class F>
  void for_each_listener(const SimStateInstance& i, bool created, F&& fn);
  void emit_created(SimStateInstance& i);
  void emit_deleted(SimStateInstance& i);

  std::vector<Bucket> buckets_;  // indexed by MetaInstance::index()
  std::size_t signals_ = 0;      // per-type signals made so far
};

}  // namespace vsd
