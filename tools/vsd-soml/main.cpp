// vsd-soml (`vsd-soml --help`): all of it is vsd::tool::vsd_soml::run (tool.hpp), so the tests run it in-process.
#include "tool.hpp"
#include "vsd_tool/runner.hpp"

int main(int argc, char** argv) {
  return vsd::tool::main(argc, argv, [](std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
    return vsd::tool::vsd_soml::run(args, out, err);
  });
}
