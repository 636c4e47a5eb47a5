// vsd-scene: print the tree of a URDF or a saved scene (`vsd-scene --help`); all of it is
// vsd::scene::run_tool.
#include <iostream>
#include <string_view>
#include <vector>

#include "vsd/scene/tool.hpp"

int main(int argc, char** argv) {
  std::vector<std::string_view> args(argv + 1, argv + argc);
  return vsd::scene::run_tool(args, std::cout, std::cerr);
}
