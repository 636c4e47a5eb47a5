/** @file
 *  @brief vsd-soml: run, debug, analyse and convert SOML++ scripts and PNML nets (`vsd-soml --help`).
 *
 *  Exit codes: 0 done (a net analysed, bounded or not), 1 a bad file, a script error or the memory limit,
 *  2 a usage error.
 */
#pragma once

#include <iosfwd>
#include <span>
#include <string_view>

namespace vsd::tool::vsd_soml {

/// @brief Runs vsd-soml with @p args (without the program name), printing to @p out and @p err; `debug`
/// reads its commands from @p in.
/// @return the exit code.
int run(std::span<const std::string_view> args, std::istream& in, std::ostream& out, std::ostream& err);
/// @brief run() with the commands of `debug` on standard input.
int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);

}  // namespace vsd::tool::vsd_soml
