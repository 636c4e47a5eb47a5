/** @file
 *  @brief KinematicTree: the extension of a 3D node that makes it the base of a kinematic tree (or chain),
 *  and the ways to build one — from a URDF loaded by vsd::scene, or from a DH table in code.
 *
 *  The tree is the database content below its base: every Node3D below it whose KinematicJoint
 *  extension says how it moves (a node without one is fixed at its `frame`). model() compiles it into a
 *  Model, kept until the topology changes (a joint's kind, placement, axis, limits or mimic, a node or an
 *  extension added or removed); changing joint values never recompiles.
 */
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "vsd/core/extension.hpp"
#include "vsd/robotics/joint.hpp"
#include "vsd/robotics/model.hpp"

namespace vsd {
class SimState;
}
namespace vsd::scene {
class Node3D;
class Scene;
}  // namespace vsd::scene

namespace vsd::robotics {

class KinematicTree : public vsd::Extension {
  VSD_INSTANCE(KinematicTree, vsd::Extension)

 public:
  /// @brief The base node (the owner), or nullptr when not attached to a Node3D.
  [[nodiscard]] scene::Node3D* base() const noexcept;
  /// @brief Every KinematicJoint below the base, depth first.
  [[nodiscard]] std::vector<KinematicJoint*> joints() const;
  /// @brief The joint named @p name below the base, or nullptr.
  [[nodiscard]] KinematicJoint* find_joint(std::string_view name) const;
  /// @brief The compiled model of the whole tree; recompiled only after a topology change (a change of
  /// anything inside the tree but joint values: a limit, a fixed link's frame, a link added or removed).
  /// The reference stays valid until the next such change: an IkSolver made from it must not be kept
  /// across one (make it again, as the two-robot work cell does before each solve).
  /// @throws vsd::Error when not attached to a Node3D or when compile() throws.
  [[nodiscard]] const Model& model() const;
  /// @brief How often model() compiled (for tests and diagnostics).
  [[nodiscard]] std::uint64_t compilations() const noexcept { return compilations_; }
  /// @brief The model's joint vector read from the database (layout order).
  [[nodiscard]] std::vector<double> positions() const;
  /// @brief Writes joint vector @p q (model layout) to the joints' position properties.
  /// @throws vsd::Error when @p q does not have model().dof() values.
  void set_positions(std::span<const double> q);

 private:
  mutable std::shared_ptr<const Model> model_;
  mutable std::uint64_t model_version_ = 0;
  mutable std::uint64_t compilations_ = 0;
};

/// @brief Makes the robotics tracker of @p state exist (in its context): joint values move link frames,
/// mimics follow, topology versions count. The link frames and mimic values it writes are derived changes
/// (SimState::Deriving): signalled, not recorded, because every state the tracker serves derives them
/// itself from the recorded joint values. The robotics Module makes it for every state it serves (all
/// states by default: a replica needs it to see its links move); every function of vsd::robotics that
/// builds or compiles makes it for its state. Idempotent.
void track(SimState& state);
/// @brief Drops the tracker of @p state (the robotics Module does so when it stops serving the state).
void untrack(SimState& state) noexcept;
/// @brief The topology version of @p state: it grows whenever anything a compiled model depends on changes.
[[nodiscard]] std::uint64_t topology_version(SimState& state);

/// @brief Adds KinematicJoints to the links of @p scene from its scene::Joints (revolute and continuous →
/// Rotary, prismatic → Prismatic, fixed → Fixed; limits, velocities, mimics and positions copied, each
/// KinematicJoint named like its scene joint) and a KinematicTree to the scene. Floating and planar joints
/// become Fixed with a warning. Calling it again returns the existing tree.
/// @param warnings receives what was not used as written, when not null.
/// @throws vsd::Error when a scene joint has no child link.
KinematicTree& build_kinematics(scene::Scene& scene, std::vector<std::string>* warnings = nullptr);

/// @brief One row of a DH-defined chain.
struct DhJoint {
  std::string name;
  KinematicJointType type = KinematicJointType::Rotary;  ///< Rotary or Prismatic
  DhParameters parameters;
  bool has_limits = false;
  double lower = 0.0, upper = 0.0;
  double velocity_limit = 0.0;
};

/// @brief Builds a serial chain from a DH table below @p base: one scene::Link per row (named after the
/// joint with the suffix "_link"), each the child of the previous, each with a KinematicJoint; a
/// KinematicTree is added to @p base.
/// @throws vsd::Error for a Universal or Fixed row type, or an empty table.
KinematicTree& build_dh_chain(scene::Node3D& base, DhConvention convention, std::span<const DhJoint> rows);

}  // namespace vsd::robotics
