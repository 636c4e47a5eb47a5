// The format-independent half of loading (see load_model.hpp).
#include "load_model.hpp"

#include <algorithm>
#include <optional>

#include "vsd/core/bytes.hpp"
#include "vsd/core/detail/tx_codec.hpp"

namespace vsd::io::detail {

LoadModel::~LoadModel() {
  if (committed_) return;
  for (auto it = defined_.rbegin(); it != defined_.rend(); ++it) {
    try {
      registry_.undefine(**it);
    } catch (const Error&) {  // still in use elsewhere: keep it
    }
  }
}

const MetaType& LoadModel::type_named(std::size_t at, std::string_view name) {
  try {
    return registry_.get_type(name);  // makes reference types of known classes on demand
  } catch (const Error&) {
    fail_at(at, "unknown type '" + std::string(name) + "'");
  }
}

const MetaInstance& LoadModel::resolve_class(std::size_t at, const std::string& name,
                                             const ClassDefinition* def) {
  if (const MetaInstance* known = registry_.find_class(name)) return *known;
  if (def == nullptr) fail_at(at, "unknown class '" + name + "' (and the file does not define it)");
  const MetaInstance* base = registry_.find_class(def->base);
  if (base == nullptr) fail_at(at, "class '" + name + "' derives from unknown class '" + def->base + "'");
  ClassBuilder builder(name, *base);
  for (const auto& p : def->properties) builder.property(p.name, *p.type, p.default_value, p.flags);
  builder.set_abstract(def->abstract);
  try {
    const MetaInstance& cls = builder.define(registry_);
    defined_.push_back(&cls);
    return cls;
  } catch (const Error& e) {  // e.g. a property that clashes with one of the base
    fail_at(at, "cannot define class '" + name + "': " + e.what());
  }
}

Slot LoadModel::make_slot(std::size_t at, const MetaInstance& cls, std::string_view prop,
                          std::string_view type_name) {
  Slot s;
  s.prop = cls.find_property(prop);
  if (s.prop == nullptr) {
    warnings_.push_back("class '" + cls.name() + "' has no property '" + std::string(prop) +
                        "' any more: its saved values are dropped");
    if (!type_name.empty()) s.file_type = registry_.find_type(type_name);  // may be unknown
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
    if (!by_id_.insert(x.id, i + 1)) fail_at(x.offset, "instance #" + std::to_string(x.id) + " appears twice");
    const MetaInstance& cls = *x.entry->cls;
    if (cls.is_abstract()) fail_at(x.offset, "class '" + cls.name() + "' is abstract: it has no instances");
    if (cls.is_a(Database::static_meta())) {  // a state file's root; it stands for the target's Database
      if (kind_ != kind_state || file_root_ != nullptr)
        fail_at(x.offset, "a Database is a state's root: a file holds at most one, in a whole state");
      file_root_ = &x;
    }
  }
  for (std::size_t i = 0; i < top_.size(); ++i) {
    const SavedInstance* top = find(top_[i]);
    if (top == nullptr)
      fail_at(top_offsets_[i], "top-level node #" + std::to_string(top_[i]) + " is not in the file");
    if (!top->entry->cls->is_a(Node::static_meta()))
      fail_at(top_offsets_[i], "top-level #" + std::to_string(top_[i]) + " is not a Node");
  }
  for (const SavedInstance& x : instances_)
    for (const SavedValue& v : values_of(x))
      for (Id id : ids_of(v)) {
        if (id == null_id) continue;
        const SavedInstance* it = find(id);
        if (it == nullptr)
          fail_at(v.offset, "dangling reference: #" + std::to_string(x.id) + "." + v.slot->prop->name() +
                                " names #" + std::to_string(id) + ", which is not in the file");
        const MetaInstance& target = *v.slot->prop->type().target();
        const MetaInstance& found = *it->entry->cls;
        if (!found.is_a(target))
          fail_at(v.offset, "#" + std::to_string(x.id) + "." + v.slot->prop->name() + " names #" +
                                std::to_string(id) + ", a '" + found.name() + "', which is not a '" + target.name() +
                                "'");
      }
  check_composite_cycles();
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
        fail_at(v.offset, "composite references form a cycle: " + chain);
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
  for (const MetaInstance* c : defined_) report.defined_classes.push_back(c->name());
  report.warnings = warnings_;
  return report;
}

// Builds the bundle that creates the file's instances in @p state, under @p parent (nullptr: the state
// must be empty and a whole-state file restores its Database's values and children too).
LoadReport LoadModel::apply(SimState& state, Node* parent) {
  LoadReport report;
  const bool whole = parent == nullptr;
  if (whole && (state.size() != 1 || !state.database().children().empty()))
    throw Error(std::string(origin_) + ": loading a file as a whole state needs an empty SimState, but '" +
                state.name() + "' holds " + std::to_string(state.size()) + " instances");
  Environment& env = state.environment();
  // Ids: kept in an empty state, fresh under a node; the Database of a state file maps to the target's.
  // A whole-state load keeps every id but the Database's: no map needed.
  vsd::detail::FlatIdMap<Id> map;
  const SavedInstance* saved_root = file_root_;
  Id highest = null_id;  // reserved once: each reservation makes the SimStates drop their blocks of ids
  for (const SavedInstance& x : instances_) {
    if (&x == saved_root) {
      // Loaded under a node, the file's Database *is* that node: its children become the node's, and
      // references to it point at the node.
      if (!whole) map.insert(x.id, parent->id());
      continue;
    }
    if (whole) {
      if (state.find(x.id) != nullptr) fail_at(x.offset, "instance #" + std::to_string(x.id) + " already exists");
      // (Ids of other sites never meet ours.)
      if ((x.id >> 48) == env.site()) highest = std::max(highest, x.id);
    } else {
      map.insert(x.id, env.next_id());
    }
  }
  if (highest != null_id) env.reserve_ids_through(highest);
  const Id file_database = saved_root != nullptr ? saved_root->id : null_id;
  auto mapped = [&](Id id) {
    if (id == null_id) return null_id;
    if (whole) return id == file_database ? state.database().id() : id;
    return map.find(id);
  };

  std::vector<std::uint8_t> bundle;
  vsd::detail::write_tx_header(bundle);
  std::size_t ops = 0;
  std::vector<vsd::detail::TxValue> values;
  for (const SavedInstance& x : instances_) {
    if (&x == saved_root) continue;
    values.clear();
    for (const SavedValue& v : values_of(x))
      if (v.slot->prop != nullptr && vsd::detail::carried_in_payload(*v.slot->prop))
        values.emplace_back(v.slot->prop->name(), v.bytes);
    vsd::detail::write_create(bundle, mapped(x.id), x.entry->cls->name(), values);
    ++ops;
  }
  if (saved_root != nullptr && whole) {  // the Database's own values
    for (const SavedValue& v : values_of(*saved_root)) {
      if (v.slot->prop == nullptr || !vsd::detail::carried_in_payload(*v.slot->prop)) continue;
      std::vector<std::uint8_t> now;
      ByteWriter w(now);
      v.slot->prop->type().write_bytes(v.slot->prop->address(state.database()), w);
      vsd::detail::write_set(bundle, state.database().id(), v.slot->prop->name(), now, v.bytes);
      ++ops;
    }
  }
  std::vector<Id> tops;
  for (const SavedInstance& x : instances_) {
    if (&x == saved_root && !whole) {  // under a node: the Database's children become top level
      for (const SavedValue& v : values_of(x))
        if (v.slot->prop == &Node::vsd_prop_children())
          for (Id id : ids_of(v)) tops.push_back(id);
      continue;
    }
    for (const SavedValue& v : values_of(x)) {
      if (v.slot->prop == nullptr || !v.slot->prop->type().is_reference() || v.slot->prop->has(Transient))
        continue;
      const MetaProperty& p = *v.slot->prop;
      if (p.type().is_ref_list()) {
        const auto ids = ids_of(v);
        for (std::size_t i = 0; i < ids.size(); ++i) {
          vsd::detail::write_list(bundle, Transaction::Op::Insert, mapped(x.id), p.name(), i, mapped(ids[i]));
          ++ops;
        }
      } else if (v.ids_count != 0 && ids_of(v).front() != null_id) {
        std::vector<std::uint8_t> null_bytes, target;
        ByteWriter(null_bytes).varint(null_id);
        ByteWriter(target).varint(mapped(ids_of(v).front()));
        vsd::detail::write_set(bundle, mapped(x.id), p.name(), null_bytes, target);
        ++ops;
      }
    }
  }
  if (kind_ == kind_subtree || !whole) {
    if (kind_ == kind_subtree) tops = top_;
    Node& into = whole ? state.database() : *parent;
    std::size_t at = into.children().size();
    for (Id id : tops) {
      vsd::detail::write_list(bundle, Transaction::Op::Insert, into.id(), Node::vsd_prop_children().name(), at++,
                              mapped(id));
      ++ops;
    }
  } else {
    tops = top_;
  }
  try {
    vsd::detail::apply_checked_values(state, vsd::detail::make_transaction(std::move(bundle), ops));
  } catch (const Error& e) {
    throw Error(std::string(origin_) + ": the file does not fit SimState '" + state.name() + "': " + e.what());
  }
  committed_ = true;
  report.subtree = kind_ == kind_subtree;
  report.instances = instances_.size() - (saved_root != nullptr ? 1 : 0);
  for (Id id : tops)
    if (Node* n = state.find<Node>(mapped(id))) report.roots.push_back(n);
  for (const MetaInstance* c : defined_) report.defined_classes.push_back(c->name());
  report.warnings = warnings_;
  return report;
}

}  // namespace vsd::io::detail
