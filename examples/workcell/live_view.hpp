// LiveView: a work cell in the browser while it runs (`--serve [PORT]`, docs/web.md) — a vsd::web::Server
// on the cell's state, the run kept at real time between steps, waiting while the page has paused it,
// and after the run the cell stays on the page until Ctrl-C or SIGTERM. Both cells' programs use it.
//
//   int port = -1;
//   if (!vsd_example::take_serve_option(args, port, error)) ...      // --serve [PORT] out of the arguments
//   vsd_example::LiveView view(env, env.main_state(), port);
//   while (...) { if (!view.pace(env)) break; env.step(); }
//   view.linger();
#pragma once

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "serve_option.hpp"
#include "vsd/web.hpp"

namespace vsd_example {

/// Set by Ctrl-C or SIGTERM while a LiveView serves.
inline std::atomic<bool> live_view_stop{false};
extern "C" inline void live_view_on_signal(int) { live_view_stop = true; }

class LiveView {
 public:
  /// Serves @p state on 127.0.0.1:@p port (0: a free one) and prints the URL and the write token.
  LiveView(vsd::Environment& env, vsd::SimState& state, int port) {
    vsd::web::Options options;
    options.port = port;
    server_ = std::make_unique<vsd::web::Server>(env, state, options);
    server_->start();
    std::signal(SIGINT, live_view_on_signal);
    std::signal(SIGTERM, live_view_on_signal);
    std::printf("web: serving %s (write token %s); Ctrl-C stops\n", server_->url().c_str(),
                server_->token().c_str());
    std::fflush(stdout);
    wall_start_ = std::chrono::steady_clock::now();
    sim_start_ = env.time();
  }

  /// Before a step: waits while the page has paused the cell, then until the wall clock has caught up
  /// with the simulated time (answering requests meanwhile). @return false once Ctrl-C asked to stop.
  bool pace(const vsd::Environment& env) {
    const auto pause_start = std::chrono::steady_clock::now();
    while (server_->paused() && !live_view_stop) server_->serve_for(std::chrono::milliseconds(20));
    paused_for_ += seconds_since(pause_start);  // not owed to real time
    const double ahead = (env.time() - sim_start_) - (seconds_since(wall_start_) - paused_for_);
    if (ahead > 0 && !live_view_stop) server_->serve_for(std::chrono::milliseconds(static_cast<long>(ahead * 1000)));
    return !live_view_stop;
  }

  /// After the run: the cell stays on the page, paused, until Ctrl-C or SIGTERM.
  void linger() {
    std::printf("web: the cell stays on %s until Ctrl-C\n", server_->url().c_str());
    std::fflush(stdout);
    server_->pause(true);
    while (!live_view_stop) server_->serve_for(std::chrono::milliseconds(100));
    std::printf("web: stopped\n");
  }

  [[nodiscard]] vsd::web::Server& server() noexcept { return *server_; }

 private:
  static double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  }
  std::unique_ptr<vsd::web::Server> server_;
  std::chrono::steady_clock::time_point wall_start_;
  double sim_start_ = 0;
  double paused_for_ = 0;
};

}  // namespace vsd_example
