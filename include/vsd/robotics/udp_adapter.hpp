/** @file
 *  @brief UdpAdapter: a HardwareAdapter speaking the FRI-like protocol of fri_protocol.hpp over UDP to a
 *  robot (here: the robot simulator of examples/robotics), on the loopback interface only.
 *
 *  Each cycle sends one command datagram and waits up to `reply_timeout` for the state that answers it
 *  (same sequence number). Damaged, wrong-version, foreign and stale datagrams are rejected and counted;
 *  a cycle without a valid answer keeps the last state (fresh = false). After `max_missed` such cycles in
 *  a row the adapter is in fault (Timeout; Protocol when datagrams did arrive but were all rejected), and
 *  it keeps sending — hold commands — so it leaves the fault by itself as soon as valid states arrive
 *  again (a restarted robot).
 *
 *  @code
 *  vsd::robotics::UdpAdapter robot({.port = 40123, .dof = 7});
 *  robot.connect();
 *  robot.write(q_command);
 *  robot.cycle(0.002);
 *  if (robot.fault() == vsd::robotics::AdapterFault::None) use(robot.read().position);
 *  @endcode
 */
#pragma once

#include <cstdint>
#include <string>

#include "vsd/robotics/hardware_adapter.hpp"

namespace vsd::robotics {

/// @brief Where and how UdpAdapter talks.
struct UdpOptions {
  std::string host = "127.0.0.1";  ///< the robot: a loopback address (127.0.0.0/8 or "localhost")
  std::uint16_t port = 0;          ///< the robot's UDP port
  int dof = 7;                     ///< joints the robot has
  double reply_timeout = 0.005;    ///< s to wait for the answer within one cycle
  int max_missed = 3;              ///< cycles in a row without a valid answer before the fault
};

class UdpAdapter final : public HardwareAdapter {
 public:
  /// @throws vsd::Error when dof is outside 1 … fri::max_joints, a timeout is not positive or max_missed < 1.
  explicit UdpAdapter(UdpOptions options);
  ~UdpAdapter() override;

  [[nodiscard]] std::string describe() const override;
  /// @brief Opens the socket (an ephemeral local port on 127.0.0.1).
  /// @throws vsd::Error for a host that is not a loopback address or when no socket can be opened.
  void connect() override;
  void disconnect() noexcept override;
  [[nodiscard]] bool connected() const noexcept override { return fd_ >= 0; }
  void cycle(double dt) noexcept override;

  [[nodiscard]] const UdpOptions& options() const noexcept { return options_; }
  /// @brief The local port the socket is bound to (0 when not connected).
  [[nodiscard]] std::uint16_t local_port() const noexcept { return local_port_; }
  /// @brief Why the last datagram was rejected (empty if none was).
  [[nodiscard]] const std::string& last_rejection() const noexcept { return last_rejection_; }

 private:
  UdpOptions options_;
  int fd_ = -1;
  std::uint16_t local_port_ = 0;
  std::uint32_t sequence_ = 0;
  int missed_in_row_ = 0;
  bool rejected_this_streak_ = false;
  std::string last_rejection_;
};

}  // namespace vsd::robotics
