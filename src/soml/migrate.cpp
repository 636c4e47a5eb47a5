// Run-time class migration: Program::reload (docs/soml.md, "Changing a running program").
//
// An instance's class fixes its memory layout (run-time properties trail the C++ object), so a class
// whose properties change cannot be redefined in place. A reload therefore retires the running version's
// classes under other names, defines and compiles the new version beside them (ProgramImpl::define), and
// moves every live object to a new instance of its new class; references held in database properties are
// redirected to the new instances, the old ones are deleted. Everything fallible (checking, compiling,
// running initialisers and constructors, converting values) happens before anything of the running
// version is deleted, under a vsd::Savepoint: an error rolls the state back, deletes the new classes and
// gives the old ones their names back, and the running ProgramImpl (whose pointers all still hold) goes on.
#include <algorithm>
#include <unordered_map>
#include <unordered_set>

#include "program_impl.hpp"
#include "vsd/core/database.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/savepoint.hpp"

namespace vsd::soml {

namespace {

// A running version's classes make room for a new version's classes of the same names: each is renamed
// to the first free `Name~N`. restore() gives the names back, newest first, when the new version is
// refused; the constructor restores what it renamed before it throws.
class RetiredNames {
 public:
  RetiredNames(Registry& reg, const std::vector<const MetaInstance*>& classes)
      : reg_(reg), classes_(classes) {
    try {
      for (const MetaInstance* m : classes_) {
        std::string retired;
        for (int n = 1; retired.empty() || reg_.find_class_exact(retired) != nullptr; ++n)
          retired = m->name() + "~" + std::to_string(n);
        std::string was = m->name();
        reg_.rename(*m, retired);
        names_.push_back(std::move(was));
      }
    } catch (...) {
      restore();
      throw;
    }
  }
  void restore() {
    for (std::size_t i = names_.size(); i-- > 0;) reg_.rename(*classes_[i], names_[i]);
    names_.clear();
  }

 private:
  Registry& reg_;
  const std::vector<const MetaInstance*>& classes_;
  std::vector<std::string> names_;  // the original names of classes_[0 .. size)
};

std::string qualified(const Decl& d) {
  std::string s = d.name;
  for (const Decl* p = d.parent; p != nullptr && p->kind != DeclKind::Script; p = p->parent)
    s = p->name + "::" + s;
  return s;
}

// What identifies a class-like declaration across versions of a script.
std::string class_key(const ClassDecl& c) {
  switch (c.kind) {
    case DeclKind::Script:
      return "script";
    case DeclKind::Object:
      return "object " + qualified(c);
    case DeclKind::Net:
      return "net " + qualified(c);
    default:
      return "class " + qualified(c);
  }
}

// The name a report uses for a class-like declaration.
std::string label(const ClassDecl& c, const std::string& stem) {
  return c.kind == DeclKind::Script ? stem : qualified(c);
}

// A place or transition of a net class by its path: sub-net members carry their substitution transitions.
std::string node_key(const NetClass& n, const std::string& name, int holder) {
  std::string k = name;
  for (int h = holder; h >= 0; h = n.transitions[static_cast<std::size_t>(h)].holder)
    k = n.transitions[static_cast<std::size_t>(h)].decl->name + "." + k;
  return k;
}

// Resolves ids of migrated instances to their new versions, every other id to itself.
struct Remap final : RefResolver {
  const SimState* state = nullptr;
  const std::unordered_map<Id, SimStateInstance*>* map = nullptr;
  SimStateInstance* resolve(Id id) const override {
    auto it = map->find(id);
    return it != map->end() ? it->second : state->find(id);
  }
};

struct Pair {
  SimStateInstance* from;
  SimStateInstance* to;
  const ClassInfo* ci;  // the new class
};

class Migration {
 public:
  Migration(ProgramImpl& old, ProgramImpl& nw, MigrationReport& report)
      : old_(old), nw_(nw), state_(old.state_), report_(report) {
    remap_.state = &state_;
    remap_.map = &map_;
  }

