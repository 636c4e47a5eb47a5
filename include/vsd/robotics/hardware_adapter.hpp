/** @file
 *  @brief HardwareAdapter: what simulation-based control needs of a robot's vendor interface — connect,
 *  write joint commands, run one communication cycle, read the joint state, report and reset faults.
 *
 *  One cycle is: write() the command of this cycle, cycle(dt) (send it, receive the state), read(). An
 *  adapter never throws from cycle(): a lost answer, a dead peer, a damaged datagram or a drive fault is
 *  reported through fault() and the statistics, and read() keeps the last good state (`fresh` false).
 *  Adapters that run here without hardware: UdpAdapter (an FRI-like protocol to a robot simulator process)
 *  and FieldbusAxisAdapter (a linear axis on a simulated cyclic I/O image). HardwareBinding runs them from
 *  the database by configuration.
 */
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vsd/core/meta_type.hpp"

namespace vsd::robotics {

/// @brief What is wrong with an adapter's link to its robot.
enum class AdapterFault : std::uint8_t {
  None,        ///< fine
  Connection,  ///< not connected, or the connection could not be made
  Timeout,     ///< no valid answer for too many cycles in a row (a dead peer)
  Protocol,    ///< the peer answers, but not in a form we accept (every datagram rejected, wrong joints)
  Device       ///< the robot or drive reports a fault of its own
};
VSD_ENUM(AdapterFault, None, Connection, Timeout, Protocol, Device)

/// @brief The joint state an adapter last received.
struct JointState {
  std::vector<double> position;  ///< rad or m, in the adapter's joint order
  std::vector<double> velocity;  ///< rad/s or m/s
  double time = 0.0;             ///< the robot's clock (s), when it has one
  bool valid = false;            ///< at least one state has been received since connect()
  bool fresh = false;            ///< received in the last cycle
};

/// @brief What an adapter counted since it was made.
struct AdapterStats {
  std::uint64_t cycles = 0;      ///< cycle() calls
  std::uint64_t received = 0;    ///< cycles that got a valid state
  std::uint64_t missed = 0;      ///< cycles that got none (lost, late, rejected)
  std::uint64_t rejected = 0;    ///< datagrams or words rejected (damaged, wrong version, stale)
  std::uint64_t faults = 0;      ///< times a fault was raised
  std::uint64_t recoveries = 0;  ///< times a fault cleared
};

class HardwareAdapter {
 public:
  virtual ~HardwareAdapter() = default;
  HardwareAdapter(const HardwareAdapter&) = delete;
  HardwareAdapter& operator=(const HardwareAdapter&) = delete;

  /// @brief A short description ("udp 127.0.0.1:40123", "fieldbus axis"), for messages.
  [[nodiscard]] virtual std::string describe() const = 0;
  /// @brief Number of joints the adapter carries.
  [[nodiscard]] int dof() const noexcept { return dof_; }
  /// @brief Opens the link. Faults clear; the first state arrives with the next cycles.
  /// @throws vsd::Error when the link cannot be opened (bad address, no socket, ...).
  virtual void connect() = 0;
  /// @brief Closes the link (idempotent).
  virtual void disconnect() noexcept = 0;
  [[nodiscard]] virtual bool connected() const noexcept = 0;
  /// @brief Sets the command of the next cycle: target positions and feed-forward velocities (may be
  /// empty).
  /// @throws vsd::Error when the sizes are not dof().
  void write(std::span<const double> position, std::span<const double> velocity = {});
  /// @brief Sets the next cycle to hold the robot where it is (what an adapter does until write()).
  void hold() noexcept { hold_ = true; }
  /// @brief One communication cycle of @p dt seconds: sends the command, receives the state, updates the
  /// fault. Never throws.
  virtual void cycle(double dt) noexcept = 0;
  /// @brief The last state received (see JointState::fresh).
  [[nodiscard]] const JointState& read() const noexcept { return state_; }
  /// @brief The current fault (None when fine) and what it is about.
  [[nodiscard]] AdapterFault fault() const noexcept { return fault_; }
  [[nodiscard]] const std::string& fault_message() const noexcept { return fault_message_; }
  /// @brief Asks the device to leave its fault (a drive's fault reset); link faults clear by themselves
  /// when valid states arrive again.
  virtual void reset_fault() {}
  [[nodiscard]] const AdapterStats& stats() const noexcept { return stats_; }

 protected:
  explicit HardwareAdapter(int dof);
  /// @brief Enters fault @p f (counted once per change of kind) with @p message.
  void raise_fault(AdapterFault f, std::string message);
  /// @brief Leaves the fault (counted as a recovery when there was one).
  void clear_fault();

  int dof_;
  JointState state_;
  AdapterStats stats_;
  std::vector<double> command_position_, command_velocity_;
  bool hold_ = true;  // until the first write()

 private:
  AdapterFault fault_ = AdapterFault::None;
  std::string fault_message_;
};

}  // namespace vsd::robotics
