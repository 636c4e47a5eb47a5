/** @file
 *  @brief EnumBuilder and StructBuilder: value types made at run time (by a script, or by a file that
 *  carries them), registered in and owned by a Registry.
 *
 *  A run-time enum, flags or struct type is a MetaType like one declared with VSD_ENUM, VSD_FLAGS or
 *  VSD_STRUCT: the same text and binary forms, usable as the type of a ClassBuilder property, as a field of
 *  another run-time struct, and as the element of a vector ("vector<Color>", which Registry::get_type makes
 *  on demand; see Registry::vector_type).
 *
 *  @code
 *  const vsd::MetaType& color = vsd::EnumBuilder("Color").value("Red", 0).value("Green", 1).define(registry);
 *  const vsd::MetaType& access = vsd::EnumBuilder("Access", vsd::TypeKind::Flags)
 *                                    .value("Read", 1).value("Write", 2).define(registry);
 *  const vsd::MetaType& tag = vsd::StructBuilder("Tag")
 *                                 .field("label", vsd::meta_type<std::string>())
 *                                 .field("color", color)
 *                                 .define(registry);
 *  vsd::ClassBuilder("Marker", vsd::Node::static_meta()).property("tags", registry.vector_type(tag))
 *      .define(registry);
 *  @endcode
 *
 *  Lifetime: a run-time type lives until its Registry undefines it (Registry::undefine(const MetaType&)),
 *  which it does only while no class property and no other type uses it. Values of the type must not
 *  outlive it.
 */
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "vsd/core/meta_type.hpp"

namespace vsd {

class Registry;

/// @brief Builds a run-time enum (TypeKind::Enum) or flags (TypeKind::Flags) type.
class EnumBuilder {
 public:
  /// @brief An enum (or flags) type named @p name; its values are int32 (enum) or uint32 (flags) unless
  /// underlying() says otherwise.
  /// @throws vsd::Error when @p kind is neither Enum nor Flags.
  explicit EnumBuilder(std::string name, TypeKind kind = TypeKind::Enum);
  /// @brief The integer type whose size and signedness the values have (int8 ... uint64).
  /// @throws vsd::Error when @p integer is not an integer type.
  EnumBuilder& underlying(const MetaType& integer);
  /// @brief Adds the named value @p name = @p value (names are identifiers: letters, digits, '_').
  EnumBuilder& value(std::string name, std::int64_t value);
  /// @brief Checks, builds and registers the type.
  /// @throws vsd::Error on a name that is not an identifier, a name given twice, a value that does not
  /// fit the underlying type, or a type name that is already taken.
  const MetaType& define(Registry& registry);
  /// @brief define() in the global Registry.
  const MetaType& define();

 private:
  std::string name_;
  TypeKind kind_;
  const MetaType* underlying_;
  std::vector<MetaType::EnumValue> values_;
};

/// @brief Builds a run-time struct type: named fields of any known value type (no references), laid out
/// in order with their alignment.
class StructBuilder {
 public:
  explicit StructBuilder(std::string name);
  /// @brief Adds field @p name of @p type.
  StructBuilder& field(std::string name, const MetaType& type);
  template <class T>
  StructBuilder& field(std::string name) {
    return field(std::move(name), meta_type<T>());
  }
  /// @brief Checks, builds and registers the type.
  /// @throws vsd::Error for a struct without fields, a field name given twice or empty, a reference
  /// field, or a type name that is already taken.
  const MetaType& define(Registry& registry);
  /// @brief define() in the global Registry.
  const MetaType& define();

 private:
  std::string name_;
  std::vector<std::pair<std::string, const MetaType*>> fields_;
};

namespace detail {
/// The MetaType "vector<E>" of run-time element type @p element (use Registry::vector_type).
std::unique_ptr<MetaType> make_runtime_vector(const MetaType& element);
/// True when @p a and @p b describe the same values with the same text and binary forms (same kind,
/// enum values, size and sign, fields by name and type, element type).
bool same_definition(const MetaType& a, const MetaType& b) noexcept;
}  // namespace detail

}  // namespace vsd
