// vsd-web (`vsd-web --help`): all of it is vsd::tool::vsd_web::run (tool.hpp), so the tests run it in-process.
#include "tool.hpp"
#include "vsd_tool/runner.hpp"

int main(int argc, char** argv) { return vsd::tool::main(argc, argv, vsd::tool::vsd_web::run); }
