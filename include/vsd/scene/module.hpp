/** @file
 *  @brief vsd::scene::Module: registers the scene classes and types with an Environment's registry and
 *  keeps the world frames of every state it serves.
 *
 *  Per state it keeps one Watch (in the state's context) that invalidates cached world frames when a
 *  `frame` of a Node3D changes or any node changes parent. It serves every state (`derived` and
 *  `stepped` mean the same here). World frames work without the module too: the first world-frame read
 *  of a state makes its watch.
 *
 *  @code
 *  vsd::Environment env;
 *  env.use<vsd::scene::Module>();
 *  auto report = vsd::scene::load_urdf(env.main_state().root(), "robot.urdf");
 *  @endcode
 */
#pragma once

#include <string_view>

#include "vsd/core/module.hpp"

namespace vsd::scene {

class Module : public vsd::Module {
 public:
  [[nodiscard]] std::string_view name() const override { return "scene"; }
  /// @brief Registers Node3D, Hull, Link, Scene, Geometry, TextureMap, Material, Joint and their enums.
  void register_types(vsd::Registry& registry) override;
  /// @brief Makes (or, for Service::none, drops) the state's world-frame watch.
  void serve(vsd::SimState& state, vsd::Service from, vsd::Service to) override;
};

}  // namespace vsd::scene
