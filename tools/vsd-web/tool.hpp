/** @file
 *  @brief vsd-web: serve the inspector (vsd::web) for a file (`vsd-web --help`).
 *
 *  `vsd-web FILE [--port N] [--bind ADDR] [--token T] [--run] [--dt S] [--seconds S]` loads FILE — a vsd
 *  file (.json vsd-text, .vsds binary), a SOML++ script (.soml) or a URDF (.urdf, .xml) — into a fresh
 *  Environment with the scene, robotics and SOML++ modules, serves it on http://ADDR:N/ (127.0.0.1:8080 by
 *  default; --port 0 picks a free port), prints `vsd-web: serving URL` and `vsd-web: write token: T` on
 *  standard output, and serves until Ctrl-C or SIGTERM (or for --seconds of wall time). The simulation is
 *  paused until the page (or --run) starts it; it then steps in real time at --dt (0.01 s). Exit codes: 0
 *  stopped, 1 the file could not be loaded or the address not bound, 2 a usage error.
 */
#pragma once

#include <iosfwd>
#include <span>
#include <string_view>

namespace vsd::tool::vsd_web {

/// @brief Runs vsd-web with @p args (without the program name), printing to @p out and @p err.
/// @return the exit code.
int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err);

}  // namespace vsd::tool::vsd_web
