/** @file
 *  @brief Material: colour and physical properties of a surface and body, shared by many hulls.
 */
#pragma once

#include <Eigen/Core>

#include "vsd/core/meta_type_eigen.hpp"
#include "vsd/core/named_model_instance.hpp"
#include "vsd/scene/namespace.hpp"

namespace vsd::scene {

class Material : public vsd::NamedModelInstance {
  VSD_INSTANCE(Material, vsd::NamedModelInstance)
  /// Red, green, blue, alpha in [0, 1].
  VSD_PROPERTY(Eigen::Vector4d, color, (Eigen::Vector4d(0.8, 0.8, 0.8, 1.0)))
  /// kg/m^3.
  VSD_PROPERTY(double, density, 1000.0)
  /// Coulomb friction coefficient.
  VSD_PROPERTY(double, friction, 0.5)
  /// Coefficient of restitution in [0, 1].
  VSD_PROPERTY(double, restitution, 0.0)
  /// S/m.
  VSD_PROPERTY(double, electric_conductivity, 0.0)
};

}  // namespace vsd::scene
