/** @file
 *  @brief The class namespace of vsd::physics: its classes are named "physics::RigidBody",
 *  "physics::World", "physics::Joint" in the Registry, in files and in bundles.
 */
#pragma once

#include "vsd/core/declare.hpp"

namespace vsd::physics {
VSD_CLASS_NAMESPACE("physics")
}  // namespace vsd::physics
