// HardwareAdapter's common part, and UdpAdapter: the FRI-like protocol over loopback UDP.
#include "vsd/robotics/udp_adapter.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>

#include "vsd/core/error.hpp"
#include "vsd/robotics/fri_protocol.hpp"

namespace vsd::robotics {

// ---- HardwareAdapter ------------------------------------------------------------------------------------

HardwareAdapter::HardwareAdapter(int dof) : dof_(dof) {
  state_.position.assign(static_cast<std::size_t>(dof), 0.0);
  state_.velocity.assign(static_cast<std::size_t>(dof), 0.0);
  command_position_.assign(static_cast<std::size_t>(dof), 0.0);
  command_velocity_.assign(static_cast<std::size_t>(dof), 0.0);
}

void HardwareAdapter::write(std::span<const double> position, std::span<const double> velocity) {
  if (position.size() != static_cast<std::size_t>(dof_) ||
      (!velocity.empty() && velocity.size() != position.size()))
    throw vsd::Error(describe() + ": command of " + std::to_string(position.size()) + " positions and " +
                     std::to_string(velocity.size()) + " velocities; the adapter has " +
                     std::to_string(dof_) + " joints");
  command_position_.assign(position.begin(), position.end());
  if (velocity.empty()) {
    command_velocity_.assign(position.size(), 0.0);
  } else {
    command_velocity_.assign(velocity.begin(), velocity.end());
  }
  hold_ = false;
}

void HardwareAdapter::raise_fault(AdapterFault f, std::string message) {
  if (fault_ != f) ++stats_.faults;
  fault_ = f;
  fault_message_ = std::move(message);
}

void HardwareAdapter::clear_fault() {
  if (fault_ != AdapterFault::None) ++stats_.recoveries;
  fault_ = AdapterFault::None;
  fault_message_.clear();
}

// ---- UdpAdapter -----------------------------------------------------------------------------------------

namespace {

bool loopback_address(const std::string& host, in_addr& out) {
  const std::string h = host == "localhost" ? "127.0.0.1" : host;
  if (inet_pton(AF_INET, h.c_str(), &out) != 1) return false;
  return (ntohl(out.s_addr) >> 24) == 127;
}

}  // namespace

UdpAdapter::UdpAdapter(UdpOptions options) : HardwareAdapter(options.dof), options_(std::move(options)) {
  if (options_.dof < 1 || static_cast<std::size_t>(options_.dof) > fri::max_joints)
    throw vsd::Error("udp adapter: " + std::to_string(options_.dof) + " joints; 1 to " +
                     std::to_string(fri::max_joints) + " are possible");
  if (!(options_.reply_timeout > 0)) throw vsd::Error("udp adapter: the reply timeout must be positive");
  if (options_.max_missed < 1) throw vsd::Error("udp adapter: max_missed must be at least 1");
}

UdpAdapter::~UdpAdapter() { disconnect(); }

std::string UdpAdapter::describe() const {
  return "udp " + options_.host + ":" + std::to_string(options_.port);
}

void UdpAdapter::connect() {
  disconnect();
  in_addr addr{};
  if (!loopback_address(options_.host, addr))
    throw vsd::Error(describe() + ": '" + options_.host +
                     "' is not a loopback address (this adapter talks to 127.0.0.0/8 only)");
  if (options_.port == 0) throw vsd::Error(describe() + ": no port given");
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw vsd::Error(describe() + ": socket: " + std::strerror(errno));
  sockaddr_in local{};
  local.sin_family = AF_INET;
  local.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  local.sin_port = 0;  // ephemeral
  sockaddr_in peer{};
  peer.sin_family = AF_INET;
  peer.sin_addr = addr;
  peer.sin_port = htons(options_.port);
  // connect() on a UDP socket filters datagrams from other senders and reports ICMP "port unreachable"
  // (a dead peer) as ECONNREFUSED.
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&local), sizeof local) != 0 ||
      ::connect(fd, reinterpret_cast<const sockaddr*>(&peer), sizeof peer) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    throw vsd::Error(describe() + ": " + why);
  }
  sockaddr_in bound{};
  socklen_t len = sizeof bound;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &len);
  local_port_ = ntohs(bound.sin_port);
  fd_ = fd;
  missed_in_row_ = 0;
  rejected_this_streak_ = false;
  state_.valid = false;
  state_.fresh = false;
  hold_ = true;
  // Connected, not yet heard from: state_.valid stays false until the first state; without one for
  // max_missed cycles the adapter is in fault.
  clear_fault();
}

void UdpAdapter::disconnect() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  local_port_ = 0;
}

