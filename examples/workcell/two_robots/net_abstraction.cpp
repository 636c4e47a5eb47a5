#include "net_abstraction.hpp"

#include <fstream>
#include <map>
#include <sstream>

#include "cell.hpp"
#include "vsd/collision.hpp"
#include "vsd/physics.hpp"
#include "vsd/robotics.hpp"
#include "vsd/soml.hpp"
#include "vsd/soml/ast.hpp"
#include "vsd/soml/checker.hpp"

namespace vsd_workcell {

namespace {

using namespace vsd::soml;

struct Builder {
  vsd::analysis::PtNet net;
  std::map<const PlaceDecl*, std::uint32_t> places;
  std::vector<std::pair<const TransitionDecl*, std::uint32_t>> transitions;
  int conditions = 0, actions = 0;
  std::string source;

  [[noreturn]] void refuse(const Decl& d, const std::string& what) const {
    throw vsd::Error(source + ":" + std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + ": " +
                     what + " is outside the place/transition abstraction");
  }

  // Places and transitions of a static instance, then of its static objects.
  void instance(const ClassDecl& c, const std::string& prefix) {
    if (!c.base_name.empty() && c.kind == DeclKind::Object && c.base.decl != nullptr)
      refuse(c, "object '" + c.name + "' derived from a script class");
    for (const DeclPtr& m : c.members) {
      const std::string id = prefix + m->name;
      switch (m->kind) {
        case DeclKind::Place: {
          const auto& p = m->as<PlaceDecl>();
          if (!p.token_class.empty()) refuse(p, "object place '" + id + "'");
          places[&p] = net.add_place(id, id, static_cast<std::uint32_t>(p.initial_tokens));
          break;
        }
        case DeclKind::Transition: {
          const auto& t = m->as<TransitionDecl>();
          if (!t.invoke_name.empty()) refuse(t, "invocation in '" + id + "'");
          if (!t.subst_name.empty()) refuse(t, "substitution '" + id + "'");
          for (const DeclPtr& tm : t.members)
            if (tm->kind == DeclKind::Place) refuse(*tm, "a place inside transition '" + id + "'");
          conditions += (t.when_expr || t.when_block) ? 1 : 0;
          actions += t.action ? 1 : 0;
          transitions.emplace_back(&t, net.add_transition(id, id));
          break;
        }
        case DeclKind::Start:
          refuse(*m, "start place");
        case DeclKind::Object:
          instance(m->as<ClassDecl>(), id + ".");
          break;
        default:
          break;
      }
    }
  }

  std::uint32_t place_of(const ArrowDecl& a, const Decl* d) const {
    const auto it = places.find(static_cast<const PlaceDecl*>(d));
    if (d == nullptr || d->kind != DeclKind::Place || it == places.end())
      refuse(a, "an arrow to a place that is not a static object's");
    return it->second;
  }

  void arcs() {
    for (const auto& [t, index] : transitions) {
      for (const ArrowDecl* a : t->inputs) {
        if (a->condition) ++conditions;
        const auto w = static_cast<std::uint32_t>(a->weight);
        if (a->arrow == ArrowKind::Inhibitor)
          net.add_inhibitor(index, place_of(*a, a->from_decl), w);
        else
          net.add_input(index, place_of(*a, a->from_decl), w);
      }
      for (const ArrowDecl* a : t->outputs) {
        if (a->condition) ++conditions;
        net.add_output(index, place_of(*a, a->to_decl), static_cast<std::uint32_t>(a->weight));
      }
    }
  }
};

}  // namespace

vsd::analysis::PtNet pt_abstraction(const std::string& path, std::vector<std::string>* notes) {
  std::ifstream in(path);
  if (!in) throw vsd::Error("cannot read " + path);
  std::ostringstream text;
  text << in.rdbuf();
  // The registry that knows the classes the script names.
  vsd::Environment env;
  add_cell_modules(env);
  const auto checked = check_source(path, text.str(), env.registry());
  if (!checked->ok()) throw vsd::Error(checked->diagnostics.format());
  Builder b;
  b.source = path;
  b.net.set_id(path);
  b.instance(*checked->script.root, "");
  b.arcs();
  if (notes != nullptr)
    notes->push_back(path + ": dropped " + std::to_string(b.conditions) + " conditions and " +
                     std::to_string(b.actions) + " actions");
  return std::move(b.net);
}

}  // namespace vsd_workcell
