// StateContext: the keys of the typed slots, and its errors.
#include "vsd/core/state_context.hpp"

#include <atomic>
#include <string>

namespace vsd::detail {

std::size_t next_context_key() noexcept {
  static std::atomic<std::size_t> next{0};
  return next.fetch_add(1, std::memory_order_relaxed);
}

void throw_context_entry_exists(const char* type_name) {
  throw_error(std::string("the SimState's context already has an entry of type ") + type_name);
}

void throw_context_entry_missing(const char* type_name) {
  throw_error(std::string("the SimState's context has no entry of type ") + type_name);
}

}  // namespace vsd::detail
