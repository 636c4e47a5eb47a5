/** @file
 *  @brief HardwareBinding: the extension that binds a KinematicTree's joints to hardware adapters chosen
 *  by a configuration string, so the same model and controller run against the simulated robot (the
 *  database itself) or real interfaces by configuration only.
 *
 *  `config` is "sim" (or empty): the JointController writes the joints, nothing else happens. Otherwise it
 *  is a ';'-separated list of adapters, each `KIND[://ADDRESS][?KEY=VALUE&...]`:
 *
 *  | kind       | address        | keys                                                                    |
 *  |------------|----------------|-------------------------------------------------------------------------|
 *  | `udp`      | HOST:PORT      | `joints` (a,b,...), `timeout` (s per cycle, 0.005), `max_missed` (3)     |
 *  | `fieldbus` | (ignored)      | `joints` (one), `velocity` (m/s, 0.5), `lower`/`upper` (m, ±2),
 * `following_error` (m, 0.05), `counts` (per m, 1e6) |
 *
 *  `joints` names entries of the tree model's layout; without it an adapter takes every joint not bound
 *  by an earlier one. Joints bound to no adapter stay simulated.
 *
 *  Each control step (the robotics Module's task, after the controllers) cycle() sends the controller's
 *  command to every adapter, runs their cycles and writes the measured positions and velocities into the
 *  joints, so the database shows the robot as it is. While any adapter is not delivering fresh states
 *  (connecting, a lost answer, a dead peer, a drive fault) the binding *holds*: adapters are sent hold
 *  commands and the JointController does not advance; `status` is Fault with the reason in `fault`
 *  (watch them as any property), and when the adapters deliver again the status returns to Running and
 *  the controller replans from the measured positions.
 *
 *  @code
 *  auto& hw = state.create<vsd::robotics::HardwareBinding>();
 *  hw.set_config("udp://127.0.0.1:40123?joints=iiwa_joint_1,iiwa_joint_2,...;fieldbus://?joints=axis");
 *  scene.add_extension(hw);   // next to the KinematicTree and the JointController
 *  @endcode
 */
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/core/extension.hpp"
#include "vsd/robotics/hardware_adapter.hpp"
#include "vsd/robotics/kinematic_tree.hpp"

namespace vsd::robotics {

/// @brief Where a HardwareBinding stands.
enum class BindingStatus : std::uint8_t {
  Simulation,  ///< config "sim": the database is the robot
  Connecting,  ///< adapters made, not all delivering yet
  Running,     ///< every adapter delivers; the database shows the measured state
  Fault        ///< an adapter is in fault (or the configuration is bad): holding, see `fault`
};
VSD_ENUM(BindingStatus, Simulation, Connecting, Running, Fault)

/// @brief One adapter of a configuration string.
struct AdapterConfig {
  std::string kind;                            ///< "udp" or "fieldbus"
  std::string address;                         ///< after "://", before '?'
  std::vector<std::string> joints;             ///< the `joints` key, split at ','
  std::map<std::string, std::string> options;  ///< the other keys
};

/// @brief Parses a binding configuration (see the file comment); "sim" and "" give no adapters.
/// @throws vsd::Error naming the item and what is wrong (unknown kind, key without '=', ...).
[[nodiscard]] std::vector<AdapterConfig> parse_hardware_config(std::string_view config);

/// @brief Makes the adapter @p c describes, for @p dof joints (not connected).
/// @throws vsd::Error for an unknown kind, an unknown key, a malformed number or address.
[[nodiscard]] std::unique_ptr<HardwareAdapter> make_adapter(const AdapterConfig& c, int dof);

class HardwareBinding : public vsd::Extension {
  VSD_INSTANCE(HardwareBinding, vsd::Extension)
  /// "sim", or the adapters (see the file comment). A change takes effect at the next cycle.
  VSD_PROPERTY(std::string, config, "sim")
  /// Where the binding stands (not saved: it is about this process's link to the robot).
  VSD_PROPERTY(BindingStatus, status, BindingStatus::Simulation, vsd::Distributed | vsd::Transient)
  /// Why it holds (empty while Running or Simulation).
  VSD_PROPERTY(std::string, fault, "", vsd::Distributed | vsd::Transient)
  /// How often the status went to Fault.
  VSD_PROPERTY(std::int64_t, fault_count, 0, vsd::Distributed | vsd::Transient)

 public:
  HardwareBinding() = default;
  ~HardwareBinding() override;
  HardwareBinding(const HardwareBinding&) = delete;
  HardwareBinding& operator=(const HardwareBinding&) = delete;

  /// @brief The KinematicTree on the same node, or nullptr.
  [[nodiscard]] KinematicTree* tree() const noexcept;
  /// @brief True when the configuration names adapters (not "sim").
  [[nodiscard]] bool active() const noexcept;
  /// @brief True when a controller must not advance: active and not every adapter delivered fresh
  /// states in the last cycle.
  [[nodiscard]] bool holding() const noexcept { return active() && holding_; }
  /// @brief How often the database took the robot's state after not having it (first contact, each
  /// recovery): a controller replans when it grows.
  [[nodiscard]] std::uint64_t synchronisations() const noexcept { return synchronisations_; }
  /// @brief The command of the next cycle, in the tree model's layout (@p qd may be empty).
  /// @throws vsd::Error when the sizes are wrong.
  void command(std::span<const double> q, std::span<const double> qd = {});
  /// @brief One cycle of @p dt seconds: (re)configures after a config change, sends the command (or
  /// hold), exchanges, writes the measured state into the joints, updates status and fault. Never
  /// throws for a bad configuration or a lost robot: they become status Fault.
  void cycle(double dt);
  /// @brief Asks every adapter to leave its device fault (a drive's fault reset).
  void reset_faults();
  /// @brief Closes every adapter; the next cycle makes and connects them again.
  void disconnect();
  /// @brief The adapters of the current configuration (after the first cycle).
  [[nodiscard]] std::size_t adapter_count() const noexcept { return bound_.size(); }
  [[nodiscard]] HardwareAdapter& adapter(std::size_t i) const { return *bound_.at(i).adapter; }
  /// @brief The layout indices adapter @p i carries, in its joint order.
  [[nodiscard]] const std::vector<int>& adapter_joints(std::size_t i) const { return bound_.at(i).layout; }

 private:
  struct Bound {
    std::unique_ptr<HardwareAdapter> adapter;
    std::vector<int> layout;
  };
  void configure();
  void set_fault_state(std::string why);

  std::vector<Bound> bound_;
  std::string built_config_;
  bool built_ = false;
  bool holding_ = true;
  bool commanded_ = false;
  std::uint64_t synchronisations_ = 0;
  std::vector<double> command_q_, command_qd_;
};

}  // namespace vsd::robotics
