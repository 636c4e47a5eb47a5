/** @file
 *  @brief Umbrella header: everything of vsd that was built (for now, the core).
 */
#pragma once

#include "vsd/core.hpp"
