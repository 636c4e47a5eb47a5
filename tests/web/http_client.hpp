// A raw HTTP/1.1 client for the vsd::web tests and benchmarks: it sends exactly the bytes given, so a test
// can send any Host, Origin or malformed request a hostile page or script could; and a reader of the event
// stream. Blocking sockets with timeouts; no dependency beyond POSIX.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vsd_web_test {

/// A connected socket to 127.0.0.1:@p port with a receive timeout of @p seconds, or -1.
inline int connect_local(int port, int seconds = 10) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval tv{seconds, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

/// Sends all of @p data; false when the connection broke.
inline bool send_all(int fd, const std::string& data) {
  std::size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n = ::send(fd, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return false;
    sent += static_cast<std::size_t>(n);
  }
  return true;
}

struct HttpReply {
  int status = 0;
  std::string head;  // status line and headers
  std::string body;
};

/// Sends @p request (the whole text) to 127.0.0.1:@p port and reads until the server closes.
inline HttpReply raw_http(int port, const std::string& request) {
  HttpReply r;
  const int fd = connect_local(port);
  if (fd < 0) return r;
  (void)send_all(fd, request);
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

}  // namespace vsd_web_test
