#include "vsd/core/error.hpp"

namespace vsd::detail {

void throw_error(const std::string& message) { throw Error(message); }

}  // namespace vsd::detail
