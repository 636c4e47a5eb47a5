/** @file
 *  @brief A simulated fieldbus drive for a linear axis: a cyclic I/O process image (control word and
 *  target position out, status word, error code and actual position in) and a drive state machine after
 *  CiA 402 in small (switch-on disabled → ready → switched on → operation enabled; fault; fault reset).
 *
 *  The process image is bytes at fixed offsets, little-endian, as a PDO mapping would place them:
 *
 *  | image   | offset | type | word                                                   |
 *  |---------|--------|------|--------------------------------------------------------|
 *  | outputs | 0      | u16  | control word (master → drive)                          |
 *  | outputs | 4      | i32  | target position, counts                                |
 *  | inputs  | 0      | u16  | status word (drive → master)                           |
 *  | inputs  | 2      | u16  | error code (0 without a fault)                         |
 *  | inputs  | 4      | i32  | actual position, counts                                |
 *
 *  Each bus cycle the drive reads the outputs, steps, and writes the inputs (SimulatedDrive::exchange).
 */
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace vsd::robotics::fieldbus {

/// @brief Control word commands (CiA 402 bits: 0 switch on, 1 enable voltage, 2 quick stop off, 3 enable
/// operation, 7 fault reset on its rising edge).
namespace control {
inline constexpr std::uint16_t disable_voltage = 0x0000;
inline constexpr std::uint16_t shutdown = 0x0006;
inline constexpr std::uint16_t switch_on = 0x0007;
inline constexpr std::uint16_t enable_operation = 0x000F;
inline constexpr std::uint16_t fault_reset = 0x0080;
}  // namespace control

/// @brief Error codes the simulated drive reports (CiA 402 / DS301 style).
namespace error {
inline constexpr std::uint16_t following = 0x8611;  ///< target too far from the actual position
inline constexpr std::uint16_t limit = 0x8612;      ///< target outside the travel range
inline constexpr std::uint16_t external = 0x9000;   ///< raised from outside (inject_fault)
}  // namespace error

/// @brief The drive's state (status word bits 0–3, 5, 6 as CiA 402 codes them).
enum class DriveState : std::uint8_t {
  NotReadyToSwitchOn,
  SwitchOnDisabled,
  ReadyToSwitchOn,
  SwitchedOn,
  OperationEnabled,
  Fault
};

/// @brief The status word of state @p s.
[[nodiscard]] std::uint16_t status_word(DriveState s) noexcept;
/// @brief The state a status word says (the CiA 402 masks).
[[nodiscard]] DriveState state_of(std::uint16_t status_word) noexcept;
/// @brief "OperationEnabled", ... for messages.
[[nodiscard]] const char* to_string(DriveState s) noexcept;

/// @brief The cyclic I/O image of one axis.
struct ProcessImage {
  std::array<std::uint8_t, 8> outputs{};  ///< master → drive
  std::array<std::uint8_t, 8> inputs{};   ///< drive → master

  [[nodiscard]] std::uint16_t control_word() const noexcept { return get16(outputs, 0); }
  void set_control_word(std::uint16_t v) noexcept { put16(outputs, 0, v); }
  [[nodiscard]] std::int32_t target_position() const noexcept { return get32(outputs, 4); }
  void set_target_position(std::int32_t v) noexcept { put32(outputs, 4, v); }
  [[nodiscard]] std::uint16_t status_word() const noexcept { return get16(inputs, 0); }
  void set_status_word(std::uint16_t v) noexcept { put16(inputs, 0, v); }
  [[nodiscard]] std::uint16_t error_code() const noexcept { return get16(inputs, 2); }
  void set_error_code(std::uint16_t v) noexcept { put16(inputs, 2, v); }
  [[nodiscard]] std::int32_t actual_position() const noexcept { return get32(inputs, 4); }
  void set_actual_position(std::int32_t v) noexcept { put32(inputs, 4, v); }

 private:
  static std::uint16_t get16(const std::array<std::uint8_t, 8>& a, int o) noexcept {
    return static_cast<std::uint16_t>(a[static_cast<std::size_t>(o)] |
                                      (a[static_cast<std::size_t>(o) + 1] << 8));
  }
  static void put16(std::array<std::uint8_t, 8>& a, int o, std::uint16_t v) noexcept {
    a[static_cast<std::size_t>(o)] = static_cast<std::uint8_t>(v);
    a[static_cast<std::size_t>(o) + 1] = static_cast<std::uint8_t>(v >> 8);
  }
  static std::int32_t get32(const std::array<std::uint8_t, 8>& a, int o) noexcept {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | a[static_cast<std::size_t>(o + i)];
    return static_cast<std::int32_t>(v);
  }
  static void put32(std::array<std::uint8_t, 8>& a, int o, std::int32_t v) noexcept {
    const auto u = static_cast<std::uint32_t>(v);
    for (int i = 0; i < 4; ++i) a[static_cast<std::size_t>(o + i)] = static_cast<std::uint8_t>(u >> (8 * i));
  }
};

/// @brief The simulated drive's parameters.
struct DriveParameters {
  double counts_per_unit = 1e6;  ///< counts per metre (1 µm resolution)
  double max_velocity = 0.5;     ///< m/s the drive moves at most
  double lower = -2.0;           ///< travel range, m
  double upper = 2.0;
  double following_error = 0.05;  ///< m between target and actual before the drive faults
};

/// @brief A drive behind the process image: cyclic synchronous position with a speed limit.
class SimulatedDrive {
 public:
  explicit SimulatedDrive(DriveParameters p = {}) : p_(p) {}

  /// @brief One bus cycle of @p dt seconds: reads @p image's outputs, steps the state machine and the
  /// motion, writes the inputs.
  void exchange(ProcessImage& image, double dt) noexcept;
  /// @brief Makes the drive fault with @p code at its next cycle (a drive error from outside).
  void inject_fault(std::uint16_t code = error::external) noexcept { injected_ = code; }
  /// @brief Places the axis (before the bus runs, e.g. where the real axis stands).
  void set_position(double metres) noexcept { position_ = metres; }

  [[nodiscard]] DriveState state() const noexcept { return state_; }
  [[nodiscard]] double position() const noexcept { return position_; }
  [[nodiscard]] std::uint16_t error_code() const noexcept { return error_code_; }
  [[nodiscard]] const DriveParameters& parameters() const noexcept { return p_; }

 private:
  void enter_fault(std::uint16_t code) noexcept;

  DriveParameters p_;
  DriveState state_ = DriveState::SwitchOnDisabled;
  double position_ = 0.0;
  double velocity_ = 0.0;
  std::uint16_t error_code_ = 0;
  std::uint16_t injected_ = 0;
  std::uint16_t last_control_ = 0;
};

}  // namespace vsd::robotics::fieldbus
