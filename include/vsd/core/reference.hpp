/** @file
 *  @brief References between instances: Ref (composite), SharedRef (shared) and their lists.
 *
 *  - Composite aggregation, `Ref<T>` / `RefList<T>`: counted. All parent-child relations are composite.
 *    When the last composite reference to an instance goes away, the instance is deleted with its own
 *    composite subtree. A newly created instance has no composite reference; it lives (floating, still
 *    in the element index) until a property attaches it and later releases it, or it is deleted
 *    explicitly. Only a property adopts a floating instance: a free Ref (a local, a Value, the temporary
 *    a setter's argument becomes) keeps an attached instance alive like a shared pointer, but dropping
 *    it leaves a floating instance floating. So a change that is rejected never deletes anything.
 *  - Shared aggregation, `SharedRef<T>` / `SharedRefList<T>`: not counted. When the target is deleted,
 *    the reference becomes null (a list loses the element) and the holding instance emits a property
 *    change, so holders are notified without polling.
 *
 *  A reference held in a property knows its holder, so every change to it goes through the holder
 *  (signals, transactions). A reference held anywhere else ("free", e.g. a local variable or a Value) is
 *  a plain handle: a free SharedRef is a safe weak handle, a free Ref owns like a shared pointer.
 *  Properties hand out references only as const: there is no writable path around the change signal.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <type_traits>
#include <vector>

#include "vsd/core/config.hpp"
#include "vsd/core/detail/class_name.hpp"
#include "vsd/core/meta_type.hpp"

namespace vsd {

namespace detail {

struct RefAccess;   // the SimState's access to link internals (reference.cpp, sim_state.cpp)
struct RefBinding;  // binds a property's reference storage to its holder (below)

/// One reference: an entry in the intrusive list of its target's holders.
struct RefLink {
  SimStateInstance* target = nullptr;
  SimStateInstance* holder = nullptr;  // instance whose property holds the link; null when free
  const MetaProperty* prop = nullptr;
  RefLink* prev = nullptr;
  RefLink* next = nullptr;
  bool composite = false;
  bool adopted = false;  // this link ended its target's floating state (revert() restores it)
  // 0: a link of its own (a RefBase's, or a list's made with new); else its place + 1 in a LinkBlock.
  // (In the padding: a link stays 48 bytes.)
  std::uint32_t block_slot = 0;

  explicit RefLink(bool is_composite) noexcept : composite(is_composite) {}
  RefLink(const RefLink&) = delete;
  RefLink& operator=(const RefLink&) = delete;
  ~RefLink() { reset(nullptr); }

  /// Points the link at @p t (nullptr clears). Releasing the last composite link of an instance that
  /// is not floating deletes it; linking to an instance that is being deleted throws vsd::Error, and so
  /// does a property link that would cross SimStates or close a composite cycle (nothing changes then).
  void reset(SimStateInstance* t);
  /// Detaches from the target without releasing it (the target is going away).
  void drop() noexcept;
  /// Undoes this link as if it had never been made: the count goes back and a target it adopted floats
  /// again, so nothing is deleted. For the rollback of an operation that failed half way.
  void revert() noexcept;
};

/// Frees a link of a list: deletes it, or (one of a LinkBlock) destroys it in place and gives up its
/// share of the block.
void free_link(RefLink* l) noexcept;

/// The links of many list elements made together (a load), in one block instead of one allocation each.
/// A block belongs to its links, not to the maker or a SimState: it is freed when its last link is freed
/// (links can outlive their SimState, e.g. in a list moved into a free Value), and the maker's unused rest
/// is given up when the maker dies. So the memory of a load's links goes back when the last of them goes.
struct LinkBlockHeader;  // reference.cpp
class LinkBlock {
 public:
  /// Room for @p count links (none made yet). @throws std::bad_alloc
  explicit LinkBlock(std::size_t count);
  LinkBlock(const LinkBlock&) = delete;
  LinkBlock& operator=(const LinkBlock&) = delete;
  ~LinkBlock();
  /// A new, unlinked link from the block; from the heap when the block is used up.
  RefLink* make(bool composite);

 private:
  LinkBlockHeader* block_ = nullptr;
  std::uint32_t next_ = 0;
  std::uint32_t count_ = 0;
};

}  // namespace detail

/// @brief Untyped storage shared by Ref<T> and SharedRef<T>.
class RefBase {
 public:
  RefBase(const RefBase& o) : link_(o.link_.composite) { link_.reset(o.link_.target); }
  RefBase& operator=(const RefBase& o) {
    link_.reset(o.link_.target);
    return *this;
  }
  ~RefBase() = default;

  /// @brief The target, or nullptr.
  [[nodiscard]] SimStateInstance* get() const noexcept { return link_.target; }
  explicit operator bool() const noexcept { return link_.target != nullptr; }
  /// @brief The target's id, or null_id.
  [[nodiscard]] Id id() const noexcept;
  [[nodiscard]] bool is_composite() const noexcept { return link_.composite; }
  /// @brief The instance holding this reference in a property, or nullptr for a free reference.
  [[nodiscard]] SimStateInstance* holder() const noexcept { return link_.holder; }

  friend bool operator==(const RefBase& a, const RefBase& b) noexcept { return a.get() == b.get(); }

 protected:
  explicit RefBase(bool composite, SimStateInstance* t = nullptr) : link_(composite) { link_.reset(t); }
  void reset_target(SimStateInstance* t) { link_.reset(t); }

 private:
  friend struct detail::RefAccess;
  friend struct detail::RefBinding;
  detail::RefLink link_;
};

/// @brief Composite (counted) reference to a T.
template <class T>
class Ref : public RefBase {
 public:
  Ref() : RefBase(true) {}
  Ref(std::nullptr_t) : RefBase(true) {}  // NOLINT(google-explicit-constructor)
  Ref(T* p) : RefBase(true, p) {}         // NOLINT(google-explicit-constructor)
  Ref(T& p) : RefBase(true, &p) {}        // NOLINT(google-explicit-constructor)
  Ref(const Ref&) = default;
  Ref& operator=(const Ref&) = default;
  Ref& operator=(T* p) {
    reset_target(p);
    return *this;
  }
  [[nodiscard]] T* get() const noexcept { return static_cast<T*>(RefBase::get()); }
  T* operator->() const noexcept { return get(); }
  T& operator*() const noexcept { return *get(); }
};

/// @brief Shared (uncounted) reference to a T: becomes null when the target is deleted.
template <class T>
class SharedRef : public RefBase {
 public:
  SharedRef() : RefBase(false) {}
  SharedRef(std::nullptr_t) : RefBase(false) {}  // NOLINT(google-explicit-constructor)
  SharedRef(T* p) : RefBase(false, p) {}         // NOLINT(google-explicit-constructor)
  SharedRef(T& p) : RefBase(false, &p) {}        // NOLINT(google-explicit-constructor)
  SharedRef(const SharedRef&) = default;
  SharedRef& operator=(const SharedRef&) = default;
  SharedRef& operator=(T* p) {
    reset_target(p);
    return *this;
  }
  [[nodiscard]] T* get() const noexcept { return static_cast<T*>(RefBase::get()); }
  T* operator->() const noexcept { return get(); }
  T& operator*() const noexcept { return *get(); }
};

/// @brief Untyped storage shared by RefList<T> and SharedRefList<T>: an ordered list of references.
class RefListBase {
 public:
  RefListBase(const RefListBase& o);
  RefListBase& operator=(const RefListBase& o);
  RefListBase(RefListBase&& o) noexcept;
  RefListBase& operator=(RefListBase&& o);
  // Inline: most lists die empty (the children of a deleted leaf), and then cost no call.
  ~RefListBase() {
    if (!links_.empty()) clear_all();
  }

  [[nodiscard]] std::size_t size() const noexcept { return links_.size(); }
  [[nodiscard]] bool empty() const noexcept { return links_.empty(); }
  [[nodiscard]] SimStateInstance* at(std::size_t i) const noexcept { return links_[i]->target; }
  [[nodiscard]] bool is_composite() const noexcept { return composite_; }
  /// @brief Position of @p p, or npos.
  [[nodiscard]] std::size_t index_of(const SimStateInstance* p) const noexcept;
  [[nodiscard]] bool contains(const SimStateInstance* p) const noexcept { return index_of(p) != npos; }
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);

  friend bool operator==(const RefListBase& a, const RefListBase& b) noexcept;

 protected:
  explicit RefListBase(bool composite) noexcept : composite_(composite) {}
  void insert_at(std::size_t i, SimStateInstance* p);
  /// insert_at() with a link made by the caller (a LinkBlock's); freed with free_link() if it fails.
  void insert_link(std::size_t i, SimStateInstance* p, detail::RefLink* l);
  void erase_at(std::size_t i);
  void clear_all();

 private:
  friend struct detail::RefAccess;
  friend struct detail::RefBinding;
  std::vector<detail::RefLink*> links_;
  SimStateInstance* holder_ = nullptr;
  const MetaProperty* prop_ = nullptr;
  bool composite_;
};

namespace detail {
/// Binds the reference storage of a property (a RefBase or a RefListBase at @p at) to the instance and
/// property holding it: inline, so that constructing an instance binds its references without a call.
struct RefBinding {
  static void bind(void* at, bool list, SimStateInstance* holder, const MetaProperty* prop) noexcept {
    if (list) {
      auto& r = *static_cast<RefListBase*>(at);
      r.holder_ = holder;
      r.prop_ = prop;
      for (RefLink* l : r.links_) {
        l->holder = holder;
        l->prop = prop;
      }
    } else {
      RefLink& l = static_cast<RefBase*>(at)->link_;
      l.holder = holder;
      l.prop = prop;
    }
  }
};

template <class T, class Base>
class TypedRefList : public Base {
 public:
  class iterator {
   public:
    using value_type = T*;
    using difference_type = std::ptrdiff_t;
    iterator() = default;
    iterator(const TypedRefList* l, std::size_t i) : l_(l), i_(i) {}
    T* operator*() const noexcept { return static_cast<T*>(l_->at(i_)); }
    iterator& operator++() noexcept {
      ++i_;
      return *this;
    }
    iterator operator++(int) noexcept {
      auto c = *this;
      ++i_;
      return c;
    }
    bool operator==(const iterator& o) const noexcept { return i_ == o.i_; }

   private:
    const TypedRefList* l_ = nullptr;
    std::size_t i_ = 0;
  };
  using element_type = T;
  using Base::Base;
  [[nodiscard]] T* operator[](std::size_t i) const noexcept { return static_cast<T*>(this->at(i)); }
  [[nodiscard]] iterator begin() const noexcept { return {this, 0}; }
  [[nodiscard]] iterator end() const noexcept { return {this, this->size()}; }
  /// @brief Appends to a free list (a list held in a property changes through its holder: use the
  /// property's `edit_name()` ListEditor, or SimStateInstance::list_insert).
  void push_back(T* p) { this->insert_at(this->size(), p); }
  void insert(std::size_t i, T* p) { this->insert_at(i, p); }
  void erase(std::size_t i) { this->erase_at(i); }
  void clear() { this->clear_all(); }
};
}  // namespace detail

/// @brief Ordered list of composite references to T.
template <class T>
class RefList : public detail::TypedRefList<T, RefListBase> {
 public:
  RefList() : detail::TypedRefList<T, RefListBase>(true) {}
};

/// @brief Ordered list of shared references to T.
template <class T>
class SharedRefList : public detail::TypedRefList<T, RefListBase> {
 public:
  SharedRefList() : detail::TypedRefList<T, RefListBase>(false) {}
};

namespace detail {
/// True for RefList<T> and SharedRefList<T>.
template <class L>
concept IsRefList = std::is_base_of_v<RefListBase, L> && requires {
  typename L::element_type;
};

extern const TypeOps ref_ops;
extern const TypeOps ref_list_ops;

template <class R, class T>
MetaType make_ref_type(std::string_view prefix, TypeKind kind) {
  MetaType t(std::string(prefix) + "<" + class_name<T>() + ">", kind, sizeof(R), alignof(R),
             kind == TypeKind::Ref || kind == TypeKind::SharedRef ? ref_ops : ref_list_ops);
  t.set_target(+[]() -> const MetaInstance& { return T::static_meta(); });
  t.set_cpp_tag(tag_of<R>());
  return t;
}
}  // namespace detail

template <class T>
struct TypeTraits<Ref<T>> {
  static MetaType make() { return detail::make_ref_type<Ref<T>, T>("ref", TypeKind::Ref); }
};
template <class T>
struct TypeTraits<SharedRef<T>> {
  static MetaType make() { return detail::make_ref_type<SharedRef<T>, T>("shared", TypeKind::SharedRef); }
};
template <class T>
struct TypeTraits<RefList<T>> {
  static MetaType make() { return detail::make_ref_type<RefList<T>, T>("list", TypeKind::RefList); }
};
template <class T>
struct TypeTraits<SharedRefList<T>> {
  static MetaType make() {
    return detail::make_ref_type<SharedRefList<T>, T>("shared_list", TypeKind::SharedRefList);
  }
};

}  // namespace vsd
