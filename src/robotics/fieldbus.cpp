// The simulated fieldbus drive (CiA 402 in small) and FieldbusAxisAdapter, its master side.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "vsd/core/error.hpp"
#include "vsd/robotics/fieldbus_adapter.hpp"

namespace vsd::robotics {

namespace fieldbus {

std::uint16_t status_word(DriveState s) noexcept {
  switch (s) {
    case DriveState::NotReadyToSwitchOn:
      return 0x0000;
    case DriveState::SwitchOnDisabled:
      return 0x0040;
    case DriveState::ReadyToSwitchOn:
      return 0x0021;
    case DriveState::SwitchedOn:
      return 0x0023;
    case DriveState::OperationEnabled:
      return 0x0027;
    case DriveState::Fault:
      return 0x0008;
  }
  return 0;
}

DriveState state_of(std::uint16_t sw) noexcept {
  if ((sw & 0x4F) == 0x08) return DriveState::Fault;
  if ((sw & 0x4F) == 0x40) return DriveState::SwitchOnDisabled;
  switch (sw & 0x6F) {
    case 0x21:
      return DriveState::ReadyToSwitchOn;
    case 0x23:
      return DriveState::SwitchedOn;
    case 0x27:
      return DriveState::OperationEnabled;
    default:
      return DriveState::NotReadyToSwitchOn;
  }
}

const char* to_string(DriveState s) noexcept {
  switch (s) {
    case DriveState::NotReadyToSwitchOn:
      return "NotReadyToSwitchOn";
    case DriveState::SwitchOnDisabled:
      return "SwitchOnDisabled";
    case DriveState::ReadyToSwitchOn:
      return "ReadyToSwitchOn";
    case DriveState::SwitchedOn:
      return "SwitchedOn";
    case DriveState::OperationEnabled:
      return "OperationEnabled";
    case DriveState::Fault:
      return "Fault";
  }
  return "?";
}

void SimulatedDrive::enter_fault(std::uint16_t code) noexcept {
  state_ = DriveState::Fault;
  error_code_ = code;
  velocity_ = 0.0;
}

void SimulatedDrive::exchange(ProcessImage& image, double dt) noexcept {
  const std::uint16_t cw = image.control_word();
  const bool reset_edge = (cw & control::fault_reset) != 0 && (last_control_ & control::fault_reset) == 0;
  last_control_ = cw;
  const bool voltage = (cw & 0x0002) != 0;
  const bool shutdown = (cw & 0x0087) == control::shutdown;
  const bool switch_on = (cw & 0x008F) == control::switch_on;
  const bool enable = (cw & 0x008F) == control::enable_operation;
  if (injected_ != 0) {
    enter_fault(injected_);
    injected_ = 0;
  }
  switch (state_) {
    case DriveState::NotReadyToSwitchOn:
      state_ = DriveState::SwitchOnDisabled;
      break;
    case DriveState::Fault:
      if (reset_edge) {
        state_ = DriveState::SwitchOnDisabled;
        error_code_ = 0;
      }
      break;
    case DriveState::SwitchOnDisabled:
      if (shutdown) state_ = DriveState::ReadyToSwitchOn;
      break;
    case DriveState::ReadyToSwitchOn:
      if (!voltage)
        state_ = DriveState::SwitchOnDisabled;
      else if (switch_on)
        state_ = DriveState::SwitchedOn;
      else if (enable)
        state_ = DriveState::OperationEnabled;
      break;
    case DriveState::SwitchedOn:
      if (!voltage)
        state_ = DriveState::SwitchOnDisabled;
      else if (shutdown)
        state_ = DriveState::ReadyToSwitchOn;
      else if (enable)
        state_ = DriveState::OperationEnabled;
      break;
    case DriveState::OperationEnabled:
      if (!voltage)
        state_ = DriveState::SwitchOnDisabled;
      else if (shutdown)
        state_ = DriveState::ReadyToSwitchOn;
      else if (switch_on)
        state_ = DriveState::SwitchedOn;
      break;
  }
  velocity_ = 0.0;
  if (state_ == DriveState::OperationEnabled && dt > 0) {
    const double target = static_cast<double>(image.target_position()) / p_.counts_per_unit;
    if (target < p_.lower || target > p_.upper) {
      enter_fault(error::limit);
    } else if (std::abs(target - position_) > p_.following_error) {
      enter_fault(error::following);
    } else {
      const double step = std::clamp(target - position_, -p_.max_velocity * dt, p_.max_velocity * dt);
      position_ += step;
      velocity_ = step / dt;
    }
  }
  image.set_status_word(status_word(state_));
  image.set_error_code(error_code_);
  image.set_actual_position(static_cast<std::int32_t>(std::lround(position_ * p_.counts_per_unit)));
}

}  // namespace fieldbus

// ---- FieldbusAxisAdapter --------------------------------------------------------------------------------

using fieldbus::DriveState;

FieldbusAxisAdapter::FieldbusAxisAdapter(FieldbusOptions options)
    : HardwareAdapter(1), options_(options), drive_(options.drive) {
  const auto& d = options_.drive;
  if (!(d.counts_per_unit > 0) || !(d.max_velocity > 0) || !(d.lower <= d.upper) || !(d.following_error > 0))
    throw vsd::Error(
        "fieldbus axis: counts per unit, speed and following error must be positive and lower <= upper");
  if (d.lower * d.counts_per_unit < -2147483647.0 || d.upper * d.counts_per_unit > 2147483647.0)
    throw vsd::Error("fieldbus axis: the travel range does not fit 32-bit counts");
  drive_.set_position(options_.initial_position);
}

void FieldbusAxisAdapter::connect() {
  on_ = true;
  enabling_cycles_ = 0;
  state_.valid = false;
  state_.fresh = false;
  hold_ = true;
  clear_fault();
}

void FieldbusAxisAdapter::disconnect() noexcept {
  if (on_) {
    // Leave the drive switched off, as a master does when it stops.
    image_.set_control_word(fieldbus::control::disable_voltage);
    drive_.exchange(image_, 0.0);
  }
  on_ = false;
}

void FieldbusAxisAdapter::cycle(double dt) noexcept {
  ++stats_.cycles;
  state_.fresh = false;
  if (!on_) {
    ++stats_.missed;
    raise_fault(AdapterFault::Connection, describe() + ": the bus is off (not connected)");
    return;
  }
  const double cpu = options_.drive.counts_per_unit;
  // What the drive said last cycle decides this cycle's control word.
  const DriveState before = fieldbus::state_of(image_.status_word());
  std::uint16_t cw = fieldbus::control::shutdown;
  switch (before) {
    case DriveState::Fault:
      cw = reset_requested_ ? fieldbus::control::fault_reset : fieldbus::control::disable_voltage;
      reset_requested_ = false;
      break;
    case DriveState::NotReadyToSwitchOn:
    case DriveState::SwitchOnDisabled:
      cw = fieldbus::control::shutdown;
      break;
    case DriveState::ReadyToSwitchOn:
      cw = fieldbus::control::switch_on;
      break;
    case DriveState::SwitchedOn:
    case DriveState::OperationEnabled:
      cw = fieldbus::control::enable_operation;
      break;
  }
  const double actual = static_cast<double>(image_.actual_position()) / cpu;
  // Until enabled, and when holding, the target is where the axis is: enabling never jumps.
  const double target = (before == DriveState::OperationEnabled && !hold_) ? command_position_[0] : actual;
  const double bounded = std::clamp(target * cpu, -2147483647.0, 2147483647.0);
  image_.set_control_word(cw);
  image_.set_target_position(static_cast<std::int32_t>(std::lround(bounded)));

  drive_.exchange(image_, dt);

  const DriveState after = fieldbus::state_of(image_.status_word());
  const double previous = state_.position[0];
  state_.position[0] = static_cast<double>(image_.actual_position()) / cpu;
  state_.velocity[0] = state_.valid && dt > 0 ? (state_.position[0] - previous) / dt : 0.0;
  state_.valid = true;
  if (after == DriveState::Fault) {
    ++stats_.missed;
    char code[8];
    std::snprintf(code, sizeof code, "0x%04X", static_cast<unsigned>(image_.error_code()));
    const std::uint16_t e = image_.error_code();
    raise_fault(AdapterFault::Device,
                describe() + ": drive fault " + code +
                    (e == fieldbus::error::following ? " (following error)"
                     : e == fieldbus::error::limit   ? " (target outside the travel range)"
                                                     : ""));
    enabling_cycles_ = 0;
    return;
  }
  if (after == DriveState::OperationEnabled) {
    ++stats_.received;
    state_.fresh = true;
    enabling_cycles_ = 0;
    if (fault() != AdapterFault::None) clear_fault();
    return;
  }
  ++stats_.missed;
  if (++enabling_cycles_ > options_.enable_timeout && fault() == AdapterFault::None)
    raise_fault(AdapterFault::Connection, describe() + ": the drive is not enabled after " +
                                              std::to_string(enabling_cycles_) + " cycles (state " +
                                              fieldbus::to_string(after) + ")");
}

}  // namespace vsd::robotics
