/** @file
 *  @brief The class namespace of vsd::scene: its classes are named "scene::Node3D", "scene::Hull", ...
 *  in the Registry, in files and in bundles (see "How a module names its classes" in docs/design.md).
 */
#pragma once

#include "vsd/core/declare.hpp"

namespace vsd::scene {
VSD_CLASS_NAMESPACE("scene")
}  // namespace vsd::scene
