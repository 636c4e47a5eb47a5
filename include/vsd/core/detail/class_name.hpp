/** @file
 *  @brief The full name of a built-in class: the namespace its C++ namespace declares with
 *  VSD_CLASS_NAMESPACE (see declare.hpp), "::", and the name given to VSD_INSTANCE.
 */
#pragma once

#include <concepts>
#include <string>
#include <string_view>

namespace vsd::detail {

// Unqualified lookup from class_namespace() stops at this (unusable) declaration, so only
// argument-dependent lookup finds a namespace's VSD_CLASS_NAMESPACE: on a class's own tag type, whose
// only associated namespace is the class's namespace (not those of its bases, and never a namespace made
// visible by a using-directive).
void vsd_class_namespace() = delete;

/// The namespace declared for the class whose tag is @p Tag, or empty.
template <class Tag>
constexpr std::string_view class_namespace() noexcept {
  if constexpr (requires(Tag * t) {
                  { vsd_class_namespace(t) } -> std::convertible_to<std::string_view>;
                }) {
    return vsd_class_namespace(static_cast<Tag*>(nullptr));
  } else {
    return {};
  }
}

/// "ns::name", or "name" when @p ns is empty.
inline std::string qualified_name(std::string_view ns, std::string_view name) {
  std::string out;
  if (!ns.empty()) {
    out.append(ns);
    out += "::";
  }
  out.append(name);
  return out;
}

/// The full name of built-in class T.
template <class T>
std::string class_name() {
  if constexpr (requires { typename T::vsd_tag; }) {
    return qualified_name(class_namespace<typename T::vsd_tag>(), T::vsd_class_name);
  } else {
    return std::string(T::vsd_class_name);
  }
}

}  // namespace vsd::detail
