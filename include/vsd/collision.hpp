/** @file
 *  @brief vsd::collision: an FCL collision world over the scene's hulls, kept current through signals;
 *  contacts, distances, ray casts, contact begin/end signals (link vsd::collision).
 */
#pragma once

#include "vsd/collision/collision_world.hpp"
#include "vsd/collision/module.hpp"
#include "vsd/scene.hpp"
