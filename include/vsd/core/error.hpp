/** @file
 *  @brief vsd::Error, the exception thrown for bad caller input (unknown names, wrong types, ...).
 */
#pragma once

#include <stdexcept>
#include <string>

namespace vsd {

/// @brief Thrown when a caller hands vsd something it cannot accept. The message names the offending
/// type, property, method or instance, and for text or bytes the position.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {
/// @brief Throws vsd::Error with the concatenation of the given pieces (kept out of line: cold path).
[[noreturn]] void throw_error(const std::string& message);
}  // namespace detail

}  // namespace vsd
