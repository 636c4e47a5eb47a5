/** @file
 *  @brief vsd-io: convert files between the text and binary formats, print one as a tree, describe or
 *  check it (`vsd-io --help`).
 *
 *  The tool knows the classes of every vsd module that was built and the run-time classes a file defines;
 *  classes it does not know (a user's C++ classes) are shown through stand-ins with their saved values and
 *  a warning (vsd::io::UnknownClasses::Placeholder). Exit codes: 0 done, 1 a bad or unreadable file, 2 a
 *  usage error.
 */
#pragma once

#include <iosfwd>
#include <span>
#include <string_view>

namespace vsd::tool::vsd_io {

/// @brief Runs vsd-io with @p args (without the program name), writing to @p out and @p err.
/// @return the exit code.
int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);

}  // namespace vsd::tool::vsd_io
