// What the inspector's benchmarks share (bench_web.cpp, bench_workcell.cpp): a page connected to a
// server's event stream, and the three cases of a step measured with and without an inspector.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>
#include <thread>

#include "../tests/web/http_client.hpp"
#include "vsd/web.hpp"

namespace vsd_bench {

inline std::string host_of(const vsd::web::Server& s) { return "127.0.0.1:" + std::to_string(s.port()); }

/// Reads the event stream until stopped; counts bytes and calls @p on_data with what arrived.
class StreamReader {
 public:
  template <class F>
  StreamReader(const vsd::web::Server& s, F on_data) {
    fd_ = vsd_web_test::connect_local(s.port(), 1);
    (void)vsd_web_test::send_all(fd_, vsd_web_test::http_text("GET", "/api/events", host_of(s), "", {}));
    thread_ = std::thread([this, on_data] {
      char buf[65536];
      while (!stop_) {
        const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
        if (n == 0) break;
        if (n < 0) continue;  // the receive timeout: look at stop_ again
        bytes_ += static_cast<std::size_t>(n);
        on_data(std::string_view(buf, static_cast<std::size_t>(n)));
      }
    });
  }
  ~StreamReader() {
    stop_ = true;
    ::shutdown(fd_, SHUT_RDWR);
    thread_.join();
    ::close(fd_);
  }
  [[nodiscard]] std::size_t bytes() const { return bytes_; }

 private:
  int fd_ = -1;
  std::atomic<bool> stop_{false};
  std::atomic<std::size_t> bytes_{0};
  std::thread thread_;
};

/// The three cases of the step benchmarks: @p mode 0 no server, 1 a server with one page connected to its
/// event stream, 2 the same with the timeline off.
struct Inspected {
  std::unique_ptr<vsd::web::Server> server;
  std::unique_ptr<StreamReader> page;
  Inspected(vsd::Environment& env, vsd::SimState& s, std::int64_t mode) {
    if (mode == 0) return;
    vsd::web::Options o;
    o.port = 0;
    if (mode == 2) o.timeline_bytes = 0;
    // For instruction counts: under callgrind a run is some 50 times slower, so a push rate in wall time
    // pushes 50 times as often per step. VSD_BENCH_PUSH_RATE (batches per second, e.g. 1e-6) takes the
    // pushes out of the steps' count; a batch's cost is counted apart (benchmarks/README.md).
    if (const char* rate = std::getenv("VSD_BENCH_PUSH_RATE")) o.push_rate = std::strtod(rate, nullptr);
    // VSD_BENCH_TIMELINE_BYTES sets the timeline's budget for mode 1 (default 64 MiB, the server's own).
    if (const char* b = std::getenv("VSD_BENCH_TIMELINE_BYTES"); b != nullptr && mode == 1)
      o.timeline_bytes = static_cast<std::size_t>(std::strtoull(b, nullptr, 10));
    server = std::make_unique<vsd::web::Server>(env, s, o);
    server->start();
    page = std::make_unique<StreamReader>(*server, [](std::string_view) {});
    while (server->stats().clients == 0) server->serve_for(std::chrono::milliseconds(1));
  }
  ~Inspected() { page.reset(); }  // the page goes before its server
};

}  // namespace vsd_bench
