// vsd-physics: simulate a URDF or a saved scene and print the final poses (`vsd-physics --help`); all of
// it is vsd::physics::run_tool.
#include <iostream>
#include <string_view>
#include <vector>

#include "vsd/physics/tool.hpp"

int main(int argc, char** argv) {
  std::vector<std::string_view> args(argv + 1, argv + argc);
  return vsd::physics::run_tool(args, std::cout, std::cerr);
}
