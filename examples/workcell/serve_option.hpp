// `--serve [PORT]` on the work cells' command lines (the live view itself is live_view.hpp, built only
// with vsd::web; the option is parsed either way, so that a build without it can say so).
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <thread>
#include <string>
#include <vector>

namespace vsd_example {

/// Takes `--serve [PORT]` out of @p args: @p port becomes PORT, 8080 without one, -1 when absent.
/// @return false with @p error set for a port outside 0..65535.
inline bool take_serve_option(std::vector<std::string>& args, int& port, std::string& error) {
  port = -1;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] != "--serve") continue;
    port = 8080;
    std::size_t n = 1;
    if (i + 1 < args.size() && !args[i + 1].empty() &&
        args[i + 1].find_first_not_of("0123456789") == std::string::npos) {
      if (args[i + 1].size() > 5 || std::stoi(args[i + 1]) > 65535) {
        error = "--serve: port " + args[i + 1] + " is not in 0..65535";
        return false;
      }
      port = std::stoi(args[i + 1]);
      n = 2;
    }
    args.erase(args.begin() + static_cast<std::ptrdiff_t>(i), args.begin() + static_cast<std::ptrdiff_t>(i + n));
    --i;
  }
  return true;
}

/// A before-step hook that keeps a run to real time without a server (the controller of two processes
/// whose ui serves the page): it sleeps until the wall clock has caught up with the simulated time.
template <class Environment>
std::function<bool(Environment&)> real_time_pacer() {
  return [start = std::chrono::steady_clock::time_point{}, t0 = 0.0](Environment& env) mutable {
    if (start == std::chrono::steady_clock::time_point{}) {
      start = std::chrono::steady_clock::now();
      t0 = env.time();
    }
    std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                              std::chrono::duration<double>(env.time() - t0)));
    return true;
  };
}

}  // namespace vsd_example