void UdpAdapter::cycle(double dt) noexcept {
  ++stats_.cycles;
  state_.fresh = false;
  if (fd_ < 0) {
    raise_fault(AdapterFault::Connection, describe() + ": not connected");
    ++stats_.missed;
    return;
  }
  try {
    fri::Message cmd;
    cmd.kind = fri::Kind::Command;
    cmd.sequence = ++sequence_;
    cmd.flags = hold_ ? fri::hold_flag : 0U;
    cmd.time = dt;
    cmd.position = command_position_;
    cmd.velocity = command_velocity_;
    const std::vector<std::uint8_t> out = fri::encode(cmd);
    // A refused send (the peer's port is closed) is a lost cycle, like a lost datagram.
    (void)::send(fd_, out.data(), out.size(), MSG_NOSIGNAL);

    using clock = std::chrono::steady_clock;
    const auto deadline = clock::now() + std::chrono::duration_cast<clock::duration>(
                                             std::chrono::duration<double>(options_.reply_timeout));
    std::array<std::uint8_t, fri::datagram_size(fri::max_joints) + 64> buf{};
    bool got = false;
    std::uint32_t peer_status = 0;
    while (!got) {
      const auto left =
          std::chrono::duration_cast<std::chrono::microseconds>(deadline - clock::now()).count();
      if (left <= 0) break;
      pollfd p{fd_, POLLIN, 0};
      const int rc = ::poll(&p, 1, static_cast<int>((left + 999) / 1000));
      if (rc <= 0) {
        if (rc < 0 && errno == EINTR) continue;
        break;
      }
      const ssize_t n = ::recv(fd_, buf.data(), buf.size(), MSG_DONTWAIT);
      if (n < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) continue;
        // ECONNREFUSED: the ICMP answer to an earlier datagram; the peer is not there. Keep waiting: a
        // restarted peer may still answer within this cycle.
        continue;
      }
      const fri::Decoded d =
          fri::decode(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n)));
      if (d.error != fri::DecodeError::None) {
        ++stats_.rejected;
        rejected_this_streak_ = true;
        last_rejection_ = d.what;
        continue;
      }
      const fri::Message& m = d.message;
      if (m.kind != fri::Kind::State) {
        ++stats_.rejected;
        rejected_this_streak_ = true;
        last_rejection_ = "a command datagram where a state was expected";
        continue;
      }
      if (m.sequence != sequence_) {  // a late answer to an earlier command
        ++stats_.rejected;
        continue;
      }
      if (m.position.size() != static_cast<std::size_t>(dof_) &&
          m.flags == static_cast<std::uint32_t>(fri::StateStatus::Ok)) {
        ++stats_.rejected;
        rejected_this_streak_ = true;
        last_rejection_ =
            "state of " + std::to_string(m.position.size()) + " joints, expected " + std::to_string(dof_);
        continue;
      }
      peer_status = m.flags;
      if (peer_status == static_cast<std::uint32_t>(fri::StateStatus::Ok)) {
        state_.position = m.position;
        state_.velocity = m.velocity;
        state_.time = m.time;
      }
      got = true;
    }
    if (got && peer_status != static_cast<std::uint32_t>(fri::StateStatus::Ok)) {
      ++stats_.missed;
      missed_in_row_ = 0;
      raise_fault(AdapterFault::Device,
                  describe() + ": the robot reports " +
                      (peer_status == static_cast<std::uint32_t>(fri::StateStatus::WrongJointCount)
                           ? std::string("a wrong joint count (it has another number of joints than ") +
                                 std::to_string(dof_) + ")"
                           : "status " + std::to_string(peer_status)));
      return;
    }
    if (got) {
      ++stats_.received;
      missed_in_row_ = 0;
      rejected_this_streak_ = false;
      state_.valid = true;
      state_.fresh = true;
      if (fault() != AdapterFault::None) clear_fault();
      return;
    }
    ++stats_.missed;
    if (++missed_in_row_ >= options_.max_missed) {
      if (rejected_this_streak_) {
        raise_fault(AdapterFault::Protocol, describe() + ": no valid state for " +
                                                std::to_string(missed_in_row_) +
                                                " cycles; last datagram rejected: " + last_rejection_);
      } else {
        raise_fault(AdapterFault::Timeout, describe() + ": no state for " + std::to_string(missed_in_row_) +
                                               " cycles (the robot does not answer)");
      }
    }
  } catch (const std::exception& e) {  // encode() cannot fail for a valid adapter; allocation might
    ++stats_.missed;
    raise_fault(AdapterFault::Connection, describe() + ": " + e.what());
  }
}

}  // namespace vsd::robotics
