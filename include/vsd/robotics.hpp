/** @file
 *  @brief vsd::robotics: kinematic chains and trees as database extensions of 3D nodes, the compiled
 *  model (forward kinematics, Jacobians), inverse kinematics and the vsd-robot tool (link vsd::robotics).
 */
#pragma once

#include "vsd/robotics/controller.hpp"
#include "vsd/robotics/ik.hpp"
#include "vsd/robotics/joint.hpp"
#include "vsd/robotics/kinematic_tree.hpp"
#include "vsd/robotics/model.hpp"
#include "vsd/robotics/module.hpp"
#include "vsd/robotics/tool.hpp"
#include "vsd/robotics/trajectory.hpp"
#include "vsd/scene.hpp"
