// Binary snapshots (see vsd/io/snapshot.hpp). A load reads and checks the file into a Transaction
// bundle and applies it: the target SimState's own dry run then makes the load all or nothing.
#include "vsd/io/snapshot.hpp"

#include <algorithm>
#include <deque>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "vsd/core/bytes.hpp"
#include "vsd/core/detail/tx_codec.hpp"
#include "vsd/io/file.hpp"

namespace vsd::io {

namespace {

constexpr std::uint8_t magic[4] = {'V', 'S', 'D', 'S'};
constexpr std::uint8_t format_version = 1;
constexpr std::uint8_t kind_state = 0;
constexpr std::uint8_t kind_subtree = 1;

bool is_saved(const MetaProperty& p) { return p.has(Savable) && !p.has(Transient); }

void write_framed(ByteWriter& w, const std::vector<std::uint8_t>& value) {
  w.fixed(static_cast<std::uint32_t>(value.size()));
  w.raw(value.data(), value.size());
}

// ---- writing ----------------------------------------------------------------------------------------------

class SnapshotWriter {
 public:
  SnapshotWriter(std::vector<const SimStateInstance*> members, SaveReport* report)
      : members_(std::move(members)), report_(report) {
    for (const SimStateInstance* x : members_) member_set_.insert(x);
  }

  std::vector<std::uint8_t> write(std::uint8_t kind, const std::vector<Id>& top) {
    for (const SimStateInstance* x : members_) class_index(x->meta());
    std::vector<std::uint8_t> out;
    ByteWriter w(out);
    for (const std::uint8_t b : magic)
      w.u8(b);  // (w.raw into the empty vector trips a GCC 12 false positive)
    w.u8(format_version);
    w.u8(kind);
    w.varint(classes_.size());
    for (const MetaInstance* c : classes_) write_class(w, *c);
    w.varint(members_.size());
    std::vector<std::uint8_t> value;
    for (const SimStateInstance* x : members_) {
      w.varint(x->id());
      w.varint(class_index(x->meta()));
      for (const MetaProperty* p : x->meta().properties()) {
        if (!is_saved(*p)) continue;
        value.clear();
        ByteWriter vw(value);
        write_value(vw, *x, *p);
        write_framed(w, value);
      }
    }
    w.varint(top.size());
    for (Id id : top) w.varint(id);
    if (report_ != nullptr) report_->instances = members_.size();
    return out;
  }

 private:
  std::size_t class_index(const MetaInstance& c) {
    if (auto it = index_.find(&c); it != index_.end()) return it->second;
    if (c.is_runtime()) class_index(*c.base());  // a run-time base is defined before its subclasses
    index_.emplace(&c, classes_.size());
    classes_.push_back(&c);
    return classes_.size() - 1;
  }

  static void write_class(ByteWriter& w, const MetaInstance& c) {
    w.string(c.name());
    w.u8(c.is_runtime() ? 1 : 0);
    if (c.is_runtime()) {
      w.string(c.base()->name());
      w.u8(c.is_abstract() ? 1 : 0);
      const auto own = c.own_properties();
      w.varint(own.size());
      std::vector<std::uint8_t> value;
      for (const MetaProperty* p : own) {
        w.string(p->name());
        w.string(p->type().name());
        w.fixed(p->flags().bits());
        value.clear();
        ByteWriter vw(value);
        p->type().write_bytes(p->default_value().data(), vw);
        write_framed(w, value);
      }
    }
    std::size_t saved = 0;
    for (const MetaProperty* p : c.properties()) saved += is_saved(*p) ? 1 : 0;
    w.varint(saved);
    for (const MetaProperty* p : c.properties()) {
      if (!is_saved(*p)) continue;
      w.string(p->name());
      w.string(p->type().name());
    }
  }

  Id member_id(const SimStateInstance* t) {
    if (t == nullptr) return null_id;
    if (member_set_.count(t) != 0) return t->id();
    if (report_ != nullptr) ++report_->cut_references;
    return null_id;
  }

