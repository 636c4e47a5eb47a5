/** @file
 *  @brief SpatialView: nodes arranged by spatial relations ("lies on", "grabbed by", "attached to"),
 *  independent of the spanning tree, and kept in force through the SimState's signals.
 *
 *  The spanning tree says who owns whom; where things are is often another matter. A cup lies on a
 *  tray that lies on a table; a gripper grabs the tray and carries tray and cup away; it releases the
 *  tray on a shelf. None of that needs the cup or the tray to change parents (which would change what
 *  saving, deleting or replicating them means). The relations form a forest of their own — every related
 *  object has one support — and a SpatialView keeps them in force:
 *
 *  - relate() and release() move nothing: the object's world pose is the same before and after, at the
 *    moment of grabbing as at the moment of releasing. relate() remembers the object's pose relative to
 *    its support;
 *  - when a support moves in the world (its own `frame` changed, an ancestor's, or it was re-parented),
 *    the objects it carries are moved through Node3D::set_world_frame, so every listener (collision,
 *    rendering, a recording transaction) sees them move, and what they carry follows in turn;
 *  - when an object is moved by anyone else (placed, pushed, simulated), it stays related and its pose
 *    relative to the support is taken over: a cup pushed across a tray still lies on it.
 *
 *  While a bundle is applied (undo, a replica's changes) the view holds back: the bundle carries the moves
 *  it made at the source already; the poses the bundle leaves become the new relative poses.
 *
 *  The relations are database state: a scene::Support extension on the object (vsd/scene/support.hpp)
 *  names its support and the kind of relation. relate() and release() write it through the ordinary
 *  setters (create and attach, set, destroy), so vsd::io saves and loads relations and a replica applying
 *  the recorded bundles ends with the same ones. The view reads what is in the SimState when it is made
 *  and follows Support changes through the signals, whoever makes them (a loaded file, a replica's bundle,
 *  an undo, a setter). A Support that the view cannot put in force — a support carried by its own object,
 *  or below it in the spanning tree, as a hand-edited file may hold — is ignored with a warning
 *  (warnings()); every view of one SimState sees the same relations.
 *
 *  Nothing polls: the view listens to Node3D frame and extension changes, Support changes, re-parentings
 *  and deletions of its SimState.
 *  Each change costs O(relations × tree depth) while the view holds relations and one branch when it
 *  holds none. An object or support that is deleted leaves the view (on_removed()). The view is a
 *  Container: its nodes are the related objects, supports before what they carry.
 *  The view must not outlive its SimState and belongs to its thread.
 */
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "vsd/core/container.hpp"
#include "vsd/core/watch.hpp"
#include "vsd/core/meta_type.hpp"
#include "vsd/scene/namespace.hpp"
#include "vsd/scene/support.hpp"

namespace vsd {
class SimState;
}

namespace vsd::scene {

class Node3D;

class SpatialView : public vsd::Container {
 public:
  /// @brief A view of the Node3Ds of @p state, holding the relations its Support extensions record.
  explicit SpatialView(SimState& state);
  ~SpatialView() override;

  /// @brief From now on @p object moves with @p support (replacing a relation it had). Nothing moves.
  /// Writes the object's Support extension (made and attached when it has none) through its setters.
  /// @throws vsd::Error when either node belongs to another SimState, when they are the same node, when
  /// @p support is carried by @p object (directly or through others) or lies below it in the spanning
  /// tree (the object would have to follow its own motion), or when a world pose is not finite.
  void relate(Node3D& object, Node3D& support, SpatialRelation relation);
  /// @brief Ends @p object's relation (destroys its Support extension); it stays where it is. Returns
  /// false when it had none.
  bool release(Node3D& object);

  /// @brief The support of @p object, or nullptr.
  [[nodiscard]] Node3D* support_of(const Node3D& object) const;
  /// @brief The relation of @p object to its support, if it has one.
  [[nodiscard]] std::optional<SpatialRelation> relation_of(const Node3D& object) const;
  /// @brief @p object's pose in its support's frame, if it has a support.
  [[nodiscard]] std::optional<Eigen::Isometry3d> offset_of(const Node3D& object) const;
  /// @brief The objects @p support carries directly, by id.
  [[nodiscard]] std::vector<Node3D*> carried_by(const Node3D& support) const;
  /// @brief Everything that moves with @p support through the view (carried directly or indirectly),
  /// supports before what they carry.
  [[nodiscard]] std::vector<Node3D*> carried_closure(const Node3D& support) const;
  /// @brief Support extensions the view could not put in force (a cycle, a support below its object),
  /// each naming the nodes and why, oldest first.
  [[nodiscard]] const std::vector<std::string>& warnings() const noexcept { return warnings_; }

  [[nodiscard]] std::size_t size() const override { return relations_.size(); }
  [[nodiscard]] bool contains(const vsd::Node& n) const override;
  /// @brief The related objects, depth first through the relation forest (roots by id).
  void for_each(const std::function<void(vsd::Node&)>& fn) const override;

 private:
  struct Relation {
    Node3D* support;
    SpatialRelation kind;
    Eigen::Isometry3d offset;  // object's world pose in the support's frame
  };

  void heard(SimStateInstance& inst, const MetaProperty* p, Changes what);
  void on_moved(vsd::Node& node);
  void refresh_offsets() const;
  void drop(vsd::Node& node);
  // Puts the Support extensions of @p object in force (or ends its relation), skipping @p ignore.
  void rescan(Node3D& object, const Support* ignore = nullptr);
  void remove(Node3D& object);
  // Why @p support cannot carry @p object ("" when it can).
  [[nodiscard]] std::string refusal(const Node3D& object, const Node3D& support) const;

  SimState& state_;
  mutable std::unordered_map<Node3D*, Relation> relations_;  // by object
  mutable bool stale_ = false;  // a bundle moved things: offsets are recomputed from the poses
  int enforcing_ = 0;  // > 0 while the view itself moves objects
  std::vector<std::string> warnings_;
  Watch watch_;  // last: destroyed first, so nothing is heard while the view is torn down
};

}  // namespace vsd::scene