  void run();

 private:
  void collect();
  void make_statics(const ClassDecl& c, Node* parent);
  void init(const Pair& p);
  void map_nets(const Pair& p);
  void copy_properties(SimStateInstance& from, SimStateInstance& to);
  void copy_marking(Place& from, Place& to, const std::string& where);
  void adopt_children(const Pair& p);
  bool doomed(const SimStateInstance* x) const;
  void report_properties(const MetaInstance& from, const MetaInstance& to, const std::string& cls);

  ProgramImpl& old_;
  ProgramImpl& nw_;
  SimState& state_;
  MigrationReport& report_;
  Remap remap_;
  std::unordered_map<Id, SimStateInstance*> map_;  // old id -> new instance (objects, places, transitions)
  std::unordered_set<Id> old_ids_;                 // the running version's instances and net nodes
  std::unordered_map<std::string, Id> old_statics_;
  std::vector<std::pair<SimStateInstance*, const ClassInfo*>> old_dynamic_;  // `new` instances
  std::vector<Pair> pairs_;
  std::vector<std::pair<const ClassDecl*, SimStateInstance*>> fresh_;  // new objects
  std::unordered_map<std::string, const ClassInfo*> new_classes_;
  std::unordered_set<std::string> reported_;
};

void Migration::collect() {
  for (const auto& [decl, ci] : nw_.image().class_info) new_classes_[class_key(*decl)] = ci.get();
  for (const auto& [decl, id] : old_.object_ids_) old_statics_[class_key(*decl)] = id;
  for (const auto& [id, net] : old_.node_net_) old_ids_.insert(id);
  std::unordered_map<std::string, std::size_t> removed_classes;
  for (SimStateInstance* x : state_.instances()) {
    auto it = old_.by_meta_.find(&x->meta());
    if (it == old_.by_meta_.end()) continue;
    old_ids_.insert(x->id());
    const ClassDecl& d = *it->second->decl;
    if (d.kind == DeclKind::Net)
      throw Error("cannot reload '" + old_.image().checked->source->name() + "' now: an invocation of net '" +
                  qualified(d) + "' is in progress (reload when it has finished)");
    if (d.kind == DeclKind::Object || d.kind == DeclKind::Script) continue;  // by make_statics
    auto nc = new_classes_.find(class_key(d));
    if (nc == new_classes_.end()) {
      ++removed_classes[qualified(d)];
      continue;
    }
    old_dynamic_.emplace_back(x, nc->second);
  }
  if (!removed_classes.empty()) {
    std::string what;
    for (const auto& [cls, n] : removed_classes)
      what += (what.empty() ? "" : ", ") + ("'" + cls + "' (" + std::to_string(n) + " live)");
    throw Error("cannot reload '" + old_.image().checked->source->name() +
                "': the new version removes classes that still have instances: " + what +
                " (delete them first)");
  }
}

// The new version's static instances (the script object and its objects), like ProgramImpl::populate:
// an object the running version had becomes a migrated pair, one it had not a fresh object.
void Migration::make_statics(const ClassDecl& c, Node* parent) {
  const ClassInfo& ci = *nw_.image().class_info.at(&c);
  SimStateInstance& y = nw_.create_node(ci, parent, c.kind == DeclKind::Script ? nw_.image().stem : c.name);
  nw_.object_ids_[&c] = y.id();
  auto it = old_statics_.find(class_key(c));
  SimStateInstance* x = it != old_statics_.end() ? state_.find(it->second) : nullptr;
  if (x != nullptr) {
    pairs_.push_back(Pair{x, &y, &ci});
    map_[x->id()] = &y;
    old_statics_.erase(it);
  } else {
    fresh_.emplace_back(&c, &y);
  }
  for (const DeclPtr& m : c.members)
    if (m->kind == DeclKind::Object) make_statics(m->as<ClassDecl>(), y.as<Node>());
}

// The new instance's initial values (every class's initialisers) and its net.
void Migration::init(const Pair& p) {
  std::vector<const ClassInfo*> chain;
  for (const ClassInfo* c = p.ci; c != nullptr; c = c->base) chain.push_back(c);
  std::reverse(chain.begin(), chain.end());
  for (const ClassInfo* c : chain)
    if (c->init >= 0) nw_.run(c->init, p.to->id(), 0, nullptr, nullptr);
  if (p.ci->net) nw_.build_net(*p.ci, *p.to);
}

// Places and transitions of the old net that the new one still has, by path.
void Migration::map_nets(const Pair& p) {
  const NetInst* on = old_.net_of(p.from->id());
  if (on == nullptr) return;
  const NetInst* nn = nw_.net_of(p.to->id());
  std::unordered_map<std::string, std::size_t> places, transitions;
  if (nn != nullptr) {
    for (std::size_t i = 0; i < nn->places.size(); ++i)
      places.emplace(node_key(*nn->cls, nn->cls->places[i]->name, nn->cls->place_holder[i]), i);
    for (std::size_t i = 0; i < nn->transitions.size(); ++i)
      transitions.emplace(
          node_key(*nn->cls, nn->cls->transitions[i].decl->name, nn->cls->transitions[i].holder), i);
  }
  const std::string owner = p.from->as<Node>()->name();
  for (std::size_t i = 0; i < on->places.size(); ++i) {
    const std::string k = node_key(*on->cls, on->cls->places[i]->name, on->cls->place_holder[i]);
    auto it = places.find(k);
    if (it == places.end()) {
      if (on->places[i]->count() != 0)
        report_.warnings.push_back(owner + "." + k + ": the place was removed; its " +
                                   std::to_string(on->places[i]->count()) + " token(s) are dropped");
      continue;
    }
    map_[on->places[i]->id()] = nn->places[it->second];
  }
  for (std::size_t i = 0; i < on->transitions.size(); ++i) {
    const std::string k =
        node_key(*on->cls, on->cls->transitions[i].decl->name, on->cls->transitions[i].holder);
    if (auto it = transitions.find(k); it != transitions.end())
      map_[on->transitions[i]->id()] = nn->transitions[it->second];
  }
}

void Migration::report_properties(const MetaInstance& from, const MetaInstance& to, const std::string& cls) {
  if (!reported_.insert(cls).second) return;
  for (const MetaProperty* p : to.properties()) {
    if (!p->owner().is_runtime()) continue;  // the built-in classes' properties do not change
    const MetaProperty* o = from.find_property(p->name());
    if (o == nullptr)
      report_.properties.push_back(cls + "." + p->name() + ": new");
    else if (o->type().name() == p->type().name())
      report_.properties.push_back(cls + "." + p->name() + ": kept");
    else
      report_.properties.push_back(cls + "." + p->name() + ": type changed from " + o->type().name() +
                                   " to " + p->type().name());
  }
  for (const MetaProperty* o : from.properties())
    if (o->owner().is_runtime() && to.find_property(o->name()) == nullptr)
      report_.properties.push_back(cls + "." + o->name() + ": removed");
}

// The values of @p from's properties in @p to: by name, converted where the type changed, references
// to migrated instances redirected. `children` is not copied (adopt_children), nor is the marking kind.
void Migration::copy_properties(SimStateInstance& from, SimStateInstance& to) {
  const std::string who = from.is_a<Node>() ? from.as<Node>()->name() : "#" + std::to_string(from.id());
  for (const MetaProperty* p : to.meta().properties()) {
    if (p == &Node::vsd_prop_children() || p->name() == "object_tokens") continue;
    const MetaProperty* o = from.meta().find_property(p->name());
    if (o == nullptr || p->has(ReadOnly)) continue;
    Value v = o->get_value(from);
    try {
      if (p->type().is_reference()) {
        to.set(p->name(), Value::from_text(p->type(), v.to_text(), &remap_, who + "." + p->name()));
      } else if (&o->type() == &p->type()) {
        to.set(p->name(), v);
      } else {
        to.set(p->name(), v.convert_to(p->type()));
      }
    } catch (const Error& e) {
      report_.warnings.push_back(who + "." + p->name() + ": the value " + v.to_text() + " (" +
                                 o->type().name() + ") does not fit " + p->type().name() + " (" + e.what() +
                                 "); it keeps its initial value");
    }
  }
  for (const MetaProperty* o : from.meta().properties()) {
    if (!o->owner().is_runtime() || to.meta().find_property(o->name()) != nullptr) continue;
    const Value v = o->get_value(from);
    if (v != o->default_value())
      report_.warnings.push_back(who + "." + o->name() + ": the property was removed; its value " +
                                 v.to_text() + " is dropped");
  }
}

void Migration::copy_marking(Place& from, Place& to, const std::string& where) {
  copy_properties(from, to);
  if (from.object_tokens() == to.object_tokens()) return;
  if (from.object_tokens()) {
    // Object tokens became black ones: their number stays.
    to.set_tokens(static_cast<std::int64_t>(from.objects().size()));
    while (!to.objects().empty()) to.list_erase(Place::vsd_prop_objects(), to.objects().size() - 1);
    report_.warnings.push_back(where + ": the place holds black tokens now; its object tokens became " +
                               std::to_string(from.objects().size()) + " black token(s)");
  } else {
    to.set_tokens(0);
    if (from.tokens() != 0)
      report_.warnings.push_back(where + ": the place holds object tokens now; its " +
                                 std::to_string(from.tokens()) + " black token(s) are dropped");
  }
}

// The old instance's children that are neither its net nor objects of the script move to the new one,
// in their order; migrated `new` instances among them are replaced by their new versions.
void Migration::adopt_children(const Pair& p) {
  const Node* from = p.from->as<Node>();
  Node* to = p.to->as<Node>();
  std::vector<Node*> kids(from->children().begin(), from->children().end());
  for (Node* c : kids) {
    auto it = map_.find(c->id());
    if (it != map_.end()) {
      Node* y = it->second->as<Node>();
      if (y->parent() == nullptr) to->add_child(*y);
      continue;
    }
    if (old_ids_.count(c->id()) != 0) continue;  // old net nodes, removed objects
    to->add_child(*c);
  }
}

bool Migration::doomed(const SimStateInstance* x) const {
  for (const SimStateInstance* i = x; i != nullptr;) {
    if (old_ids_.count(i->id()) != 0 || i == old_.source_node_) return true;
    const Node* n = i->as<Node>();
    i = n != nullptr ? n->parent() : nullptr;
  }
  return false;
}

void Migration::run() {
  collect();
  // ---- everything that may fail, before anything of the running version goes ----
  nw_.connect_listeners();
  nw_.make_source();
  make_statics(*nw_.image().checked->script.root, &state_.database());
  nw_.root_ = state_.find(nw_.object_ids_.at(nw_.image().checked->script.root.get()))->as<Node>();
  for (auto& [x, ci] : old_dynamic_) {
    SimStateInstance& y = nw_.create_node(*ci, nullptr, "");
    pairs_.push_back(Pair{x, &y, ci});
    map_[x->id()] = &y;
  }
  nw_.link_objects();
  for (const Pair& p : pairs_) init(p);
  for (const Pair& p : pairs_) map_nets(p);
  for (const Pair& p : pairs_) {
    const std::string cls = label(*p.ci->decl, nw_.image().stem);
    report_properties(p.from->meta(), p.to->meta(), cls);
    copy_properties(*p.from, *p.to);
    const NetInst* on = old_.net_of(p.from->id());
    if (on != nullptr) {
      // Places and transitions with members have classes of their own (port-net copies are transitions):
      // their properties are reported per class as the object's are, e.g. "Demo.done.visits: kept".
      const std::string owner = p.from->as<Node>()->name();
      for (std::size_t i = 0; i < on->places.size(); ++i)
        if (auto it = map_.find(on->places[i]->id()); it != map_.end()) {
          report_properties(on->places[i]->meta(), it->second->meta(), cls + "." + on->places[i]->name());
          copy_marking(*on->places[i], static_cast<Place&>(*it->second), owner + "." + on->places[i]->name());
        }
      for (Transition* t : on->transitions)
        if (auto it = map_.find(t->id()); it != map_.end()) {
          report_properties(t->meta(), it->second->meta(), cls + "." + t->name());
          copy_properties(*t, *it->second);
        }
    }
  }
  for (const Pair& p : pairs_) adopt_children(p);
  for (auto& [decl, y] : fresh_) nw_.setup(*nw_.image().class_info.at(decl), *y, nullptr, nullptr, 0);
  // References to the old instances from outside the running version (C++ nodes, other programs): each
  // must accept the new instance's class.
  struct Redirect {
    SimStateInstance* holder;
    const MetaProperty* prop;
    SimStateInstance* from;
    SimStateInstance* to;
  };
  std::vector<Redirect> redirects;
  for (const Pair& p : pairs_)
    for (auto [h, prop] : p.from->referrers()) {
      if (doomed(h) || map_.count(h->id()) != 0) continue;
      const MetaInstance* target = prop->type().target();
      if (target != nullptr && !p.to->is_a(*target))
        throw Error("cannot reload: property '" + h->meta().name() + "::" + prop->name() + "' of #" +
                    std::to_string(h->id()) + " refers to " + p.from->meta().name() + " #" +
                    std::to_string(p.from->id()) + " and cannot hold its new class '" + p.to->meta().name() +
                    "'");
      redirects.push_back(Redirect{h, prop, p.from, p.to});
    }
  for (const auto& [key, id] : old_statics_) {
    (void)id;
    ++report_.deleted;
  }
  report_.created = fresh_.size();
  report_.migrated = pairs_.size();

  // ---- the switch: redirect, then delete the running version's content ----
  // Shared references first: releasing a composite one (a parent's `children`) deletes the old instance
  // and its subtree, which would drop the shared references to them before they are redirected.
  std::stable_partition(redirects.begin(), redirects.end(), [](const Redirect& r) {
    return r.prop->type().kind() != TypeKind::Ref && r.prop->type().kind() != TypeKind::RefList;
  });
  // Ids, not pointers: a composite redirect deletes the old instance it releases, with its subtree.
  std::vector<Id> gone{old_.root_->id()};
  for (const Pair& p : pairs_) gone.push_back(p.from->id());
  for (const auto& [key, id] : old_statics_) gone.push_back(id);
  for (const auto& [id, net] : old_.node_net_) gone.push_back(id);
  if (old_.source_node_ != nullptr) gone.push_back(old_.source_node_->id());
  std::vector<std::pair<Id, Id>> ids;  // holder, old instance
  for (const Redirect& r : redirects) ids.emplace_back(r.holder->id(), r.from->id());
  for (std::size_t k = 0; k < redirects.size(); ++k) {
    const Redirect& r = redirects[k];
    SimStateInstance* holder = state_.find(ids[k].first);
    if (holder == nullptr) continue;
    const Id from = ids[k].second;
    if (r.prop->type().is_ref_list()) {
      const auto* list = static_cast<const RefListBase*>(r.prop->address(*holder));
      // The Database holds the new script object already (a node has one place in its parent).
      const bool has_new = list->contains(r.to);
      for (std::size_t i = 0; i < list->size();) {
        if (list->at(i)->id() != from) {
          ++i;
          continue;
        }
        if (!has_new) holder->list_insert(*r.prop, i++, *r.to);
        holder->list_erase(*r.prop, i);
      }
    } else {
      holder->set(r.prop->name(),
                  Value::from_text(r.prop->type(), r.prop->get_value(*holder).to_text(), &remap_));
    }
  }
  for (Id id : gone)
    if (SimStateInstance* x = state_.find(id); x != nullptr) state_.destroy(*x);
}

}  // namespace

MigrationReport migrate(ProgramImpl& old, ProgramImpl& nw, std::string name, std::string text) {
  if (old.debug_ != nullptr) throw Error("cannot reload a SOML++ program while a debugger is attached");
  if (!old.frames_.empty() || old.entry_depth_ != 0)
    throw Error("cannot reload a SOML++ program from its own code (it is running)");
  SimState& state = old.state_;
  Registry& reg = state.environment().registry();

  // The running version's classes make room for the new ones under retired names.
  const std::vector<const MetaInstance*> old_classes = old.runtime_classes();
  RetiredNames retired(reg, old_classes);

  auto undefine_new = [&] {
    nw.used_classes_.clear();  // (never counted: it was not registered)
    nw.used_enums_.clear();
    for (const MetaInstance* m : nw.runtime_classes()) try {
        reg.undefine(*m);
      } catch (const Error&) {  // NOLINT(bugprone-empty-catch): a leftover class is harmless; it is named
      }
    for (const auto& [decl, t] : nw.enums_)
      if (std::find(nw.reused_enums_.begin(), nw.reused_enums_.end(), t) == nw.reused_enums_.end()) try {
          reg.undefine(*t);
        } catch (const Error&) {  // NOLINT(bugprone-empty-catch)
        }
  };

  nw.previous_ = &old;
  try {
    nw.define(std::move(name), std::move(text));
  } catch (...) {
    undefine_new();
    retired.restore();
    throw;
  }

  MigrationReport report;
  old.stop_listening();
  {
    Savepoint sp(state);
    try {
      Migration(old, nw, report).run();
      sp.commit();
    } catch (const Error& e) {
      std::string extra;
      try {
        sp.rollback();
      } catch (const Error& r) {
        extra = "; rolling back failed too: " + std::string(r.what());
      }
      nw.stop_listening();
      undefine_new();
      retired.restore();
      old.connect_listeners();
      if (extra.empty()) throw;
      throw Error(std::string(e.what()) + extra);
    } catch (...) {
      sp.rollback();
      nw.stop_listening();
      undefine_new();
      retired.restore();
      old.connect_listeners();
      throw;
    }
  }

  // The running version's executor settings go on in the new one.
  nw.on_dirty_ = old.on_dirty_;
  nw.trace_ = old.trace_;
  nw.firings_ = old.firings_;
  nw.rng_ = old.rng_;
  nw.tests_ = old.tests_;
  nw.condition_errors_ = old.condition_errors_;
  nw.previous_ = nullptr;
  // The executor's database state (docs/soml.md 8.7) moved to the new script object with the old one's
  // other children; from now on it describes the new version's run (so attach works after a reload).
  nw.exec_ = nullptr;
  for (Node* c : nw.root_->children())
    if (auto* e = c != nullptr ? c->as<Executor>() : nullptr; e != nullptr) nw.exec_ = e;
  if (nw.exec_ == nullptr) {
    nw.exec_ = &state.create<Executor>();
    nw.exec_->set_name("(executor)");
    nw.root_->add_child(*nw.exec_);
  }
  nw.sync_state();
  // The retired classes and enums go (a class something else still uses stays, under its retired name):
  // the running version stops counting as their user first (ProgramImpl::release_uses).
  old.release_uses(false);
  for (const MetaInstance* m : old_classes) try {
      reg.undefine(*m);
    } catch (const Error& e) {
      report.warnings.push_back("the retired class '" + m->name() + "' stays: " + e.what());
    }
  for (const auto& [decl, t] : old.enums_)
    if (std::find(nw.reused_enums_.begin(), nw.reused_enums_.end(), t) == nw.reused_enums_.end()) try {
        reg.undefine(*t);
      } catch (const Error& e) {
        report.warnings.push_back("the enum '" + t->name() + "' of the running version stays: " + e.what());
      }
  old.enums_.clear();
  old.scope_meta_.clear();
  old.by_meta_.clear();
  if (!nw.dirty_.empty() && nw.on_dirty_) nw.on_dirty_();
  return report;
}

MigrationReport Program::reload(std::string name, std::string text) {
  auto fresh = std::make_shared<ProgramImpl>(impl_->state_, impl_->opt_);
  fresh->weak_self_ = fresh;
  MigrationReport report = migrate(*impl_, *fresh, std::move(name), std::move(text));
  fresh->register_program();
  impl_ = std::move(fresh);
  return report;
}

void Program::follow_reload(std::string name, std::string text, const Transaction& bundle) {
  ProgramImpl& old = *impl_;
  if (old.debug_ != nullptr) throw Error("cannot follow a reload while a debugger is attached");
  if (!old.frames_.empty() || old.entry_depth_ != 0)
    throw Error("cannot follow a reload from the program's own code (it is running)");
  SimState& state = old.state_;
  Registry& reg = state.environment().registry();
  auto fresh = std::make_shared<ProgramImpl>(state, old.opt_);
  fresh->weak_self_ = fresh;

  // As on the source: the running version's classes make room under retired names.
  const std::vector<const MetaInstance*> old_classes = old.runtime_classes();
  RetiredNames retired(reg, old_classes);
  try {
    fresh->previous_ = &old;
    fresh->define(std::move(name), std::move(text));
  } catch (...) {
    fresh->undefine_own();
    retired.restore();
    throw;
  }

  // The bundle creates the new version's instances and deletes the old ones (checked whole first: one
  // that does not apply changes nothing); then the new version attaches to what it made.
  old.stop_listening();
  {
    Savepoint sp(state);
    bool applied = false;
    try {
      state.apply(bundle);
      applied = true;
      fresh->attaching_ = true;
      fresh->populate();
      sp.commit();
    } catch (const Error& e) {
      fresh->stop_listening();
      std::string extra;
      try {
        sp.rollback();
      } catch (const Error& r) {
        extra = "; rolling back failed too: " + std::string(r.what());
      }
      fresh->undefine_own();
      retired.restore();
      if (!applied) {
        old.connect_listeners();
        throw;
      }
      // The old version's nodes came back at other addresses: attach it again to them.
      try {
        auto again = std::make_shared<ProgramImpl>(state, old.opt_);
        again->weak_self_ = again;
        again->attaching_ = true;
        again->load_or_undo(old.image().checked->source->name(), old.image().checked->source->text());
        again->attaching_ = false;
        again->on_dirty_ = old.on_dirty_;
        again->trace_ = old.trace_;
        again->register_program();
        impl_ = std::move(again);
      } catch (const Error& r) {
        extra += "; attaching the running version again failed: " + std::string(r.what());
      }
      throw Error(std::string(e.what()) + extra);
    }
  }
  fresh->attaching_ = false;
  fresh->previous_ = nullptr;
  fresh->on_dirty_ = old.on_dirty_;
  fresh->trace_ = old.trace_;
  fresh->tests_ = old.tests_;
  fresh->condition_errors_ = old.condition_errors_;
  // The retired classes and enums go, as on the source (one something else still uses stays).
  old.release_uses(false);
  for (const MetaInstance* m : old_classes) try {
      reg.undefine(*m);
    } catch (const Error&) {  // NOLINT(bugprone-empty-catch): it stays under its retired name
    }
  for (const auto& [decl, t] : old.enums_)
    if (std::find(fresh->reused_enums_.begin(), fresh->reused_enums_.end(), t) == fresh->reused_enums_.end())
      try {
        reg.undefine(*t);
      } catch (const Error&) {  // NOLINT(bugprone-empty-catch)
      }
  old.enums_.clear();
  old.scope_meta_.clear();
  old.by_meta_.clear();
  fresh->register_program();
  impl_ = std::move(fresh);
  if (!impl_->dirty_.empty() && impl_->on_dirty_) impl_->on_dirty_();
}

}  // namespace vsd::soml
