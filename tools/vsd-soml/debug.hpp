// `vsd-soml debug FILE [--break FILE:LINE]... [--break-transition NAME]... [--seed S] [--steps N]`: the
// interactive debugger (commands from @p in, one per line). Throws vsd::tool::UsageError for a usage error.
#pragma once

#include <iosfwd>
#include <span>
#include <string_view>

namespace vsd::tool::vsd_soml {

int debug_command(std::span<const std::string_view> args, std::istream& in, std::ostream& out, std::ostream& err);

}  // namespace vsd::tool::vsd_soml
