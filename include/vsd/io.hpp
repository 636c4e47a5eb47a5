/** @file
 *  @brief vsd::io: persistence of SimStates through the meta-information (link vsd::io).
 */
#pragma once

#include "vsd/io/file.hpp"
#include "vsd/io/snapshot.hpp"