  void write_value(ByteWriter& w, const SimStateInstance& x, const MetaProperty& p) {
    const void* at = p.address(x);
    if (p.type().is_ref_list()) {
      const auto& list = *static_cast<const RefListBase*>(at);
      std::vector<Id> ids;
      for (std::size_t i = 0; i < list.size(); ++i)
        if (const Id id = member_id(list.at(i)); id != null_id) ids.push_back(id);
      w.varint(ids.size());
      for (Id id : ids) w.varint(id);
    } else if (p.type().is_reference()) {
      w.varint(member_id(static_cast<const RefBase*>(at)->get()));
    } else {
      p.type().write_bytes(at, w);
    }
  }

  std::vector<const SimStateInstance*> members_;
  std::unordered_set<const SimStateInstance*> member_set_;
  std::vector<const MetaInstance*> classes_;
  std::unordered_map<const MetaInstance*, std::size_t> index_;
  SaveReport* report_;
};

// ---- reading ----------------------------------------------------------------------------------------------

struct Slot {
  const MetaProperty* prop = nullptr;  // null: the class has no such property any more
  const MetaType* file_type = nullptr;
  bool convert = false;  // a number whose type changed: converted value by value
};

struct ClassEntry {
  const MetaInstance* cls = nullptr;
  std::vector<Slot> slots;
};

struct SavedValue {
  const Slot* slot;
  std::size_t offset;                   // of the frame in the file, for messages
  std::span<const std::uint8_t> bytes;  // the value in the property's type: in the file, or converted
  std::uint32_t ids_first = 0;          // reference targets (file ids): ids_[ids_first, + ids_count)
  std::uint32_t ids_count = 0;
};

struct SavedInstance {
  Id id;
  const ClassEntry* entry;
  std::size_t offset;
  std::size_t first;  // its values are values_[first, first + count)
  std::size_t count;
};

class SnapshotReader {
 public:
  SnapshotReader(Registry& registry, std::span<const std::uint8_t> bytes, std::string_view origin)
      : registry_(registry), in_(bytes.data(), bytes.size()), origin_(origin) {}

  ~SnapshotReader() {
    if (!committed_)  // a failed load leaves no class behind either
      for (auto it = defined_.rbegin(); it != defined_.rend(); ++it) {
        try {
          registry_.undefine(**it);
        } catch (const Error&) {  // still in use elsewhere: keep it
        }
      }
  }

  void read() {
    try {
      read_all();
    } catch (const Error& e) {  // errors of the byte reader itself carry the offset but not the file
      const std::string msg = e.what();
      if (msg.rfind(std::string(origin_) + ":", 0) == 0) throw;
      throw Error(std::string(origin_) + ": " + msg);
    }
  }

  void read_all() {
    std::uint8_t head[4];
    in_.raw(head, 4);
    if (!std::equal(head, head + 4, magic)) fail_at(0, "not a vsd snapshot (no VSDS header)");
    const std::uint8_t version = in_.u8();
    if (version != format_version)
      fail_at(4, "snapshot format version " + std::to_string(version) + " is not supported (this is " +
                     std::to_string(format_version) + ")");
    kind_ = in_.u8();
    if (kind_ != kind_state && kind_ != kind_subtree)
      fail_at(5, "unknown snapshot kind " + std::to_string(kind_));
    const std::size_t nclasses = in_.size_prefix(2);
    classes_.reserve(nclasses);
    for (std::size_t i = 0; i < nclasses; ++i) classes_.push_back(read_class());
    const std::size_t ninstances = in_.size_prefix(2);
    instances_.reserve(ninstances);
    for (std::size_t i = 0; i < ninstances; ++i) instances_.push_back(read_instance());
    index();
    const std::size_t ntop = in_.size_prefix(1);
    for (std::size_t i = 0; i < ntop; ++i) {
      const std::size_t at = in_.position();
      const Id id = in_.varint();
      auto it = by_id_.find(id);
      if (it == by_id_.end())
        fail_at(at, "top-level node #" + std::to_string(id) + " is not in the snapshot");
      if (!it->second->entry->cls->is_a(Node::static_meta()))
        fail_at(at, "top-level #" + std::to_string(id) + " is not a Node");
      top_.push_back(id);
    }
    if (!in_.at_end())
      fail_at(in_.position(), std::to_string(in_.remaining()) + " unexpected bytes after the snapshot");
    for (const SavedInstance& x : instances_)
      for (const SavedValue& v : values_of(x))
        for (Id id : ids_of(v))
          if (id != null_id && by_id_.count(id) == 0)
            fail_at(v.offset, "dangling reference: #" + std::to_string(x.id) + "." + v.slot->prop->name() +
                                  " names #" + std::to_string(id) + ", which is not in the snapshot");
  }

