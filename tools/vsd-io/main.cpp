// vsd-io: the command-line tool for vsd files (`vsd-io --help`). All of it lives in vsd::io::run_tool, so
// a program that links its own classes can offer the same tool for its files with this one line.
#include "vsd/io/tool.hpp"

int main(int argc, char** argv) { return vsd::io::run_tool(argc, argv); }
