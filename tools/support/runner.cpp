// The start and end of every vsd-* tool (see vsd_tool/runner.hpp).
#include "vsd_tool/runner.hpp"

#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "vsd/core/error.hpp"
#include "vsd_tool/arguments.hpp"
#include "vsd_tool/text.hpp"

namespace vsd::tool {

namespace {

bool wants_help(const Tool& tool, std::span<const std::string_view> args) {
  if (tool.has_commands && !args.empty() && args[0] == "help") return true;
  for (const std::string_view a : args) {
    if (a == "--") return false;
    if (a == "--help" || a == "-h") return true;
  }
  return false;
}

// A message without its final line break (vsd::Error texts of SOML++ diagnostics end in one).
std::string message(std::string_view what) {
  while (!what.empty() && what.back() == '\n') what.remove_suffix(1);
  return printable_lines(what);
}

}  // namespace

int run(const Tool& tool, std::span<const std::string_view> args, std::ostream& out, std::ostream& err,
        const Body& body) {
  auto failed = [&](std::string_view what) {
    out.flush();
    err << tool.name << ": " << message(what) << '\n';
    return exit_failure;
  };
  try {
    if (wants_help(tool, args)) {
      out << tool.usage;
      return exit_ok;
    }
    return body(args, out, err);
  } catch (const UsageError& e) {
    out.flush();
    err << tool.name << ": " << message(e.what()) << "\nTry '" << tool.name << " --help'.\n";
    return exit_usage;
  } catch (const Error& e) {
    return failed(e.what());
  } catch (const std::bad_alloc&) {
    return failed("out of memory");
  } catch (const std::exception& e) {
    return failed(e.what());
  } catch (...) {
    return failed("unexpected error");
  }
}

int main(int argc, char** argv, Entry entry) {
  try {
    const std::vector<std::string_view> args(argv + (argc > 0 ? 1 : 0), argv + argc);
    const int code = entry(args, std::cout, std::cerr);
    std::cout.flush();
    return code;
  } catch (...) {  // the argument vector itself could not be had
    return exit_failure;
  }
}

void print_warnings(std::span<const std::string> warnings, std::ostream& err) {
  for (const std::string& w : warnings) err << "warning: " << printable_lines(w) << '\n';
}

}  // namespace vsd::tool
