/** @file
 *  @brief vsd::robotics::Module: registers the robotics classes and types, and tracks the SimStates of
 *  the Environment (joint values move link frames; see track()).
 *
 *  @code
 *  vsd::Environment env;
 *  env.use<vsd::robotics::Module>();   // uses vsd::scene::Module too
 *  auto report = vsd::scene::load_urdf(env.main_state().root(), "iiwa14.urdf");
 *  auto& tree = vsd::robotics::build_kinematics(*report.scene);
 *  tree.find_joint("iiwa_joint_2")->set_position(0.5);   // iiwa_link_2 and below move
 *  @endcode
 */
#pragma once

#include <cstdint>
#include <string_view>

#include "vsd/core/module.hpp"

namespace vsd::robotics {

class Module : public vsd::Module {
 public:
  [[nodiscard]] std::string_view name() const override { return "robotics"; }
  /// @brief Registers KinematicJoint, KinematicTree, the controllers and their enums.
  void register_types(vsd::Registry& registry) override;
  /// @brief Uses vsd::scene::Module and adds the periodic task "robotics control" (every base step, phase
  /// controllers) that steps every JointController of every state the module serves `stepped` (by default
  /// the main state), then cycles every HardwareBinding (send the commands, read the robots).
  void attach(vsd::Environment& env) override;
  /// @brief Removes the control task.
  void detach(vsd::Environment& env) override;
  /// @brief `derived` (the default for every state but the main one): the state's robotics tracker
  /// (track()) derives link frames and mimic values from joint values; `stepped` also steps its
  /// controllers and hardware bindings; `none` drops the tracker.
  void serve(SimState& state, Service from, Service to) override;

 private:
  std::uint32_t control_task_ = 0;
};

}  // namespace vsd::robotics
