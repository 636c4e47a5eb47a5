/** @file
 *  @brief vsd::dist: SimStates kept in sync across processes and machines on Cyclone DDS — participants,
 *  the wire form of bundles, and the module (link vsd::dist).
 */
#pragma once

#include "vsd/core.hpp"
#include "vsd/dist/module.hpp"
#include "vsd/dist/participant.hpp"
#include "vsd/dist/wire.hpp"
