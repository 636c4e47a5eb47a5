// What the vsd::web tests share: a raw HTTP/1.1 client (so a test can send any Host, Origin or malformed
// request a hostile page or script could), and a fixture whose test thread serves the server's jobs
// while a client thread waits for the answer — the simulation thread and the HTTP threads as in a program.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

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
#include "web/json.hpp"

namespace vsd_web_test {

struct HttpReply {
  int status = 0;
  std::string head;  // status line and headers
  std::string body;
};

/// Sends @p request (the whole text) to 127.0.0.1:@p port and reads until the server closes.
inline HttpReply raw_http(int port, const std::string& request) {
  HttpReply r;
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return r;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval tv{10, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return r;
  }
  std::size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = ::send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<std::size_t>(n);
  }
  std::string all;
  char buf[65536];
  for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;) all.append(buf, static_cast<std::size_t>(n));
  ::close(fd);
  const std::size_t end = all.find("\r\n\r\n");
  r.head = all.substr(0, end);
  r.body = end == std::string::npos ? std::string() : all.substr(end + 4);
  if (all.rfind("HTTP/1.1 ", 0) == 0) r.status = std::stoi(all.substr(9, 3));
  return r;
}

/// A request's text: @p headers are whole lines ("Origin: http://x").
inline std::string http_text(const std::string& method, const std::string& path, const std::string& host,
                             const std::string& body, const std::vector<std::string>& headers) {
  std::string t = method + " " + path + " HTTP/1.1\r\nHost: " + host + "\r\nConnection: close\r\n";
  for (const auto& h : headers) t += h + "\r\n";
  if (method == "POST") t += "Content-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) + "\r\n";
  return t + "\r\n" + body;
}

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
