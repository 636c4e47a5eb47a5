/** @file
 *  @brief vsd::robotics: kinematic chains and trees as database extensions of 3D nodes, the compiled
 *  model (forward kinematics, Jacobians), inverse kinematics, controllers and hardware adapters (UDP,
 *  fieldbus) (link vsd::robotics).
 */
#pragma once

#include "vsd/robotics/controller.hpp"
#include "vsd/robotics/fieldbus_adapter.hpp"
#include "vsd/robotics/fieldbus_drive.hpp"
#include "vsd/robotics/fri_protocol.hpp"
#include "vsd/robotics/hardware_adapter.hpp"
#include "vsd/robotics/hardware_binding.hpp"
#include "vsd/robotics/ik.hpp"
#include "vsd/robotics/joint.hpp"
#include "vsd/robotics/kinematic_tree.hpp"
#include "vsd/robotics/model.hpp"
#include "vsd/robotics/module.hpp"
#include "vsd/robotics/trajectory.hpp"
#include "vsd/robotics/udp_adapter.hpp"
#include "vsd/scene.hpp"
