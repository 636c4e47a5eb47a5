// SpatialView (see vsd/scene/spatial_view.hpp): relations kept in force through frame signals.
#include "vsd/scene/spatial_view.hpp"

#include <algorithm>
#include <string>

#include "vsd/core/element_index.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/scene/node3d.hpp"
#include "vsd/scene/support.hpp"

namespace vsd::scene {

namespace {

bool at_or_below(const vsd::Node& n, const vsd::Node& top) {
  for (const vsd::Node* p = &n; p != nullptr; p = p->parent())
    if (p == &top) return true;
  return false;
}

std::string name_of(const Node3D& n) { return "'" + n.name() + "' (id " + std::to_string(n.id()) + ")"; }

}  // namespace

SpatialView::SpatialView(SimState& state)
    : state_(state),
      watch_(state, [this](SimStateInstance& inst, const MetaProperty* p, Changes what) { heard(inst, p, what); }) {
  // Node3D frames (what moves carried objects) and extensions (a Support attached or detached), any
  // property of a Support, Supports and Node3Ds deleted, and nodes that change parent (a re-parented
  // node may have moved in the world: its frame is now relative to another parent; a move between
  // parents attaches before it detaches, so the new parent is known only at the removal).
  watch_.properties(Node3D::static_meta(), {&Node3D::vsd_prop_frame(), &vsd::NamedModelInstance::vsd_prop_extensions()})
      .all_properties(Support::static_meta())
      .deleted(Support::static_meta())
      .deleted(Node3D::static_meta())
      .reparented(vsd::Node::static_meta());
  // What the SimState holds already (a loaded file, a copied replica). Supports carried by others are put
  // in force after theirs (by id, as a file or a replica orders them), which keeps the cycle check exact.
  std::vector<Support*> sups = state.index().all<Support>();
  std::sort(sups.begin(), sups.end(), [](const Support* a, const Support* b) { return a->id() < b->id(); });
  for (Support* sup : sups)
    if (auto* owner = sup->owner())
      if (auto* object = owner->as<Node3D>()) rescan(*object);
}

SpatialView::~SpatialView() = default;

void SpatialView::heard(SimStateInstance& inst, const MetaProperty* p, Changes what) {
  if (auto* sup = inst.as<Support>()) {
    if (auto* owner = sup->owner())
      if (auto* object = owner->as<Node3D>()) rescan(*object, what.has(Changes::deleted) ? sup : nullptr);
    return;
  }
  if (what.has(Changes::deleted)) {
    if (!relations_.empty()) drop(static_cast<vsd::Node&>(inst));
  } else if (what.has(Changes::parent)) {
    if (!relations_.empty()) on_moved(static_cast<vsd::Node&>(inst));
  } else if (p == &vsd::NamedModelInstance::vsd_prop_extensions()) {
    rescan(static_cast<Node3D&>(inst));
  } else if (!relations_.empty()) {  // the frame
    on_moved(static_cast<vsd::Node&>(inst));
  }
}

std::string SpatialView::refusal(const Node3D& object, const Node3D& support) const {
  if (&object == &support) return name_of(object) + " cannot be its own support";
  for (const Node3D* s = &support; s != nullptr; s = support_of(*s))
    if (s == &object)
      return name_of(support) + " is carried by " + name_of(object) + ", so it cannot carry it";
  if (at_or_below(support, object))
    return name_of(support) + " lies below " + name_of(object) +
           " in the spanning tree, so it cannot carry it";
  return {};
}

void SpatialView::rescan(Node3D& object, const Support* ignore) {
  const Support* sup = nullptr;
  for (const vsd::Extension* e : object.extensions())
    if (const auto* x = e->as<Support>(); x != nullptr && x != ignore && x->support().get() != nullptr) {
      sup = x;
      break;
    }
  if (sup == nullptr) {
    remove(object);
    return;
  }
  Node3D& support = *sup->support();
  auto it = relations_.find(&object);
  if (it != relations_.end() && it->second.support == &support) {  // same support: the kind may have changed
    it->second.kind = sup->relation();
    return;
  }
  // Checked against the relations without this object's own (it is being replaced).
  std::optional<Relation> old;
  if (it != relations_.end()) {
    old = it->second;
    relations_.erase(it);
  }
  if (std::string why = refusal(object, support); !why.empty() || &support.state() != &state_) {
    if (why.empty()) why = name_of(support) + " belongs to another SimState";
    std::string text = "spatial view: the Support of " + name_of(object) + " is not in force: " + why;
    if (std::find(warnings_.begin(), warnings_.end(), text) == warnings_.end())
      warnings_.push_back(std::move(text));
    if (old) removed_.emit(object);
    return;
  }
  if (stale_) refresh_offsets();
  // The relative pose now (the view keeps it equal to the current one); during a bundle the poses may be
  // half applied: every later change of the bundle recomputes it (on_moved).
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d& sw = support.world_frame();
  const Eigen::Isometry3d& ow = object.world_frame();
  if (sw.matrix().allFinite() && ow.matrix().allFinite()) offset = sw.inverse() * ow;
  relations_[&object] = Relation{&support, sup->relation(), offset};
  if (!old) added_.emit(object);
}

void SpatialView::remove(Node3D& object) {
  if (!relations_.contains(&object)) return;
  removed_.emit(object);
  relations_.erase(&object);  // by key: a listener may have changed the map
}

void SpatialView::relate(Node3D& object, Node3D& support, SpatialRelation relation) {
  if (&object.state() != &state_ || &support.state() != &state_)
    throw Error("spatial view: " + name_of(object) + " and " + name_of(support) +
                " must belong to the view's SimState");
  if (std::string why = refusal(object, support); !why.empty()) throw Error("spatial view: " + why);
  const Eigen::Isometry3d& sw = support.world_frame();
  const Eigen::Isometry3d& ow = object.world_frame();
  if (!sw.matrix().allFinite() || !ow.matrix().allFinite())
    throw Error("spatial view: the world poses of " + name_of(object) + " and " + name_of(support) +
                " must be finite to relate them");
  if (stale_) refresh_offsets();
  // The database is the truth: write the Support; the listeners put it in force.
  Support* sup = object.find_extension<Support>();
  if (sup == nullptr) {
    sup = &state_.create<Support>();
    sup->set_support(&support);
    sup->set_relation(relation);
    object.add_extension(*sup);
  } else {
    sup->set_relation(relation);
    sup->set_support(&support);
  }
}

bool SpatialView::release(Node3D& object) {
  if (!relations_.contains(&object)) return false;
  // Every Support of the object goes (a file may hold more than one); the listeners end the relation.
  std::vector<Support*> sups;
  for (vsd::Extension* e : object.extensions())
    if (auto* x = e->as<Support>()) sups.push_back(x);
  for (Support* x : sups) state_.destroy(*x);
  remove(object);
  return true;
}

Node3D* SpatialView::support_of(const Node3D& object) const {
  auto it = relations_.find(const_cast<Node3D*>(&object));
  return it != relations_.end() ? it->second.support : nullptr;
}

std::optional<SpatialRelation> SpatialView::relation_of(const Node3D& object) const {
  auto it = relations_.find(const_cast<Node3D*>(&object));
  if (it == relations_.end()) return std::nullopt;
  return it->second.kind;
}

std::optional<Eigen::Isometry3d> SpatialView::offset_of(const Node3D& object) const {
  if (stale_) refresh_offsets();
  auto it = relations_.find(const_cast<Node3D*>(&object));
  if (it == relations_.end()) return std::nullopt;
  return it->second.offset;
}

std::vector<Node3D*> SpatialView::carried_by(const Node3D& support) const {
  std::vector<Node3D*> out;
  for (const auto& [object, r] : relations_)
    if (r.support == &support) out.push_back(object);
  std::sort(out.begin(), out.end(), [](const Node3D* a, const Node3D* b) { return a->id() < b->id(); });
  return out;
}

std::vector<Node3D*> SpatialView::carried_closure(const Node3D& support) const {
  std::vector<Node3D*> out;
  std::vector<const Node3D*> todo{&support};
  while (!todo.empty()) {
    const Node3D* s = todo.front();
    todo.erase(todo.begin());
    for (Node3D* o : carried_by(*s)) {
      out.push_back(o);
      todo.push_back(o);
    }
  }
  return out;
}

bool SpatialView::contains(const vsd::Node& n) const {
  const auto* n3 = n.as<Node3D>();
  return n3 != nullptr && relations_.contains(const_cast<Node3D*>(n3));
}

void SpatialView::for_each(const std::function<void(vsd::Node&)>& fn) const {
  // Roots: supports that are not carried themselves, by id.
  std::vector<Node3D*> roots;
  for (const auto& [object, r] : relations_)
    if (!relations_.contains(r.support)) roots.push_back(r.support);
  std::sort(roots.begin(), roots.end(), [](const Node3D* a, const Node3D* b) { return a->id() < b->id(); });
  roots.erase(std::unique(roots.begin(), roots.end()), roots.end());
  for (Node3D* root : roots)
    for (Node3D* o : carried_closure(*root)) fn(*o);
}

void SpatialView::refresh_offsets() const {
  stale_ = false;
  for (auto& [object, r] : relations_) {
    const Eigen::Isometry3d& ow = object->world_frame();
    const Eigen::Isometry3d& sw = r.support->world_frame();
    if (ow.matrix().allFinite() && sw.matrix().allFinite()) r.offset = sw.inverse() * ow;
  }
}

void SpatialView::on_moved(vsd::Node& node) {
  // An applied bundle (undo, a replica's changes) already carries the moves the view would make, in an
  // order of its own: hold back, and take the poses it leaves as the new relative poses.
  if (state_.applying()) {
    // Recomputed at every change of the bundle (not lazily after it: the first change after the bundle
    // may be a support's move, and offsets taken then would already contain it), so the last change
    // leaves them equal to the poses the bundle leaves.
    Node3D::invalidate_below(node);
    refresh_offsets();
    return;
  }
  if (stale_) refresh_offsets();
  // The world-frame caches may not have heard of this change yet (listeners run in connection order):
  // mark them now, which is idempotent, so the reads below are current.
  Node3D::invalidate_below(node);
  // 1. Objects moved by someone else (not by the view's own enforcement) keep their relation with their
  //    new pose relative to the support — unless the support moved along with them.
  if (enforcing_ == 0) {
    for (auto& [object, r] : relations_) {
      if (at_or_below(*object, node) && !at_or_below(*r.support, node)) {
        const Eigen::Isometry3d& ow = object->world_frame();
        const Eigen::Isometry3d& sw = r.support->world_frame();
        if (ow.matrix().allFinite() && sw.matrix().allFinite()) r.offset = sw.inverse() * ow;
      }
    }
  }
  // 2. Objects whose support moved follow it, unless they moved along (below the moved node in the
  //    spanning tree). Collected first: moving them re-enters this function (what they carry follows).
  std::vector<Node3D*> follow;
  for (const auto& [object, r] : relations_)
    if (at_or_below(*r.support, node) && !at_or_below(*object, node)) follow.push_back(object);
  std::sort(follow.begin(), follow.end(), [](const Node3D* a, const Node3D* b) { return a->id() < b->id(); });
  for (Node3D* object : follow) {
    auto it = relations_.find(object);
    if (it == relations_.end()) continue;  // released or deleted by a listener meanwhile
    const Eigen::Isometry3d target = it->second.support->world_frame() * it->second.offset;
    if (!target.matrix().allFinite()) continue;  // a support with a NaN pose drags nothing into NaN
    ++enforcing_;
    try {
      object->set_world_frame(target);
    } catch (...) {
      --enforcing_;
      throw;
    }
    --enforcing_;
  }
}

void SpatialView::drop(vsd::Node& node) {
  auto* n3 = node.as<Node3D>();
  if (n3 == nullptr) return;
  std::vector<Node3D*> gone;
  for (const auto& [object, r] : relations_)
    if (object == n3 || r.support == n3) gone.push_back(object);
  std::sort(gone.begin(), gone.end(), [](const Node3D* a, const Node3D* b) { return a->id() < b->id(); });
  for (Node3D* o : gone) {
    if (!relations_.contains(o)) continue;
    removed_.emit(*o);
    relations_.erase(o);
  }
}

}  // namespace vsd::scene
