#include "vsd/core/container.hpp"

#include <algorithm>

#include "vsd/core/sim_state.hpp"

namespace vsd {

View::View(SimState& state, Filter filter, Order order)
    : filter_(std::move(filter)), order_(std::move(order)) {
  state.index().for_each(Node::static_meta(), true, [&](SimStateInstance& i) {
    auto& n = static_cast<Node&>(i);
    if (!filter_ || filter_(n)) nodes_.push_back(&n);
  });
  if (order_) {
    std::stable_sort(nodes_.begin(), nodes_.end(), [&](Node* a, Node* b) { return order_(*a, *b); });
  } else {
    std::sort(nodes_.begin(), nodes_.end(), [](Node* a, Node* b) { return a->id() < b->id(); });
  }
  connections_.push_back(state.on_created().connect([this](SimStateInstance& i) { consider(i); }));
  connections_.push_back(state.on_deleted().connect([this](SimStateInstance& i) { drop(i); }));
  // Membership and order may depend on any property: re-evaluate on change.
  connections_.push_back(
      state.on_property_changed().connect([this](SimStateInstance& i, const MetaProperty&) { consider(i); }));
}

View::~View() = default;

bool View::contains(const Node& n) const {
  return std::find(nodes_.begin(), nodes_.end(), &n) != nodes_.end();
}

void View::for_each(const std::function<void(Node&)>& fn) const {
  const std::vector<Node*> copy = nodes_;  // fn may change the view
  for (Node* n : copy) fn(*n);
}

void View::consider(SimStateInstance& inst) {
  Node* n = inst.as<Node>();
  if (n == nullptr || n->is_being_deleted()) return;
  const bool wanted = !filter_ || filter_(*n);
  auto it = std::find(nodes_.begin(), nodes_.end(), n);
  if (!wanted) {
    if (it != nodes_.end()) {
      nodes_.erase(it);
      removed_.emit(*n);
    }
    return;
  }
  if (it != nodes_.end()) {
    if (!order_) return;
    nodes_.erase(it);  // re-place: the order key may have changed
    place(*n);
    return;
  }
  place(*n);
  added_.emit(*n);
}

void View::place(Node& n) {
  if (!order_) {
    nodes_.push_back(&n);
    return;
  }
  auto at =
      std::upper_bound(nodes_.begin(), nodes_.end(), &n, [&](Node* a, Node* b) { return order_(*a, *b); });
  nodes_.insert(at, &n);
}

void View::drop(SimStateInstance& inst) {
  auto it = std::find(nodes_.begin(), nodes_.end(), &inst);
  if (it == nodes_.end()) return;
  Node* n = *it;
  nodes_.erase(it);
  removed_.emit(*n);
}

}  // namespace vsd
