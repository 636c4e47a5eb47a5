/** @file
 *  @brief CollisionWorld: an FCL collision world over the hulls of a SimState (or of a subtree), kept
 *  current through the core's signals; contact, distance and ray queries; contact begin/end signals.
 *
 *  The world follows the database instead of polling it. Listeners on the SimState note what changed —
 *  a Node3D's `frame`, a re-parenting, a hull's `role` or `geometry`, a Geometry's dimensions or mesh,
 *  created and deleted hulls and geometries — and the next sync() (which update() and every query run
 *  first) touches only that: the hulls below a moved node get their new world pose and only they are
 *  updated in the broadphase (FCL's dynamic AABB tree); a changed geometry rebuilds its one FCL shape,
 *  which every hull sharing that Geometry shares too.
 *
 *  Contacts are computed on an explicit update(), which then emits on_contact_begin() and
 *  on_contact_end() for the pairs that started or stopped touching since the previous update(): a
 *  listener always sees one consistent set of pairs, never a half-moved scene. The one exception is a
 *  hull being deleted: its pairs end at once (the signal comes while the hull is still whole), because
 *  afterwards there would be no hull to name.
 *
 *  Degenerate input never reaches FCL or libccd: a hull whose world pose is not finite, or whose
 *  geometry is degenerate (a dimension that is zero, negative or not finite, a mesh with vertices but
 *  without triangles or with indices out of range), is kept out of the world and listed in problems();
 *  update() then throws vsd::Error naming those hulls, their shapes and poses, after it has brought every
 *  other hull up to date. Exceptions thrown by FCL itself are caught and reported the same way, with both
 *  hulls. A mesh without any vertex is not degenerate but empty (a URDF loaded without its meshes): its
 *  hulls are skipped with one warning each in warnings(), as vsd::physics does, and never make update()
 *  throw; distance() on such a hull throws.
 *
 *  Which hulls: by default the Collision-role hulls (Hull::role) of the whole SimState; Options select
 *  visual hulls too, restrict the world to the subtree below a node, and filter pairs. A Geometry of kind
 *  Plane is the solid half-space below the plane (n·x <= 0 in the hull's frame), as a ground in ODE is.
 *
 *  FCL is a private dependency: no FCL header is reachable from here.
 */
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "vsd/core/signal.hpp"
#include "vsd/scene/fwd.hpp"

namespace vsd {
class Node;
class SimState;
}  // namespace vsd

namespace vsd::collision {

/// @brief One contact point between two hulls, in world coordinates.
struct Contact {
  scene::Hull* a = nullptr;  ///< the hull with the smaller id
  scene::Hull* b = nullptr;  ///< the other hull
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit normal pointing from a towards b
  double depth = 0;                                  ///< penetration depth (>= 0)
};

/// @brief The result of a distance query, in world coordinates.
struct DistanceResult {
  /// Distance between the surfaces; when the hulls overlap, minus the deepest penetration depth, and
  /// both points are that contact's point (which need not lie on either surface).
  double distance = 0;
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();  ///< nearest point on the first hull
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();  ///< nearest point on the second hull
};

/// @brief The first hull a ray hits.
struct RayHit {
  scene::Hull* hull = nullptr;
  double distance = 0;                               ///< along the (normalised) direction
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   ///< world coordinates
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< outward surface normal at the point
};

/// @brief Which hulls a CollisionWorld holds and how it computes contacts.
struct Options {
  /// Only hulls at or below this node (the whole SimState when null). Must outlive the world or be
  /// deleted (then the world is empty).
  vsd::Node* root = nullptr;
  /// Visual hulls too (by default only hulls whose role is Collision).
  bool include_visual = false;
  /// Contact points computed per pair of hulls (at least 1).
  std::size_t max_contacts_per_pair = 4;
  /// Contact points one update() may find in all (hulls overlapping en masse would otherwise fill memory):
  /// beyond it update() stops the query and throws vsd::Error, keeping the previous contacts.
  std::size_t max_contacts = 100'000;
  /// Pairs for which this returns false are never in contact (e.g. hulls of one rigid body).
  std::function<bool(const scene::Hull&, const scene::Hull&)> pair_filter;
};

/// @brief An FCL collision world over the hulls of a SimState, kept current through signals.
///
/// @code
/// vsd::collision::CollisionWorld world(env.main_state());
/// auto c = world.on_contact_begin().connect([](Hull& a, Hull& b) { ... });
/// for (;;) { move_things(); world.update(); for (const Contact& k : world.contacts()) ... }
/// @endcode
/// The world must not outlive its SimState; it belongs to the SimState's thread.
class CollisionWorld {
 public:
  using PairSignal = Signal<void(scene::Hull& a, scene::Hull& b)>;
  using PairSink = Sink<void(scene::Hull& a, scene::Hull& b)>;

