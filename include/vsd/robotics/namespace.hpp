/** @file
 *  @brief The class namespace of vsd::robotics: its classes are named "robotics::KinematicJoint",
 *  "robotics::KinematicTree", ... in the Registry, in files and in bundles.
 */
#pragma once

#include "vsd/core/declare.hpp"

namespace vsd::robotics {
VSD_CLASS_NAMESPACE("robotics")
}  // namespace vsd::robotics
