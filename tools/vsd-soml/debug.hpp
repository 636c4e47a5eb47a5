// `vsd-soml debug FILE [--break FILE:LINE]... [--break-transition NAME]... [--seed S] [--steps N]`: the
// interactive debugger (commands on stdin). Throws std::invalid_argument for a usage error.
#pragma once

#include <string_view>
#include <vector>

int debug_command(const std::vector<std::string_view>& args);
