/** @file
 *  @brief The declaration macros: VSD_INSTANCE, VSD_PROPERTY, VSD_METHOD.
 *
 *  @code
 *  class Robot : public vsd::Node {
 *    VSD_INSTANCE(Robot, vsd::Node)
 *    VSD_PROPERTY(double, speed, 1.0, vsd::Editable | vsd::Savable)
 *    VSD_PROPERTY(vsd::SharedRef<vsd::Node>, target, nullptr)
 *   public:
 *    void home() { set_speed(0.0); }
 *    VSD_METHOD(home)
 *  };
 *  @endcode
 *
 *  VSD_PROPERTY(Type, name, default, flags...) gives a private member `name_`, an inline getter
 *  `name()` (a plain load), a setter `set_name(v)` (a store behind one branch while nobody observes the
 *  instance) and an entry in the class's MetaProperty table. Flags default to Editable|Savable|Distributed.
 *  A reference-list property (`RefList<T>`, `SharedRefList<T>`) also gets `edit_name()`, a ListEditor<T>
 *  with push_back, insert, erase, remove and clear, recorded and signalled like the setter.
 *  Write a default containing commas in parentheses: `(std::vector<int>{1, 2})`.
 *
 *  The tables are built by a chain of overloads numbered with __COUNTER__; do not declare another
 *  vsd class inside the body of a vsd class.
 */
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <string_view>

#include "vsd/core/detail/class_name.hpp"
#include "vsd/core/flags.hpp"
#include "vsd/core/instance.hpp"
#include "vsd/core/list_editor.hpp"
#include "vsd/core/meta_instance.hpp"
#include "vsd/core/meta_method.hpp"

namespace vsd::detail {

template <int N>
struct Slot {};

/// Lets `Type(def)` work for any spelling of a type ("long long", "std::vector<int>").
template <class T>
using TypeOf = T;

constexpr PropertyFlags flags_or_default() noexcept { return DefaultFlags; }
constexpr PropertyFlags flags_or_default(PropertyFlags f) noexcept { return f; }

/// Registers a built-in class with the global Registry when the program starts (see registry.hpp).
bool auto_register(const MetaInstance& meta) noexcept;

template <class T>
SimStateInstance* construct_instance(void* memory) {
  static_assert(std::is_base_of_v<SimStateInstance, T>, "only SimStateInstances can be created by a factory");
  static_assert(std::is_default_constructible_v<T>, "a vsd class needs a default constructor");
  // Default-initialised, as `new T` does, not value-initialised (`T()`): for a class without a
  // user-provided constructor `T()` first zeroes the whole object (a `rep stos` of its size, about a
  // quarter of a pooled create + destroy) before the member initialisers store the same fields again.
  // Every property has an initialiser; a plain member of a vsd class needs one too (docs/design.md).
  return ::new (memory) T;
}

template <class T>
void declare_property(MetaInstance& m, std::size_t slot, const char* name, std::size_t offset,
                      PropertyFlags flags, T default_value) {
  auto& p = m.add_property(
      std::make_unique<MetaProperty>(name, meta_type<T>(), flags, offset, Value(std::move(default_value))));
  m.set_slot(slot, &p);
}

}  // namespace vsd::detail

#define VSD_DETAIL_INSTANCE(Name, Base, construct)                                                         \
 public:                                                                                                   \
  using vsd_self = Name;                                                                                   \
  using vsd_base = Base;                                                                                   \
  static constexpr std::string_view vsd_class_name = #Name;                                                \
  /* Its only associated namespace is the class's own: see VSD_CLASS_NAMESPACE. */                         \
  struct vsd_tag {};                                                                                       \
  /** @brief The MetaInstance of this class. */                                                            \
  static const ::vsd::MetaInstance& static_meta() {                                                        \
    /* Never destroyed: class descriptors outlive every static that might still use them. */               \
    static const ::vsd::MetaInstance& meta = *new ::vsd::MetaInstance(                                     \
        ::vsd::detail::class_name<Name>(), &Base::static_meta(), sizeof(Name), alignof(Name), construct,   \
        [](::vsd::MetaInstance& m) { vsd_register(m, ::vsd::detail::Slot<0>{}); });                        \
    return meta;                                                                                           \
  }                                                                                                        \
                                                                                                           \
 private:                                                                                                  \
  static constexpr int vsd_counter_base = __COUNTER__;                                                     \
  template <int N>                                                                                         \
  static void vsd_register(::vsd::MetaInstance&, ::vsd::detail::Slot<N>) {}                                \
  [[maybe_unused]] static inline const bool vsd_registered_ = ::vsd::detail::auto_register(static_meta()); \
                                                                                                           \
 public:

