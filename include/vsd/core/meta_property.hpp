/** @file
 *  @brief MetaProperty: one property of a class — name, MetaType, flags, default, and access.
 *
 *  Every property's value lives at a fixed offset inside its instance (a C++ member for built-in
 *  classes, a slot in the instance's trailing storage for run-time classes), so generic access costs
 *  the same for both: a type check, then a load or a store. Stores go through the holder's change
 *  path (signal, transaction), never around it.
 */
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/core/flags.hpp"
#include "vsd/core/meta_type.hpp"
#include "vsd/core/value.hpp"

namespace vsd {

class SimStateInstance;
class MetaInstance;

class MetaProperty {
 public:
  MetaProperty(std::string name, const MetaType& type, PropertyFlags flags, std::size_t offset,
               Value default_value)
      : name_(std::move(name)),
        type_(&type),
        get_tag_(type.cpp_tag()),
        set_tag_(flags.has(ReadOnly) ? nullptr : type.cpp_tag()),
        flags_(flags),
        offset_(offset),
        default_(std::move(default_value)) {}
  MetaProperty(const MetaProperty&) = delete;
  MetaProperty& operator=(const MetaProperty&) = delete;

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] const MetaType& type() const noexcept { return *type_; }
  [[nodiscard]] PropertyFlags flags() const noexcept { return flags_; }
  [[nodiscard]] bool has(PropertyFlags f) const noexcept { return flags_.has(f); }
  /// @brief The class that declares the property.
  [[nodiscard]] const MetaInstance& owner() const noexcept { return *owner_; }
  /// @brief Position of the property in the property list of its class (MetaInstance::properties()),
  /// inherited properties first: the same position in every subclass.
  [[nodiscard]] std::size_t index() const noexcept { return index_; }
  /// @brief Byte offset of the value from the start of the instance.
  [[nodiscard]] std::size_t offset() const noexcept { return offset_; }
  /// @brief The value a new instance starts with.
  [[nodiscard]] const Value& default_value() const noexcept { return default_; }
  /// @brief Former names that still find this property (schema evolution).
  [[nodiscard]] const std::vector<std::string>& aliases() const noexcept { return aliases_; }
  MetaProperty& add_alias(std::string old_name) {
    aliases_.push_back(std::move(old_name));
    return *this;
  }

  /// @brief Address of the value inside @p obj (no checks).
  [[nodiscard]] const void* address(const SimStateInstance& obj) const noexcept {
    return reinterpret_cast<const char*>(&obj) + offset_;
  }

  /// @brief The value as a T; throws vsd::Error when T is not the property's type.
  template <class T>
  [[nodiscard]] const T& get(const SimStateInstance& obj) const {
    if (VSD_UNLIKELY(get_tag_ != detail::tag_of<T>()) && !views_as(meta_type<T>()))
      throw_type(meta_type<T>());
    if (VSD_UNLIKELY(!instance_fits(obj))) throw_owner(obj);
    return *static_cast<const T*>(address(obj));
  }
  /// @brief Sets the value from a T (signals and records like the typed setter); throws vsd::Error on a
  /// wrong type or a ReadOnly property.
  template <class T>
  void set(SimStateInstance& obj, const T& v) const;

  /// @brief A copy of the value.
  [[nodiscard]] Value get_value(const SimStateInstance& obj) const {
    if (VSD_UNLIKELY(!instance_fits(obj))) throw_owner(obj);
    return Value(*type_, address(obj));
  }
  /// @brief Sets from a Value, converting numbers where exact; throws vsd::Error on a wrong type.
  void set_value(SimStateInstance& obj, const Value& v) const;
  /// @brief Sets from raw memory holding a value of type(); ignores ReadOnly (transactions, loaders).
  void assign_raw(SimStateInstance& obj, const void* v) const;

 private:
  friend class MetaInstance;
  friend class SimStateInstance;
  [[nodiscard]] bool instance_fits(const SimStateInstance& obj) const noexcept;
  // A reference type made at run time and the C++ one of the same kind and target (or, for reading, a
  // base of the target) are interchangeable: same layout, same ops.
  [[nodiscard]] bool views_as(const MetaType& wanted) const noexcept;
  [[nodiscard]] bool stores_from(const MetaType& given) const noexcept;
  [[noreturn]] void throw_type(const MetaType& wanted) const;
  [[noreturn]] void throw_set(const MetaType& given) const;  // wrong type or ReadOnly
  [[noreturn]] void throw_read_only_named() const;
  [[noreturn]] void throw_owner(const SimStateInstance& obj) const;

  std::string name_;
  const MetaType* type_;
  const void* get_tag_;  // type_->cpp_tag(): the check of a typed read is one compare with a constant
  const void* set_tag_;  // the same, or null when ReadOnly: one compare checks both
  PropertyFlags flags_;
  std::size_t offset_;
  Value default_;
  std::vector<std::string> aliases_;
  const MetaInstance* owner_ = nullptr;
  std::size_t index_ = 0;
};

}  // namespace vsd
