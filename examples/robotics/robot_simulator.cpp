// A robot simulator speaking the FRI-like protocol of vsd/robotics/fri_protocol.hpp over loopback UDP:
// the peer of vsd::robotics::UdpAdapter, as a separate process. Copy it to write the bridge to a real robot.
//
//   vsd_robot_simulator [--port N] [--dof N] [--initial v1,v2,...] [--lag SECONDS] [--max-velocity V]
//                       [--drop-every N] [--garble-every N] [--wrong-version-every N]
//                       [--idle-exit SECONDS] [--exit-after N]
//
// It binds 127.0.0.1:N (0, the default: an ephemeral port) and prints one line
// "robot_simulator: listening on 127.0.0.1:PORT, N joints" on stdout, so a parent process can read the port.
// Every valid command moves the joints towards its target (hold: towards where they are) over the command's
// cycle period — with a first-order lag of time constant --lag and at most --max-velocity — and is answered
// by a state datagram with the same sequence number. A command of another joint count is answered with
// status WrongJointCount. To test the controller side it can leave every N-th command unanswered
// (--drop-every), damage every N-th answer (--garble-every), send every N-th answer with protocol version 2
// (--wrong-version-every), and exit after N commands (--exit-after, a crash) or after SECONDS without any
// command (--idle-exit, default 30: no orphans).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "vsd/robotics/fri_protocol.hpp"

namespace fri = vsd::robotics::fri;

namespace {

struct Options {
  unsigned port = 0;
  int dof = 7;
  std::vector<double> initial;
  double lag = 0.0;
  double max_velocity = 10.0;
  long drop_every = 0, garble_every = 0, wrong_version_every = 0;
  double idle_exit = 30.0;
  long exit_after = 0;
};

[[noreturn]] void usage(const std::string& why) {
  std::cerr
      << "robot_simulator: " << why
      << "\nusage: vsd_robot_simulator [--port N] [--dof N] [--initial v1,...] [--lag S] [--max-velocity V]"
         " [--drop-every N] [--garble-every N] [--wrong-version-every N] [--idle-exit S] [--exit-after N]\n";
  std::exit(2);
}

double to_number(const std::string& flag, const std::string& v) {
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(d))
    usage(flag + ": '" + v + "' is not a number");
  return d;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--help" || flag == "-h") usage("help");
    if (i + 1 >= argc) usage(flag + " needs a value");
    const std::string v = argv[++i];
    if (flag == "--port") {
      const double p = to_number(flag, v);
      if (p < 0 || p > 65535 || p != std::floor(p)) usage("--port: 0 to 65535");
      o.port = static_cast<unsigned>(p);
    } else if (flag == "--dof") {
      o.dof = static_cast<int>(to_number(flag, v));
      if (o.dof < 1 || static_cast<std::size_t>(o.dof) > fri::max_joints) usage("--dof: 1 to 64");
    } else if (flag == "--initial") {
      std::size_t start = 0;
      while (start <= v.size()) {
        const std::size_t comma = std::min(v.find(',', start), v.size());
        o.initial.push_back(to_number(flag, v.substr(start, comma - start)));
        start = comma + 1;
      }
    } else if (flag == "--lag") {
      o.lag = to_number(flag, v);
    } else if (flag == "--max-velocity") {
      o.max_velocity = to_number(flag, v);
    } else if (flag == "--drop-every") {
      o.drop_every = static_cast<long>(to_number(flag, v));
    } else if (flag == "--garble-every") {
      o.garble_every = static_cast<long>(to_number(flag, v));
    } else if (flag == "--wrong-version-every") {
      o.wrong_version_every = static_cast<long>(to_number(flag, v));
    } else if (flag == "--idle-exit") {
      o.idle_exit = to_number(flag, v);
    } else if (flag == "--exit-after") {
      o.exit_after = static_cast<long>(to_number(flag, v));
    } else {
      usage("unknown option " + flag);
    }
  }
  if (!o.initial.empty() && o.initial.size() != static_cast<std::size_t>(o.dof))
    usage("--initial: " + std::to_string(o.initial.size()) + " values for " + std::to_string(o.dof) +
          " joints");
  if (o.lag < 0 || o.max_velocity <= 0 || o.idle_exit <= 0)
    usage("--lag >= 0, --max-velocity > 0, --idle-exit > 0");
  return o;
}

