#include <map>
#include <string>
#include <unordered_set>
#include <vector>

#include "json.hpp"
#include "views.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/soml/module.hpp"
#include "vsd/soml/net_classes.hpp"
#include "vsd/soml/runtime.hpp"

namespace vsd::web::detail {
namespace {

using soml::Arrow;
using soml::Place;
using soml::Transition;

const char* arrow_type(soml::ArrowType t) {
  switch (t) {
    case soml::ArrowType::Inhibitor:
      return "Inhibitor";
    case soml::ArrowType::Communication:
      return "Communication";
    case soml::ArrowType::Normal:
      break;
  }
  return "Normal";
}

}  // namespace

std::vector<soml::Program*> programs_of(Environment& env, const SimState& state) {
  const auto* m = env.module<soml::Module>();
  return m != nullptr ? m->programs(state) : std::vector<soml::Program*>{};
}

void write_nets(JsonWriter& out, const SimState& state) {
  // The enabled transitions as the executors last left them (every step, firing and edit refreshes them).
  std::unordered_set<Id> enabled;
  state.index().for_each(soml::Executor::static_meta(), true, [&](SimStateInstance& i) {
    const auto& list = static_cast<const soml::Executor&>(i).enabled();
    for (std::size_t k = 0; k < list.size(); ++k)
      if (list.at(k) != nullptr) enabled.insert(list.at(k)->id());
  });
  // A net is the places and transitions one node owns (its children), ordered by the owner's id.
  struct Net {
    const Node* owner;
    std::vector<const Place*> places;
    std::vector<const Transition*> transitions;
  };
  std::map<Id, Net> nets;
  const auto net_of = [&](const Node& n) -> Net* {
    const Node* owner = n.parent();
    if (owner == nullptr) return nullptr;  // not in the tree (being built or torn down)
    Net& net = nets[owner->id()];
    net.owner = owner;
    return &net;
  };
  state.index().for_each(Place::static_meta(), true, [&](SimStateInstance& i) {
    if (Net* n = net_of(static_cast<const Node&>(i))) n->places.push_back(static_cast<const Place*>(&i));
  });
  state.index().for_each(Transition::static_meta(), true, [&](SimStateInstance& i) {
    if (Net* n = net_of(static_cast<const Node&>(i))) n->transitions.push_back(static_cast<const Transition*>(&i));
  });
  const auto by_id = [](const auto* a, const auto* b) { return a->id() < b->id(); };
  out.begin_object().key("nets").begin_array();
  for (auto& [id, net] : nets) {
    std::sort(net.places.begin(), net.places.end(), by_id);
    std::sort(net.transitions.begin(), net.transitions.end(), by_id);
    out.begin_object().member("id", id).member("name", net.owner->name()).member("class", net.owner->meta().name());
    out.key("places").begin_array();
    for (const Place* p : net.places) {
      out.begin_object().member("id", p->id()).member("name", p->name()).member("tokens", p->count());
      out.key("objects").begin_array();
      for (std::size_t k = 0; k < p->objects().size(); ++k)
        if (const auto* o = p->objects().at(k)) out.number(o->id());
      out.end_array().end_object();
    }
    out.end_array();
    out.key("transitions").begin_array();
    for (const Transition* t : net.transitions)
      out.begin_object()
          .member("id", t->id())
          .member("name", t->name())
          .member("enabled", enabled.count(t->id()) != 0)
          .member("firings", t->firings())
          .end_object();
    out.end_array();
    // Arrows are children of the place or transition they leave.
    out.key("arrows").begin_array();
    const auto arrows_of = [&](const Node& from) {
      for (std::size_t k = 0; k < from.children().size(); ++k) {  // NOLINT
        const auto* a = from.children()[k] != nullptr ? from.children()[k]->as<Arrow>() : nullptr;
        if (a == nullptr) continue;
        out.begin_object().member("id", a->id()).member("from", from.id());
        out.member("to", a->target().get() != nullptr ? a->target()->id() : Id{0});
        out.member("type", arrow_type(a->type())).member("weight", a->weight()).end_object();
      }
    };
    for (const Place* p : net.places) arrows_of(*p);
    for (const Transition* t : net.transitions) arrows_of(*t);
    out.end_array();
    out.end_object();
  }
  out.end_array().end_object();
}

bool fire_transition(Environment& env, SimState& state, Id id) {
  const Transition* t = state.find<Transition>(id);
  if (t == nullptr) throw Error("instance #" + std::to_string(id) + " is not a transition of this state");
  for (soml::Program* p : programs_of(env, state))
    if (p->fire(*t)) return true;
  return false;
}

void refresh_programs(Environment& env, SimState& state) {
  for (soml::Program* p : programs_of(env, state)) (void)p->enabled_any();
}

std::uint64_t firings(Environment& env, const SimState& state) {
  std::uint64_t n = 0;
  for (const soml::Program* p : programs_of(env, state)) n += p->firings();
  return n;
}

}  // namespace vsd::web::detail