  /// @brief A world over the hulls of @p state chosen by @p options, filled at once.
  /// @throws vsd::Error when options.root belongs to another SimState.
  explicit CollisionWorld(SimState& state, Options options = {});
  ~CollisionWorld();
  CollisionWorld(const CollisionWorld&) = delete;
  CollisionWorld& operator=(const CollisionWorld&) = delete;

  /// @brief Applies the pending changes (sync()), computes all contacts, and emits on_contact_end()
  /// then on_contact_begin() for the pairs that changed since the previous update().
  /// @throws vsd::Error naming the hulls, shapes and poses when a hull is degenerate (it is left out;
  /// everything else is current and signalled) or when FCL fails on a pair. When the contact points
  /// exceed Options::max_contacts or memory runs out, vsd::Error too, but then contacts, pairs and
  /// signals stay as the previous update() left them; an exception thrown by the pair filter stops the
  /// query the same way and is rethrown as it is. Nothing is ever thrown through FCL.
  void update();
  /// @brief Applies the pending changes to poses, shapes and the broadphase without computing
  /// contacts. Queries call it themselves. Never throws for degenerate hulls (see problems()).
  void sync();

  /// @brief The contact points found by the last update(), ordered by (a id, b id).
  [[nodiscard]] const std::vector<Contact>& contacts() const noexcept;
  /// @brief The pairs in contact after the last update(), each once, ordered by (a id, b id).
  [[nodiscard]] std::vector<std::pair<scene::Hull*, scene::Hull*>> contact_pairs() const;
  /// @brief True when @p a and @p b touched at the last update().
  [[nodiscard]] bool in_contact(const scene::Hull& a, const scene::Hull& b) const;

  /// @brief Distance between @p a and @p b now (pending changes applied first), with nearest points.
  /// @throws vsd::Error when a hull is not in the world, is degenerate, or FCL fails (naming both).
  DistanceResult distance(const scene::Hull& a, const scene::Hull& b);
  /// @brief The first hull hit by the ray from @p origin along @p direction within @p max_distance
  /// (pending changes applied first). A ray starting inside a hull hits it at distance 0.
  /// @throws vsd::Error for a zero or non-finite direction or a non-finite origin.
  std::optional<RayHit> ray_cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                 double max_distance = std::numeric_limits<double>::infinity());

  /// @brief Emitted by update() for each pair that started touching (a has the smaller id).
  [[nodiscard]] PairSink on_contact_begin() noexcept;
  /// @brief Emitted by update() for each pair that stopped touching, and at once for the pairs of a
  /// hull that is being deleted (while it is still whole).
  [[nodiscard]] PairSink on_contact_end() noexcept;

  /// @brief Number of hulls in the world (degenerate ones included).
  [[nodiscard]] std::size_t size() const noexcept;
  /// @brief True when @p hull is in the world.
  [[nodiscard]] bool contains(const scene::Hull& hull) const;
  /// @brief Number of distinct FCL shapes (hulls sharing a Geometry share one).
  [[nodiscard]] std::size_t shape_count() const noexcept;
  /// @brief How many hulls the last sync() moved in the broadphase (for tests and diagnostics).
  [[nodiscard]] std::size_t last_moved() const noexcept;
  /// @brief One line per degenerate hull, naming it, its shape and its pose (empty when all are fine).
  [[nodiscard]] std::vector<std::string> problems() const;
  /// @brief Warnings, each once, in the order they arose: hulls skipped because their mesh has no
  /// vertices (a URDF loaded without its meshes, or a mesh file that was missing). They do not collide,
  /// are not problems and do not make update() throw.
  [[nodiscard]] const std::vector<std::string>& warnings() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vsd::collision