bool every(long n, long count) { return n > 0 && count % n == 0; }

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    std::perror("robot_simulator: socket");
    return 1;
  }
  const int yes = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);  // a restarted robot takes its port again
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);  // loopback only
  addr.sin_port = htons(static_cast<std::uint16_t>(o.port));
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    std::perror("robot_simulator: bind");
    return 1;
  }
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  std::cout << "robot_simulator: listening on 127.0.0.1:" << ntohs(addr.sin_port) << ", " << o.dof
            << " joints" << std::endl;

  const auto n = static_cast<std::size_t>(o.dof);
  std::vector<double> q = o.initial.empty() ? std::vector<double>(n, 0.0) : o.initial;
  std::vector<double> qd(n, 0.0);
  double clock = 0.0;
  long commands = 0;
  std::array<std::uint8_t, 2048> buf{};
  auto last = std::chrono::steady_clock::now();
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    const int rc = ::poll(&p, 1, 100);
    if (rc < 0 && errno != EINTR) break;
    if (rc <= 0) {
      if (std::chrono::duration<double>(std::chrono::steady_clock::now() - last).count() > o.idle_exit) {
        std::cout << "robot_simulator: no command for " << o.idle_exit << " s, exiting" << std::endl;
        break;
      }
      continue;
    }
    sockaddr_in from{};
    socklen_t from_len = sizeof from;
    const ssize_t got =
        ::recvfrom(fd, buf.data(), buf.size(), 0, reinterpret_cast<sockaddr*>(&from), &from_len);
    if (got < 0) continue;
    const fri::Decoded d =
        fri::decode(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(got)));
    if (d.error != fri::DecodeError::None || d.message.kind != fri::Kind::Command) continue;  // not for us
    last = std::chrono::steady_clock::now();
    ++commands;
    const fri::Message& cmd = d.message;
    fri::Message state;
    state.kind = fri::Kind::State;
    state.sequence = cmd.sequence;
    if (cmd.position.size() != n) {
      state.flags = static_cast<std::uint32_t>(fri::StateStatus::WrongJointCount);
    } else {
      const double dt = std::clamp(cmd.time, 0.0, 0.1);
      clock += dt;
      const bool hold = (cmd.flags & fri::hold_flag) != 0;
      const double alpha = o.lag > 0 ? 1.0 - std::exp(-dt / o.lag) : 1.0;
      for (std::size_t i = 0; i < n; ++i) {
        const double target = hold || !std::isfinite(cmd.position[i]) ? q[i] : cmd.position[i];
        const double step = std::clamp(alpha * (target - q[i]), -o.max_velocity * dt, o.max_velocity * dt);
        q[i] += step;
        qd[i] = dt > 0 ? step / dt : 0.0;
      }
      state.position = q;
      state.velocity = qd;
    }
    state.time = clock;
    if (every(o.drop_every, commands)) continue;  // lost on the way
    std::vector<std::uint8_t> out = fri::encode(state);
    if (every(o.garble_every, commands)) out[fri::header_size + 3] ^= 0x5A;  // a damaged datagram
    if (every(o.wrong_version_every, commands)) out[4] = 2;                  // a peer of another version
    ::sendto(fd, out.data(), out.size(), 0, reinterpret_cast<const sockaddr*>(&from), from_len);
    if (o.exit_after > 0 && commands >= o.exit_after) {
      std::cout << "robot_simulator: exiting after " << commands << " commands" << std::endl;
      break;
    }
  }
  ::close(fd);
  return 0;
}
