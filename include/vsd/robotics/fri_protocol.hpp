/** @file
 *  @brief The small FRI-like joint-state/command protocol spoken by UdpAdapter and the robot simulator
 *  (examples/robotics/robot_simulator.cpp): versioned binary datagrams with sequence numbers and a CRC-32.
 *
 *  One datagram, every number little-endian (docs/robotics.md has the same table):
 *
 *  | offset     | size | field                                                                 |
 *  |------------|------|-----------------------------------------------------------------------|
 *  | 0          | 4    | magic "VSDR"                                                          |
 *  | 4          | 1    | version (protocol_version = 1)                                        |
 *  | 5          | 1    | kind: 1 command (controller → robot), 2 state (robot → controller)    |
 *  | 6          | 2    | n, the number of joints (≤ max_joints)                                |
 *  | 8          | 4    | sequence: a command's own counter; a state repeats the command's      |
 *  | 12         | 4    | flags: command bit 0 = hold (keep the position, ignore the values); state: 0 or a
 * StateStatus | | 16         | 8    | time (f64): command the cycle period in s; state the robot's clock in s
 * | | 24         | 8 n  | position (f64): command the target, state the measured position      | | 24 + 8 n
 * | 8 n  | velocity (f64): command the feed-forward velocity, state the measured  | | 24 + 16 n  | 4    |
 * CRC-32 (IEEE 802.3) of bytes 0 … 23 + 16 n                           |
 *
 *  The controller sends one command per cycle and waits (with a timeout) for the state that answers it;
 *  a state whose sequence is not the last command's is stale and dropped.
 */
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace vsd::robotics::fri {

/// @brief The version this library speaks; a datagram of another version is rejected.
inline constexpr std::uint8_t protocol_version = 1;
/// @brief The most joints one datagram carries.
inline constexpr std::size_t max_joints = 64;
/// @brief Bytes before the joint values.
inline constexpr std::size_t header_size = 24;

/// @brief What a datagram is.
enum class Kind : std::uint8_t { Command = 1, State = 2 };

/// @brief Command flag: the robot keeps its position and ignores the values.
inline constexpr std::uint32_t hold_flag = 1;

/// @brief The status a state datagram reports (its flags field).
enum class StateStatus : std::uint32_t {
  Ok = 0,
  WrongJointCount = 1,  ///< the command's joint count is not the robot's
  Fault = 2             ///< the robot is in a fault of its own
};

/// @brief One datagram's content.
struct Message {
  Kind kind = Kind::Command;
  std::uint32_t sequence = 0;
  std::uint32_t flags = 0;
  double time = 0.0;
  std::vector<double> position;
  std::vector<double> velocity;  ///< empty, or as many values as position
};

/// @brief Size in bytes of a datagram with @p joints joints.
[[nodiscard]] constexpr std::size_t datagram_size(std::size_t joints) noexcept {
  return header_size + 16 * joints + 4;
}

/// @brief Encodes @p m (a missing velocity is sent as zeros).
/// @throws vsd::Error for more than max_joints joints or a velocity of another size than position.
[[nodiscard]] std::vector<std::uint8_t> encode(const Message& m);

/// @brief Why a datagram was rejected.
enum class DecodeError : std::uint8_t {
  None,
  TooShort,
  BadMagic,
  WrongVersion,
  BadKind,
  BadLength,
  BadChecksum
};

/// @brief The result of decode().
struct Decoded {
  DecodeError error = DecodeError::None;
  std::string what;          ///< the reason, for messages ("version 2, expected 1", ...)
  std::uint8_t version = 0;  ///< the version byte (when the datagram was long enough)
  Message message;           ///< valid when error is None
};

/// @brief Decodes one datagram; never throws on malformed input (the error says what is wrong).
[[nodiscard]] Decoded decode(std::span<const std::uint8_t> bytes);

/// @brief CRC-32 (IEEE 802.3, reflected, as zlib's crc32) of @p bytes.
[[nodiscard]] std::uint32_t crc32(std::span<const std::uint8_t> bytes) noexcept;

}  // namespace vsd::robotics::fri
