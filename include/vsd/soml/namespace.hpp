/** @file
 *  @brief The class namespace of vsd::soml: its database classes are named "soml::Place", ...
 */
#pragma once

#include "vsd/core/declare.hpp"

namespace vsd::soml {
VSD_CLASS_NAMESPACE("soml")
}  // namespace vsd::soml
