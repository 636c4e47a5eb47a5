/** @file
 *  @brief FieldbusAxisAdapter: a HardwareAdapter for one linear axis on a fieldbus, here a simulated
 *  cyclic I/O image with a simulated drive (fieldbus_drive.hpp) — the shape of a Profibus or EtherCAT
 *  axis driver.
 *
 *  Each cycle the adapter writes the control word and the target position into the output image, runs
 *  the bus exchange, and reads the status word, error code and actual position. It brings the drive up
 *  by the CiA 402 sequence (shutdown, switch on, enable operation) over the first cycles; the state is
 *  `fresh` only in Operation enabled. A drive fault is an AdapterFault::Device with the error code;
 *  reset_fault() sends the fault-reset edge and the adapter enables the drive again. A hold command
 *  targets the actual position.
 */
#pragma once

#include "vsd/robotics/fieldbus_drive.hpp"
#include "vsd/robotics/hardware_adapter.hpp"

namespace vsd::robotics {

/// @brief How FieldbusAxisAdapter's simulated bus is set up.
struct FieldbusOptions {
  fieldbus::DriveParameters drive;  ///< the simulated drive behind the image
  double initial_position = 0.0;    ///< where the simulated axis stands at the start, m
  int enable_timeout = 20;          ///< cycles the enable sequence may take before a Connection fault
};

class FieldbusAxisAdapter final : public HardwareAdapter {
 public:
  /// @throws vsd::Error for non-positive counts per unit or speed, or lower > upper.
  explicit FieldbusAxisAdapter(FieldbusOptions options = {});

  [[nodiscard]] std::string describe() const override { return "fieldbus axis"; }
  /// @brief Switches the bus on; the drive is enabled over the next cycles.
  void connect() override;
  void disconnect() noexcept override;
  [[nodiscard]] bool connected() const noexcept override { return on_; }
  void cycle(double dt) noexcept override;
  /// @brief Sends the fault-reset edge in the next cycle, then enables the drive again.
  void reset_fault() override { reset_requested_ = true; }

  /// @brief The I/O image as last exchanged.
  [[nodiscard]] const fieldbus::ProcessImage& image() const noexcept { return image_; }
  /// @brief The simulated drive (to inject faults in tests and examples).
  [[nodiscard]] fieldbus::SimulatedDrive& drive() noexcept { return drive_; }

 private:
  FieldbusOptions options_;
  fieldbus::ProcessImage image_;
  fieldbus::SimulatedDrive drive_;
  bool on_ = false;
  bool reset_requested_ = false;
  int enabling_cycles_ = 0;
};

}  // namespace vsd::robotics
