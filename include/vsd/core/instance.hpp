/** @file
 *  @brief Instance and SimStateInstance: the roots of the M1 class hierarchy.
 *
 *  `Instance` is the base of everything in the database (and of Environment and SimState): it knows
 *  its MetaInstance and answers generic calls (vsdMetaCall). `SimStateInstance` belongs to one SimState,
 *  has a stable id, holds properties and is the target of references.
 *
 *  Ownership: a SimState owns its instances. They are made only by `SimState::create` and go away by
 *  `SimState::destroy`, by losing their last composite reference, or with their SimState. Instances
 *  never move in memory, so pointers to them stay valid until they are deleted; hold a SharedRef
 *  (nulled on deletion) where a pointer could outlive its target.
 */
#pragma once

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "vsd/core/config.hpp"
#include "vsd/core/meta_instance.hpp"
#include "vsd/core/reference.hpp"
#include "vsd/core/signal.hpp"
#include "vsd/core/value.hpp"

namespace vsd {

class SimState;
namespace detail {
class Applier;
}  // namespace detail

class Instance {
 public:
  static constexpr std::string_view vsd_class_name = "Instance";
  /// @brief The MetaInstance of Instance itself.
  static const MetaInstance& static_meta();

  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;
  virtual ~Instance();

  /// @brief The class of this instance (a run-time class for instances of run-time classes).
  [[nodiscard]] const MetaInstance& meta() const noexcept { return *meta_; }
  [[nodiscard]] bool is_a(const MetaInstance& m) const noexcept { return meta_->is_a(m); }
  template <class T>
  [[nodiscard]] bool is_a() const noexcept {
    return meta_->is_a(T::static_meta());
  }
  /// @brief This instance as a T, or nullptr when it is not one.
  template <class T>
  [[nodiscard]] T* as() noexcept {
    return is_a<T>() ? static_cast<T*>(this) : nullptr;
  }
  template <class T>
  [[nodiscard]] const T* as() const noexcept {
    return is_a<T>() ? static_cast<const T*>(this) : nullptr;
  }

  /// @brief vsdMetaCall: calls method @p name with @p args. @throws vsd::Error (see MetaInstance::call).
  Value call(std::string_view name, std::span<const Value> args = {});
  Value call(std::string_view name, std::initializer_list<Value> args) {
    return call(name, std::span<const Value>(args.begin(), args.size()));
  }

 protected:
  Instance() noexcept = default;
  void set_meta(const MetaInstance& m) noexcept { meta_ = &m; }

 private:
  friend class MetaInstance;
  const MetaInstance* meta_ = nullptr;
};

/// @brief Listener signature of property changes.
using PropertySignal = Signal<void(SimStateInstance&, const MetaProperty&)>;

class SimStateInstance : public Instance {
 public:
  static constexpr std::string_view vsd_class_name = "SimStateInstance";
  static const MetaInstance& static_meta();

  /// @brief The SimState this instance lives in.
  [[nodiscard]] SimState& state() const noexcept { return *state_; }
  /// @brief Stable id, unique in the Environment and equal in every replica.
  [[nodiscard]] Id id() const noexcept { return id_; }
  /// @brief Number of composite references to this instance.
  [[nodiscard]] std::uint32_t composite_count() const noexcept { return refs_; }
  /// @brief True from the moment its deletion starts.
  [[nodiscard]] bool is_being_deleted() const noexcept { return (life_ & dying_bit) != 0; }
  /// @brief True while no property has ever held this instance compositely: it was created and never
  /// attached. A floating instance is not deleted when its count falls back to zero (a free Ref or a
  /// rejected change that held it for a moment leaves it floating); it lives until it is deleted
  /// explicitly or attached and later released.
  [[nodiscard]] bool is_floating() const noexcept { return (life_ & floating_bit) != 0; }
  /// @brief Instances holding composite references to this one (a Node's parent among them).
  [[nodiscard]] std::vector<SimStateInstance*> composite_holders() const;
  /// @brief Every (instance, property) whose value refers to this one, composite and shared references
  /// alike (references held outside properties are not listed), oldest first, each pair once.
  [[nodiscard]] std::vector<std::pair<SimStateInstance*, const MetaProperty*>> referrers() const;
  /// @brief The first instance holding this one compositely through property @p p, or nullptr.
  [[nodiscard]] SimStateInstance* composite_holder(const MetaProperty& p) const noexcept;

  // ---- generic property access ----
  /// @brief Value of property @p name. @throws vsd::Error when the class has no such property.
  [[nodiscard]] Value get(std::string_view name) const;
  /// @brief Sets property @p name from a Value. @throws vsd::Error on unknown name, wrong type, ReadOnly.
  void set(std::string_view name, const Value& v);
  template <class T>
  [[nodiscard]] const T& get(std::string_view name) const {
    const MetaProperty& p = meta().property(name);  // of this instance's class: no owner check needed
    if (VSD_UNLIKELY(p.get_tag_ != detail::tag_of<T>()) && !p.views_as(meta_type<T>()))
      p.throw_type(meta_type<T>());
    return *static_cast<const T*>(p.address(*this));
  }
  template <class T>
  void set(std::string_view name, const T& v) {
    const MetaProperty& p = meta().property(name);
    if (VSD_UNLIKELY(p.set_tag_ != detail::tag_of<T>()) && !p.stores_from(meta_type<T>()))
      p.throw_set(meta_type<T>());
    assign_at(*static_cast<T*>(const_cast<void*>(p.address(*this))), v, p);
  }