/// @brief Declares the namespace of the vsd classes of the enclosing C++ namespace: a class declared
/// there with VSD_INSTANCE(Node3D, ...) is named "scene::Node3D" (in files, bundles and the Registry).
/// Write it once, at namespace scope, in a header that the classes' headers include:
/// `namespace vsd::scene { VSD_CLASS_NAMESPACE("scene") }`. It applies to classes declared directly in
/// that C++ namespace (not in namespaces nested in it, nor to subclasses declared elsewhere); classes of a
/// namespace that declares none keep their plain names, as vsd's own classes (Node, Database, ...) do.
#define VSD_CLASS_NAMESPACE(ns)                                                         \
  template <class VsdTag>                                                               \
  [[maybe_unused]] constexpr ::std::string_view vsd_class_namespace(VsdTag*) noexcept { \
    return ns;                                                                          \
  }

/// @brief Opens the declaration of a vsd class @p Name deriving from @p Base (instances can be created).
#define VSD_INSTANCE(Name, Base) VSD_DETAIL_INSTANCE(Name, Base, &::vsd::detail::construct_instance<Name>)
/// @brief Like VSD_INSTANCE for a class that cannot be instantiated by the factory.
#define VSD_ABSTRACT_INSTANCE(Name, Base) VSD_DETAIL_INSTANCE(Name, Base, nullptr)

#define VSD_DETAIL_SLOT(tag) static constexpr int tag = __COUNTER__ - vsd_counter_base - 1;

/// @brief Declares a property; see the file comment.
#define VSD_PROPERTY(Type, name, def, ...)                                                             \
 private:                                                                                              \
  Type name##_ = def;                                                                                  \
  VSD_DETAIL_SLOT(vsd_slot_##name)                                                                     \
  static void vsd_register(::vsd::MetaInstance& m, ::vsd::detail::Slot<vsd_slot_##name>) {             \
    _Pragma("GCC diagnostic push")                                                                     \
        _Pragma("GCC diagnostic ignored \"-Winvalid-offsetof\"")::vsd::detail::declare_property<Type>( \
            m, vsd_slot_##name, #name, offsetof(vsd_self, name##_),                                    \
            ::vsd::detail::flags_or_default(__VA_ARGS__), ::vsd::detail::TypeOf<Type>(def));           \
    _Pragma("GCC diagnostic pop") vsd_register(m, ::vsd::detail::Slot<vsd_slot_##name + 1>{});         \
  }                                                                                                    \
                                                                                                       \
 public:                                                                                               \
  /** @brief Value of property `name`. */                                                              \
  [[nodiscard]] const Type& name() const noexcept { return name##_; }                                  \
  /** @brief Sets property `name` (signals and records when observed). */                              \
  void set_##name(const Type& v) { this->vsd_assign(name##_, v, &vsd_prop_##name); }                   \
  /** @brief The MetaProperty of `name`. */                                                            \
  static const ::vsd::MetaProperty& vsd_prop_##name() { return static_meta().slot(vsd_slot_##name); }  \
  /** @brief Typed, recorded editing of reference list `name` (see list_editor.hpp). */                \
  template <class vsd_L = Type>                                                                        \
  requires ::vsd::detail::IsRefList<vsd_L>                                                             \
  [[nodiscard]] ::vsd::ListEditor<typename vsd_L::element_type> edit_##name() {                        \
    return {*this, vsd_prop_##name()};                                                                 \
  }

/// @brief Publishes member function @p name as a MetaMethod (callable through vsdMetaCall).
#define VSD_METHOD(name)                                                                     \
 private:                                                                                    \
  VSD_DETAIL_SLOT(vsd_slot_m_##name)                                                         \
  static void vsd_register(::vsd::MetaInstance& m, ::vsd::detail::Slot<vsd_slot_m_##name>) { \
    m.add_method(::vsd::detail::make_method<vsd_self, &vsd_self::name>(#name));              \
    m.set_slot(vsd_slot_m_##name, nullptr);                                                  \
    vsd_register(m, ::vsd::detail::Slot<vsd_slot_m_##name + 1>{});                           \
  }                                                                                          \
                                                                                             \
 public:
