// vsd-robot: kinematics of a robot description (`vsd-robot --help`); all of it is vsd::robotics::run_tool.
#include <iostream>
#include <string_view>
#include <vector>

#include "vsd/robotics/tool.hpp"

int main(int argc, char** argv) {
  std::vector<std::string_view> args(argv + 1, argv + argc);
  return vsd::robotics::run_tool(args, std::cout, std::cerr);
}
