/** @file
 *  @brief vsd::physics: ODE rigid-body dynamics of scene nodes — bodies, joints, contacts, gravity —
 *  driven by the database's signals and run by the Scheduler (link vsd::physics).
 */
#pragma once

#include "vsd/core.hpp"
#include "vsd/physics/joint.hpp"
#include "vsd/physics/module.hpp"
#include "vsd/physics/rigid_body.hpp"
#include "vsd/physics/simulation.hpp"
#include "vsd/physics/world.hpp"
#include "vsd/scene.hpp"
