/** @file
 *  @brief The `vsd-io` command-line tool as a function: convert files between the text and binary
 *  formats, print one as a tree, describe or check it.
 *
 *  The tool knows the classes linked into the program that runs it, plus the run-time classes a file
 *  defines. A file of instances of your own C++ classes therefore needs a tool that links them: write a
 *  main() that calls run_tool() in a program that links your classes (see tools/vsd-io/main.cpp).
 */
#pragma once

#include <ostream>
#include <span>
#include <string_view>

namespace vsd::io {

/// @brief Runs the tool with @p args (without the program name), writing to @p out and @p err.
/// @return 0 on success, 1 when a file is bad or cannot be read or written, 2 on a usage error.
int run_tool(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);

/// @brief run_tool() for main(argc, argv), on std::cout and std::cerr.
int run_tool(int argc, char** argv);

}  // namespace vsd::io
