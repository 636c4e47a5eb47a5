/** @file
 *  @brief World: an extension that makes the subtree of its node one ODE world — gravity, step size,
 *  solver and contact parameters. Rigid bodies belong to the world of their nearest ancestor (or own
 *  node) that carries a World.
 */
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "vsd/core/extension.hpp"
#include "vsd/core/meta_type_eigen.hpp"
#include "vsd/physics/namespace.hpp"

namespace vsd::physics {

/// @brief Which ODE stepper advances the world.
enum class Solver : std::uint8_t {
  Quick,  ///< dWorldQuickStep: iterative (SOR-LCP, `iterations`), O(n) in the constraints
  Exact   ///< dWorldStep: a direct (Dantzig) LCP solve per island, O(n^3), accurate for small islands
};
VSD_ENUM(Solver, Quick, Exact)

class World : public vsd::Extension {
  VSD_INSTANCE(World, vsd::Extension)
  /// m/s^2, in world coordinates.
  VSD_PROPERTY(Eigen::Vector3d, gravity, (Eigen::Vector3d(0.0, 0.0, -9.81)))
  /// Fixed ODE step in seconds; a scheduler step of dt runs as many whole steps as fit (the rest waits).
  VSD_PROPERTY(double, step, 0.001)
  VSD_PROPERTY(Solver, solver, Solver::Quick)
  /// Iterations of the Quick solver.
  VSD_PROPERTY(std::int32_t, iterations, 20)
  /// Error reduction parameter of joints and contacts (fraction of a position error corrected per step).
  VSD_PROPERTY(double, erp, 0.2)
  /// Constraint force mixing (softness of joints and contacts).
  VSD_PROPERTY(double, cfm, 1e-9)
  /// Depth (m) contacts may sink in before they are pushed apart, so resting contacts do not jitter.
  VSD_PROPERTY(double, contact_surface_layer, 0.0005)
  /// Limit (m/s) of the velocity with which a penetration is corrected (0: no limit).
  VSD_PROPERTY(double, max_correcting_velocity, 1.0)
  /// Contact points generated per pair of hulls.
  VSD_PROPERTY(std::int32_t, max_contacts, 8)
  /// Normal approach speed (m/s) below which a contact does not bounce.
  VSD_PROPERTY(double, bounce_threshold, 0.01)
  /// Friction and restitution of hulls without a Material.
  VSD_PROPERTY(double, default_friction, 0.5)
  VSD_PROPERTY(double, default_restitution, 0.0)
  /// Seconds simulated in this world so far (written by vsd::physics).
  VSD_PROPERTY(double, time, 0.0)
};

}  // namespace vsd::physics
