// Node3D world frames: the lazy cache and the per-SimState listeners that keep it honest.
#include "vsd/scene/node3d.hpp"

#include <vector>

#include "vsd/core/sim_state.hpp"
#include "world_frames.hpp"

namespace vsd::scene {

WorldFrameWatch::WorldFrameWatch(SimState& state)
    : watch(state, [](SimStateInstance& inst, const MetaProperty*, Changes) {
        Node3D::invalidate_below(static_cast<vsd::Node&>(inst));
      }) {
  // Plain nodes between Node3Ds are transparent, so re-parenting any node may move Node3Ds below it.
  watch.properties(Node3D::static_meta(), {&Node3D::vsd_prop_frame()}).reparented(vsd::Node::static_meta());
}

WorldFrameWatch::~WorldFrameWatch() {
  // Without the watch no cache of this state can be trusted: all dirty, all untracked.
  watch.state().index().for_each(Node3D::static_meta(), true, [](SimStateInstance& i) {
    auto& n = static_cast<Node3D&>(i);
    n.world_clean_ = false;
    n.tracked_ = false;
  });
}

Node3D* Node3D::frame_parent() const noexcept {
  for (vsd::Node* p = parent(); p != nullptr; p = p->parent())
    if (auto* n = p->as<Node3D>()) return n;
  return nullptr;
}

void Node3D::invalidate_below(vsd::Node& node) {
  // Iterative: trees may be deeper than the stack. A dirty Node3D has only dirty Node3Ds below it (a clean
  // node's frame parent is always clean), so the walk stops there.
  auto* top = node.as<Node3D>();
  if (top != nullptr && !top->world_clean_) return;  // dirty already: so is everything below
  if (node.children().empty()) {                     // a leaf (a moved hull): no walk
    if (top != nullptr) top->world_clean_ = false;
    return;
  }
  std::vector<vsd::Node*> todo{&node};
  while (!todo.empty()) {
    vsd::Node* n = todo.back();
    todo.pop_back();
    if (auto* n3 = n->as<Node3D>()) {
      if (!n3->world_clean_) continue;
      n3->world_clean_ = false;
    }
    for (vsd::Node* c : n->children()) todo.push_back(c);
  }
}

const Eigen::Isometry3d& Node3D::update_world_frame() const {
  if (tracked_) {
    // The common case after a move: the frame parent is clean (or there is none), so this node is the
    // whole dirty chain; no chain to collect.
    const Node3D* p = frame_parent();
    if (p == nullptr || p->world_clean_) {
      world_ = p != nullptr ? p->world_ * frame_ : frame_;
      world_.makeAffine();
      ++world_updates_;
      world_clean_ = true;
      return world_;
    }
  }
  // The dirty chain from this node up to the first clean ancestor (or the top), then top-down.
  std::vector<const Node3D*> chain;
  const Node3D* top_parent = nullptr;
  for (const Node3D* n = this; n != nullptr; n = n->frame_parent()) {
    if (n->world_clean_) {
      top_parent = n;
      break;
    }
    chain.push_back(n);
  }
  if (!tracked_) {
    // Before any cache of this SimState becomes clean, its watch must exist.
    state().context().get_or_emplace<WorldFrameWatch>(state());
    for (const Node3D* n : chain) n->tracked_ = true;
  }
  const Eigen::Isometry3d* above = top_parent != nullptr ? &top_parent->world_ : nullptr;
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    const Node3D& n = **it;
    if (above != nullptr) {
      n.world_ = *above * n.frame_;
    } else {
      n.world_ = n.frame_;
    }
    n.world_.makeAffine();
    ++n.world_updates_;
    n.world_clean_ = true;
    above = &n.world_;
  }
  return world_;
}

void Node3D::set_world_frame(const Eigen::Isometry3d& world) {
  const Node3D* p = frame_parent();
  set_frame(p != nullptr ? Eigen::Isometry3d(p->world_frame().inverse() * world) : world);
}

}  // namespace vsd::scene
