#include "vsd/core/registry.hpp"

#include <algorithm>
#include <unordered_set>

#include "vsd/core/database.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/extension.hpp"
#include "vsd/core/node.hpp"
#include "vsd/core/reference.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/core/type_builder.hpp"

namespace vsd {

namespace detail {
bool auto_register(const MetaInstance& meta) noexcept {
  try {
    Registry::global().add(meta);
    return true;
  } catch (...) {
    return false;  // a name clash is reported again, as an Error, by an explicit add()
  }
}
}  // namespace detail

Registry& Registry::global() {
  // Never destroyed: static objects of any translation unit may still look classes up at exit.
  static Registry& registry = *new Registry;
  return registry;
}

Registry::Registry() {
  // Built-in value types and core classes are always known by name.
  for (const MetaType* t : {&meta_type<bool>(),
                            &meta_type<std::int8_t>(),
                            &meta_type<std::int16_t>(),
                            &meta_type<std::int32_t>(),
                            &meta_type<std::int64_t>(),
                            &meta_type<std::uint8_t>(),
                            &meta_type<std::uint16_t>(),
                            &meta_type<std::uint32_t>(),
                            &meta_type<std::uint64_t>(),
                            &meta_type<float>(),
                            &meta_type<double>(),
                            &meta_type<std::string>(),
                            &meta_type<Eigen::Vector2d>(),
                            &meta_type<Eigen::Vector3d>(),
                            &meta_type<Eigen::Vector4d>(),
                            &meta_type<Eigen::Quaterniond>(),
                            &meta_type<Eigen::Isometry3d>(),
                            &meta_type<std::vector<bool>>(),
                            &meta_type<std::vector<std::int32_t>>(),
                            &meta_type<std::vector<std::int64_t>>(),
                            &meta_type<std::vector<double>>(),
                            &meta_type<std::vector<std::string>>(),
                            &meta_type<std::vector<Eigen::Vector3d>>()})
    add_type_locked(*t);
  for (const MetaInstance* c :
       {&Instance::static_meta(), &SimStateInstance::static_meta(), &NamedModelInstance::static_meta(),
        &Node::static_meta(), &Extension::static_meta(), &Database::static_meta(), &SimState::static_meta(),
        &Environment::static_meta()})
    add_locked(*c);
}

Registry::~Registry() {
  // Subclasses before their bases (a run-time class unlinks itself from its base), and classes before
  // the types their properties' default values use: the reverse of the order of definition.
  while (!runtime_classes_.empty()) runtime_classes_.pop_back();
  while (!runtime_types_.empty()) runtime_types_.pop_back();
}

void Registry::add(const MetaInstance& cls) {
  std::unique_lock lock(mutex_);
  add_locked(cls);
}

namespace {
// Room for one more element, growing geometrically (reserve(size() + 1) reallocates every time: defining
// n classes or types one by one cost n^2 moves).
template <class V>
void room_for_one(V& v) {
  if (v.size() == v.capacity()) v.reserve(std::max<std::size_t>(16, 2 * v.size()));
}

// The part of a full class name after the last "::" (the whole name when it has none).
std::string_view short_name(std::string_view full) {
  const std::size_t sep = full.rfind("::");
  return sep == std::string_view::npos ? full : full.substr(sep + 2);
}

// A full name is "Name" or "ns::Name" (namespaces may nest): no empty part.
void check_class_name(const std::string& name) {
  bool bad = name.empty();
  for (std::size_t from = 0; !bad;) {
    const std::size_t sep = name.find("::", from);
    const std::size_t end = sep == std::string::npos ? name.size() : sep;
    bad = end == from;
    if (sep == std::string::npos) break;
    from = sep + 2;
  }
  if (bad) detail::throw_error("'" + name + "' is not a class name (Name or namespace::Name)");
}
}  // namespace

void Registry::index_locked(const MetaInstance& cls) {
  const std::string_view s = short_name(cls.name());
  if (s.size() != cls.name().size()) short_names_[std::string(s)].push_back(&cls);
}

void Registry::unindex_locked(const MetaInstance& cls) {
  auto it = short_names_.find(std::string(short_name(cls.name())));
  if (it == short_names_.end()) return;
  std::erase(it->second, &cls);
  if (it->second.empty()) short_names_.erase(it);
}

void Registry::add_locked(const MetaInstance& cls) {
  if (auto it = classes_.find(cls.name()); it != classes_.end()) {
    if (it->second != &cls)
      detail::throw_error("class name '" + cls.name() + "' is already registered for another class");
    return;
  }
  // All or nothing: check every type before anything is registered.
  check_class_name(cls.name());
  for (const MetaProperty* p : cls.own_properties()) check_type_locked(p->type());
  short_names_.reserve(short_names_.size() + 1);
  classes_.emplace(cls.name(), &cls);
  index_locked(cls);
  for (const MetaProperty* p : cls.own_properties()) add_type_locked(p->type());
}

void Registry::check_type_locked(const MetaType& type) const {
  if (auto it = types_.find(type.name());
      it != types_.end() && it->second != &type && !same_reference(*it->second, type))
    detail::throw_error("type name '" + type.name() + "' is already registered for another type");
  if (type.element() != nullptr) check_type_locked(*type.element());
  for (const auto& f : type.fields()) check_type_locked(*f.type);
}

bool Registry::same_reference(const MetaType& a, const MetaType& b) noexcept {
  // Reference types are made per C++ class and on demand for run-time classes: two objects of one name
  // are the same type when kind and target agree.
  return a.is_reference() && a.kind() == b.kind() && a.target() == b.target();
}

void Registry::add(const MetaType& type) {
  std::unique_lock lock(mutex_);
  check_type_locked(type);
  add_type_locked(type);
}

void Registry::add_type_locked(const MetaType& type) {
  types_.emplace(type.name(), &type);  // checked before: an existing entry is this type or its equal
  if (type.element() != nullptr) add_type_locked(*type.element());
  for (const auto& f : type.fields()) add_type_locked(*f.type);
}

const MetaInstance* Registry::find_class(std::string_view name) const {
  std::shared_lock lock(mutex_);
  return find_class_locked(name);
}

const MetaInstance* Registry::find_class_locked(std::string_view name) const {
  if (auto it = classes_.find(std::string(name)); it != classes_.end()) return it->second;
  if (name.find("::") != std::string_view::npos) return nullptr;  // a full name: no other way to find it
  auto it = short_names_.find(std::string(name));
  if (it == short_names_.end()) return nullptr;
  if (it->second.size() == 1) return it->second.front();
  std::vector<std::string> names;
  for (const MetaInstance* c : it->second) names.push_back("'" + c->name() + "'");
  std::sort(names.begin(), names.end());
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  detail::throw_error("class name '" + std::string(name) + "' is ambiguous: it may be " + list +
                      " (use the full name)");
}

const MetaInstance* Registry::find_class_exact(std::string_view name) const {
  std::shared_lock lock(mutex_);
  auto it = classes_.find(std::string(name));
  return it == classes_.end() ? nullptr : it->second;
}

const MetaInstance& Registry::get_class(std::string_view name) const {
  if (const MetaInstance* c = find_class(name)) return *c;
  detail::throw_error("unknown class '" + std::string(name) + "'");
}

const MetaType* Registry::find_type(std::string_view name) const {
  std::shared_lock lock(mutex_);
  auto it = types_.find(std::string(name));
  return it == types_.end() ? nullptr : it->second;
}

const MetaType& Registry::get_type(std::string_view name) {
  if (const MetaType* t = find_type(name)) return *t;
  static constexpr std::pair<std::string_view, TypeKind> kinds[] = {
      {"ref<", TypeKind::Ref},
      {"shared<", TypeKind::SharedRef},
      {"list<", TypeKind::RefList},
      {"shared_list<", TypeKind::SharedRefList}};
  for (const auto& [prefix, kind] : kinds) {
    if (name.size() > prefix.size() + 1 && name.substr(0, prefix.size()) == prefix && name.back() == '>') {
      const auto cls = name.substr(prefix.size(), name.size() - prefix.size() - 1);
      return reference_type(kind, get_class(cls));
    }
  }
  constexpr std::string_view vector_prefix = "vector<";
  if (name.size() > vector_prefix.size() + 1 && name.substr(0, vector_prefix.size()) == vector_prefix &&
      name.back() == '>') {
    // Each level below is a call: a name nested deeper than any type may be is refused before.
    std::size_t levels = 0;
    for (std::string_view rest = name; levels <= MetaType::max_depth && rest.starts_with(vector_prefix);
         rest.remove_prefix(vector_prefix.size()))
      ++levels;
    if (levels > MetaType::max_depth)
      detail::throw_error("unknown type '" + std::string(name.substr(0, 60)) +
                          "...': vectors nest deeper than " + std::to_string(MetaType::max_depth) +
                          " levels");
    const MetaType* element = nullptr;
    try {
      element = &get_type(name.substr(vector_prefix.size(), name.size() - vector_prefix.size() - 1));
    } catch (const Error&) {
    }
    // Only a run-time element: a C++ element's vector is the C++ type, registered with its class.
    if (element != nullptr && element->cpp_tag() == nullptr && !element->is_reference())
      return vector_type(*element);
  }
  detail::throw_error("unknown type '" + std::string(name) + "'");
}

const MetaType& Registry::reference_type(TypeKind kind, const MetaInstance& target) {
  std::string prefix;
  switch (kind) {
    case TypeKind::Ref:
      prefix = "ref";
      break;
    case TypeKind::SharedRef:
      prefix = "shared";
      break;
    case TypeKind::RefList:
      prefix = "list";
      break;
    case TypeKind::SharedRefList:
      prefix = "shared_list";
      break;
    default:
      detail::throw_error("reference_type: not a reference kind");
  }
  const std::string name = prefix + "<" + target.name() + ">";
  std::unique_lock lock(mutex_);
  if (auto it = types_.find(name); it != types_.end()) return *it->second;
  const bool single = kind == TypeKind::Ref || kind == TypeKind::SharedRef;
  auto t = std::make_unique<MetaType>(name, kind, single ? sizeof(RefBase) : sizeof(RefListBase),
                                      single ? alignof(RefBase) : alignof(RefListBase),
                                      single ? detail::ref_ops : detail::ref_list_ops);
  t->set_target(&target);
  const MetaType& ref = *t;
  runtime_types_.push_back(std::move(t));
  types_.emplace(name, &ref);
  return ref;
}

std::vector<const MetaInstance*> Registry::classes() const {
  std::shared_lock lock(mutex_);
  std::vector<const MetaInstance*> out;
  for (const auto& [n, c] : classes_) out.push_back(c);
  std::sort(out.begin(), out.end(), [](auto* a, auto* b) { return a->name() < b->name(); });
  return out;
}

std::vector<const MetaType*> Registry::types() const {
  std::shared_lock lock(mutex_);
  std::vector<const MetaType*> out;
  for (const auto& [n, t] : types_) out.push_back(t);
  std::sort(out.begin(), out.end(), [](auto* a, auto* b) { return a->name() < b->name(); });
  return out;
}

const MetaInstance& Registry::define(std::unique_ptr<MetaInstance> cls) {
  std::unique_lock lock(mutex_);
  if (classes_.count(cls->name()) != 0)
    detail::throw_error("class name '" + cls->name() + "' is already registered");
  check_class_name(cls->name());
  // A base must outlive its subclasses: a built-in class (never destroyed) or one of this registry's.
  if (const MetaInstance* base = cls->base(); base != nullptr && base->is_runtime() && !owns_locked(*base))
    detail::throw_error("run-time class '" + cls->name() + "' derives from run-time class '" + base->name() +
                        "' of another registry; define both in the same registry");
  for (const MetaProperty* p : cls->own_properties()) check_type_locked(p->type());
  room_for_one(runtime_classes_);  // nothing below may fail half way
  short_names_.reserve(short_names_.size() + 1);
  owned_classes_.insert(cls.get());
  cls->link_to_base();
  const MetaInstance& ref = *cls;
  classes_.emplace(ref.name(), &ref);
  index_locked(ref);
  for (const MetaProperty* p : ref.own_properties()) add_type_locked(p->type());
  runtime_classes_.push_back(std::move(cls));
  return ref;
}

bool Registry::owns_locked(const MetaInstance& cls) const noexcept { return owned_classes_.contains(&cls); }

void Registry::undefine(const MetaInstance& cls) {
  std::unique_lock lock(mutex_);
  if (!cls.is_runtime()) detail::throw_error("built-in class '" + cls.name() + "' cannot be undefined");
  if (cls.live_instances() != 0)
    detail::throw_error("class '" + cls.name() + "' still has " + std::to_string(cls.live_instances()) +
                        " instance(s)");
  if (!cls.derived().empty()) detail::throw_error("class '" + cls.name() + "' still has subclasses");
  auto it = std::find_if(runtime_classes_.begin(), runtime_classes_.end(),
                         [&](auto& p) { return p.get() == &cls; });
  if (it == runtime_classes_.end())
    detail::throw_error("class '" + cls.name() + "' is not defined in this registry");
  // A property of another class that references cls would be left pointing at nothing.
  for (const auto& [name, other] : classes_) {
    if (other == &cls) continue;
    for (const MetaProperty* p : other->own_properties())
      if (p->type().is_reference() && p->type().target() == &cls)
        detail::throw_error("class '" + cls.name() + "' is still referenced by property '" + other->name() +
                            "::" + p->name() + "'");
  }
  std::erase_if(types_, [&](const auto& entry) {
    return entry.second->is_reference() && entry.second->target() == &cls;
  });
  std::erase_if(runtime_types_, [&](const auto& t) { return t->target() == &cls; });
  classes_.erase(cls.name());
  unindex_locked(cls);
  owned_classes_.erase(&cls);
  runtime_classes_.erase(it);  // ~MetaInstance unlinks it from its base
}

void Registry::add_methods(const MetaInstance& cls, ClassBuilder&& from) {
  std::unique_lock lock(mutex_);
  if (!cls.is_runtime()) detail::throw_error("built-in class '" + cls.name() + "' cannot be given methods");
  if (!owns_locked(cls)) detail::throw_error("class '" + cls.name() + "' is not defined in this registry");
  if (!from.meta_) detail::throw_error("add_methods: the ClassBuilder was used up");
  auto& target = const_cast<MetaInstance&>(cls);  // this registry owns it
  std::vector<std::unique_ptr<MetaMethod>> fresh;
  for (auto& m : from.meta_->own_methods_) {
    auto same = std::find_if(target.own_methods_.begin(), target.own_methods_.end(),
                             [&](const auto& x) { return x->name() == m->name(); });
    if (same == target.own_methods_.end()) {
      fresh.push_back(std::move(m));
    } else if ((*same)->result() != m->result() || (*same)->arguments() != m->arguments()) {
      detail::throw_error("class '" + cls.name() + "' has method " + (*same)->signature() + ", not " +
                          m->signature());
    }
  }
  from.meta_.reset();
  if (fresh.empty()) return;
  for (auto& m : fresh) target.add_method(std::move(m));
  // finish() copies the base's method list into each subclass: redo it down the hierarchy.
  std::vector<MetaInstance*> todo{&target};
  while (!todo.empty()) {
    MetaInstance* m = todo.back();
    todo.pop_back();
    m->finish();
    for (const MetaInstance* d : m->derived()) todo.push_back(const_cast<MetaInstance*>(d));
  }
}

void Registry::rename(const MetaInstance& cls, std::string name) {
  std::unique_lock lock(mutex_);
  if (!cls.is_runtime()) detail::throw_error("built-in class '" + cls.name() + "' cannot be renamed");
  if (!owns_locked(cls)) detail::throw_error("class '" + cls.name() + "' is not defined in this registry");
  if (name == cls.name()) return;
  if (classes_.count(name) != 0) detail::throw_error("class name '" + name + "' is already registered");
  check_class_name(name);
  for (const auto& t : runtime_types_)
    if (t->target() == &cls)
      detail::throw_error("class '" + cls.name() + "' cannot be renamed: type '" + t->name() + "' names it");
  short_names_.reserve(short_names_.size() + 1);
  classes_.reserve(classes_.size() + 1);
  auto& m = const_cast<MetaInstance&>(cls);  // the Registry owns it (checked above)
  unindex_locked(cls);
  classes_.erase(cls.name());
  m.name_ = std::move(name);
  classes_.emplace(cls.name(), &cls);
  index_locked(cls);
}

}  // namespace vsd

