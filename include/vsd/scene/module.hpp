/** @file
 *  @brief vsd::scene::Module: registers the scene classes and types with an Environment's registry.
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
};

}  // namespace vsd::scene
