// What the vsd::web tests share: the raw HTTP client (http_client.hpp), and a fixture whose test thread serves the server's jobs
// while a client thread waits for the answer — the simulation thread and the HTTP threads as in a program.
#pragma once

#include <atomic>
#include <chrono>
#include <future>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "vsd/core.hpp"
#include "vsd/scene.hpp"
#include "vsd/soml.hpp"
#include "vsd/web.hpp"
#include "http_client.hpp"
#include "web/json.hpp"

namespace vsd_web_test {

class WebTest : public ::testing::Test {
 protected:
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
  std::unique_ptr<vsd::web::Server> server;

  WebTest() { env.use<vsd::scene::Module>(); }

  void start(vsd::web::Options options = {}) {
    options.port = 0;
    options.assets = "/nonexistent-vsd-web-assets";  // the API alone
    server = std::make_unique<vsd::web::Server>(env, state, std::move(options));
    server->start();
  }
  [[nodiscard]] std::string host() const { return "127.0.0.1:" + std::to_string(server->port()); }

  /// Sends the request from another thread and serves the server's jobs here until it is answered.
  HttpReply send(const std::string& text) {
    auto f = std::async(std::launch::async, [port = server->port(), text] { return raw_http(port, text); });
    while (f.wait_for(std::chrono::milliseconds(0)) != std::future_status::ready)
      server->serve_for(std::chrono::milliseconds(2));
    return f.get();
  }
  HttpReply get(const std::string& path) { return send(http_text("GET", path, host(), "", {})); }
  HttpReply post(const std::string& path, const std::string& body, bool with_token = true,
                 std::vector<std::string> headers = {}) {
    if (with_token) headers.push_back("X-VSD-Token: " + server->token());
    return send(http_text("POST", path, host(), body, headers));
  }
};

/// Reads the event stream of @p port until @p until is in what arrived (or 5 s pass).
inline std::string read_events(int port, const std::string& host, const std::string& until, std::atomic<bool>& connected) {
  const int fd = connect_local(port, 5);
  std::string all;
  if (fd >= 0) {
    (void)send_all(fd, http_text("GET", "/api/events", host, "", {}));
    char buf[4096];
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    for (ssize_t n; std::chrono::steady_clock::now() < deadline && (n = ::recv(fd, buf, sizeof buf, 0)) > 0;) {
      all.append(buf, static_cast<std::size_t>(n));
      if (all.find("event: hello") != std::string::npos) connected = true;
      if (all.find(until) != std::string::npos) break;
    }
    ::close(fd);
  }
  return all;
}

/// Member @p name of the JSON object @p json, as raw JSON text.
inline std::string member(std::string_view json, std::string_view name) {
  return std::string(vsd::web::detail::JsonObject::parse(json).require(name));
}
/// The elements of array member @p name of @p json, as raw JSON texts.
inline std::vector<std::string> items(std::string_view json, std::string_view name) {
  const auto o = vsd::web::detail::JsonObject::parse(json);
  std::vector<std::string> out;
  for (auto v : o.array(name)) out.emplace_back(v);
  return out;
}
/// The elements of the top-level JSON array @p json.
inline std::vector<std::string> elements(std::string_view json) {
  return items("{\"a\":" + std::string(json) + "}", "a");
}

}  // namespace vsd_web_test
