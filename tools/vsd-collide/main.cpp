// vsd-collide: list the contacts and distances between the hulls of a URDF or a saved scene
// (`vsd-collide --help`); all of it is vsd::collision::run_tool.
#include <iostream>
#include <string_view>
#include <vector>

#include "vsd/collision/tool.hpp"

int main(int argc, char** argv) {
  std::vector<std::string_view> args(argv + 1, argv + argc);
  return vsd::collision::run_tool(args, std::cout, std::cerr);
}