  // ---- reference lists ----
  /// @brief Inserts @p target at @p index of list property @p p (index == size appends).
  /// @throws vsd::Error when @p p is not a reference list, the target's class does not fit, the index is
  /// out of range, or a composite insert would make an instance its own ancestor.
  void list_insert(const MetaProperty& p, std::size_t index, SimStateInstance& target);
  /// @brief Removes element @p index of list property @p p. Releasing the last composite reference
  /// deletes the element.
  void list_erase(const MetaProperty& p, std::size_t index);

  /// @brief True while a change of this instance is observed: someone listens to it (itself, its class,
  /// its state) or its state records. Otherwise a typed set is a compare and a store. (The flag is
  /// switched off lazily: the first change that finds nobody interested clears it.)
  [[nodiscard]] bool observed() const noexcept { return watch_ != 0; }
  /// @brief Listeners of every property change of this instance.
  [[nodiscard]] Sink<void(SimStateInstance&, const MetaProperty&)> on_changed();

 protected:
  SimStateInstance() noexcept = default;
  ~SimStateInstance() override;

  /// Store of a typed setter: one branch when nobody observes the instance.
  template <class T>
  void vsd_assign(T& field, const T& v, const MetaProperty& (*prop)()) {
    if (VSD_LIKELY(watch_ == 0)) {
      field = v;
    } else {
      assign_slow<T>(field, v, prop);
    }
  }

 private:
  friend class SimState;
  friend class MetaProperty;
  friend class MetaInstance;
  friend class ElementIndex;
  friend struct detail::RefAccess;
  friend class detail::Applier;
  static constexpr std::uint8_t dying_bit = 1;
  static constexpr std::uint8_t floating_bit = 2;  // never held compositely by a property yet
  static constexpr std::uint8_t own_watch = 1;     // this instance has listeners
  static constexpr std::uint8_t state_watch = 2;   // its SimState records or has state-wide listeners
  static constexpr std::uint8_t class_watch = 4;   // its class (or a base) has per-class listeners

  template <class T>
  void assign_at(T& field, const T& v, const MetaProperty& p) {
    if (VSD_LIKELY(watch_ == 0)) {
      field = v;
    } else {
      assign_slow<T>(field, v, p);
    }
  }
  // The observed store, kept out of the callers' loops: they pay a compare and a branch, nothing more.
  // Small values travel in registers, so the fast path never spills them for the slow one's sake.
  template <class T>
  using SlowArg = std::conditional_t<std::is_trivially_copyable_v<T> && sizeof(T) <= 16, T, const T&>;
  template <class T>
  VSD_NOINLINE void assign_slow(T& field, SlowArg<T> v, const MetaProperty& (*prop)()) {
    assign_watched(field, static_cast<const T&>(v), prop());
  }
  template <class T>
  VSD_NOINLINE void assign_slow(T& field, SlowArg<T> v, const MetaProperty& p) {
    assign_watched(field, static_cast<const T&>(v), p);
  }
  template <class T>
  void assign_watched(T& field, const T& v, const MetaProperty& p) {
    if constexpr (std::is_base_of_v<RefBase, T> || std::is_base_of_v<RefListBase, T>) {
      if (field == v) return;
    } else {
      if (detail::equal_values(field, v)) return;
    }
    T old(field);
    field = v;
    notify_changed(p, &old);
  }
  /// The slow path of every store: records the change and emits the signals.
  void notify_changed(const MetaProperty& p, const void* old_value);

  SimState* state_ = nullptr;
  Id id_ = null_id;
  std::uint32_t refs_ = 0;
  std::uint32_t index_pos_ = 0;  // position in the element index bucket of its class
  std::uint8_t watch_ = 0;
  std::uint8_t life_ = 0;
  detail::RefLink* composite_head_ = nullptr;
  detail::RefLink* shared_head_ = nullptr;
};

// ---- MetaProperty templates that need SimStateInstance ----

template <class T>
inline void MetaProperty::set(SimStateInstance& obj, const T& v) const {
  if (VSD_UNLIKELY(set_tag_ != detail::tag_of<T>()) && !stores_from(meta_type<T>()))
    throw_set(meta_type<T>());
  if (VSD_UNLIKELY(!instance_fits(obj))) throw_owner(obj);
  obj.assign_at(*static_cast<T*>(const_cast<void*>(address(obj))), v, *this);
}

}  // namespace vsd

namespace vsd {
inline bool MetaProperty::instance_fits(const SimStateInstance& obj) const noexcept {
  return obj.meta().is_a(*owner_);
}
}  // namespace vsd
