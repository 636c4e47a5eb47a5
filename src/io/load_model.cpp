// The format-independent half of loading (see load_model.hpp).
#include "load_model.hpp"

#include <algorithm>
#include <optional>
#include <tuple>
#include <unordered_map>

#include "vsd/core/bytes.hpp"
#include "vsd/core/detail/state_builder.hpp"
#include "vsd/core/detail/tx_codec.hpp"

namespace vsd::io::detail {

LoadModel::~LoadModel() {
  if (committed_) return;
  // What is still in use elsewhere stays; the rest goes, in one pass however many the file defined.
  try {
    registry_.undefine_all(defined_, defined_types_);
  } catch (...) {  // out of memory: the definitions stay, as if still in use
  }
}

namespace {
// True when the program's type @p t is what @p def describes (same values, same text and binary forms).
bool matches(const MetaType& t, const TypeDefinition& def) {
  if (t.kind() != def.kind) return false;
  if (def.kind == TypeKind::Struct) {
    if (t.fields().size() != def.fields.size()) return false;
    for (std::size_t i = 0; i < def.fields.size(); ++i)
      if (t.fields()[i].name != def.fields[i].first ||
          !vsd::detail::same_definition(*t.fields()[i].type, *def.fields[i].second))
        return false;
    return true;
  }
  const bool is_unsigned =
      def.underlying != nullptr ? def.underlying->is_unsigned() : def.kind == TypeKind::Flags;
  const std::size_t size = def.underlying != nullptr ? def.underlying->size() : 4;
  if (t.size() != size || t.is_unsigned() != is_unsigned || t.enum_values().size() != def.values.size())
    return false;
  for (const auto& v : def.values) {
    std::int64_t value = 0;
    if (!t.enum_value(v.name, value) || value != v.value) return false;
  }
  return true;
}
}  // namespace

const MetaType& LoadModel::resolve_type(std::size_t at, const TypeDefinition& def) {
  if (const MetaType* known = registry_.find_type(def.name)) {
    if (!matches(*known, def))
      fail_at(at, "type '" + def.name + "' of the file clashes with this program's type '" + def.name +
                      "', which is defined differently");
    return *known;
  }
  try {
    const MetaType* t = nullptr;
    if (def.kind == TypeKind::Struct) {
      StructBuilder b(def.name);
      for (const auto& [name, type] : def.fields) b.field(name, *type);
      t = &b.define(registry_);
    } else {
      EnumBuilder b(def.name, def.kind);
      if (def.underlying != nullptr) b.underlying(*def.underlying);
      for (const auto& v : def.values) b.value(v.name, v.value);
      t = &b.define(registry_);
    }
    defined_types_.push_back(t);
    return *t;
  } catch (const Error& e) {
    fail_at(at, "cannot define type '" + def.name + "': " + e.what());
  }
}

const MetaType& LoadModel::type_named(std::size_t at, std::string_view name) {
  try {
    return registry_.get_type(name);  // makes reference types of known classes on demand
  } catch (const Error& e) {
    const std::string what = e.what();
    if (what.find("ambiguous") != std::string::npos) fail_at(at, "type '" + std::string(name) + "': " + what);
    fail_at(at, "unknown type '" + std::string(name) + "'");
  }
}

const MetaInstance& LoadModel::resolve_class(std::size_t at, const std::string& name,
                                             const ClassDefinition* def, std::span<const SavedProperty> saved) {
  // Files carry full names. A class the file defines is found by that name only; one it merely uses may
  // be given by its short name (hand-written files), unless that is ambiguous.
  const MetaInstance* known = nullptr;
  try {
    known = def != nullptr ? registry_.find_class_exact(name) : registry_.find_class(name);
  } catch (const Error& e) {
    fail_at(at, e.what());
  }
  if (known != nullptr) return *known;
  if (def == nullptr) {
    if (options_.unknown_classes == UnknownClasses::Placeholder && !saved.empty())
      return make_placeholder(at, name, saved);
    fail_at(at, "unknown class '" + name + "' (and the file does not define it)");
  }
  const MetaInstance* base = nullptr;
  try {
    base = registry_.find_class(def->base);
  } catch (const Error& e) {
    fail_at(at, e.what());
  }
  if (base == nullptr) fail_at(at, "class '" + name + "' derives from unknown class '" + def->base + "'");
  try {
    ClassBuilder builder(name, *base);
    for (const auto& p : def->properties) builder.property(p.name, *p.type, p.default_value, p.flags);
    builder.set_abstract(def->abstract);
    const MetaInstance& cls = builder.define(registry_);
    defined_.push_back(&cls);
    return cls;
  } catch (const Error& e) {  // e.g. a property that clashes with one of the base
    fail_at(at, "cannot define class '" + name + "': " + e.what());
  }
}

namespace {

// "ref<X>", "shared<X>", "list<X>", "shared_list<X>": the kind and X; nullopt for other type names.
std::optional<std::pair<TypeKind, std::string_view>> reference_type_name(std::string_view type) {
  static constexpr std::pair<std::string_view, TypeKind> kinds[] = {{"ref<", TypeKind::Ref},
                                                                     {"shared<", TypeKind::SharedRef},
                                                                     {"list<", TypeKind::RefList},
                                                                     {"shared_list<", TypeKind::SharedRefList}};
  if (!type.ends_with('>')) return std::nullopt;
  for (const auto& [prefix, kind] : kinds)
    if (type.starts_with(prefix))
      return std::pair{kind, type.substr(prefix.size(), type.size() - prefix.size() - 1)};
  return std::nullopt;
}

}  // namespace

// A stand-in for a class nobody defines, from the saved properties the file lists. Its base: the class of
// this program whose saved properties the list starts with — same names, same types, same order, as a save
// writes a class's properties, its bases' first (a user's Robot derived from Node lists name, extensions
// and children first: its stand-in is a Node). The longest such prefix wins; of classes that fit equally
// well, vsd's core classes (Node, Extension, ...) come before a module's (whose listeners would take the
// stand-in for one of theirs), then the more derived class (an Extension, not a NamedModelInstance), then
// the first name. The Database is never a base: a state has one.
const MetaInstance& LoadModel::make_placeholder(std::size_t at, const std::string& name,
                                                std::span<const SavedProperty> saved) {
  auto depth = [](const MetaInstance* c) {
    std::size_t d = 0;
    for (; c != nullptr; c = c->base()) ++d;
    return d;
  };
  auto is_core = [](const MetaInstance* c) { return !c->is_runtime() && c->name().find("::") == std::string::npos; };
  auto rank = [&](const MetaInstance* c, std::size_t prefix) { return std::tuple(prefix, is_core(c), depth(c)); };
  const MetaInstance* base = &SimStateInstance::static_meta();
  std::size_t base_saved = 0;
  for (const MetaInstance* c : registry_.classes()) {
    if (!c->is_a(SimStateInstance::static_meta()) || c->is_a(Database::static_meta())) continue;
    std::size_t n = 0;
    bool fits = true;
    for (const MetaProperty* p : c->properties()) {
      if (!is_saved(*p)) continue;
      if (n >= saved.size() || saved[n].name != p->name() || saved[n].type != p->type().name()) {
        fits = false;
        break;
      }
      ++n;
    }
    if (!fits) continue;
    const auto mine = rank(c, n), theirs = rank(base, base_saved);
    if (mine > theirs || (mine == theirs && c->name() < base->name())) {
      base = c;
      base_saved = n;
    }
  }
  std::vector<std::string> left_out;
  try {
    ClassBuilder builder(name, *base);
    for (const SavedProperty& p : saved) {
      if (base->find_property(p.name) != nullptr) continue;
      const MetaType* type = nullptr;
      if (const auto ref = reference_type_name(p.type)) {
        // A reference to a class this program knows keeps its type; to one it does not, it holds any
        // instance (the target's stand-in may not be made yet).
        const MetaInstance* target = nullptr;
        try {
          target = registry_.find_class(ref->second);
        } catch (const Error&) {  // an ambiguous short name: any instance
        }
        type = &registry_.reference_type(ref->first, target != nullptr ? *target : SimStateInstance::static_meta());
      } else {
        try {
          type = &registry_.get_type(p.type);
        } catch (const Error&) {
          left_out.push_back(std::string(p.name) + " (of unknown type " + std::string(p.type) + ")");
          continue;
        }
      }
      builder.property(std::string(p.name), *type);
    }
    const MetaInstance& cls = builder.define(registry_);
    defined_.push_back(&cls);
    placeholders_.push_back(&cls);
    std::string what = "class '" + name + "' is not known to this program: its instances are shown through a "
                       "stand-in derived from " + base->name() + " with the file's saved values";
    if (!left_out.empty()) {
      what += "; left out:";
      for (const std::string& l : left_out) what += " " + l;
    }
    warnings_.push_back(what);
    return cls;
  } catch (const Error& e) {  // a property name that is not an identifier, say
    fail_at(at, "unknown class '" + name + "', and no stand-in can be made for it: " + e.what());
  }
}

Slot LoadModel::make_slot(std::size_t at, const MetaInstance& cls, std::string_view prop,
                          std::string_view type_name) {
  Slot s;
  s.prop = cls.find_property(prop);
  const bool placeholder = std::find(placeholders_.begin(), placeholders_.end(), &cls) != placeholders_.end();
  if (placeholder) {  // made from this very list: the file's types are its types (or it was left out)
    if (s.prop != nullptr) s.file_type = &s.prop->type();
    return s;
  }
  if (s.prop == nullptr) {
    warnings_.push_back("class '" + cls.name() + "' has no property '" + std::string(prop) +
                        "' any more: its saved values are dropped");
    if (!type_name.empty()) s.file_type = registry_.find_type(type_name);  // may be unknown
    return s;
  }
  if (!s.prop->has(Savable) || s.prop->has(Transient)) {
    // A load gives exactly what a save writes: values of a property this program does not save (a file
    // made elsewhere, or by hand) are dropped, so that saving the loaded state loses nothing it holds.
    warnings_.push_back("property '" + cls.name() + "::" + s.prop->name() +
                        "' is not saved by this program (not Savable, or Transient): its values are dropped");
    if (!type_name.empty()) s.file_type = registry_.find_type(type_name);  // may be unknown
    s.prop = nullptr;
    return s;
  }
  if (type_name.empty()) {  // the file does not say: read as today's type
    s.file_type = &s.prop->type();
    return s;
  }
  s.file_type = &type_named(at, type_name);
  if (s.file_type->name() == s.prop->type().name()) return s;
  const std::string what = "property '" + cls.name() + "::" + s.prop->name() + "' changed from " +
                           std::string(type_name) + " to " + s.prop->type().name();
  if (s.file_type->is_arithmetic() && s.prop->type().is_arithmetic()) {
    s.convert = true;
    warnings_.push_back(what + ": values are converted");
  } else {
    warnings_.push_back(what + ": saved values are dropped");
    s.prop = nullptr;
  }
  return s;
}

std::span<const std::uint8_t> LoadModel::own(std::span<const std::uint8_t> bytes) {
  constexpr std::size_t chunk = std::size_t{1} << 16;
  if (arena_.empty() || arena_.back().capacity() - arena_.back().size() < bytes.size())
    arena_.emplace_back().reserve(std::max(chunk, bytes.size()));
  auto& into = arena_.back();  // reserved: inserting never reallocates, earlier spans stay valid
  const std::size_t at = into.size();
  into.insert(into.end(), bytes.begin(), bytes.end());
  return {into.data() + at, bytes.size()};
}

void LoadModel::finish() {
  for (std::size_t i = 0; i < instances_.size(); ++i) {
    const SavedInstance& x = instances_[i];
    if (!by_id_.insert(x.id, i + 1))
      fail_at(x.offset, "instance #" + std::to_string(x.id) + " appears twice");
    const MetaInstance& cls = *x.entry->cls;
    if (cls.is_abstract()) fail_at(x.offset, "class '" + cls.name() + "' is abstract: it has no instances");
    if (cls.is_a(Database::static_meta())) {  // a state file's root; it stands for the target's Database
      if (kind_ != kind_state || file_root_ != nullptr)
        fail_at(x.offset, "a Database is a state's root: a file holds at most one, in a whole state");
      file_root_ = &x;
    }
  }
  for (const SavedInstance& x : instances_)
    for (const SavedValue& v : values_of(x))
      for (Id id : ids_of(v)) {
        if (id == null_id) continue;
        const SavedInstance* it = find(id);
        if (it == nullptr)
          fail_at(offset_of(x, v), "dangling reference: #" + std::to_string(x.id) + "." +
                                       v.slot->prop->name() + " names #" + std::to_string(id) +
                                       ", which is not in the file");
        const MetaInstance& target = *v.slot->prop->type().target();
        const MetaInstance& found = *it->entry->cls;
        if (!found.is_a(target))
          fail_at(offset_of(x, v), "#" + std::to_string(x.id) + "." + v.slot->prop->name() + " names #" +
                                       std::to_string(id) + ", a '" + found.name() + "', which is not a '" +
                                       target.name() + "'");
      }
  check_one_parent();
  check_composite_cycles();
  check_top();
}

// A node has one parent and an extension one owner: each is listed once in all the children lists (all
// the extensions lists) of the file together. The second listing is the error.
void LoadModel::check_one_parent() const {
  const MetaProperty& children = Node::vsd_prop_children();
  const MetaProperty& extensions = NamedModelInstance::vsd_prop_extensions();
  vsd::detail::FlatIdMap<std::size_t> first;  // listed id -> index of its first holder in instances_ + 1
  for (std::size_t i = 0; i < instances_.size(); ++i) {
    const SavedInstance& x = instances_[i];
    for (const SavedValue& v : values_of(x)) {
      if (v.slot->prop != &children && v.slot->prop != &extensions) continue;
      const auto ids = ids_of(v);
      for (std::size_t k = 0; k < ids.size(); ++k) {
        if (first.insert(ids[k], i + 1)) continue;
        const bool node = v.slot->prop == &children;
        const SavedInstance& other = instances_[first.find(ids[k]) - 1];
        fail_at(
            list_element_at(offset_of(x, v), k),
            std::string(node ? "node #" : "extension #") + std::to_string(ids[k]) +
                (&other == &x ? " is listed twice in #" + std::to_string(x.id) + "." + v.slot->prop->name()
                              : std::string(node ? " is already a child of #" : " is already attached to #") +
                                    std::to_string(other.id) + ": #" + std::to_string(x.id) + "." +
                                    v.slot->prop->name() + " lists it too") +
                (node ? " (a node has one parent)" : " (an extension has one owner)"));
      }
    }
  }
}

namespace {
std::string id_list(std::span<const Id> ids) {
  std::string out = "[";
  for (std::size_t i = 0; i < ids.size(); ++i) out += (i == 0 ? "#" : ", #") + std::to_string(ids[i]);
  return out + "]";
}
}  // namespace

// The top-level nodes. A state file with a Database: they are its children, and "top" (redundant) must
// list exactly those. Otherwise (a subtree, or a state file without a Database) "top" names them: each
// once, a Node of the file that no other instance of the file holds compositely, since a load attaches it.
void LoadModel::check_top() {
  std::unordered_map<Id, std::size_t> listed;  // top-level id -> index in top_
  for (std::size_t i = 0; i < top_.size(); ++i) {
    const SavedInstance* top = find(top_[i]);
    if (top == nullptr)
      fail_at(top_offsets_[i], "top-level node #" + std::to_string(top_[i]) + " is not in the file");
    if (!top->entry->cls->is_a(Node::static_meta()))
      fail_at(top_offsets_[i], "top-level #" + std::to_string(top_[i]) + " is not a Node");
    if (!listed.emplace(top_[i], i).second)
      fail_at(top_offsets_[i], "top-level node #" + std::to_string(top_[i]) + " is listed twice");
  }
  if (kind_ == kind_state && file_root_ != nullptr) {
    std::span<const Id> children;
    for (const SavedValue& v : values_of(*file_root_))
      if (v.slot->prop == &Node::vsd_prop_children()) children = ids_of(v);
    roots_.assign(children.begin(), children.end());
    if (!has_top_) return;
    for (std::size_t i = 0; i < std::max(top_.size(), children.size()); ++i) {
      if (i < top_.size() && i < children.size() && top_[i] == children[i]) continue;
      fail_at(i < top_.size() ? top_offsets_[i] : top_at_,
              "\"top\" " + id_list(top_) + " is not what the Database #" + std::to_string(file_root_->id) +
                  " holds as its children " + id_list(children));
    }
    return;
  }
  if (kind_ == kind_subtree && top_.empty()) fail_at(top_at_, "a subtree file names its root in \"top\"");
  roots_ = top_;
  if (listed.empty()) return;
  for (const SavedInstance& x : instances_)
    for (const SavedValue& v : values_of(x)) {
      if (!v.slot->prop->type().is_composite()) continue;
      for (Id id : ids_of(v))
        if (listed.count(id) != 0)
          fail_at(offset_of(x, v), "top-level node #" + std::to_string(id) + " is held by #" +
                                       std::to_string(x.id) + "." + v.slot->prop->name() +
                                       ": a load attaches it, so nothing in the file may hold it");
    }
}

// Composite references must form a forest: a depth-first walk that meets an instance still on its path has
// found a cycle, reported where the closing reference was written.
void LoadModel::check_composite_cycles() const {
  enum : std::uint8_t { unvisited, on_path, done };
  std::vector<std::uint8_t> mark(instances_.size(), unvisited);
  struct Frame {
    std::size_t inst, value, id;
  };
  std::vector<Frame> path;
  auto index_of = [&](Id id) { return by_id_.find(id) - 1; };  // present: finish() checked
  for (std::size_t root = 0; root < instances_.size(); ++root) {
    if (mark[root] != unvisited) continue;
    mark[root] = on_path;
    path.push_back({root, 0, 0});
    while (!path.empty()) {
      Frame& f = path.back();
      const auto values = values_of(instances_[f.inst]);
      if (f.value == values.size()) {
        mark[f.inst] = done;
        path.pop_back();
        continue;
      }
      const SavedValue& v = values[f.value];
      const auto ids = ids_of(v);
      if (!v.slot->prop->type().is_composite() || f.id == ids.size()) {
        ++f.value;
        f.id = 0;
        continue;
      }
      const Id id = ids[f.id++];
      if (id == null_id) continue;
      const std::size_t next = index_of(id);
      if (mark[next] == on_path) {
        std::string chain = "#" + std::to_string(instances_[f.inst].id);
        auto from = std::find_if(path.begin(), path.end(), [&](const Frame& p) { return p.inst == next; });
        for (bool first = true; from != path.end(); ++from, first = false)
          chain += (first ? " holds #" : ", which holds #") + std::to_string(instances_[from->inst].id);
        fail_at(offset_of(instances_[f.inst], v), "composite references form a cycle: " + chain);
      }
      if (mark[next] == unvisited) {
        mark[next] = on_path;
        path.push_back({next, 0, 0});
      }
    }
  }
}

LoadReport LoadModel::summary() const {
  LoadReport report;
  report.subtree = kind_ == kind_subtree;
  report.instances = instances_.size() - (file_root_ != nullptr ? 1 : 0);  // the Database is not added
  for (const MetaInstance* c : defined_)
    if (std::find(placeholders_.begin(), placeholders_.end(), c) == placeholders_.end())
      report.defined_classes.push_back(c->name());
  for (const MetaInstance* c : placeholders_) report.placeholder_classes.push_back(c->name());
  for (const MetaType* t : defined_types_) report.defined_types.push_back(t->name());
  report.version = version_;
  report.warnings = warnings_;
  return report;
}

// Fills @p state with the model: under @p parent, or (nullptr) as the whole of an empty state.
//
// What a bundle's dry run used to check is checked here, before the first change: the model itself has
// been checked by finish() (unique ids, references that name instances of the file of the right class,
// no null in a list, no composite cycle, the top-level nodes), and what depends on the target state is
// checked below (each class may live in it, kept ids are free). The build then cannot fail on the
// file's account; it does what applying the bundle did, in the same order (creates with their values,
// the Database's own values, references, the top-level nodes attached), so the same signals fire and a
// recording state records the same changes.
LoadReport LoadModel::apply(SimState& state, Node* parent) {
  const bool whole = parent == nullptr;
  if (whole && (state.size() != 1 || !state.database().children().empty()))
    throw Error(std::string(origin_) + ": loading a file as a whole state needs an empty SimState, but '" +
                state.name() + "' holds " + std::to_string(state.size()) + " instances");
  Environment& env = state.environment();
  const SavedInstance* saved_root = file_root_;

  // ---- checks against the state; nothing changes before they pass ----
  std::vector<std::pair<const MetaInstance*, std::size_t>> per_class;  // instances to make, by class
  Id highest = null_id;
  for (const SavedInstance& x : instances_) {
    if (&x == saved_root) continue;  // stands for the target's Database, or for the node loaded under
    const MetaInstance& cls = *x.entry->cls;
    if (per_class.empty() || per_class.back().first != &cls) {
      auto it =
          std::find_if(per_class.begin(), per_class.end(), [&](const auto& e) { return e.first == &cls; });
      if (it == per_class.end()) {
        try {
          vsd::detail::StateBuilder::check_class(state, cls);
        } catch (const Error& e) {
          fail_at(x.offset, "instance #" + std::to_string(x.id) + ": " + e.what());
        }
        per_class.emplace_back(&cls, 0);
      } else {
        std::rotate(it, it + 1, per_class.end());  // the current class last: files group instances by class
      }
    }
    ++per_class.back().second;
    if (whole) {
      // The state is empty but for its Database: a kept id can only clash with the Database's.
      if (x.id == state.database().id())
        fail_at(x.offset, "instance #" + std::to_string(x.id) + " already exists in SimState '" +
                              state.name() + "' (its Database)");
      if ((x.id >> 48) == env.site())
        highest = std::max(highest, x.id);  // ids of other sites never meet ours
    }
  }
  // Ids: kept in an empty state (the counter moves past them: reserved once, since each reservation makes
  // the SimStates drop their blocks of ids), fresh under a node.
  if (highest != null_id) env.reserve_ids_through(highest);

  // ---- the build ----
  vsd::detail::StateBuilder build(state);
  std::size_t creates = 0;
  for (const auto& [cls, n] : per_class) creates += n;
  if (creates >= 64) {  // one reservation instead of growing step by step (small loads: not worth it)
    build.reserve_ids(creates);
    for (const auto& [cls, n] : per_class) build.reserve(*cls, n);
  }
  // The links of all list elements in one block (a million elements: one allocation, not a million).
  std::size_t links = roots_.size();
  for (const SavedInstance& x : instances_)
    for (const SavedValue& v : values_of(x))
      if (v.slot->prop != nullptr && v.slot->prop->type().is_ref_list()) links += v.ids_count;
  if (links >= 64) build.reserve_links(links);
  // made[i]: what instances_[i] became. The file's Database is the target's Database, or the node loaded
  // under (its children become the node's and references to it point at the node).
  BigVector<SimStateInstance*> made(instances_.size(), nullptr);
  for (std::size_t i = 0; i < instances_.size(); ++i) {
    const SavedInstance& x = instances_[i];
    if (&x == saved_root) {
      made[i] = whole ? static_cast<SimStateInstance*>(&state.database()) : parent;
      continue;
    }
    SimStateInstance& obj = build.make(*x.entry->cls, whole ? x.id : env.next_id());
    for (const SavedValue& v : values_of(x)) {
      if (v.slot->prop == nullptr || !vsd::detail::carried_in_payload(*v.slot->prop)) continue;
      // Initial values, not changes; checked by the reader, so they read back without fail.
      ByteReader r(v.data, v.size);
      v.slot->prop->type().read_bytes(const_cast<void*>(v.slot->prop->address(obj)), r, nullptr);
    }
    made[i] = &obj;
    build.finish_create(obj);
  }
  // A listener may delete what the load made; that is reported (the load stops there), not dereferenced.
  // (One dispatch spans the build: a deleted instance stays allocated until the builder is done.)
  auto live = [&](std::size_t i) -> SimStateInstance& {
    SimStateInstance* x = made[i];
    if (VSD_UNLIKELY(x->is_being_deleted()))
      throw Error(std::string(origin_) + ": instance #" + std::to_string(x->id()) +
                  " was deleted by a listener while the file was loaded into SimState '" + state.name() +
                  "'; what came before was loaded");
    return *x;
  };
  auto index_of = [&](Id id) { return by_id_.find(id) - 1; };  // present: finish() checked
  if (saved_root != nullptr && whole) {                        // the Database's own values
    Database& db = state.database();
    for (const SavedValue& v : values_of(*saved_root)) {
      if (v.slot->prop == nullptr || !vsd::detail::carried_in_payload(*v.slot->prop)) continue;
      const MetaProperty& p = *v.slot->prop;
      Value now(p.type());
      ByteReader r(v.data, v.size);
      p.type().read_bytes(now.data(), r, nullptr);
      p.assign_raw(db, now.data());
    }
  }
  struct One final : RefResolver {  // resolves the one id a single reference's bytes hold
    SimStateInstance* target = nullptr;
    SimStateInstance* resolve(Id) const override { return target; }
  };
  for (std::size_t i = 0; i < instances_.size(); ++i) {
    const SavedInstance& x = instances_[i];
    if (&x == saved_root && !whole) continue;  // under a node: the Database's children are roots_
    for (const SavedValue& v : values_of(x)) {
      if (v.slot->prop == nullptr || !v.slot->prop->type().is_reference()) continue;
      const MetaProperty& p = *v.slot->prop;
      if (p.type().is_ref_list()) {
        for (Id id : ids_of(v)) build.append(live(i), p, live(index_of(id)));
      } else if (v.ids_count != 0 && ids_of(v).front() != null_id) {
        One one;
        one.target = &live(index_of(ids_of(v).front()));
        std::vector<std::uint8_t> bytes;
        ByteWriter(bytes).varint(one.target->id());
        Value now(p.type());
        ByteReader r(bytes.data(), bytes.size());
        p.type().read_bytes(now.data(), r, &one);
        p.assign_raw(live(i), now.data());
      }
    }
  }
  // The top-level nodes are attached, except in a whole-state load of a file with a Database: that restored
  // the Database's own children list above.
  if (!whole || saved_root == nullptr) {
    Node& into = whole ? state.database() : *parent;
    if (into.is_being_deleted())
      throw Error(
          std::string(origin_) + ": node #" + std::to_string(into.id()) +
          " was deleted by a listener while the file was loaded into it; what came before was loaded");
    for (Id id : roots_) build.append(into, Node::vsd_prop_children(), live(index_of(id)));
  }
  committed_ = true;
  LoadReport report;
  report.subtree = kind_ == kind_subtree;
  report.instances = instances_.size() - (saved_root != nullptr ? 1 : 0);
  for (Id id : roots_)
    if (SimStateInstance* n = made[index_of(id)]; !n->is_being_deleted())
      report.roots.push_back(n->as<Node>());
  for (const MetaInstance* c : defined_)
    if (std::find(placeholders_.begin(), placeholders_.end(), c) == placeholders_.end())
      report.defined_classes.push_back(c->name());
  for (const MetaInstance* c : placeholders_) report.placeholder_classes.push_back(c->name());
  for (const MetaType* t : defined_types_) report.defined_types.push_back(t->name());
  report.version = version_;
  report.warnings = warnings_;
  return report;
}

}  // namespace vsd::io::detail
