#include "vsd/analysis/pt_net.hpp"

#include <algorithm>

#include "vsd/core/error.hpp"

namespace vsd::analysis {

PtNet::PtNet(std::string id, std::string name) : id_(std::move(id)), name_(std::move(name)) {}

void PtNet::check_new_id(const std::string& id, const char* what) const {
  if (id.empty()) detail::throw_error(std::string("PtNet: a ") + what + " needs a non-empty id");
  if (place_index_.count(id) != 0 || transition_index_.count(id) != 0)
    detail::throw_error(std::string("PtNet: id '") + id + "' of a " + what + " is already used in net '" +
                        id_ + "'");
}

std::uint32_t PtNet::add_place(std::string id, std::string name, std::uint32_t initial) {
  check_new_id(id, "place");
  const auto index = static_cast<std::uint32_t>(places_.size());
  if (name.empty()) name = id;
  place_index_.emplace(id, index);
  places_.push_back(Place{std::move(id), std::move(name), initial});
  return index;
}

std::uint32_t PtNet::add_transition(std::string id, std::string name) {
  check_new_id(id, "transition");
  const auto index = static_cast<std::uint32_t>(transitions_.size());
  if (name.empty()) name = id;
  transition_index_.emplace(id, index);
  Transition t;
  t.id = std::move(id);
  t.name = std::move(name);
  transitions_.push_back(std::move(t));
  return index;
}

void PtNet::check_arc(std::uint32_t transition, std::uint32_t place, std::uint32_t weight,
                      const char* what) const {
  if (transition >= transitions_.size())
    detail::throw_error(std::string("PtNet: ") + what + " arc names transition index " +
                        std::to_string(transition) + ", the net has " + std::to_string(transitions_.size()));
  if (place >= places_.size())
    detail::throw_error(std::string("PtNet: ") + what + " arc of transition '" + transitions_[transition].id +
                        "' names place index " + std::to_string(place) + ", the net has " +
                        std::to_string(places_.size()));
  if (weight == 0)
    detail::throw_error(std::string("PtNet: ") + what + " arc between '" + places_[place].id + "' and '" +
                        transitions_[transition].id + "' has weight 0");
}

namespace {
enum class Merge { Sum, Min };

// Parallel arcs between one place and one transition in one direction are one arc: input and output
// arcs add their weights (a P/T net's arcs form a multiset), inhibitor arcs keep the stricter (smaller)
// weight, since both must hold. @p slots finds an arc by (transition, place) in O(1): a scan of the
// transition's arcs made a transition of n arcs cost O(n^2) to build.
void add_arc(std::vector<ArcRef>& arcs, std::unordered_map<std::uint64_t, std::uint32_t>& slots,
             std::uint32_t transition, std::uint32_t place, std::uint32_t weight, std::string arc_id, Merge merge,
             const Transition& t, const char* what) {
  const auto [it, fresh] =
      slots.try_emplace(std::uint64_t{transition} << 32 | place, static_cast<std::uint32_t>(arcs.size()));
  if (fresh) {
    arcs.push_back(ArcRef{place, weight, std::move(arc_id)});
    return;
  }
  ArcRef& a = arcs[it->second];
  if (merge == Merge::Min) {
    a.weight = std::min(a.weight, weight);
  } else if (weight > UINT32_MAX - a.weight) {
    detail::throw_error(std::string("PtNet: parallel ") + what + " arcs of transition '" + t.id +
                        "' weigh more than 2^32-1 together");
  } else {
    a.weight += weight;
  }
}
}  // namespace

void PtNet::add_input(std::uint32_t transition, std::uint32_t place, std::uint32_t weight,
                      std::string arc_id) {
  check_arc(transition, place, weight, "input");
  Transition& t = transitions_[transition];
  add_arc(t.inputs, input_slot_, transition, place, weight, std::move(arc_id), Merge::Sum, t, "input");
}

void PtNet::add_output(std::uint32_t transition, std::uint32_t place, std::uint32_t weight,
                       std::string arc_id) {
  check_arc(transition, place, weight, "output");
  Transition& t = transitions_[transition];
  add_arc(t.outputs, output_slot_, transition, place, weight, std::move(arc_id), Merge::Sum, t, "output");
}

void PtNet::add_inhibitor(std::uint32_t transition, std::uint32_t place, std::uint32_t weight,
                          std::string arc_id) {
  check_arc(transition, place, weight, "inhibitor");
  Transition& t = transitions_[transition];
  add_arc(t.inhibitors, inhibitor_slot_, transition, place, weight, std::move(arc_id), Merge::Min, t,
          "inhibitor");
}

std::optional<std::uint32_t> PtNet::find_place(std::string_view id) const {
  auto it = place_index_.find(std::string(id));
  if (it == place_index_.end()) return std::nullopt;
  return it->second;
}

std::optional<std::uint32_t> PtNet::find_transition(std::string_view id) const {
  auto it = transition_index_.find(std::string(id));
  if (it == transition_index_.end()) return std::nullopt;
  return it->second;
}

std::size_t PtNet::arc_count() const noexcept {
  std::size_t n = 0;
  for (const auto& t : transitions_) n += t.inputs.size() + t.outputs.size() + t.inhibitors.size();
  return n;
}

bool PtNet::has_inhibitors() const noexcept {
  return std::any_of(transitions_.begin(), transitions_.end(),
                     [](const Transition& t) { return !t.inhibitors.empty(); });
}

std::vector<std::uint32_t> PtNet::initial_marking() const {
  std::vector<std::uint32_t> m;
  m.reserve(places_.size());
  for (const auto& p : places_) m.push_back(p.initial);
  return m;
}

void PtNet::set_initial(std::uint32_t place, std::uint32_t tokens) {
  if (place >= places_.size())
    detail::throw_error("PtNet::set_initial: place index " + std::to_string(place) + " out of range (" +
                        std::to_string(places_.size()) + " places)");
  places_[place].initial = tokens;
}

bool PtNet::enabled(std::uint32_t t, const std::vector<std::uint32_t>& marking) const {
  if (t >= transitions_.size() || marking.size() != places_.size())
    detail::throw_error("PtNet::enabled: transition index " + std::to_string(t) + " or marking size " +
                        std::to_string(marking.size()) + " does not fit net '" + id_ + "'");
  const Transition& tr = transitions_[t];
  for (const auto& a : tr.inputs)
    if (marking[a.place] < a.weight) return false;
  for (const auto& a : tr.inhibitors)
    if (marking[a.place] >= a.weight) return false;
  return true;
}

void PtNet::fire(std::uint32_t t, std::vector<std::uint32_t>& marking) const {
  if (!enabled(t, marking))
    detail::throw_error("PtNet::fire: transition '" + transitions_[t].id + "' is not enabled");
  const Transition& tr = transitions_[t];
  for (const auto& a : tr.inputs) marking[a.place] -= a.weight;
  for (const auto& a : tr.outputs) {
    if (marking[a.place] > UINT32_MAX - a.weight)
      detail::throw_error("PtNet::fire: place '" + places_[a.place].id + "' would exceed 2^32-1 tokens");
    marking[a.place] += a.weight;
  }
}

}  // namespace vsd::analysis
