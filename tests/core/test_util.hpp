// Helpers shared by the core tests.
#pragma once

#include <functional>
#include <span>
#include <string>
#include <vector>
#include <vsd/core/error.hpp>
#include <vsd/core/meta_property.hpp>

namespace vsd_test {

/// The message of the vsd::Error that @p fn throws, or "<no error>".
inline std::string error_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const vsd::Error& e) {
    return e.what();
  }
  return "<no error>";
}

/// The names of @p props, in order.
inline std::vector<std::string> names_of(std::span<const vsd::MetaProperty* const> props) {
  std::vector<std::string> out;
  for (const vsd::MetaProperty* p : props) out.push_back(p->name());
  return out;
}

}  // namespace vsd_test
