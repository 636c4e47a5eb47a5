/** @file
 *  @brief Simulation: ODE rigid-body dynamics over the bodies, joints and collision hulls of one
 *  SimState, kept current through the database's signals.
 *
 *  What it reads: physics::World extensions (each makes its node's subtree one ODE world), RigidBody
 *  extensions on scene::Node3D (dynamic bodies), physics::Joint extensions, and scene::Hulls of role
 *  Collision (geoms: below a body they move with it, elsewhere they are static).
 *
 *  How it stays current: listeners on the SimState's signals only take notes — a structural change
 *  (created, deleted, re-parented, hull geometry or role, joint definition, World) marks the layout
 *  dirty, a frame set by someone else marks the node moved, a changed mass or velocity marks the body.
 *  sync(), at the start of every advance(), applies the notes: a dirty layout is rebuilt (every ODE
 *  object compared with what the database asks for; what is missing is made, what is gone destroyed),
 *  a moved node teleports the bodies and static hulls below it, a changed body gets its new mass or
 *  velocity. The database is the truth: everything sync() gives ODE comes from it, so after an error
 *  the next sync() rebuilds ODE from the last good state.
 *
 *  What it writes: after the steps, every body's node frame (through Node3D::set_world_frame, so every
 *  listener sees the motion), its velocities, cleared force/torque accumulators, the joints' positions
 *  and rates and each World's time.
 *
 *  Contacts come from ODE's own collider (dSpaceCollide and dCollide on ODE geoms that mirror the
 *  hulls' primitives), not from vsd::collision: see docs/physics.md for why and what would change.
 *
 *  Errors — a body without mass, a joint between bodies of different worlds, a NaN in a frame, a
 *  velocity or a force, a NaN produced by the step — are vsd::Error naming the instance, thrown by
 *  sync() or advance(); nothing in the database changes then. ODE's own error and debug handlers are
 *  redirected to throw vsd::Error too (never an abort), and its messages are kept as warnings().
 */
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "vsd/core/fwd.hpp"
#include "vsd/physics/joint.hpp"
#include "vsd/physics/rigid_body.hpp"
#include "vsd/physics/world.hpp"

namespace vsd::scene {
class Scene;
}

namespace vsd::physics {

/// At most this many ODE steps per World in one Simulation::advance() (1000 s at the default step of 1 ms).
inline constexpr std::uint64_t max_steps_per_advance = 1'000'000;
/// At most this many contact points in one step of one World (each is an ODE contact joint).
inline constexpr std::size_t max_contacts_per_step = 100'000;

/// @brief The mass properties ODE uses for a body, in the body node's frame.
struct MassProperties {
  double mass = 0.0;                                  ///< kg
  Eigen::Vector3d center = Eigen::Vector3d::Zero();   ///< centre of mass
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about the centre of mass, node axes
};

/// @brief Counts of what the simulation holds in ODE (for tests, tools and diagnostics).
struct SimulationStats {
  std::size_t worlds = 0;
  std::size_t bodies = 0;
  std::size_t joints = 0;
  std::size_t geoms = 0;     ///< body and static hull geoms
  std::size_t meshes = 0;    ///< ODE trimesh data sets in use (one per mesh Geometry, shared by its hulls)
  std::size_t contacts = 0;  ///< contact points of the last step
  std::size_t rebuilds = 0;  ///< layout rebuilds so far
  std::uint64_t steps = 0;   ///< ODE steps so far (all worlds)
};

class Simulation {
 public:
  /// @brief Follows @p state from now on (connects its listeners; builds ODE objects on the first sync).
  explicit Simulation(vsd::SimState& state);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  /// @brief Applies the changes made in the database since the last sync to ODE.
  /// @throws vsd::Error for an invalid body, hull, joint or value (nothing changes then).
  void sync();
  /// @brief Advances every world by @p seconds: sync(), as many fixed steps of each World's `step` as
  /// fit (the remainder is carried to the next call), then writes poses and velocities back.
  /// @throws vsd::Error for a negative or non-finite @p seconds and when a World would need more than
  /// max_steps_per_advance steps for it (nothing changes then); as sync(); and when a step produced a
  /// non-finite pose, more than max_contacts_per_step contact points or ran out of memory (the database
  /// keeps the last good state; the next sync rebuilds ODE from it).
  void advance(double seconds);
  /// @brief Adds @p force (N, world) acting at @p point (world) to @p body's accumulators: the force,
  /// and the torque (point - centre of mass) x force. @throws vsd::Error when @p body is not simulated.
  void add_force_at(RigidBody& body, const Eigen::Vector3d& force, const Eigen::Vector3d& point);
  /// @brief The mass properties used for @p body (after a sync). @throws vsd::Error when @p body is
  /// not simulated.
  [[nodiscard]] MassProperties mass_of(const RigidBody& body) const;
  /// @brief True when @p body currently exists in ODE.
  [[nodiscard]] bool simulates(const RigidBody& body) const noexcept;
  [[nodiscard]] SimulationStats stats() const noexcept;
  /// @brief ODE's messages and what vsd::physics skipped (e.g. hulls without geometry or with a mesh
  /// that has no vertices), oldest first.
  [[nodiscard]] const std::vector<std::string>& warnings() const noexcept;
  [[nodiscard]] vsd::SimState& state() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// @brief Makes a loaded URDF scene dynamic: a RigidBody on every Link with a mass, a physics::Joint
/// for every revolute, continuous (hinge), prismatic (slider) and fixed scene::Joint whose child link has
/// a mass (with its limits), and a World on the scene unless it is already below one. A floating joint
/// leaves its child free; links without mass move with their parent body.
/// @param fix_base also hold every root body (a body link that is no joint's child) to the static world.
/// @return the number of bodies made.
/// @throws vsd::Error for a planar or unknown joint (nothing is changed then).
std::size_t make_dynamic(scene::Scene& scene, bool fix_base = true);

}  // namespace vsd::physics