  // Builds the bundle that creates the snapshot's instances in @p state, under @p parent (nullptr: the
  // state must be empty and a whole-state snapshot restores its Database's values and children too).
  LoadReport apply(SimState& state, Node* parent) {
    LoadReport report;
    const bool whole = parent == nullptr;
    if (whole && (state.size() != 1 || !state.database().children().empty()))
      throw Error(std::string(origin_) +
                  ": loading a snapshot as a whole state needs an empty SimState, but '" + state.name() +
                  "' holds " + std::to_string(state.size()) + " instances");
    Environment& env = state.environment();
    // Ids: kept in an empty state, fresh under a node; the Database of a state snapshot maps to the target's.
    std::unordered_map<Id, Id> map;
    const SavedInstance* saved_root = nullptr;
    for (const SavedInstance& x : instances_) {
      if (kind_ == kind_state && x.entry->cls->is_a(Database::static_meta())) {
        saved_root = &x;
        // Loaded under a node, the file's Database *is* that node: its children become the node's, and
        // references to it point at the node.
        map[x.id] = whole ? state.database().id() : parent->id();
        continue;
      }
      if (whole) {
        if (state.find(x.id) != nullptr)
          fail_at(x.offset, "instance #" + std::to_string(x.id) + " already exists");
        env.reserve_ids_through(x.id);
        map[x.id] = x.id;
      } else {
        map[x.id] = env.next_id();
      }
    }
    auto mapped = [&](Id id) { return id == null_id ? null_id : map.at(id); };

    std::vector<std::uint8_t> bundle;
    detail::write_tx_header(bundle);
    std::size_t ops = 0;
    for (const SavedInstance& x : instances_) {
      if (&x == saved_root) continue;
      std::vector<detail::TxValue> values;
      for (const SavedValue& v : values_of(x))
        if (v.slot->prop != nullptr && detail::carried_in_payload(*v.slot->prop))
          values.emplace_back(v.slot->prop->name(), v.bytes);
      detail::write_create(bundle, mapped(x.id), x.entry->cls->name(), values);
      ++ops;
    }
    if (saved_root != nullptr && whole) {  // the Database's own values
      for (const SavedValue& v : values_of(*saved_root)) {
        if (v.slot->prop == nullptr || !detail::carried_in_payload(*v.slot->prop)) continue;
        std::vector<std::uint8_t> now;
        ByteWriter w(now);
        v.slot->prop->type().write_bytes(v.slot->prop->address(state.database()), w);
        detail::write_set(bundle, state.database().id(), v.slot->prop->name(), now, v.bytes);
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
            detail::write_list(bundle, Transaction::Op::Insert, mapped(x.id), p.name(), i, mapped(ids[i]));
            ++ops;
          }
        } else if (v.ids_count != 0 && ids_of(v).front() != null_id) {
          std::vector<std::uint8_t> null_bytes, target;
          ByteWriter(null_bytes).varint(null_id);
          ByteWriter(target).varint(mapped(ids_of(v).front()));
          detail::write_set(bundle, mapped(x.id), p.name(), null_bytes, target);
          ++ops;
        }
      }
    }
    if (kind_ == kind_subtree || !whole) {
      if (kind_ == kind_subtree) tops = top_;
      Node& into = whole ? state.database() : *parent;
      std::size_t at = into.children().size();
      for (Id id : tops) {
        detail::write_list(bundle, Transaction::Op::Insert, into.id(), Node::vsd_prop_children().name(), at++,
                           mapped(id));
        ++ops;
      }
    } else {
      tops = top_;
    }
    try {
      detail::apply_checked_values(state, detail::make_transaction(std::move(bundle), ops));
    } catch (const Error& e) {
      throw Error(std::string(origin_) + ": the snapshot does not fit SimState '" + state.name() +
                  "': " + e.what());
    }
    committed_ = true;
    report.instances = instances_.size() - (saved_root != nullptr ? 1 : 0);
    for (Id id : tops)
      if (Node* n = state.find<Node>(mapped(id))) report.roots.push_back(n);
    for (const MetaInstance* c : defined_) report.defined_classes.push_back(c->name());
    report.warnings = warnings_;
    return report;
  }

