#include "vsd/core/container.hpp"

#include <algorithm>

#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"

namespace vsd {

namespace {
bool by_id(const Node* a, const Node* b) noexcept { return a->id() < b->id(); }
}  // namespace

View::View(SimState& state, Filter filter, Order order)
    : View(state, Node::static_meta(), std::move(filter), std::move(order)) {}

View::View(SimState& state, const MetaInstance& cls, Filter filter, Order order)
    : cls_(&cls), filter_(std::move(filter)), order_(std::move(order)) {
  if (!cls.is_a(Node::static_meta()))
    detail::throw_error("a View holds nodes, but class '" + cls.name() + "' is not a Node");
  state.index().for_each(cls, true, [&](SimStateInstance& i) {
    auto& n = static_cast<Node&>(i);
    if (!filter_ || filter_(n)) nodes_.push_back(&n);
  });
  std::sort(nodes_.begin(), nodes_.end(), by_id);  // creation order; an order then sorts stably
  if (order_)
    std::stable_sort(nodes_.begin(), nodes_.end(), [&](Node* a, Node* b) { return order_(*a, *b); });
  members_.insert(nodes_.begin(), nodes_.end());
  // Only the viewed class's signals: changes of other instances never reach the view.
  ElementIndex& index = state.index();
  connections_.push_back(index.on_created(cls, true).connect([this](SimStateInstance& i) { consider(i); }));
  connections_.push_back(index.on_deleted(cls, true).connect([this](SimStateInstance& i) { drop(i); }));
  // Membership and order may depend on any property: re-evaluate on change.
  connections_.push_back(state.on_property_changed(cls, true).connect(
      [this](SimStateInstance& i, const MetaProperty&) { consider(i); }));
}

View::~View() = default;

void View::for_each(const std::function<void(Node&)>& fn) const {
  const std::vector<Node*> copy = nodes_;  // fn may change the view
  for (Node* n : copy) fn(*n);
}

void View::consider(SimStateInstance& inst) {
  auto& n = static_cast<Node&>(inst);  // the signals are those of the viewed class, a Node class
  if (n.is_being_deleted()) return;
  const bool wanted = !filter_ || filter_(n);
  const bool member = members_.contains(&n);
  if (!wanted) {
    if (member) {
      unplace(n);
      members_.erase(&n);
      removed_.emit(n);
    }
    return;
  }
  if (member) {
    if (!order_) return;  // creation order does not change
    unplace(n);           // re-place: the order key may have changed
    place(n);
    return;
  }
  place(n);
  members_.insert(&n);
  added_.emit(n);
}

void View::place(Node& n) {
  const auto at = order_ ? std::upper_bound(nodes_.begin(), nodes_.end(), &n,
                                            [&](Node* a, Node* b) { return order_(*a, *b); })
                         : std::upper_bound(nodes_.begin(), nodes_.end(), &n, by_id);
  nodes_.insert(at, &n);
}

void View::unplace(Node& n) {
  // Without an order the nodes are sorted by id; with one, the key may already have changed.
  const auto it = order_ ? std::find(nodes_.begin(), nodes_.end(), &n)
                         : std::lower_bound(nodes_.begin(), nodes_.end(), &n, by_id);
  VSD_ASSERT(it != nodes_.end() && *it == &n, "a member of a view is in its list");
  nodes_.erase(it);
}

void View::drop(SimStateInstance& inst) {
  auto& n = static_cast<Node&>(inst);
  if (!members_.contains(&n)) return;
  unplace(n);
  members_.erase(&n);
  removed_.emit(n);
}

}  // namespace vsd
