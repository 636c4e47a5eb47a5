/** @file
 *  @brief How every vsd-* tool starts and ends: `--help`, exit codes, errors.
 *
 *  run() calls the tool's body and turns what it throws into a message on the error stream and an exit
 *  code, so that nothing ends in std::terminate:
 *  - 0: done;
 *  - 1: a failure: vsd::Error (a bad or unreadable file, a model that cannot be simulated, ...), running out
 *    of memory (std::bad_alloc: "out of memory"), any other exception;
 *  - 2: a usage error (UsageError), in one style for all tools: "<tool>: <what>" and
 *    "Try '<tool> --help'.".
 *  Messages are printed through printable_lines(): a name with control characters cannot garble the
 *  terminal. `--help` or `-h` anywhere before `--` (and the command `help` of a tool with commands) prints
 *  the usage on the output stream and exits 0.
 */
#pragma once

#include <functional>
#include <iosfwd>
#include <span>
#include <string>
#include <string_view>

namespace vsd::tool {

/// @brief Exit codes of every tool.
enum ExitCode : int { exit_ok = 0, exit_failure = 1, exit_usage = 2 };

/// @brief A tool: its name (for messages) and its usage text (for --help).
struct Tool {
  std::string_view name;
  std::string_view usage;
  bool has_commands = false;  ///< `<tool> help` prints the usage too
};

/// @brief A tool's body: the arguments without the program name; returns the exit code.
using Body = std::function<int(std::span<const std::string_view> args, std::ostream& out, std::ostream& err)>;

/// @brief Runs @p body with @p args, mapping exceptions to messages and exit codes (see the file comment).
int run(const Tool& tool, std::span<const std::string_view> args, std::ostream& out, std::ostream& err,
        const Body& body);
/// @brief A tool's entry point: its run(), which calls run() above with its Tool and body.
using Entry = int (*)(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);
/// @brief What a tool's main() returns: @p entry with argv (without the program name), std::cout and
/// std::cerr.
int main(int argc, char** argv, Entry entry);

/// @brief Prints a "warning: <w>" line (printable_lines()) for each warning.
void print_warnings(std::span<const std::string> warnings, std::ostream& err);

}  // namespace vsd::tool