 private:
  [[noreturn]] void fail_at(std::size_t at, const std::string& what) const {
    throw Error(std::string(origin_) + ": byte " + std::to_string(at) + ": " + what);
  }
  // Runs @p f, turning a vsd::Error of a nested reader into one that names the origin.
  template <class F>
  decltype(auto) guarded(F&& f) {
    try {
      return f();
    } catch (const Error& e) {
      const std::string msg = e.what();
      if (msg.rfind(std::string(origin_) + ":", 0) == 0) throw;
      throw Error(std::string(origin_) + ": " + msg);
    }
  }

  const MetaType& type_named(std::size_t at, std::string_view name) {
    return guarded([&]() -> const MetaType& {
      try {
        return registry_.get_type(name);
      } catch (const Error&) {
        fail_at(at, "unknown type '" + std::string(name) + "'");
      }
    });
  }

  ClassEntry read_class() {
    return guarded([&] {
      const std::size_t at = in_.position();
      const std::string name = in_.string();
      const bool runtime = in_.u8() != 0;
      ClassEntry entry;
      entry.cls = registry_.find_class(name);
      if (runtime) {
        const std::string base_name = in_.string();
        const bool abstract = in_.u8() != 0;
        const std::size_t nprops = in_.size_prefix(7);
        const MetaInstance* base = registry_.find_class(base_name);
        if (entry.cls == nullptr && base == nullptr)
          fail_at(at, "class '" + name + "' derives from unknown class '" + base_name + "'");
        std::optional<ClassBuilder> builder;
        if (entry.cls == nullptr) builder.emplace(name, *base);
        for (std::size_t i = 0; i < nprops; ++i) {
          const std::string prop = in_.string();
          const std::size_t type_at = in_.position();
          const MetaType& type = type_named(type_at, in_.string_view());
          const PropertyFlags flags{in_.fixed<std::uint32_t>()};
          const std::size_t value_at = in_.position();
          const auto frame = read_frame();
          Value def(type);
          if (!type.is_reference()) decode_into(value_at, type, frame, def);
          if (builder) builder->property(prop, type, std::move(def), flags);
        }
        if (builder) {
          builder->set_abstract(abstract);
          entry.cls = &builder->define(registry_);
          defined_.push_back(entry.cls);
        }
      }
      if (entry.cls == nullptr)
        fail_at(at, "unknown class '" + name + "' (and the snapshot does not define it)");
      const std::size_t nsaved = in_.size_prefix(2);
      entry.slots.reserve(nsaved);
      for (std::size_t i = 0; i < nsaved; ++i) {
        const std::string prop = in_.string();
        const std::size_t type_at = in_.position();
        const std::string type_name = in_.string();
        Slot s;
        s.prop = entry.cls->find_property(prop);
        if (s.prop == nullptr) {
          warnings_.push_back("class '" + entry.cls->name() + "' has no property '" + prop +
                              "' any more: its saved values are dropped");
          s.file_type = registry_.find_type(type_name);  // may be unknown: the frames are skipped
        } else {
          s.file_type = &type_named(type_at, type_name);
          if (s.file_type->name() != s.prop->type().name()) {
            if (s.file_type->is_arithmetic() && s.prop->type().is_arithmetic()) {
              s.convert = true;
              warnings_.push_back("property '" + entry.cls->name() + "::" + s.prop->name() +
                                  "' changed from " + type_name + " to " + s.prop->type().name() +
                                  ": values are converted");
            } else {
              warnings_.push_back("property '" + entry.cls->name() + "::" + s.prop->name() +
                                  "' changed from " + type_name + " to " + s.prop->type().name() +
                                  ": saved values are dropped");
              s.prop = nullptr;
            }
          }
        }
        entry.slots.push_back(s);
      }
      return entry;
    });
  }

