// Loading a checked SOML++ script into a SimState (see runtime.hpp): source components, run-time
// classes and enums, the linkage table, compilation, and the instances of the script object, its objects
// and their nets.
#include <algorithm>
#include <cctype>
#include <limits>
#include <mutex>

#include "program_impl.hpp"
#include "vsd/core/database.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/meta_method.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/savepoint.hpp"
#include "vsd/core/type_builder.hpp"

namespace vsd::soml {

using K = Type::Kind;

namespace {

// "Outer::Inner" for nested declarations (the script object's members are top level).
std::string qualified(const Decl& d) {
  std::string s = d.name;
  for (const Decl* p = d.parent; p != nullptr && p->kind != DeclKind::Script; p = p->parent)
    s = p->name + "::" + s;
  return s;
}

template <class F>
void walk(const Decl& d, F&& fn) {
  fn(d);
  if (d.has_members())
    for (const DeclPtr& m : d.as<ScopeDecl>().members) walk(*m, fn);
}

}  // namespace

ProgramImpl::ProgramImpl(SimState& state, RunOptions options)
    : registry_(state.environment().registry()), state_(state), opt_(options) {}

ProgramImpl::~ProgramImpl() {
  stop_listening();
  xregs_.clear();  // values of the program's struct and enum types go before those types may
  release_uses(true);
}

namespace {
// How many live programs use each run-time class and enum (ProgramImpl::used_classes_): the last one to
// go undefines them. Keyed by address; an entry lives only while its count is positive, that is while some
// program holds the class.
std::mutex users_mutex;
std::unordered_map<const void*, int>& users() {
  static std::unordered_map<const void*, int> all;
  return all;
}
// True when a method of a class still defined takes or returns @p t (or a vector of it). The Registry
// refuses to undefine a type that a property uses, but does not look at method signatures: a class that
// stays (its instances outlive the program) keeps the enums its methods name.
bool used_by_methods(const Registry& reg, const MetaType& t) {
  auto names = [&](const MetaType* x) { return x == &t || (x != nullptr && x->element() == &t); };
  for (const MetaInstance* c : reg.classes())
    for (const MetaMethod* m : c->methods()) {
      if (names(m->result())) return true;
      for (const MetaType* a : m->arguments())
        if (names(a)) return true;
    }
  return false;
}
int users_of(const void* p) {
  std::lock_guard lock(users_mutex);
  auto it = users().find(p);
  return it == users().end() ? 0 : it->second;
}
}  // namespace

void ProgramImpl::release_uses(bool undefine) noexcept {
  if (!counted_) return;
  counted_ = false;
  std::vector<const MetaInstance*> classes;
  std::vector<const MetaType*> enums;
  {
    std::lock_guard lock(users_mutex);
    auto last = [](const void* p) {
      auto it = users().find(p);
      if (it == users().end() || --it->second > 0) return false;
      users().erase(it);
      return true;
    };
    for (const MetaInstance* m : used_classes_)
      if (last(m)) classes.push_back(m);
    for (const MetaType* t : used_enums_)
      if (last(t)) enums.push_back(t);
  }
  used_classes_.clear();
  used_enums_.clear();
  if (!undefine) return;
  Registry& reg = registry_;
  // Subclasses first. One with instances left (a state that outlives its program) or one still named by
  // another class's property stays; a later load replaces it once nothing uses it.
  std::stable_sort(classes.begin(), classes.end(),
                   [](const MetaInstance* a, const MetaInstance* b) { return a->depth() > b->depth(); });
  for (const MetaInstance* m : classes) try {
      reg.undefine(*m);
    } catch (const Error&) {  // NOLINT(bugprone-empty-catch): it stays (see above)
    }
  for (auto it = enums.rbegin(); it != enums.rend(); ++it)
    if (!used_by_methods(reg, **it)) try {
        reg.undefine(**it);
      } catch (const Error&) {  // NOLINT(bugprone-empty-catch)
      }
}

// SOML++ classes and enums that no live program uses and no instance holds are garbage — left by a
// program that went while its state lived on, whose instances are gone now — and go before a load, so
// that a script loads again under its names (docs/soml.md 8.1). Repeated while it makes progress: a class
// goes after its subclasses and after the classes whose properties name it.
void ProgramImpl::sweep_leftovers() { sweep_soml_leftovers(registry_); }

void sweep_soml_leftovers(Registry& reg) {
  auto garbage_class = [&](const MetaInstance* m) {
    return m->is_runtime() && m->name().starts_with("soml::") && m->live_instances() == 0 && users_of(m) == 0;
  };
  for (bool progress = true; progress;) {
    progress = false;
    std::vector<const MetaInstance*> classes;
    for (const MetaInstance* m : reg.classes())
      if (garbage_class(m)) classes.push_back(m);
    std::stable_sort(classes.begin(), classes.end(),
                     [](const MetaInstance* a, const MetaInstance* b) { return a->depth() > b->depth(); });
    for (const MetaInstance* m : classes) try {
        reg.undefine(*m);
        progress = true;
      } catch (const Error&) {  // NOLINT(bugprone-empty-catch): a subclass or a property still names it
      }
  }
  std::vector<const MetaType*> enums;  // collected first: undefining changes what types() walks
  for (const MetaType* t : reg.types())
    if (t->kind() == TypeKind::Enum && t->name().starts_with("soml::") && reg.owns(*t) && users_of(t) == 0 &&
        !used_by_methods(reg, *t))
      enums.push_back(t);
  for (const MetaType* t : enums) try {
      reg.undefine(*t);
    } catch (const Error&) {  // NOLINT(bugprone-empty-catch): a class still uses it
    }
}

const MetaInstance& ProgramImpl::class_for(ClassBuilder& b, const std::string& name, const MetaInstance& base,
                                           const ScopeDecl& decl) {
  const MetaInstance* m = nullptr;
  if (!attaching_ && registry_.find_class_exact(name) == nullptr) {
    adopted_props_.clear();
    adopted_methods_.clear();
    m = &define_class(b);
  } else {
    m = &adopt_class(b, name, base, decl);  // shared when it is the same (defined when there is none)
  }
  used_classes_.push_back(m);
  return *m;
}

const MetaType& ProgramImpl::enum_for(EnumBuilder& b, const std::string& name, const EnumDecl& decl) {
  const MetaType* t =
      !attaching_ && registry_.find_type(name) == nullptr ? &define_enum(b) : &adopt_enum(b, name, decl);
  used_enums_.push_back(t);
  return *t;
}

// The MetaType that stores a value of static type t (references to script classes are stored as
// references to their nearest built-in class: the checker already typed them).
const MetaType* storage_type(ProgramImpl& p, Registry& reg, const Type& t) {
  switch (t.kind) {
    case K::Bool:
      return t.meta != nullptr ? t.meta : &meta_type<bool>();
    case K::Int:
      return t.meta != nullptr ? t.meta : &meta_type<std::int64_t>();
    case K::Double:
      return t.meta != nullptr ? t.meta : &meta_type<double>();
    case K::String:
      return &meta_type<std::string>();
    case K::Enum:
      if (t.enum_decl != nullptr) {
        auto it = p.enums_.find(t.enum_decl);
        return it != p.enums_.end() ? it->second : nullptr;
      }
      return t.meta;
    case K::Struct:
      return t.meta;
    case K::Vector:
      if (t.enum_decl != nullptr) {  // of a script enum: the vector of its run-time enum (made on demand)
        auto it = p.enums_.find(t.enum_decl);
        return it != p.enums_.end() ? &reg.vector_type(*it->second) : nullptr;
      }
      return t.meta;
    case K::Ref:
    case K::List: {
      const MetaInstance* m = t.cls.builtin();
      if (m == nullptr) return nullptr;
      const char* kind =
          t.kind == K::Ref ? (t.shared ? "shared<" : "ref<") : (t.shared ? "shared_list<" : "list<");
      return &reg.get_type(std::string(kind) + m->name() + ">");
    }
    default:
      return nullptr;
  }
}

// How the VM stores a property of static type t (see PK).
static PK prop_kind(const Type& t, const MetaProperty& mp) {
  switch (t.kind) {
    case K::Bool:
      return PK::Bool;
    case K::Int:
      return &mp.type() == &meta_type<std::int64_t>() ? PK::I64 : PK::Int;
    case K::Double:
      return &mp.type() == &meta_type<double>() ? PK::Double : PK::Other;
    case K::String:
      return PK::String;
    case K::Enum:
      return PK::Enum;
    case K::Ref:
      return PK::Ref;
    case K::List:
      return PK::List;
    case K::Vector:
      return vector_elem_kind(mp.type()) != RK::None ? PK::Vector : PK::Value;
    case K::Struct:
      return PK::Value;
    default:
      return PK::Other;
  }
  return PK::Other;
}

void ProgramImpl::load(std::string name, std::string text) {
  define(std::move(name), std::move(text));
  populate();
}

void ProgramImpl::load_or_undo(std::string name, std::string text) {
  Savepoint sp(state_);
  try {
    load(std::move(name), std::move(text));
    bind_pending_methods();
    sp.commit();
  } catch (...) {
    // The instances first (a class with instances cannot go), then the classes, subclasses first.
    stop_listening();
    try {
      sp.rollback();
    } catch (const Error&) {  // NOLINT(bugprone-empty-catch): the load's error says more; classes with
    }                         // instances left then stay defined (undefine_own skips them)
    undefine_own();
    throw;
  }
}

const MetaInstance& ProgramImpl::define_class(ClassBuilder& b) {
  const MetaInstance& m = b.define(state_.environment().registry());
  defined_classes_.push_back(&m);
  return m;
}

const MetaType& ProgramImpl::define_enum(EnumBuilder& b) {
  const MetaType& t = b.define(state_.environment().registry());
  defined_enums_.push_back(&t);
  return t;
}

void ProgramImpl::undefine_own() noexcept {
  Registry& reg = state_.environment().registry();
  // Bases were defined before their subclasses: undefining in reverse order goes subclasses first.
  for (auto it = defined_classes_.rbegin(); it != defined_classes_.rend(); ++it) try {
      reg.undefine(**it);
    } catch (const Error&) {  // NOLINT(bugprone-empty-catch): one that still has instances stays
    }
  for (auto it = defined_enums_.rbegin(); it != defined_enums_.rend(); ++it) try {
      reg.undefine(**it);
    } catch (const Error&) {  // NOLINT(bugprone-empty-catch)
    }
  defined_classes_.clear();
  defined_enums_.clear();
  used_classes_.clear();
  used_enums_.clear();
  scope_meta_.clear();
  by_meta_.clear();
  enums_.clear();
}

void ProgramImpl::define(std::string name, std::string text) {
  auto fresh = std::make_shared<ProgramImage>();
  build_ = fresh.get();
  image_ = std::move(fresh);
  struct Done {  // build() is over when define() returns or throws
    ProgramImage*& b;
    ~Done() { b = nullptr; }
  } done{build_};
  define_image(std::move(name), std::move(text));
  prepare_run();
}

void ProgramImpl::define_image(std::string name, std::string text) {
  Registry& reg = state_.environment().registry();
  sweep_leftovers();
  build().checked = check_source(name, std::move(text), reg);
  if (!build().checked->ok()) throw Error(build().checked->diagnostics.format());
  {
    std::string base = name.substr(name.find_last_of("/\\") + 1);
    base = base.substr(0, base.find('.'));
    for (char& c : base)
      if (std::isalnum(static_cast<unsigned char>(c)) == 0) c = '_';
    if (base.empty() || std::isdigit(static_cast<unsigned char>(base[0])) != 0) base = "script_" + base;
    build().stem = base;
  }
  const ClassDecl& root = *build().checked->script.root;

  // 1. What the runtime cannot run yet is refused with its position, never ignored.
  walk(root, [&](const Decl& d) {
    if (d.kind == DeclKind::Net && !d.as<ClassDecl>().is_port_net) {
      const auto& n = d.as<ClassDecl>();
      for (const DeclPtr& m : n.members)
        if (m->name == "finished" || (m->name == "result" && n.result_type.kind != K::Void))
          not_supported(*this, m->loc,
                        "a member named '" + m->name + "' in an invocable net (the runtime's property)");
    }
    if (d.kind == DeclKind::Object && !is_static_instance(d))
      not_supported(*this, d.loc, "an object nested in a class");
    if (d.kind == DeclKind::Class && d.parent != nullptr && d.parent->kind == DeclKind::Class)
      not_supported(*this, d.loc, "a class nested in a class");
  });

  // 2. Script enums become run-time enums.
  walk(root, [&](const Decl& d) {
    if (d.kind != DeclKind::Enum) return;
    const auto& e = d.as<EnumDecl>();
    // A reload (migrate.cpp) keeps the running version's enum when its values are the same.
    if (previous_ != nullptr)
      for (const auto& [old_decl, old_type] : previous_->enums_) {
        if (old_type->name() != "soml::" + qualified(e)) continue;
        bool same = old_type->enum_values().size() == e.values.size();
        for (std::size_t i = 0; same && i < e.values.size(); ++i)
          same = old_type->enum_values()[i].name == e.values[i] &&
                 old_type->enum_values()[i].value == static_cast<std::int64_t>(i);
        if (!same) not_supported(*this, e.loc, "changing the values of enum '" + e.name + "' at run time");
        enums_[&e] = old_type;
        reused_enums_.push_back(old_type);
        used_enums_.push_back(old_type);
        return;
      }
    EnumBuilder b("soml::" + qualified(e));
    b.underlying(meta_type<std::int64_t>());
    for (std::size_t i = 0; i < e.values.size(); ++i) b.value(e.values[i], static_cast<std::int64_t>(i));
    enums_[&e] = &enum_for(b, "soml::" + qualified(e), e);
  });

  // 3. Class-like declarations, bases first.
  std::vector<const ClassDecl*> all;
  walk(root, [&](const Decl& d) {
    if (d.kind == DeclKind::Class || d.kind == DeclKind::Object || d.kind == DeclKind::Script ||
        (d.kind == DeclKind::Net && !d.as<ClassDecl>().is_port_net))
      all.push_back(&d.as<ClassDecl>());
  });
  std::unordered_map<const ClassDecl*, bool> placed;
  std::vector<const ClassDecl*> chain;  // a class and its bases not placed yet (no recursion: chains of
  for (const ClassDecl* c : all) {      // any length)
    for (const ClassDecl* d = c; d != nullptr && !placed[d]; d = d->base.decl) {
      placed[d] = true;
      chain.push_back(d);
    }
    build().class_order.insert(build().class_order.end(), chain.rbegin(), chain.rend());
    chain.clear();
  }

  // Function shells first: the MetaMethods' invokers and the compiler refer to them by index.
  walk(root, [&](const Decl& d) {
    if (d.kind != DeclKind::Function) return;
    const auto& fd = d.as<FunctionDecl>();
    const std::string owner =
        d.parent != nullptr && d.parent->kind != DeclKind::Script ? qualified(*d.parent) + "." : "";
    build().function_index[&fd] =
        new_function(*this, owner + (fd.is_constructor ? fd.name + " (constructor)" : fd.name));
  });

  auto add_members = [&](ClassBuilder& b, const ScopeDecl& s) {
    for (const DeclPtr& m : s.members) {
      if (m->kind == DeclKind::Property) {
        const auto& pd = m->as<PropertyDecl>();
        const MetaType* t = storage_type(*this, reg, pd.type);
        if (t == nullptr) not_supported(*this, pd.loc, "a property of type '" + pd.type.name() + "'");
        b.property(pd.name, *t);
        adopted_props_.emplace_back(pd.name, t);  // (what class_for compares with a class of that name)
      } else if (m->kind == DeclKind::Function && !m->as<FunctionDecl>().is_constructor) {
        const auto& fd = m->as<FunctionDecl>();
        std::vector<const MetaType*> args;
        for (const Param& prm : fd.params) {
          const MetaType* t = storage_type(*this, reg, prm.type);
          if (t == nullptr) not_supported(*this, prm.loc, "a parameter of type '" + prm.type.name() + "'");
          args.push_back(t);
        }
        const MetaType* result =
            fd.result_type.kind == K::Void ? nullptr : storage_type(*this, reg, fd.result_type);
        const int fi = build().function_index.at(&fd);
        std::weak_ptr<ProgramImpl> weak = weak_self_;
        adopted_methods_.push_back(AdoptedMethod{fd.name, args, result});
        b.method(fd.name, std::move(args), result,
                 [weak, fi, fname = build().functions[static_cast<std::size_t>(fi)]->name](
                     SimStateInstance& self, std::span<const Value> a) {
                   return dispatch(weak, fi, fname, self, a);
                 });
      }
    }
  };

  auto own_members = [](const ScopeDecl& s) {
    bool own = false;
    for (const DeclPtr& x : s.members)
      own = own || x->kind == DeclKind::Property || x->kind == DeclKind::Function;
    return own;
  };
  // Places and transitions with members of their own get a class of their own.
  auto member_classes = [&](const ScopeDecl& c, const std::string& cname) {
    for (const DeclPtr& m : c.members) {
      if (m->kind != DeclKind::Place && m->kind != DeclKind::Transition) continue;
      const auto& s = m->as<ScopeDecl>();
      const MetaInstance& sb = m->kind == DeclKind::Place ? Place::static_meta() : Transition::static_meta();
      if (!own_members(s)) {
        scope_meta_[m.get()] = &sb;
        continue;
      }
      ClassBuilder pb(cname + "::" + m->name, sb);
      add_members(pb, s);
      scope_meta_[m.get()] = &class_for(pb, cname + "::" + m->name, sb, s);
    }
  };
  for (const ClassDecl* c : build().class_order) {
    auto ci = std::make_unique<ClassInfo>();
    ci->decl = c;
    const MetaInstance* base = &Node::static_meta();
    if (c->base.decl != nullptr) {
      ci->base = build().class_info.at(c->base.decl).get();
      base = ci->base->meta;
    } else if (c->base.meta != nullptr) {
      base = c->base.meta;
    } else if (c->kind == DeclKind::Net) {
      base = &Invocation::static_meta();  // one instance per invocation (4.11)
    }
    if (!base->is_a(Node::static_meta()))
      not_supported(*this, c->base_loc, "a class derived from '" + base->name() + "' (not a Node)");
    const std::string cname =
        c->kind == DeclKind::Script ? "soml::" + build().stem : "soml::" + qualified(*c);
    ClassBuilder b(cname, *base);
    add_members(b, *c);
    if (c->kind == DeclKind::Net && c->result_type.kind != K::Void) {
      const MetaType* t = storage_type(*this, reg, c->result_type);
      if (t == nullptr) not_supported(*this, c->loc, "a net result of type '" + c->result_type.name() + "'");
      b.property("result", *t);
      adopted_props_.emplace_back("result", t);
    }
    ci->meta = &class_for(b, cname, *base, *c);
    scope_meta_[c] = ci->meta;
    by_meta_[ci->meta] = ci.get();
    member_classes(*c, cname);
    build().class_info[c] = std::move(ci);
  }
  // A port net (4.11, 5.5) with properties or functions of its own is a run-time class derived from
  // soml::Transition: the class of the node of every substitution transition that copies the net, which
  // is that copy's instance (its properties, its functions' `this`). Its places and transitions with
  // members get classes of their own, as an object's do.
  walk(root, [&](const Decl& d) {
    if (d.kind != DeclKind::Net || !d.as<ClassDecl>().is_port_net) return;
    const auto& n = d.as<ClassDecl>();
    const std::string cname = "soml::" + qualified(n);
    if (own_members(n)) {
      const MetaInstance& sb = Transition::static_meta();
      ClassBuilder b(cname, sb);
      add_members(b, n);
      scope_meta_[&n] = &class_for(b, cname, sb, n);
    }
    member_classes(n, cname);
  });
  walk(root, [&](const Decl& d) {
    if (d.kind != DeclKind::Transition) return;
    const TransitionDecl& t = d.as<TransitionDecl>();
    if (t.substituted == nullptr) return;
    if (auto it = scope_meta_.find(t.substituted); it != scope_meta_.end()) scope_meta_[&t] = it->second;
  });

  // 4. Linkage: property declarations -> MetaProperties (build().props slots).
  walk(root, [&](const Decl& d) {
    if (d.kind != DeclKind::Property) return;
    const MetaInstance* m = scope_meta_.at(d.parent);
    const MetaProperty* mp = m->find_property(d.name);
    if (mp == nullptr) not_supported(*this, d.loc, "property '" + d.name + "'");
    PropSlot s;
    s.prop = mp;
    const auto& pd = d.as<PropertyDecl>();
    s.kind = prop_kind(pd.type, *mp);
    build().props.push_back(s);
    build().prop_slot[&pd] = static_cast<int>(build().props.size() - 1);
    build().meta_prop_slot[mp] = build().prop_slot[&pd];
  });

  // The `result` property of invocable nets (read when an instance finishes, written by `finish`).
  for (const ClassDecl* c : build().class_order) {
    if (c->kind != DeclKind::Net || c->result_type.kind == K::Void) continue;
    ClassInfo& ci = *build().class_info.at(c);
    const MetaProperty* mp = ci.meta->find_property("result");
    build().props.push_back(PropSlot{mp, prop_kind(c->result_type, *mp)});
    ci.result_slot = static_cast<int>(build().props.size() - 1);
    build().meta_prop_slot[mp] = ci.result_slot;
  }

  // 5. Overrides: a function with the name of a base class's function is called virtually.
  for (const ClassDecl* c : build().class_order) {
    ClassInfo& ci = *build().class_info.at(c);
    if (ci.base != nullptr) ci.vtable = ci.base->vtable;
    for (const DeclPtr& m : c->members) {
      if (m->kind != DeclKind::Function || m->as<FunctionDecl>().is_constructor) continue;
      const auto& fd = m->as<FunctionDecl>();
      const FunctionDecl* rootf = &fd;
      for (const ClassInfo* b = ci.base; b != nullptr; b = b->base)
        for (const DeclPtr& bm : b->decl->members)
          if (bm->kind == DeclKind::Function && bm->name == fd.name) rootf = &bm->as<FunctionDecl>();
      if (rootf != &fd) {
        if (build().vslot_of.find(rootf) == build().vslot_of.end()) {
          build().vslot_of[rootf] = static_cast<int>(build().vslots.size());
          build().vslots.push_back(rootf);
          build().vslot_default.push_back(build().function_index.at(rootf));
        }
        build().vslot_of[&fd] = build().vslot_of[rootf];
        ci.vtable[rootf] = build().function_index.at(&fd);
      }
    }
  }

  // 6. Nets of every class: places and transitions, bases' first. A substitution transition's sub-net
  // (4.11, hierarchical nets) is copied into the net: the port net's inner places follow, its ports are
  // the socket places (the same index). Each copy is an Expansion, recorded depth first in member order
  // so that step 7 adds the sub-net's transitions in the same order.
  struct Expansion {
    const TransitionDecl* holder = nullptr;
    std::unordered_map<const Decl*, int> places;  // the port net's places -> index in the class's net
    std::vector<int> own;                         // indices of the places this copy added
  };
  std::unordered_map<const ClassDecl*, std::vector<Expansion>> expansions;
  std::function<void(NetClass&, std::vector<Expansion>&, const TransitionDecl&,
                     const std::unordered_map<const Decl*, int>&, int)>
      expand_places = [&](NetClass& net, std::vector<Expansion>& exps, const TransitionDecl& t,
                          const std::unordered_map<const Decl*, int>& outer, int depth) {
        if (depth >= 16)
          not_supported(*this, t.subst_loc, "net substitution nested 16 levels deep (recursive?)");
        const ClassDecl& n = *t.substituted;
        Expansion e;
        e.holder = &t;
        for (std::size_t i = 0; i < n.params.size() && i < t.subst_args.size(); ++i) {
          const Decl* socket = t.subst_args[i]->type.decl;
          auto it = socket != nullptr ? outer.find(socket) : outer.end();
          if (it == outer.end()) not_supported(*this, t.subst_args[i]->loc, "this socket place");
          for (const DeclPtr& m : n.members)
            if (m->kind == DeclKind::Place && m->name == n.params[i].name) e.places[m.get()] = it->second;
        }
        for (const DeclPtr& m : n.members) {
          if (m->kind != DeclKind::Place || m->as<PlaceDecl>().is_port) continue;
          e.places[m.get()] = static_cast<int>(net.places.size());
          e.own.push_back(static_cast<int>(net.places.size()));
          net.places.push_back(&m->as<PlaceDecl>());
          net.place_holder.push_back(-1);  // set when step 7 numbers the holder transition
        }
        const std::unordered_map<const Decl*, int> map = e.places;
        exps.push_back(std::move(e));
        for (const DeclPtr& m : n.members)
          if (m->kind == DeclKind::Transition && m->as<TransitionDecl>().substituted != nullptr)
            expand_places(net, exps, m->as<TransitionDecl>(), map, depth + 1);
      };
  // Each class's net holds its bases' places and transitions too: a long chain of classes with nets
  // would hold the square of its length. Refused past this many copied (the input bounds nothing else).
  constexpr std::size_t kMaxInherited = 4'000'000;
  std::size_t inherited = 0;
  auto inherit = [&](const ClassDecl& c, std::size_t n) {
    inherited += n;
    if (inherited > kMaxInherited)
      not_supported(*this, c.loc,
                    "nets this large through inheritance (the classes would hold more than " +
                        std::to_string(kMaxInherited) + " places and transitions of their bases)");
  };
  for (const ClassDecl* c : build().class_order) {
    ClassInfo& ci = *build().class_info.at(c);
    auto net = std::make_unique<NetClass>();
    if (ci.base != nullptr && ci.base->net) {
      inherit(*c, ci.base->net->places.size());
      net->places = ci.base->net->places;
      net->place_holder = ci.base->net->place_holder;
      net->transitions = ci.base->net->transitions;
    }
    for (const DeclPtr& m : c->members)
      if (m->kind == DeclKind::Place) {
        net->places.push_back(&m->as<PlaceDecl>());
        net->place_holder.push_back(-1);
      }
    std::unordered_map<const Decl*, int> top;
    for (std::size_t i = 0; i < net->places.size(); ++i) top.emplace(net->places[i], static_cast<int>(i));
    for (const DeclPtr& m : c->members)
      if (m->kind == DeclKind::Transition && m->as<TransitionDecl>().substituted != nullptr)
        expand_places(*net, expansions[c], m->as<TransitionDecl>(), top, 0);
    net->invocable = c->kind == DeclKind::Net;
    if (c->kind == DeclKind::Net && c->start != nullptr)
      ci.start_place = top.count(c->start->place_decl) != 0 ? top.at(c->start->place_decl) : -1;
    if (!net->places.empty()) ci.net = std::move(net);
  }
  // A place's index in a class's net, by a table made once per net (a search per arrow was quadratic in
  // a net of many places: a PNML net of 100,000 places took seconds to load).
  std::unordered_map<const NetClass*, std::unordered_map<const Decl*, int>> place_indices;
  auto place_index = [&](const NetClass& n, const Decl* d) {
    auto [it, fresh] = place_indices.try_emplace(&n);
    if (fresh)
      for (std::size_t i = 0; i < n.places.size(); ++i)
        it->second.try_emplace(n.places[i], static_cast<int>(i));
    const auto at = it->second.find(d);
    return at == it->second.end() ? -1 : at->second;
  };
  for (const ClassDecl* c : build().class_order) {
    ClassInfo& ci = *build().class_info.at(c);
    bool has_transitions = false;
    for (const DeclPtr& m : c->members) has_transitions = has_transitions || m->kind == DeclKind::Transition;
    if (has_transitions && !ci.net) ci.net = std::make_unique<NetClass>();
  }

  // Communication arrows: the path to the remote place, resolved like the checker did (objects and
  // reference properties), as steps the executor follows when it tests or fires.
  auto comm_path = [&](const ArrowDecl& a, const ClassDecl& owner) {
    const std::vector<std::string>& path = a.to_decl->kind == DeclKind::Transition ? a.from : a.to;
    std::vector<PathStep> steps;
    ClassRef cls{&owner, nullptr};
    auto find_in = [&](ClassRef c, const std::string& n, PathStep& st, ClassRef& next) {
      for (const ClassDecl* d = c.decl; d != nullptr; d = d->base.decl)
        for (const DeclPtr& m : d->members) {
          if (m->name != n) continue;
          if (m->kind == DeclKind::Object && is_static_instance(*m)) {
            st.object = &m->as<ClassDecl>();
            next = ClassRef{st.object, nullptr};
            return true;
          }
          if (m->kind == DeclKind::Property && m->as<PropertyDecl>().type.kind == K::Ref) {
            st.prop = scope_meta_.at(d)->find_property(n);
            next = m->as<PropertyDecl>().type.cls;
            return st.prop != nullptr;
          }
          return false;
        }
      const MetaInstance* b = c.builtin();
      if (b != nullptr && c.decl == nullptr) {
        if (const MetaProperty* mp = b->find_property(n);
            mp != nullptr && mp->type().kind() == TypeKind::SharedRef) {
          st.prop = mp;
          next = ClassRef{nullptr, mp->type().target()};
          return true;
        }
      }
      return false;
    };
    for (std::size_t i = 0; i + 1 < path.size(); ++i) {
      PathStep st;
      ClassRef next;
      bool ok = find_in(cls, path[i], st, next);
      // The first name may also be a static object or a property of a static object around the owner.
      for (const Decl* up = owner.parent; !ok && i == 0 && up != nullptr; up = up->parent)
        if (up->is_class_like() && is_static_instance(*up)) {
          ok = find_in(ClassRef{&up->as<ClassDecl>(), nullptr}, path[i], st, next);
          if (ok && st.prop != nullptr) steps.push_back(PathStep{&up->as<ClassDecl>(), nullptr});
        }
      if (!ok) not_supported(*this, a.loc, "this communication arrow path");
      steps.push_back(st);
      cls = next;
    }
    if (steps.empty()) not_supported(*this, a.loc, "a communication arrow without a path");
    return steps;
  };

  // 7. Compile.
  // In function order, not the map's (pointer hashes): the operand tables (constants, strings, ...) fill
  // as the code is compiled, and the same text must give the same image every time (the native code
  // generated from it is matched by the image's hash).
  {
    std::vector<std::pair<int, const FunctionDecl*>> order;
    for (auto& [fd, fi] : build().function_index) order.emplace_back(fi, fd);
    std::sort(order.begin(), order.end());
    for (const auto& [fi, fd] : order) compile_function(*this, fi, *fd);
  }
  for (const ClassDecl* c : build().class_order) {
    ClassInfo& ci = *build().class_info.at(c);
    const std::string cname = c->kind == DeclKind::Script ? build().stem : qualified(*c);
    const std::string prefix = c->kind == DeclKind::Script ? "" : cname + ".";
    ci.init = compile_init(*this, *c, cname + " (initialisers)");
    if (c->constructor != nullptr) ci.ctor = build().function_index.at(c->constructor);
    if (c->kind == DeclKind::Object && c->has_args && c->base.decl != nullptr &&
        c->base.decl->constructor != nullptr)
      ci.object_ctor = compile_object_ctor(*this, *c, build().function_index.at(c->base.decl->constructor),
                                           *c->base.decl->constructor);
    std::size_t next_expansion = 0;
    // One transition of the class's net, or of a sub-net copied into it (map: the copy's places).
    std::function<void(const TransitionDecl&, const std::unordered_map<const Decl*, int>*, int,
                       const std::string&)>
        make_transition = [&](const TransitionDecl& t, const std::unordered_map<const Decl*, int>* map,
                              int holder, const std::string& pre) {
          TransitionInfo ti;
          ti.decl = &t;
          ti.index = static_cast<int>(ci.net->transitions.size());
          ti.holder = holder;
          if (t.substituted != nullptr) {  // inert: its sub-net's transitions follow, children of its node
            ti.inert = true;
            Expansion& e = expansions.at(c).at(next_expansion++);
            ti.sub_places = e.places;
            ci.net->transitions.push_back(std::move(ti));
            const int h = static_cast<int>(ci.net->transitions.size() - 1);
            for (int p : e.own) ci.net->place_holder[static_cast<std::size_t>(p)] = h;
            const std::unordered_map<const Decl*, int> sub = e.places;
            for (const DeclPtr& m : t.substituted->members)
              if (m->kind == DeclKind::Transition)
                make_transition(m->as<TransitionDecl>(), &sub, h, pre + t.name + ".");
            return;
          }
          if (t.when_expr || t.when_block)
            ti.cond = compile_condition(*this, t, pre + t.name + " (condition)");
          if (t.action) {
            ti.action = compile_action(*this, t, pre + t.name + " (action)");
            if (t.invoked != nullptr && t.invoked->result_type.kind != K::Void) {
              // The action of an invoking transition runs when the net finished: `result` is its slot 0.
              Function& f = *build().functions[static_cast<std::size_t>(ti.action)];
              f.nparams = 1;
              f.param_kinds = {reg_kind(t.invoked->result_type)};
            }
          }
          if (t.invoked != nullptr) {
            ti.invoke = build().class_info.at(t.invoked).get();
            if (!t.invoke_args.empty())
              ti.invoke_args = compile_invoke_args(*this, t, pre + t.name + " (invocation arguments)");
          }
          auto arrow_info = [&](const ArrowDecl& a, const Decl* place) {
            ArrowInfo ai;
            ai.decl = &a;
            // An arrow of a substituted sub-net belongs to the port net's copy: its condition's `this`
            // and the start of its path are the copy's instance, the substitution transition's node.
            if (map != nullptr) ai.holder = holder;
            if (a.arrow == ArrowKind::Communication) {
              ai.remote = true;
              ai.remote_place = &place->as<PlaceDecl>();
              ai.path = comm_path(a, map != nullptr ? parent_scope(a)->as<ClassDecl>() : *c);
              ai.weight = a.weight;
              ai.object = !ai.remote_place->token.empty();
              if (a.condition) {
                auto dotted = [](const std::vector<std::string>& path) {
                  std::string s;
                  for (const std::string& n : path) s += (s.empty() ? "" : ".") + n;
                  return s;
                };
                ai.cond = compile_arrow_condition(*this, a,
                                                  pre + "arrow " + dotted(a.from) + " ~> " + dotted(a.to));
              }
              return ai;
            }
            if (map != nullptr) {
              auto it = map->find(place);
              ai.place = it != map->end() ? it->second : -1;
            } else {
              ai.place = place_index(*ci.net, place);
            }
            if (ai.place < 0) not_supported(*this, a.loc, "an arrow to a place of another net");
            ai.weight = a.weight;
            ai.inhibitor = a.arrow == ArrowKind::Inhibitor;
            ai.object = !place->as<PlaceDecl>().token.empty();
            if (a.condition)
              ai.cond = compile_arrow_condition(
                  *this, a, pre + "arrow " + a.from_decl->name + " -> " + a.to_decl->name);
            return ai;
          };
          for (const ArrowDecl* a : t.inputs) {
            ti.in.push_back(arrow_info(*a, a->from_decl));
            if (ti.in.back().object && !ti.in.back().inhibitor)
              ti.mark_in = static_cast<int>(ti.in.size() - 1);
          }
          for (const ArrowDecl* a : t.outputs) {
            ti.out.push_back(arrow_info(*a, a->to_decl));
            if (!ti.out.back().object &&
                __builtin_add_overflow(ti.out_weight, ti.out.back().weight, &ti.out_weight))
              ti.out_weight = std::numeric_limits<std::int64_t>::max();
          }
          ti.guarded = ti.action >= 0 || ti.invoke != nullptr;
          for (const ArrowInfo& a : ti.out) ti.guarded = ti.guarded || a.cond >= 0;
          ci.net->transitions.push_back(std::move(ti));
        };
    for (const DeclPtr& m : c->members) {
      if (m->kind == DeclKind::Place || m->kind == DeclKind::Transition)
        build().scope_init[m.get()] =
            compile_init(*this, m->as<ScopeDecl>(), prefix + m->name + " (initialisers)");
      if (m->kind != DeclKind::Transition) continue;
      make_transition(m->as<TransitionDecl>(), nullptr, -1, prefix);
    }
  }
  // Port nets: the initialisers of the net's instance (run for each substitution transition's node, which
  // is the copy's instance) and of its places and transitions (run for each copy of them).
  walk(root, [&](const Decl& d) {
    if (d.kind != DeclKind::Net || !d.as<ClassDecl>().is_port_net) return;
    const auto& n = d.as<ClassDecl>();
    for (const DeclPtr& m : n.members)
      if (m->kind == DeclKind::Place || m->kind == DeclKind::Transition)
        build().scope_init[m.get()] =
            compile_init(*this, m->as<ScopeDecl>(), qualified(n) + "." + m->name + " (initialisers)");
  });
  std::unordered_map<const ClassDecl*, int> port_init;
  walk(root, [&](const Decl& d) {
    if (d.kind != DeclKind::Transition || d.as<TransitionDecl>().substituted == nullptr) return;
    const ClassDecl& n = *d.as<TransitionDecl>().substituted;
    if (!own_members(n)) return;
    auto it = port_init.find(&n);
    if (it == port_init.end())
      it = port_init.emplace(&n, compile_init(*this, n, qualified(n) + " (initialisers)")).first;
    build().scope_init[&d] = it->second;
  });
  // Subclasses copied their bases' transitions before these were compiled: copy again.
  for (const ClassDecl* c : build().class_order) {
    ClassInfo& ci = *build().class_info.at(c);
    if (ci.base == nullptr || !ci.base->net || !ci.net) continue;
    inherit(*c, ci.base->net->transitions.size());
    std::vector<TransitionInfo> own = std::move(ci.net->transitions);
    ci.net->transitions = ci.base->net->transitions;
    const int offset = static_cast<int>(ci.net->transitions.size());
    for (auto& t : own) {
      t.index = static_cast<int>(ci.net->transitions.size());
      if (t.holder >= 0) t.holder += offset;
      ci.net->transitions.push_back(std::move(t));
    }
    // Holders of sub-net places: the base's (numbered after the copy in step 6), the own ones shifted.
    const std::size_t nbase = ci.base->net->places.size();
    for (std::size_t i = 0; i < ci.net->place_holder.size(); ++i) {
      int& h = ci.net->place_holder[i];
      if (i < nbase)
        h = ci.base->net->place_holder[i];
      else if (h >= 0)
        h += offset;
    }
  }
}

void ProgramImpl::prepare_run() {
  consts_ = image().consts;
  outer_ids_.assign(image().outer_plans.size(), 0);
  run_.clear();
  run_.reserve(image().functions.size());
  for (const auto& f : image().functions) run_.push_back(RunCode{f.get(), f->code, {}, false});
}

void ProgramImpl::link_objects() {
  for (const auto& [slot, decl] : image().object_refs)
    consts_[static_cast<std::size_t>(slot)] = static_cast<std::int64_t>(object_ids_.at(decl));
  for (std::size_t i = 0; i < image().outer_plans.size(); ++i)
    if (const ClassDecl* d = image().outer_plans[i].static_decl; d != nullptr)
      outer_ids_[i] = object_ids_.at(d);
}

void ProgramImpl::connect_listeners() {
  watch_.emplace(state_, &ProgramImpl::heard, this);
  // Nets, places, transitions and the executor are nodes: a deletion of any of them stops a net.
  watch_->deleted(Node::static_meta())
      .properties(Place::static_meta(), {&Place::vsd_prop_tokens(), &Place::vsd_prop_objects()});
  // What the tests read so far (a program that listens again after a failed live reload).
  covered_properties_.clear();
  covered_classes_.clear();
  deps_map_.for_each([&](const DepKey& key, const DepTable::Watchers&) { cover(key.id, key.prop); });
}

void ProgramImpl::cover_new(std::uint64_t id, const MetaProperty* prop) {
  if (!watch_) return;
  if (prop != nullptr) {
    const std::size_t cls = prop->owner().index();
    const std::size_t i = prop->index();
    if (cls >= covered_properties_.size()) covered_properties_.resize(cls + 1);
    auto& row = covered_properties_[cls];
    if (i / 64 >= row.size()) row.resize(i / 64 + 1, 0);
    const std::uint64_t bit = std::uint64_t{1} << (i % 64);
    if ((row[i / 64] & bit) != 0) return;
    watch_->properties(prop->owner(), {prop});
    row[i / 64] |= bit;
    return;
  }
  // A test called a C++ method of instance @p id, which may read any property of it.
  const SimStateInstance* o = state_.find(id);
  if (o != nullptr && covered_classes_.insert(&o->meta()).second) watch_->all_properties(o->meta());
}

std::vector<const MetaInstance*> ProgramImpl::runtime_classes() const {
  std::vector<const MetaInstance*> out;
  for (const auto& [decl, m] : scope_meta_)
    if (m->is_runtime() && std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
  // Subclasses first (the order Registry::undefine needs), then by name for a stable order.
  std::sort(out.begin(), out.end(), [](const MetaInstance* a, const MetaInstance* b) {
    return a->depth() != b->depth() ? a->depth() > b->depth() : a->name() < b->name();
  });
  return out;
}

void ProgramImpl::make_source() {
  source_node_ = &state_.create<SourceFile>();
  source_node_->set_name(image().stem + " (source)");
  source_node_->set_file(image().checked->source->name());
  source_node_->set_text(image().checked->source->text());
  state_.database().add_child(*source_node_);
  std::function<void(const Decl&, Node&)> component = [&](const Decl& d, Node& parent) {
    auto& sc = state_.create<SourceComponent>();
    sc.set_name(d.kind == DeclKind::Script ? image().stem : d.name);
    sc.set_kind(std::string(d.kind_name()));
    sc.set_line(d.loc.line);
    sc.set_column(d.loc.column);
    parent.add_child(sc);
    components_[&d] = &sc;
    if (d.has_members())
      for (const DeclPtr& m : d.as<ScopeDecl>().members) component(*m, sc);
  };
  component(*image().checked->script.root, *source_node_);
}

void ProgramImpl::populate() {
  const ClassDecl& root = *image().checked->script.root;
  // 8. The database content: source components, the script object and its objects.
  connect_listeners();
  if (attaching_) {  // the content is there already (attach.cpp)
    attach_content();
    return;
  }
  make_source();

  // Static instances first (their ids are constants of the code), then their values, nets and constructors.
  std::vector<std::pair<const ClassDecl*, SimStateInstance*>> statics;
  std::function<void(const ClassDecl&, Node*)> make = [&](const ClassDecl& c, Node* parent) {
    SimStateInstance& inst =
        create_node(*image().class_info.at(&c), parent, c.kind == DeclKind::Script ? image().stem : c.name);
    object_ids_[&c] = inst.id();
    statics.emplace_back(&c, &inst);
    for (const DeclPtr& m : c.members)
      if (m->kind == DeclKind::Object) make(m->as<ClassDecl>(), inst.as<Node>());
  };
  make(root, &state_.database());
  root_ = statics.front().second->as<Node>();
  link_objects();
  for (auto& [decl, inst] : statics) setup(*image().class_info.at(decl), *inst, nullptr, nullptr, 0);
  // What decides the continuation of the run, as database state (attach.cpp).
  exec_ = &state_.create<Executor>();
  exec_->set_name("(executor)");
  root_->add_child(*exec_);
  sync_state();
}

SimStateInstance& ProgramImpl::create_node(const ClassInfo& ci, Node* parent, const std::string& name) {
  SimStateInstance& inst = state_.create(*ci.meta);
  Node* n = inst.as<Node>();
  if (!name.empty()) n->set_name(name);
  if (parent != nullptr) parent->add_child(*n);
  return inst;
}

SimStateInstance& ProgramImpl::instantiate(const ClassInfo& ci, Node* parent, std::string name,
                                           const Val* args, const std::string* sargs, int nargs,
                                           const VecReg* vargs, const Value* xargs) {
  SimStateInstance& inst = create_node(ci, parent, name);
  setup(ci, inst, args, sargs, nargs, vargs, xargs);
  return inst;
}

void ProgramImpl::setup(const ClassInfo& ci, SimStateInstance& inst, const Val* args,
                        const std::string* sargs, int nargs, const VecReg* vargs, const Value* xargs) {
  std::vector<const ClassInfo*> chain;
  for (const ClassInfo* c = &ci; c != nullptr; c = c->base) chain.push_back(c);
  std::reverse(chain.begin(), chain.end());
  for (const ClassInfo* c : chain)
    if (c->init >= 0) run(c->init, inst.id(), 0, nullptr, nullptr);
  if (ci.net) build_net(ci, inst);
  // The start place: the most derived class's (a net's receives the invocation's black token instead).
  for (auto c = chain.rbegin(); c != chain.rend() && ci.decl->kind != DeclKind::Net; ++c) {
    const StartDecl* sd = (*c)->decl->start;
    if (sd == nullptr || sd->place_decl == nullptr) continue;
    const ScopeDecl* owner = parent_scope(*sd->place_decl);
    NetInst* net = nullptr;
    if (owner != nullptr && owner->is_class_like() && is_static_instance(*owner)) {
      net = net_of(object_ids_.at(&owner->as<ClassDecl>()));
    } else {
      net = net_of(inst.id());
    }
    if (net == nullptr) not_supported(*this, sd->loc, "this start place (its net does not exist yet)");
    for (std::size_t i = 0; i < net->cls->places.size(); ++i)
      if (net->cls->places[i] == sd->place_decl) put_token(*net->places[i], &inst, 1);
    break;
  }
  // Constructors: bases' without arguments, then the class's own (or an object's base's) with them.
  for (const ClassInfo* c : chain) {
    if (c->ctor < 0) continue;
    const Function& f = *image().functions[static_cast<std::size_t>(c->ctor)];
    if (c == &ci ||
        (c == ci.base && ci.decl->kind == DeclKind::Object && ci.object_ctor < 0 && f.nparams == 0)) {
      if (c == &ci && f.nparams != nargs)
        fail("constructor of " + ci.decl->name + " needs " + std::to_string(f.nparams) + " arguments");
      run(c->ctor, inst.id(), 0, args, sargs, nullptr, vargs, nullptr, xargs);
    } else if (f.nparams == 0) {
      run(c->ctor, inst.id(), 0, nullptr, nullptr);
    }
  }
  if (ci.object_ctor >= 0) {
    const Node* parent = inst.as<Node>()->parent();
    Val self{};
    self.id = inst.id();
    run(ci.object_ctor, parent != nullptr ? parent->id() : 0, 0, &self, nullptr);
  }
}

void ProgramImpl::build_net(const ClassInfo& ci, SimStateInstance& inst) {
  auto net = std::make_unique<NetInst>();
  net->owner = inst.id();
  net->cls = ci.net.get();
  Node& owner = *inst.as<Node>();
  // Places and transitions of a substituted sub-net are children of the substitution transition's node.
  auto meta_of = [&](const Decl* d, const MetaInstance& fallback) {
    auto it = scope_meta_.find(d);
    return it != scope_meta_.end() ? it->second : &fallback;
  };
  for (std::size_t i = 0; i < ci.net->places.size(); ++i) {
    const PlaceDecl* pd = ci.net->places[i];
    auto& p = static_cast<Place&>(state_.create(*meta_of(pd, Place::static_meta())));
    p.set_name(pd->name);
    p.set_object_tokens(!pd->token.empty());
    p.set_tokens(pd->initial_tokens);
    if (ci.net->place_holder[i] < 0) owner.add_child(p);
    net->places.push_back(&p);
    place_watch_[p.id()];
  }
  for (const TransitionInfo& t : ci.net->transitions) {
    auto& tn = static_cast<Transition&>(state_.create(*meta_of(t.decl, Transition::static_meta())));
    tn.set_name(t.decl->name);
    (t.holder < 0 ? owner : static_cast<Node&>(*net->transitions[static_cast<std::size_t>(t.holder)]))
        .add_child(tn);
    net->transitions.push_back(&tn);
  }
  for (std::size_t i = 0; i < ci.net->places.size(); ++i)
    if (const int h = ci.net->place_holder[i]; h >= 0)
      net->transitions[static_cast<std::size_t>(h)]->add_child(*net->places[i]);
  for (std::size_t ti = 0; ti < ci.net->transitions.size(); ++ti) {
    const TransitionInfo& t = ci.net->transitions[ti];
    Node* tnode = net->transitions[ti];
    auto add_arrow = [&](const ArrowInfo& a) {
      const bool input = a.decl->to_decl->kind == DeclKind::Transition;
      if (a.remote) {
        // A communication arrow leaves the transition (output) or points at it (input); its place is
        // found when it fires, so its target is set only when it is local.
        auto& an = state_.create<Arrow>();
        an.set_name(a.decl->from_decl->name + " ~> " + a.decl->to_decl->name);
        an.set_type(ArrowType::Communication);
        an.set_weight(a.weight);
        if (input) an.set_target(tnode);
        tnode->add_child(an);
        return;
      }
      // By index, not by declaration: a sub-net's port is its socket, and a port net copied twice has
      // two nodes per place.
      Node* pnode = net->places[static_cast<std::size_t>(a.place)];
      auto& an = state_.create<Arrow>();
      an.set_name(a.decl->from_decl->name + (a.inhibitor ? " -o " : " -> ") + a.decl->to_decl->name);
      an.set_type(a.inhibitor ? ArrowType::Inhibitor : ArrowType::Normal);
      an.set_weight(a.weight);
      an.set_target(input ? tnode : pnode);
      (input ? pnode : tnode)->add_child(an);
    };
    for (const ArrowInfo& a : t.in) add_arrow(a);
    for (const ArrowInfo& a : t.out) add_arrow(a);
  }
  // Initialisers of places and transitions with properties.
  for (std::size_t i = 0; i < ci.net->places.size(); ++i)
    if (auto it = image().scope_init.find(ci.net->places[i]); it != image().scope_init.end())
      run(it->second, net->places[i]->id(), 0, nullptr, nullptr);
  for (std::size_t i = 0; i < ci.net->transitions.size(); ++i)
    if (auto it = image().scope_init.find(ci.net->transitions[i].decl); it != image().scope_init.end())
      run(it->second, net->transitions[i]->id(), 0, nullptr, nullptr);
  register_net(std::move(net), ci, inst);
}

void ProgramImpl::register_net(std::unique_ptr<NetInst> net, const ClassInfo& ci, SimStateInstance& inst) {
  // Register with the executor: every transition is tested once.
  net->first_ti = static_cast<std::uint32_t>(tis_.size());
  NetInst* n = net.get();
  node_net_[inst.id()] = n;
  for (Place* p : n->places) node_net_[p->id()] = n;
  for (Transition* t : n->transitions) node_net_[t->id()] = n;
  if (auto old = nets_.find(inst.id()); old != nets_.end())
    dead_nets_.push_back(std::move(old->second));  // a dead net revived (roll_back): tis_ still point at it
  nets_[inst.id()] = std::move(net);
  net_order_.push_back(n);
  for (std::size_t t = 0; t < ci.net->transitions.size(); ++t) {
    const auto ti = static_cast<std::uint32_t>(tis_.size());
    tis_.push_back(TI{{}, n, static_cast<int>(t)});
    tis_.back().dirty = false;
    const TransitionInfo& info = ci.net->transitions[t];
    bool counts_only = info.mark_in < 0 && info.cond < 0;
    for (const ArrowInfo& a : info.in) counts_only = counts_only && !a.remote && a.cond < 0;
    for (const ArrowInfo& a : info.out) counts_only = counts_only && !a.remote;
    tis_.back().counts_only = counts_only;
    if (!info.inert) mark_dirty(ti);  // a substitution transition never fires: its sub-net does
    for (const ArrowInfo& a : info.in)
      if (!a.remote) place_watch_[n->places[static_cast<std::size_t>(a.place)]->id()].push_back(ti);
  }
}

namespace {
// The live programs of one state (in its context): a C++ call of a script method on an instance finds
// the program that runs the instance's state there (dispatch). Expired entries are swept on registering.
struct StatePrograms {
  std::vector<std::weak_ptr<ProgramImpl>> programs;
};
}  // namespace

void ProgramImpl::register_program() {
  {
    auto& all = state_.context().get_or_emplace<StatePrograms>().programs;
    std::erase_if(all, [](const auto& w) { return w.expired(); });
    all.push_back(weak_self_);
  }
  if (!counted_) {  // from now on a user of its classes (release_uses)
    std::lock_guard lock(users_mutex);
    for (const MetaInstance* m : used_classes_) ++users()[m];
    for (const MetaType* t : used_enums_) ++users()[t];
    counted_ = true;
  }
}

Value ProgramImpl::dispatch(const std::weak_ptr<ProgramImpl>& weak, int fi, const std::string& fname,
                            SimStateInstance& self, std::span<const Value> args) {
  if (std::shared_ptr<ProgramImpl> p = weak.lock(); p && &p->state_ == &self.state())
    return p->call_from_cpp(fi, self, args);
  // Another program runs this instance's state with the same classes (a replica's, or the program that
  // attached again after this one went): its function of the same name.
  std::shared_ptr<ProgramImpl> other;
  if (const auto* live = self.state().context().find<StatePrograms>())
    for (const auto& w : live->programs) {
      std::shared_ptr<ProgramImpl> q = w.lock();
      if (!q) continue;
      for (const auto& [decl, m] : q->scope_meta_)
        if (m == &self.meta()) other = q;
    }
  if (!other)
    throw Error("no SOML++ program runs the state of " + self.meta().name() + " #" +
                std::to_string(self.id()) + " (its program was unloaded, or the state was never attached)");
  for (std::size_t i = 0; i < other->image().functions.size(); ++i)
    if (other->image().functions[i]->name == fname)
      return other->call_from_cpp(static_cast<int>(i), self, args);
  throw Error("the SOML++ program that runs " + self.meta().name() + " #" + std::to_string(self.id()) +
              " has no function " + fname);
}

Value ProgramImpl::call_from_cpp(int fi, SimStateInstance& self, std::span<const Value> args) {
  const Function& f = *image().functions[static_cast<std::size_t>(fi)];
  if (static_cast<int>(args.size()) != f.nparams)
    throw Error("SOML++ function " + f.name + " takes " + std::to_string(f.nparams) + " arguments, " +
                std::to_string(args.size()) + " given");
  std::vector<Val> v(args.size());
  std::vector<std::string> s(args.size());
  std::vector<VecReg> vs(args.size());
  std::vector<Value> xs(args.size());
  for (std::size_t i = 0; i < args.size(); ++i) {
    const Value& a = args[i];
    const MetaType* t = a.type();
    if (t == nullptr)
      throw Error("SOML++ function " + f.name + ": argument " + std::to_string(i + 1) + " is empty");
    switch (f.param_kinds[i]) {
      case RK::I:
        if (t->kind() == TypeKind::Bool)
          v[i].i = a.as<bool>() ? 1 : 0;
        else if (t->kind() == TypeKind::Enum || t->kind() == TypeKind::Int || t->kind() == TypeKind::UInt)
          v[i].i = t->load_integer(a.data());
        else
          throw Error("SOML++ function " + f.name + ": argument " + std::to_string(i + 1) +
                      " must be an integer, not " + t->name());
        break;
      case RK::D:
        v[i].d = a.convert_to(meta_type<double>()).as<double>();
        break;
      case RK::S:
        if (t->kind() != TypeKind::String)
          throw Error("SOML++ function " + f.name + ": argument " + std::to_string(i + 1) +
                      " must be a string, not " + t->name());
        s[i] = a.as<std::string>();
        break;
      case RK::R: {
        if (!t->is_reference() || t->is_ref_list())
          throw Error("SOML++ function " + f.name + ": argument " + std::to_string(i + 1) +
                      " must be a reference, not " + t->name());
        const SimStateInstance* o = static_cast<const RefBase*>(a.data())->get();
        v[i].id = o != nullptr ? o->id() : 0;
        break;
      }
      case RK::V: {
        const MetaType* want = i < f.locals.size() ? f.locals[i].type.meta : nullptr;  // params come first
        if (want == nullptr || !detail::same_definition(*t, *want))
          throw Error("SOML++ function " + f.name + ": argument " + std::to_string(i + 1) + " must be a " +
                      (want != nullptr ? want->name() : std::string("vector")) + ", not " + t->name());
        vector_load(*t, a.data(), vs[i]);
        break;
      }
      case RK::X: {  // a struct or a vector of structs or enums: the same type (run-time ones by definition)
        const MetaType* want = i < f.locals.size()  // params come first
                                   ? storage_type(*this, state_.environment().registry(), f.locals[i].type)
                                   : nullptr;
        if (want == nullptr || !detail::same_definition(*t, *want))
          throw Error("SOML++ function " + f.name + ": argument " + std::to_string(i + 1) + " must be a " +
                      (want != nullptr ? want->name() : std::string("value")) + ", not " + t->name());
        xs[i] = t == want ? a : Value(*want, a.data());
        break;
      }
      default:
        throw Error("SOML++ function " + f.name + ": unsupported argument type");
    }
  }
  std::string sres;
  VecReg vres;
  Value xres;
  const Val r = run(fi, self.id(), 0, v.data(), s.data(), &sres, vs.data(), &vres, xs.data(), &xres);
  switch (f.result_type.kind) {
    case K::Bool:
      return Value(r.i != 0);
    case K::Int:
      return Value(r.i);
    case K::Double:
      return Value(r.d);
    case K::String:
      return Value(std::move(sres));
    case K::Enum: {
      const MetaType* et =
          f.result_type.enum_decl != nullptr ? enums_.at(f.result_type.enum_decl) : f.result_type.meta;
      Value e(*et);
      std::memcpy(e.data(), &r.i, std::min<std::size_t>(et->size(), 8));
      return e;
    }
    case K::Ref: {
      SimStateInstance* o = r.id == 0 ? nullptr : state_.find(r.id);
      return Value(SharedRef<Node>(o != nullptr ? o->as<Node>() : nullptr));
    }
    case K::Vector:
      if (f.result == RK::X) return xres;
      return vector_value(*f.result_type.meta, vres, "the result of " + f.name);
    case K::Struct:
      return xres;
    default:
      return {};
  }
}

// ---- Program ----

Program::Program(std::shared_ptr<ProgramImpl> impl) : impl_(std::move(impl)) {}
Program::~Program() {
  // A debugger may outlive the program (a server's, attached to every program it saw): it is told, and
  // from then on refuses its calls instead of reading freed memory.
  if (impl_ && impl_->debug_ != nullptr) impl_->debug_->on_program_gone();
}

std::unique_ptr<Program> Program::load(SimState& state, std::string name, std::string text,
                                       RunOptions options) {
  auto impl = std::make_shared<ProgramImpl>(state, options);
  impl->weak_self_ = impl;
  impl->rng_ = options.seed == 0 ? 0x9E3779B97F4A7C15ULL : options.seed;
  impl->load_or_undo(std::move(name), std::move(text));
  impl->register_program();
  return std::unique_ptr<Program>(new Program(std::move(impl)));
}

std::unique_ptr<Program> Program::attach(SimState& state, std::string name, std::string text,
                                         RunOptions options) {
  auto impl = std::make_shared<ProgramImpl>(state, options);
  impl->weak_self_ = impl;
  impl->attaching_ = true;
  impl->load_or_undo(std::move(name), std::move(text));
  impl->register_program();
  return std::unique_ptr<Program>(new Program(std::move(impl)));
}

Node& Program::root() const noexcept { return *impl_->root_; }

Node* Program::object(std::string_view name) const {
  for (const auto& [decl, id] : impl_->object_ids_)
    if (decl->kind == DeclKind::Object && decl->name == name && decl->parent != nullptr &&
        decl->parent->kind == DeclKind::Script) {
      SimStateInstance* o = impl_->state_.find(id);
      return o != nullptr ? o->as<Node>() : nullptr;
    }
  return nullptr;
}

Place* Program::place(std::string_view name, const Node* owner) const {
  const Node* o = owner != nullptr ? owner : impl_->root_;
  const NetInst* n = impl_->net_of(o->id());
  if (n == nullptr) return nullptr;
  for (std::size_t i = 0; i < n->places.size(); ++i)  // the net's own places before sub-nets' ones
    if (n->cls->places[i]->name == name && n->cls->place_holder[i] < 0) return n->places[i];
  for (std::size_t i = 0; i < n->places.size(); ++i)
    if (n->cls->places[i]->name == name) return n->places[i];
  return nullptr;
}

std::vector<Place*> Program::places() const {
  std::vector<Place*> all;
  for (const NetInst* n : impl_->net_order_)
    if (!n->dead) all.insert(all.end(), n->places.begin(), n->places.end());
  return all;
}

const MetaInstance* Program::script_class(std::string_view name) const {
  for (const auto& [decl, ci] : impl_->image().class_info)
    if (decl->name == name && decl->kind != DeclKind::Script) return ci->meta;
  return nullptr;
}

std::uint64_t Program::step(std::uint64_t n) { return impl_->step(n); }
std::uint64_t Program::run_until_quiet(std::uint64_t limit) { return impl_->step(limit); }
bool Program::enabled_any() {
  const bool any = impl_->refresh();
  impl_->sync_state();
  return any;
}
bool Program::fire(const Transition& transition) { return impl_->fire_chosen(transition); }
std::uint64_t Program::firings() const noexcept { return impl_->firings_; }
void Program::on_firing(std::function<void(const Firing&)> fn) { impl_->trace_ = std::move(fn); }
std::size_t Program::watched_properties() const noexcept { return impl_->deps_map_.size(); }
std::size_t Program::executor_entries() const noexcept { return impl_->tis_.size(); }
std::uint64_t Program::condition_tests() const noexcept { return impl_->tests_; }
std::string Program::disassemble() const { return soml::disassemble(impl_->image()); }

const std::vector<std::string>& Program::condition_errors() const noexcept {
  return impl_->condition_errors_;
}

}  // namespace vsd::soml
