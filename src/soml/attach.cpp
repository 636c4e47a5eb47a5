// Attaching a Program to content already in a SimState (docs/soml.md 8.7): a state loaded by vsd::io,
// or a replica that applied the recorded bundles. The script is checked and compiled as for a load; the
// run-time classes and enums the file defined are checked against the script's and used; the script
// object, its objects and every net are found among the nodes instead of created; and the executor's
// state (generator, firings, the enabled transitions in choice order, the transitions waiting for a test)
// is read from the script object's "(executor)" node, which the executor keeps current. Also here: the
// executor's side of that node (sync_state) and the revival of nets a rolled-back firing had deleted.
#include <algorithm>
#include <unordered_map>

#include "program_impl.hpp"
#include "vsd/core/database.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/registry.hpp"

namespace vsd::soml {

namespace {

std::string type_name(const MetaType* t) { return t != nullptr ? t->name() : std::string("(none)"); }

template <class T>
std::vector<T*> children_of(const Node& n) {
  std::vector<T*> out;
  for (Node* c : n.children())
    if (T* x = c != nullptr ? c->as<T>() : nullptr; x != nullptr) out.push_back(x);
  return out;
}

}  // namespace

const MetaInstance& ProgramImpl::adopt_class(ClassBuilder& b, const std::string& name,
                                             const MetaInstance& base, const ScopeDecl& decl) {
  Registry& reg = state_.environment().registry();
  const auto props = std::move(adopted_props_);
  adopted_props_.clear();
  const auto methods = std::move(adopted_methods_);
  adopted_methods_.clear();
  const MetaInstance* known = reg.find_class_exact(name);
  if (known == nullptr) return define_class(b);  // the state has no instance of it: defined as by a load
  auto disagree = [&](const std::string& what) {
    throw Error(where(*this, decl.loc) + ": class '" + name +
                (attaching_ ? "' of the state does not match the script: "
                            : "' is registered already, in use with another definition: ") +
                what);
  };
  const std::string theirs = attaching_ ? "the state's" : "the registered one";
  const std::string in_theirs = attaching_ ? " in the state" : " in the registered one";
  if (!known->is_runtime()) disagree(theirs + " is a built-in class");
  if (known->base() != &base)
    disagree("it derives from '" +
             (known->base() != nullptr ? known->base()->name() : std::string("nothing")) +
             "', the script's from '" + base.name() + "'");
  const auto own = known->own_properties();
  for (std::size_t i = 0; i < props.size() || i < own.size(); ++i) {
    if (i >= own.size()) disagree(theirs + " has no property '" + props[i].first + "'");
    if (i >= props.size())
      disagree(theirs + " has a property '" + own[i]->name() + "' the script does not declare");
    if (own[i]->name() != props[i].first)
      disagree("property " + std::to_string(i + 1) + " is '" + own[i]->name() + "'" + in_theirs + ", '" +
               props[i].first + "' in the script");
    if (&own[i]->type() != props[i].second)
      disagree("property '" + props[i].first + "' is " + own[i]->type().name() + in_theirs + ", " +
               type_name(props[i].second) + " in the script");
  }
  // Its methods: none when a file defined it (they are bound once the attach succeeded), the script's
  // when a program of this Registry defined it (a replica of its state).
  for (const MetaMethod* m : known->methods()) {
    if (&m->owner() != known) continue;
    auto it =
        std::find_if(methods.begin(), methods.end(), [&](const auto& x) { return x.name == m->name(); });
    if (it == methods.end())
      disagree(theirs + " has a method '" + m->name() + "' the script does not declare");
    if (it->args != m->arguments() || it->result != m->result())
      disagree("method '" + m->name() + "' is " + m->signature() + in_theirs);
  }
  pending_methods_.emplace_back(known, std::move(b));
  return *known;
}

void ProgramImpl::bind_pending_methods() {
  Registry& reg = state_.environment().registry();
  for (auto& [cls, b] : pending_methods_) reg.add_methods(*cls, std::move(b));
  pending_methods_.clear();
}

const MetaType& ProgramImpl::adopt_enum(EnumBuilder& b, const std::string& name, const EnumDecl& e) {
  Registry& reg = state_.environment().registry();
  const MetaType* known = reg.find_type(name);
  if (known == nullptr) return define_enum(b);
  bool same = known->kind() == TypeKind::Enum && known->enum_values().size() == e.values.size();
  for (std::size_t i = 0; same && i < e.values.size(); ++i) {
    std::int64_t v = 0;
    same = known->enum_value(e.values[i], v) && v == static_cast<std::int64_t>(i);
  }
  if (!same)
    throw Error(where(*this, e.loc) + ": enum '" + name +
                (attaching_ ? "' of the state does not match the script's values"
                            : "' is registered already, in use with other values"));
  return *known;
}

std::unique_ptr<NetInst> ProgramImpl::find_net(const ClassInfo& ci, SimStateInstance& owner) {
  const NetClass& nc = *ci.net;
  Node& on = *owner.as<Node>();
  auto net = std::make_unique<NetInst>();
  net->owner = owner.id();
  net->cls = &nc;
  net->places.assign(nc.places.size(), nullptr);
  net->transitions.assign(nc.transitions.size(), nullptr);
  const std::string who = owner.meta().name() + " '" + on.name() + "' (#" + std::to_string(owner.id()) + ")";
  auto disagree = [&](const std::string& what) {
    throw Error(image().checked->source->name() + ": the net of " + who +
                " does not match the script: " + what);
  };
  auto meta_of = [&](const Decl* d, const MetaInstance& fallback) {
    auto it = scope_meta_.find(d);
    return it != scope_meta_.end() ? it->second : &fallback;
  };
  // As build_net made them: the net's own places and transitions are children of the owner, in order;
  // those of a substituted sub-net children of their substitution transition.
  std::unordered_map<const Node*, std::pair<std::vector<Place*>, std::size_t>> places;
  std::unordered_map<const Node*, std::pair<std::vector<Transition*>, std::size_t>> transitions;
  auto next_transition = [&](const Node& parent, const TransitionDecl& d) {
    auto [it, fresh] = transitions.try_emplace(&parent);
    if (fresh) it->second.first = children_of<Transition>(parent);
    auto& [list, used] = it->second;
    if (used >= list.size()) disagree("transition '" + d.name + "' is missing");
    Transition* t = list[used++];
    if (t->name() != d.name || &t->meta() != meta_of(&d, Transition::static_meta()))
      disagree("transition '" + d.name + "' of the script is '" + t->name() + "' (" + t->meta().name() +
               ") in the state");
    return t;
  };
  for (std::size_t k = 0; k < nc.transitions.size(); ++k) {
    const TransitionInfo& t = nc.transitions[k];
    net->transitions[k] = next_transition(
        t.holder < 0 ? on : static_cast<Node&>(*net->transitions[static_cast<std::size_t>(t.holder)]),
        *t.decl);
  }
  for (std::size_t i = 0; i < nc.places.size(); ++i) {
    const PlaceDecl& d = *nc.places[i];
    const int h = nc.place_holder[i];
    const Node& parent =
        h < 0 ? on : static_cast<const Node&>(*net->transitions[static_cast<std::size_t>(h)]);
    auto [it, fresh] = places.try_emplace(&parent);
    if (fresh) it->second.first = children_of<Place>(parent);
    auto& [list, used] = it->second;
    if (used >= list.size()) disagree("place '" + d.name + "' is missing");
    Place* p = list[used++];
    if (p->name() != d.name || &p->meta() != meta_of(&d, Place::static_meta()))
      disagree("place '" + d.name + "' of the script is '" + p->name() + "' (" + p->meta().name() +
               ") in the state");
    if (p->object_tokens() != !d.token.empty())
      disagree("place '" + d.name + "' holds " + (d.token.empty() ? "black" : "object") +
               " tokens in the script");
    net->places[i] = p;
  }
  for (const auto& [parent, l] : places)
    if (l.second != l.first.size())
      disagree("the state has a place '" + l.first[l.second]->name() + "' the script does not declare");
  for (const auto& [parent, l] : transitions)
    if (l.second != l.first.size())
      disagree("the state has a transition '" + l.first[l.second]->name() + "' the script does not declare");
  return net;
}

void ProgramImpl::attach_content() {
  const ClassDecl& root = *image().checked->script.root;
  const std::string& file = image().checked->source->name();
  Node& db = state_.database();
  // The script object, its objects (by name and class, as load made them).
  const MetaInstance& root_meta = *image().class_info.at(&root)->meta;
  for (Node* c : db.children())
    if (c != nullptr && c->name() == image().stem && &c->meta() == &root_meta) root_ = c;
  if (root_ == nullptr)
    throw Error(file + ": the state holds no script object '" + image().stem + "' (a node of class " +
                root_meta.name() + " under the Database): nothing to attach to");
  std::function<void(const ClassDecl&, SimStateInstance&, const std::string&)> find =
      [&](const ClassDecl& c, SimStateInstance& inst, const std::string& path) {
        object_ids_[&c] = inst.id();
        for (const DeclPtr& m : c.members) {
          if (m->kind != DeclKind::Object) continue;
          const MetaInstance& meta = *image().class_info.at(&m->as<ClassDecl>())->meta;
          Node* found = nullptr;
          for (Node* x : inst.as<Node>()->children())
            if (x != nullptr && x->name() == m->name && &x->meta() == &meta) found = x;
          if (found == nullptr)
            throw Error(where(*this, m->loc) + ": object '" + path + m->name + "' (a node of class " +
                        meta.name() + " under '" + inst.as<Node>()->name() + "') is not in the state");
          find(m->as<ClassDecl>(), *found, path + m->name + ".");
        }
      };
  find(root, *root_, "");
  link_objects();

  // The source: the same text, or the bytecode would not be the state's.
  for (Node* c : db.children())
    if (auto* f = c != nullptr ? c->as<SourceFile>() : nullptr;
        f != nullptr && f->name() == image().stem + " (source)")
      source_node_ = f;
  if (source_node_ == nullptr)
    throw Error(file + ": the state holds no source of script '" + image().stem +
                "' (a soml::SourceFile named '" + image().stem + " (source)')");
  if (source_node_->text() != image().checked->source->text()) {
    const std::string& a = source_node_->text();
    const std::string& b = image().checked->source->text();
    std::size_t line = 1, i = 0;
    for (; i < a.size() && i < b.size() && a[i] == b[i]; ++i)
      if (a[i] == '\n') ++line;
    throw Error(file + ":" + std::to_string(line) +
                ": the script differs from the one the state was loaded from (" + source_node_->file() +
                "), first at this line");
  }
  std::function<void(const Decl&, Node&)> component = [&](const Decl& d, Node& sc) {
    components_[&d] = sc.as<SourceComponent>();
    if (!d.has_members()) return;
    const auto kids = children_of<SourceComponent>(sc);
    const auto& members = d.as<ScopeDecl>().members;
    for (std::size_t i = 0; i < members.size() && i < kids.size(); ++i) component(*members[i], *kids[i]);
  };
  if (const auto top = children_of<SourceComponent>(*source_node_); !top.empty())
    component(root, *top.front());

  // Every net: of the static objects, of instances made by `new`, of running invocations (id order).
  for (SimStateInstance* x : state_.instances()) {
    auto it = by_meta_.find(&x->meta());
    if (it == by_meta_.end() || !it->second->net || x->as<Node>() == nullptr) continue;
    register_net(find_net(*it->second, *x), *it->second, *x);
  }

  // The executor's state.
  for (Node* c : root_->children())
    if (auto* e = c != nullptr ? c->as<Executor>() : nullptr; e != nullptr) exec_ = e;
  if (exec_ == nullptr)
    throw Error(file + ": script object '" + image().stem +
                "' has no executor state (a soml::Executor child named "
                "'(executor)'): the state was not made by a running program");
  rng_ = exec_->rng();
  firings_ = exec_->firings();
  std::unordered_map<Id, std::uint32_t> ti_of;
  for (std::uint32_t i = 0; i < tis_.size(); ++i)
    ti_of[tis_[i].net->transitions[static_cast<std::size_t>(tis_[i].t)]->id()] = i;
  auto lookup = [&](const SimStateInstance* n) -> std::int64_t {
    auto it = n != nullptr ? ti_of.find(n->id()) : ti_of.end();
    return it != ti_of.end() ? static_cast<std::int64_t>(it->second) : -1;
  };
  // register_net asked for a test of everything; what the state says replaces that.
  for (std::uint32_t i : dirty_) tis_[i].dirty = false;
  dirty_.clear();
  for (std::size_t k = 0; k < exec_->enabled().size(); ++k)
    if (const std::int64_t i = lookup(exec_->enabled().at(k)); i >= 0)
      set_enabled(static_cast<std::uint32_t>(i), true);
  for (std::size_t k = 0; k < exec_->dirty().size(); ++k)
    if (const std::int64_t i = lookup(exec_->dirty().at(k)); i >= 0)
      mark_dirty(static_cast<std::uint32_t>(i));
  // The others are tested now: that finds the mark of each enabled one and what each reads (the
  // dependencies that make a property change re-test it). Conditions are deterministic, so an enabled one
  // stays enabled in its place; one the state did not list as enabled and that is (C++ changed something
  // after the last step) joins at the end.
  for (std::uint32_t i = 0; i < tis_.size(); ++i) {
    TI& ti = tis_[i];
    if (ti.dirty || ti.net->dead || ti.net->cls->transitions[static_cast<std::size_t>(ti.t)].inert) continue;
    set_enabled(i, test(ti));
  }
}

void ProgramImpl::sync_state() {
  if (exec_ == nullptr) return;  // on_deleted forgets it when it is deleted
  if (exec_->rng() != rng_) exec_->set_rng(rng_);
  if (exec_->firings() != firings_) exec_->set_firings(firings_);
  auto node = [&](std::uint32_t i) -> Node* {
    const TI& ti = tis_[i];
    return ti.net->dead ? nullptr : ti.net->transitions[static_cast<std::size_t>(ti.t)];
  };
  auto sync = [&](const SharedRefList<Node>& have, auto&& edit, const std::vector<std::uint32_t>& want) {
    std::size_t n = 0;
    bool same = true;
    for (std::uint32_t i : want)
      if (Node* x = node(i); x != nullptr) same = same && n < have.size() && have.at(n++) == x;
    if (same && n == have.size()) return;
    auto e = edit();
    e.clear();
    for (std::uint32_t i : want)
      if (Node* x = node(i); x != nullptr) e.push_back(*x);
  };
  sync(
      exec_->enabled(), [&] { return exec_->edit_enabled(); }, enabled_);
  sync(
      exec_->dirty(), [&] { return exec_->edit_dirty(); }, dirty_);
}

void ProgramImpl::revive(NetInst* dead) {
  SimStateInstance* o = state_.find(dead->owner);
  if (o == nullptr || o->as<Node>() == nullptr) return;  // created by the failed firing: gone again
  auto it = by_meta_.find(&o->meta());
  if (it == by_meta_.end() || it->second->net.get() != dead->cls) return;
  register_net(find_net(*it->second, *o), *it->second, *o);
}

}  // namespace vsd::soml