  std::span<const std::uint8_t> read_frame() {
    const auto n = in_.fixed<std::uint32_t>();
    if (n > in_.remaining())
      in_.fail("a value of " + std::to_string(n) + " bytes runs past the end of the file");
    return {in_.skip(n), n};
  }

  // Checks that a frame holds exactly one value of @p type. Plain numbers need no decoding beyond their size.
  void check_value(std::size_t frame_at, const MetaType& type, std::span<const std::uint8_t> frame) {
    const TypeKind k = type.kind();
    if (k == TypeKind::Int || k == TypeKind::UInt || k == TypeKind::Float || k == TypeKind::Double ||
        k == TypeKind::Enum || k == TypeKind::Flags) {
      if (frame.size() != type.size())
        fail_at(frame_at, "a value of type " + type.name() + " takes " + std::to_string(type.size()) +
                              " bytes, not " + std::to_string(frame.size()));
      return;
    }
    if (k == TypeKind::String) {  // checked in place: no string is built
      ByteReader r(frame.data(), frame.size());
      try {
        (void)r.string_view();
        if (!r.at_end()) r.fail(std::to_string(r.remaining()) + " unexpected bytes after the value");
      } catch (const Error& e) {
        fail_at(frame_at + 4 + r.position(), std::string("value of type string: ") + e.what());
      }
      return;
    }
    Value scratch(type);
    decode_into(frame_at, type, frame, scratch);
  }

  // Decodes one framed value of @p type (no references) into @p out, checking it is exactly one value.
  void decode_into(std::size_t frame_at, const MetaType& type, std::span<const std::uint8_t> frame,
                   Value& out) {
    ByteReader r(frame.data(), frame.size());
    try {
      type.read_bytes(out.data(), r, nullptr);
      if (!r.at_end()) r.fail(std::to_string(r.remaining()) + " unexpected bytes after the value");
    } catch (const Error& e) {
      // The nested reader counts from the frame's first byte; report file offsets.
      fail_at(frame_at + 4 + r.position(), std::string("value of type ") + type.name() + ": " + e.what());
    }
  }

  std::span<const Id> ids_of(const SavedValue& v) const {
    return std::span<const Id>(ids_).subspan(v.ids_first, v.ids_count);
  }

  std::span<const SavedValue> values_of(const SavedInstance& x) const {
    return std::span<const SavedValue>(values_).subspan(x.first, x.count);
  }

  SavedInstance read_instance() {
    return guarded([&] {
      SavedInstance x;
      x.first = values_.size();
      x.offset = in_.position();
      x.id = in_.varint();
      if (x.id == null_id) fail_at(x.offset, "instance id 0 is not valid");
      const std::size_t at = in_.position();
      const std::uint64_t c = in_.varint();
      if (c >= classes_.size())
        fail_at(at, "class index " + std::to_string(c) + " is out of the class table");
      x.entry = &classes_[c];
      for (const Slot& s : x.entry->slots) {
        const std::size_t frame_at = in_.position();
        const auto frame = read_frame();
        if (s.prop == nullptr) continue;  // reported once per class
        SavedValue v{&s, frame_at, {}, static_cast<std::uint32_t>(ids_.size()), 0};
        const MetaType& type = s.prop->type();
        if (type.is_reference()) {
          ByteReader r(frame.data(), frame.size());
          try {
            if (type.is_ref_list()) {
              const std::size_t n = r.size_prefix(1);
              for (std::size_t i = 0; i < n; ++i) {
                ids_.push_back(r.varint());
                if (ids_.back() == null_id) r.fail("a reference list cannot hold null");
              }
            } else {
              ids_.push_back(r.varint());
            }
            if (!r.at_end()) r.fail(std::to_string(r.remaining()) + " unexpected bytes after the value");
          } catch (const Error& e) {
            fail_at(frame_at + 4 + r.position(), "reference " + s.prop->name() + ": " + e.what());
          }
        } else if (s.convert) {
          Value file_value(*s.file_type);
          decode_into(frame_at, *s.file_type, frame, file_value);
          Value converted;
          try {
            converted = file_value.convert_to(type);
          } catch (const Error& e) {
            fail_at(frame_at, std::string("value of ") + s.prop->name() + ": " + e.what());
          }
          auto& owned = converted_.emplace_back();  // a deque: earlier values never move
          ByteWriter w(owned);
          type.write_bytes(converted.data(), w);
          v.bytes = owned;
        } else {
          check_value(frame_at, type, frame);
          v.bytes = frame;
        }
        v.ids_count = static_cast<std::uint32_t>(ids_.size() - v.ids_first);
        values_.push_back(v);
      }
      x.count = values_.size() - x.first;
      return x;
    });
  }

