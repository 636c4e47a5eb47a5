// The two-robot cell's hardware adapters (issue 24, item 4; docs/workcell.md, "Hardware adapters"): with
// `--hardware` each robot's HardwareBinding drives its arm through the UDP FRI-like protocol
// (vsd::robotics::UdpAdapter) to a robot simulator process of its own and its linear axis through the
// fieldbus adapter (vsd::robotics::FieldbusAxisAdapter). The nets, the controllers and the checks are the
// same as in simulation; the database shows the joints as the adapters measure them.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace vsd {
class Node;
}
namespace vsd::robotics {
class HardwareBinding;
class KinematicTree;
}  // namespace vsd::robotics

namespace vsd_workcell {

struct FaultSpec;

/// The `--hardware` options of the cell.
struct HardwareOptions {
  bool enabled = false;         ///< --hardware: the arms over UDP, the linear axes over the fieldbus
  std::string simulator;        ///< --simulator PATH: vsd_robot_simulator (default: next to the program)
  std::string arm[2];           ///< --arm-a / --arm-b HOST:PORT: a simulator already running, not started here
  double timeout = 0.02;        ///< --hardware-timeout S: how long one cycle waits for the arm's answer
  double connect_timeout = 2.0; ///< s of wall time the adapters may take to deliver before the first step
};

/// Takes the hardware option at @p args[@p i] (and its value: @p i moves on); false when it is none.
/// @throws vsd::Error for a missing or malformed value.
bool take_hardware_option(const std::vector<std::string>& args, std::size_t& i, HardwareOptions& o);

/// @throws vsd::Error when a fault of @p faults needs what @p o does not give: an arm's silence needs
/// --hardware with that arm's simulator started here (not --arm-a/--arm-b: a process this run can stop).
void check_faults(const std::vector<FaultSpec>& faults, const HardwareOptions& o);

/// The adapters of both robots: starts the simulator processes (unless an endpoint was given) and binds
/// each robot's joints to them. Stops the processes it started when it goes.
class CellHardware {
 public:
  explicit CellHardware(HardwareOptions options);
  ~CellHardware();
  CellHardware(const CellHardware&) = delete;
  CellHardware& operator=(const CellHardware&) = delete;

  /// Binds robot @p i (0 A, 1 B) whose KinematicTree @p tree is on @p arm (its posture is where the
  /// simulated arm starts): a HardwareBinding next to the tree, arm joints on udp://, rail on fieldbus://.
  /// @throws vsd::Error when the simulator cannot be started.
  vsd::robotics::HardwareBinding& attach(int i, vsd::Node& arm, vsd::robotics::KinematicTree& tree);
  /// Cycles both bindings (holding the robots where they stand) until every adapter delivers, so that
  /// the run starts with both robots Running at the posture they report.
  /// @throws vsd::Error naming the robot and its binding's fault when that takes longer than
  /// HardwareOptions::connect_timeout.
  void connect(double dt);
  /// The binding of robot @p i (after attach).
  [[nodiscard]] vsd::robotics::HardwareBinding& binding(int i) const { return *bindings_[i]; }
  /// "udp://127.0.0.1:PORT?...;fieldbus://?..." of robot @p i.
  [[nodiscard]] const std::string& config(int i) const { return configs_[i]; }
  /// True when robot @p i's simulator was started here (so it can be silenced).
  [[nodiscard]] bool started(int i) const;
  /// "udp 127.0.0.1:PORT: cycles N, received N, missed N, rejected N, faults N, recoveries N; fieldbus axis: ...".
  [[nodiscard]] std::string summary(int i) const;
  /// Stops (true) or continues (false) robot @p i's simulator process: it stops answering, or answers again.
  void silence(int i, bool silent);

 private:
  struct Process;
  HardwareOptions options_;
  std::unique_ptr<Process> processes_[2];
  vsd::robotics::HardwareBinding* bindings_[2] = {nullptr, nullptr};
  std::string configs_[2];
  bool silent_[2] = {false, false};
};

}  // namespace vsd_workcell
