/** @file
 *  @brief vsd-dist: serve a file as the shared model of a DDS domain, or watch a domain's changes
 *  (`vsd-dist --help`).
 *
 *  @code
 *  vsd-dist serve FILE --domain N [--topic T] [--config URI] [--for SECONDS]
 *  vsd-dist watch --domain N [--topic T] [--config URI] [--for SECONDS]
 *  @endcode
 *  --domain is 0 to 230 (a DDS domain id), --for 0 to 31536000 seconds; anything else is a usage error.
 *  FILE may be "-" (standard input). Exit codes: 0 done, 1 a bad file or nobody answered, 2 a usage error.
 */
#pragma once

#include <iosfwd>
#include <span>
#include <string_view>

namespace vsd::tool::vsd_dist {

/// @brief Runs vsd-dist with @p args (without the program name), printing to @p out and @p err. Runs
/// until --for has passed or SIGINT/SIGTERM arrives.
/// @return the exit code.
int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);

}  // namespace vsd::tool::vsd_dist