  void index() {
    for (const SavedInstance& x : instances_)
      if (!by_id_.emplace(x.id, &x).second)
        fail_at(x.offset, "instance #" + std::to_string(x.id) + " appears twice");
  }

  Registry& registry_;
  ByteReader in_;
  std::string_view origin_;
  std::uint8_t kind_ = kind_state;
  std::vector<ClassEntry> classes_;
  std::vector<SavedInstance> instances_;
  std::vector<SavedValue> values_;  // of all instances, in file order
  std::vector<Id> ids_;             // reference targets of all values
  std::deque<std::vector<std::uint8_t>> converted_;
  std::unordered_map<Id, const SavedInstance*> by_id_;
  std::vector<Id> top_;
  std::vector<const MetaInstance*> defined_;
  std::vector<std::string> warnings_;
  bool committed_ = false;
};

LoadReport load_into(SimState& state, Node* parent, std::span<const std::uint8_t> bytes,
                     std::string_view origin) {
  SnapshotReader reader(state.environment().registry(), bytes, origin);
  reader.read();
  return reader.apply(state, parent);
}

// Everything @p root holds compositely, @p root first, each once.
std::vector<const SimStateInstance*> composite_closure(const SimStateInstance& root) {
  std::vector<const SimStateInstance*> out{&root};
  std::unordered_set<const SimStateInstance*> seen{&root};
  for (std::size_t i = 0; i < out.size(); ++i) {
    for (const MetaProperty* p : out[i]->meta().reference_properties()) {
      if (!p->type().is_composite()) continue;
      auto visit = [&](const SimStateInstance* t) {
        if (t != nullptr && seen.insert(t).second) out.push_back(t);
      };
      if (p->type().is_ref_list()) {
        const auto& list = *static_cast<const RefListBase*>(p->address(*out[i]));
        for (std::size_t k = 0; k < list.size(); ++k) visit(list.at(k));
      } else {
        visit(static_cast<const RefBase*>(p->address(*out[i]))->get());
      }
    }
  }
  return out;
}

}  // namespace

std::vector<std::uint8_t> save_bytes(const SimState& state, SaveReport* report) {
  std::vector<const SimStateInstance*> members;
  for (SimStateInstance* x : state.instances()) members.push_back(x);
  if (report != nullptr) *report = SaveReport{};
  std::vector<Id> top;
  for (const Node* n : state.database().children()) top.push_back(n->id());
  return SnapshotWriter(std::move(members), report).write(kind_state, top);
}

std::vector<std::uint8_t> save_bytes(const Node& root, SaveReport* report) {
  if (report != nullptr) *report = SaveReport{};
  if (root.is_a<Database>()) return save_bytes(root.state(), report);
  return SnapshotWriter(composite_closure(root), report).write(kind_subtree, {root.id()});
}

LoadReport load_bytes(SimState& state, std::span<const std::uint8_t> bytes, std::string_view origin) {
  return load_into(state, nullptr, bytes, origin);
}

LoadReport load_bytes(Node& parent, std::span<const std::uint8_t> bytes, std::string_view origin) {
  return load_into(parent.state(), &parent, bytes, origin);
}

SaveReport save(const SimState& state, const std::filesystem::path& path) {
  SaveReport report;
  write_file_atomically(path, save_bytes(state, &report));
  return report;
}

SaveReport save(const Node& root, const std::filesystem::path& path) {
  SaveReport report;
  write_file_atomically(path, save_bytes(root, &report));
  return report;
}

LoadReport load(SimState& state, const std::filesystem::path& path) {
  return load_bytes(state, read_file(path), path.string());
}

LoadReport load(Node& parent, const std::filesystem::path& path) {
  return load_bytes(parent, read_file(path), path.string());
}

}  // namespace vsd::io