namespace vsd {

namespace {
// True when values of @p t contain values of @p part (through struct fields and vector elements).
bool uses(const MetaType& t, const MetaType& part) {
  if (&t == &part) return true;
  if (t.element() != nullptr && uses(*t.element(), part)) return true;
  for (const auto& f : t.fields())
    if (uses(*f.type, part)) return true;
  return false;
}
// A vector (of vectors ...) of @p part, which get_type made on demand.
bool vector_of(const MetaType& t, const MetaType& part) {
  if (t.kind() != TypeKind::Vector || t.cpp_tag() != nullptr) return false;
  return t.element() == &part || vector_of(*t.element(), part);
}
}  // namespace

const MetaType& Registry::define(std::unique_ptr<MetaType> type) {
  std::unique_lock lock(mutex_);
  if (type->is_reference()) detail::throw_error("define: reference types are made by the Registry itself");
  if (type->name().empty()) detail::throw_error("define: a type needs a name");
  if (types_.count(type->name()) != 0)
    detail::throw_error("type name '" + type->name() + "' is already registered for another type");
  if (type->element() != nullptr) check_type_locked(*type->element());
  for (const auto& f : type->fields()) check_type_locked(*f.type);
  room_for_one(runtime_types_);  // nothing below may fail half way
  const MetaType& ref = *type;
  add_type_locked(ref);  // with the types of its fields or elements, so that files find them by name
  runtime_types_.push_back(std::move(type));
  return ref;
}

bool Registry::owns(const MetaType& type) const {
  std::shared_lock lock(mutex_);
  return !type.is_reference() && std::any_of(runtime_types_.begin(), runtime_types_.end(),
                                             [&](const auto& t) { return t.get() == &type; });
}

const MetaType& Registry::vector_type(const MetaType& element) {
  const std::string name = "vector<" + element.name() + ">";
  {
    std::shared_lock lock(mutex_);
    if (auto it = types_.find(name); it != types_.end()) return *it->second;
  }
  if (element.cpp_tag() != nullptr)
    detail::throw_error("unknown type '" + name +
                        "': the vector of a C++ type is known once a class uses it");
  auto t = detail::make_runtime_vector(element);
  std::unique_lock lock(mutex_);
  if (auto it = types_.find(name); it != types_.end()) return *it->second;  // made meanwhile
  room_for_one(runtime_types_);
  const MetaType& ref = *t;
  types_.emplace(name, &ref);
  runtime_types_.push_back(std::move(t));
  return ref;
}

void Registry::undefine(const MetaType& type) {
  std::unique_lock lock(mutex_);
  auto owned = [&](const MetaType& t) {
    return std::any_of(runtime_types_.begin(), runtime_types_.end(),
                       [&](const auto& p) { return p.get() == &t; });
  };
  if (type.is_reference() || !owned(type))
    detail::throw_error("type '" + type.name() + "' is not a run-time type of this registry");
  for (const auto& [name, cls] : classes_)
    for (const MetaProperty* p : cls->own_properties())
      if (uses(p->type(), type))
        detail::throw_error("type '" + type.name() + "' is still used by property '" + cls->name() +
                            "::" + p->name() + "'");
  std::vector<const MetaType*> vectors;
  for (const auto& [name, t] : types_) {
    if (t == &type) continue;
    if (vector_of(*t, type)) {
      vectors.push_back(t);
    } else if (t->kind() != TypeKind::Vector && uses(*t, type)) {  // (a vector of a user: that user is named)
      detail::throw_error("type '" + type.name() + "' is still used by type '" + t->name() + "'");
    }
  }
  vectors.push_back(&type);
  for (const MetaType* t : vectors) types_.erase(t->name());
  std::erase_if(runtime_types_, [&](const auto& p) {
    return std::find(vectors.begin(), vectors.end(), p.get()) != vectors.end();
  });
}

void Registry::undefine_all(std::span<const MetaInstance* const> classes,
                            std::span<const MetaType* const> types) {
  std::unique_lock lock(mutex_);
  // The candidates: the given run-time classes and types of this registry, with the reference types of
  // those classes and the vectors of those types (made on demand, they go with what they are made of).
  std::unordered_set<const MetaInstance*> cls;
  for (const MetaInstance* c : classes)
    if (c != nullptr && owns_locked(*c)) cls.insert(c);
  std::unordered_set<const MetaType*> typ;
  for (const MetaType* t : types)
    if (t != nullptr && !t->is_reference()) typ.insert(t);
  auto innermost = [](const MetaType* t) {
    while (t->kind() == TypeKind::Vector && t->cpp_tag() == nullptr && t->element() != nullptr)
      t = t->element();
    return t;
  };
  std::unordered_set<const MetaType*> owned_types;
  for (const auto& t : runtime_types_) owned_types.insert(t.get());
  std::erase_if(typ, [&](const MetaType* t) { return !owned_types.contains(t); });
  for (const auto& t : runtime_types_) {
    if (t->is_reference() ? cls.contains(t->target())
                          : t.get() != innermost(t.get()) && typ.contains(innermost(t.get())))
      typ.insert(t.get());
  }
  // What is kept, and what a kept one uses (a worklist: each candidate is kept at most once).
  std::unordered_set<const void*> kept;
  std::vector<const void*> todo;
  auto keep = [&](const void* x) {
    if ((cls.contains(static_cast<const MetaInstance*>(x)) ||
         typ.contains(static_cast<const MetaType*>(x))) &&
        kept.insert(x).second)
      todo.push_back(x);
  };
  // A value type's parts (and a reference type's target) that are candidates.
  auto keep_parts = [&](const MetaType& t) {
    if (t.is_reference()) {
      keep(&t);
      keep(t.target());
      return;
    }
    keep(&t);
    if (t.element() != nullptr) keep(t.element());
    for (const auto& f : t.fields()) keep(f.type);
  };
  for (const MetaInstance* c : cls) {
    if (c->live_instances() != 0) keep(c);
    for (const MetaInstance* d : c->derived())
      if (!cls.contains(d)) keep(c);
  }
  for (const auto& [name, c] : classes_)
    if (!cls.contains(c))
      for (const MetaProperty* p : c->own_properties()) keep_parts(p->type());
  for (const auto& [name, t] : types_)
    if (!typ.contains(t) && !t->is_reference()) keep_parts(*t);
  while (!todo.empty()) {
    const void* x = todo.back();
    todo.pop_back();
    if (const auto* c = static_cast<const MetaInstance*>(x); cls.contains(c)) {
      keep(c->base());
      for (const MetaProperty* p : c->own_properties()) keep_parts(p->type());
    } else {
      const auto* t = static_cast<const MetaType*>(x);
      if (t->is_reference()) keep(t->target());
      if (t->element() != nullptr) keep(t->element());
      for (const auto& f : t->fields()) keep(f.type);
    }
  }
  // Remove the rest: classes before the types their properties use, each list in one pass in the reverse
  // order of definition (subclasses before their bases).
  auto gone = [&](const void* x) { return !kept.contains(x); };
  for (auto it = runtime_classes_.rbegin(); it != runtime_classes_.rend(); ++it) {
    const MetaInstance* c = it->get();
    if (!cls.contains(c) || !gone(c)) continue;
    classes_.erase(c->name());
    unindex_locked(*c);
    owned_classes_.erase(c);
    it->reset();  // ~MetaInstance unlinks it from its base
  }
  std::erase(runtime_classes_, nullptr);
  for (auto it = runtime_types_.rbegin(); it != runtime_types_.rend(); ++it) {
    const MetaType* t = it->get();
    if (!typ.contains(t) || !gone(t)) continue;
    types_.erase(t->name());
    it->reset();
  }
  std::erase(runtime_types_, nullptr);
}

}  // namespace vsd
