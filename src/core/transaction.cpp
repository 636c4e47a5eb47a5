// Transaction bundles: encoding, parsing, inversion, and applying with an all-or-nothing check first.
#include "vsd/core/transaction.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <unordered_map>
#include <unordered_set>

#include "vsd/core/bytes.hpp"
#include "vsd/core/detail/tx_codec.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"

namespace vsd {

namespace detail {

namespace {
constexpr std::uint8_t magic[4] = {'V', 'S', 'D', 'T'};
constexpr std::size_t header_size = tx_header_size;

// Writes a value framed by a 4-byte length, so that readers can skip or check it without its type.
void write_framed(std::vector<std::uint8_t>& out, const MetaType& type, const void* value) {
  const std::size_t at = out.size();
  out.resize(at + 4);
  ByteWriter w(out);
  type.write_bytes(value, w);
  const auto n = static_cast<std::uint32_t>(out.size() - at - 4);
  std::memcpy(out.data() + at, &n, 4);
}

std::span<const std::uint8_t> read_framed(ByteReader& r) {
  const auto n = r.fixed<std::uint32_t>();
  if (n > r.remaining()) r.fail("a value of " + std::to_string(n) + " bytes runs past the end of the bundle");
  return {r.skip(n), n};
}
}  // namespace

bool carried_in_payload(const MetaProperty& p) noexcept {
  return !p.type().is_reference() && !p.has(Transient);
}

void write_tx_header(std::vector<std::uint8_t>& out) {
  out.insert(out.end(), std::begin(magic), std::end(magic));
  out.push_back(Transaction::format_version);
}

void write_lifecycle(std::vector<std::uint8_t>& out, Transaction::Op op, const SimStateInstance& inst) {
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(op));
  w.varint(inst.id());
  w.string(inst.meta().name());
  std::size_t n = 0;
  for (const MetaProperty* p : inst.meta().properties()) n += carried_in_payload(*p) ? 1 : 0;
  w.varint(n);
  for (const MetaProperty* p : inst.meta().properties()) {
    if (!carried_in_payload(*p)) continue;
    w.string(p->name());
    write_framed(out, p->type(), p->address(inst));
  }
}

namespace {
std::uint8_t* put_varint(std::uint8_t* d, std::uint64_t v) noexcept {  // ByteWriter::varint's encoding
  while (v >= 0x80) {
    *d++ = static_cast<std::uint8_t>(v | 0x80);
    v >>= 7;
  }
  *d++ = static_cast<std::uint8_t>(v);
  return d;
}

std::uint8_t* put_framed_fixed(std::uint8_t* d, const TypeOps& ops, const void* value) noexcept {
  const auto n = static_cast<std::uint32_t>(ops.fixed_bytes);
  std::memcpy(d, &n, 4);
  ops.write_fixed(value, d + 4);
  return d + 4 + n;
}
}  // namespace

// The hot path of a recording SimState: one set per setter call. Values of a fixed binary size (numbers,
// frames, ...) are framed in one step into space grown once; the bytes are those of the general path below.
void write_set(std::vector<std::uint8_t>& out, const SimStateInstance& inst, const MetaProperty& p,
               const void* old_value, const void* new_value) {
  const TypeOps& ops = p.type().ops();
  if (ops.write_fixed != nullptr) {
    constexpr std::size_t max_varint = 10;
    const std::string_view name = p.name();
    const std::size_t at = out.size();
    out.resize(at + 1 + 2 * max_varint + name.size() + 2 * (4 + ops.fixed_bytes));
    std::uint8_t* d = out.data() + at;
    *d++ = static_cast<std::uint8_t>(Transaction::Op::Set);
    d = put_varint(d, inst.id());
    d = put_varint(d, name.size());
    std::memcpy(d, name.data(), name.size());
    d = put_framed_fixed(d + name.size(), ops, old_value);
    d = put_framed_fixed(d, ops, new_value);
    out.resize(static_cast<std::size_t>(d - out.data()));
    return;
  }
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(Transaction::Op::Set));
  w.varint(inst.id());
  w.string(p.name());
  write_framed(out, p.type(), old_value);
  write_framed(out, p.type(), new_value);
}

void write_list(std::vector<std::uint8_t>& out, Transaction::Op op, Id holder, const MetaProperty& p,
                std::size_t index, Id target) {
  write_list(out, op, holder, p.name(), index, target);
}

void write_list(std::vector<std::uint8_t>& out, Transaction::Op op, Id holder, std::string_view prop,
                std::size_t index, Id target) {
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(op));
  w.varint(holder);
  w.string(prop);
  w.varint(index);
  w.varint(target);
}

namespace {
void write_span_framed(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> s) {
  ByteWriter w(out);
  w.fixed(static_cast<std::uint32_t>(s.size()));
  w.raw(s.data(), s.size());
}
}  // namespace

void write_create(std::vector<std::uint8_t>& out, Id id, std::string_view cls,
                  std::span<const TxValue> values) {
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(Transaction::Op::Create));
  w.varint(id);
  w.string(cls);
  w.varint(values.size());
  for (const auto& [name, bytes] : values) {
    w.string(name);
    write_span_framed(out, bytes);
  }
}

void write_set(std::vector<std::uint8_t>& out, Id id, std::string_view prop,
               std::span<const std::uint8_t> old_value, std::span<const std::uint8_t> new_value) {
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(Transaction::Op::Set));
  w.varint(id);
  w.string(prop);
  write_span_framed(out, old_value);
  write_span_framed(out, new_value);
}

Transaction make_transaction(std::vector<std::uint8_t> bytes, std::size_t ops) {
  Transaction t;
  t.bytes_ = std::move(bytes);
  t.ops_ = ops;
  return t;
}

}  // namespace detail
}  // namespace vsd

namespace vsd {
namespace detail {

TxParser::TxParser(const Transaction& t) : bytes_(&t.bytes()), pos_(t.bytes().empty() ? 0 : header_size) {}

bool TxParser::next(TxOp& op) {
  const auto& b = *bytes_;
  if (pos_ >= b.size()) return false;
  ByteReader r(b.data(), b.size());
  r.skip(pos_);
  op.offset = r.position();
  op.values.clear();
  const std::uint8_t code = r.u8();
  if (code < 1 || code > 5) r.fail_at(op.offset, "unknown operation code " + std::to_string(code));
  op.op = static_cast<Transaction::Op>(code);
  op.id = r.varint();
  op.name = r.string_view();
  switch (op.op) {
    case Transaction::Op::Create:
    case Transaction::Op::Delete: {
      const std::size_t n = r.size_prefix(6);  // a name and a frame take at least 6 bytes
      for (std::size_t i = 0; i < n; ++i) {
        const auto name = r.string_view();
        op.values.emplace_back(name, read_framed(r));
      }
      break;
    }
    case Transaction::Op::Set:
      op.old_value = read_framed(r);
      op.new_value = read_framed(r);
      break;
    case Transaction::Op::Insert:
    case Transaction::Op::Erase:
      op.index = r.varint();
      op.target = r.varint();
      break;
  }
  pos_ = r.position();
  return true;
}

std::vector<TxOp> parse_tx(const Transaction& t) {
  std::vector<TxOp> ops;
  TxParser parser(t);
  for (TxOp op; parser.next(op);) ops.push_back(op);
  return ops;
}

namespace {
void write_span(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> s) {
  const auto n = static_cast<std::uint32_t>(s.size());
  ByteWriter w(out);
  w.fixed(n);
  w.raw(s.data(), s.size());
}
}  // namespace

}  // namespace detail

Transaction::Transaction() : bytes_{'V', 'S', 'D', 'T', format_version} {}

Transaction Transaction::from_bytes(std::vector<std::uint8_t> bytes) {
  Transaction t;
  if (bytes.empty()) return t;  // the empty bundle (a header alone reads as one too)
  if (bytes.size() < detail::header_size || std::memcmp(bytes.data(), detail::magic, 4) != 0)
    throw Error("byte 0: not a vsd transaction bundle (no VSDT header)");
  if (bytes[4] != format_version)
    throw Error("byte 4: transaction format version " + std::to_string(bytes[4]) +
                " is not supported (this is " + std::to_string(format_version) + ")");
  t.bytes_ = std::move(bytes);
  t.ops_ = detail::parse_tx(t).size();
  return t;
}

Transaction Transaction::inverted() const {
  Transaction inv;  // starts with the header
  const auto ops = detail::parse_tx(*this);
  auto& out = inv.bytes_;
  ByteWriter w(out);
  for (auto it = ops.rbegin(); it != ops.rend(); ++it) {
    const detail::TxOp& op = *it;
    Op code = op.op;
    switch (op.op) {
      case Op::Create:
        code = Op::Delete;
        break;
      case Op::Delete:
        code = Op::Create;
        break;
      case Op::Insert:
        code = Op::Erase;
        break;
      case Op::Erase:
        code = Op::Insert;
        break;
      case Op::Set:
        break;
    }
    w.u8(static_cast<std::uint8_t>(code));
    w.varint(op.id);
    w.string(op.name);
    if (op.op == Op::Create || op.op == Op::Delete) {
      w.varint(op.values.size());
      for (const auto& [name, v] : op.values) {
        w.string(name);
        detail::write_span(out, v);
      }
    } else if (op.op == Op::Set) {
      detail::write_span(out, op.new_value);
      detail::write_span(out, op.old_value);
    } else {
      w.varint(op.index);
      w.varint(op.target);
    }
    ++inv.ops_;
  }
  return inv;
}

std::string Transaction::describe() const {
  std::string s;
  for (const auto& op : detail::parse_tx(*this)) {
    switch (op.op) {
      case Op::Create:
        s += "create #" + std::to_string(op.id) + " " + std::string(op.name);
        break;
      case Op::Delete:
        s += "delete #" + std::to_string(op.id) + " " + std::string(op.name);
        break;
      case Op::Set:
        s += "set #" + std::to_string(op.id) + "." + std::string(op.name);
        break;
      case Op::Insert:
        s += "insert #" + std::to_string(op.target) + " into #" + std::to_string(op.id) + "." +
             std::string(op.name) + "[" + std::to_string(op.index) + "]";
        break;
      case Op::Erase:
        s += "erase #" + std::to_string(op.target) + " from #" + std::to_string(op.id) + "." +
             std::string(op.name) + "[" + std::to_string(op.index) + "]";
        break;
    }
    s += "\n";
  }
  return s;
}

// ---- applying ---------------------------------------------------------------------------------------------

namespace detail {

/// Applies a bundle to a SimState: a full dry run over a model of the state first, then the real run.
class Applier {
  using RefLink = vsd::detail::RefLink;

 public:
  Applier(SimState& s, const Transaction& t) : s_(s), t_(t) {}

  void run() {
    TxOp op;  // reused: its storage serves every operation
    {
      TxParser parser(t_);
      for (std::size_t i = 0; parser.next(op); ++i) check(op, i);
    }
    check_one_parent();
    reserve();
    ++s_.applying_;
    struct Done {
      SimState& s;
      ~Done() { --s.applying_; }
    } done{s_};
    TxParser parser(t_);
    while (parser.next(op)) apply(op);
  }

 private:
  struct StateResolver final : RefResolver {
    SimState* s;
    SimStateInstance* resolve(Id id) const override { return s->find(id); }
  };

  [[noreturn]] void fail(const TxOp& op, std::size_t n, const std::string& what) const {
    throw Error("byte " + std::to_string(op.offset) + ", operation " + std::to_string(n + 1) + " (" +
                op_name(op) + "): " + what + "; nothing was applied to SimState '" + s_.name() + "'");
  }
  static std::string op_name(const TxOp& op) {
    switch (op.op) {
      case Transaction::Op::Create:
        return "create #" + std::to_string(op.id);
      case Transaction::Op::Delete:
        return "delete #" + std::to_string(op.id);
      case Transaction::Op::Set:
        return "set #" + std::to_string(op.id) + "." + std::string(op.name);
      case Transaction::Op::Insert:
        return "insert into #" + std::to_string(op.id) + "." + std::string(op.name);
      case Transaction::Op::Erase:
        return "erase from #" + std::to_string(op.id) + "." + std::string(op.name);
    }
    return "?";
  }

  // Bundles create many instances of few classes: remember the last lookup (no lock, no string).
  const MetaInstance* class_named(std::string_view name) {
    if (last_class_ != nullptr && name == last_class_->name()) return last_class_;
    const MetaInstance* c = s_.environment().registry().find_class(name);
    if (c != nullptr) last_class_ = c;
    return c;
  }

  // A big bundle (a load) makes room for its instances at once: the id map, the element index and the
  // instance memory of the state grow once instead of step by step. Creates that the bundle deletes
  // again are counted too; their room stays for later instances.
  void count_create(const MetaInstance& cls) {
    ++creates_;
    if (!per_class_.empty() && per_class_.back().first == &cls) {
      ++per_class_.back().second;
      return;
    }
    for (auto& [c, n] : per_class_)
      if (c == &cls) {
        ++n;
        return;
      }
    per_class_.emplace_back(&cls, 1);
  }
  void reserve() {
    if (creates_ < 64) return;  // not worth it for small bundles
    s_.by_id_.reserve(s_.by_id_.size() + creates_);
    for (const auto& [cls, n] : per_class_) s_.reserve_instances(*cls, n);
  }

  // ---- the model used by the dry run ----
  const MetaInstance* class_of(Id id) const {
    if (id == null_id || deleted_.contains(id)) return nullptr;
    if (const MetaInstance* c = created_.find(id)) return c;
    const SimStateInstance* x = s_.find(id);
    return x != nullptr ? &x->meta() : nullptr;
  }
  // Counts the places @p id has in the lists of the model.
  void listed(Id id, int change) {
    if (std::uint32_t* times = listed_.get(id)) {
      *times = static_cast<std::uint32_t>(static_cast<int>(*times) + change);
    } else if (change > 0) {
      listed_.insert(id, 1);
    }
  }
  std::vector<Id>& list_model(Id holder, const MetaProperty& p) {
    auto key = std::make_pair(holder, &p);
    // A bundle fills one list after the other: remember the last one (map nodes never move).
    if (last_list_ != nullptr && last_list_key_ == key) return *last_list_;
    auto it = lists_.find(key);
    if (it != lists_.end()) {
      last_list_key_ = key;
      return *(last_list_ = &it->second);
    }
    std::vector<Id> ids;
    if (!created_.contains(holder)) {
      if (const SimStateInstance* x = s_.find(holder)) {
        const auto& list = *static_cast<const RefListBase*>(p.address(*x));
        for (std::size_t i = 0; i < list.size(); ++i)
          if (!deleted_.contains(list.at(i)->id())) ids.push_back(list.at(i)->id());
      }
    }
    for (Id id : ids) listed(id, +1);
    last_list_key_ = key;
    return *(last_list_ = &lists_.emplace(key, std::move(ids)).first->second);
  }
  const MetaProperty& property_of(const TxOp& op, std::size_t n, const MetaInstance& cls) const {
    return property_named(op, n, cls, op.name);
  }
  const MetaProperty& property_named(const TxOp& op, std::size_t n, const MetaInstance& cls,
                                     std::string_view name) const {
    const MetaProperty* p = cls.find_property(name);
    if (p == nullptr) fail(op, n, "class '" + cls.name() + "' has no property '" + std::string(name) + "'");
    return *p;
  }
  void check_target(const TxOp& op, std::size_t n, Id id, const MetaType& t) const {
    if (id == null_id) return;
    const MetaInstance* cls = class_of(id);
    if (cls == nullptr) fail(op, n, "dangling reference: no instance #" + std::to_string(id));
    if (t.target() != nullptr && !cls->is_a(*t.target()))
      fail(op, n,
           "#" + std::to_string(id) + " is a '" + cls->name() + "', not a '" + t.target()->name() + "'");
  }
  // Checks that @p bytes hold exactly one value of @p p's type; returns the ids of a list value.
  std::vector<Id> check_value(const TxOp& op, std::size_t n, const MetaProperty& p,
                              std::span<const std::uint8_t> bytes) {
    ByteReader r(bytes.data(), bytes.size());
    std::vector<Id> ids;
    try {
      const MetaType& t = p.type();
      if (t.is_ref_list()) {
        const std::size_t count = r.size_prefix(1);
        for (std::size_t i = 0; i < count; ++i) {
          ids.push_back(r.varint());
          if (ids.back() == null_id) r.fail("a reference list cannot hold null");
          check_target(op, n, ids.back(), t);
        }
      } else if (t.is_reference()) {
        ids.push_back(r.varint());
        check_target(op, n, ids.back(), t);
        if (ids.back() == null_id) ids.clear();
      } else {
        Value v(t);
        t.read_bytes(v.data(), r, nullptr);
      }
      if (!r.at_end()) r.fail(std::to_string(r.remaining()) + " unexpected bytes after the value");
    } catch (const Error& e) {
      fail(op, n, "value of '" + p.name() + "': " + e.what());
    }
    return ids;
  }

  void check(const TxOp& op, std::size_t n) {
    switch (op.op) {
      case Transaction::Op::Create: {
        const MetaInstance* cls = class_named(op.name);
        if (cls == nullptr) fail(op, n, "unknown class '" + std::string(op.name) + "'");
        if (cls->is_abstract() || !cls->is_a(SimStateInstance::static_meta()) ||
            cls->is_a(Database::static_meta()))
          fail(op, n, "class '" + cls->name() + "' cannot be instantiated here");
        if (op.id == null_id || class_of(op.id) != nullptr ||
            (!created_.contains(op.id) && !deleted_.contains(op.id) && s_.by_id_.contains(op.id)))
          fail(op, n, "instance #" + std::to_string(op.id) + " already exists");
        for (const auto& [name, bytes] : op.values) {
          const MetaProperty& p = property_named(op, n, *cls, name);
          if (!carried_in_payload(p)) fail(op, n, "property '" + p.name() + "' cannot be part of a create");
          check_value(op, n, p, bytes);
        }
        deleted_.erase(op.id);
        created_.assign(op.id, cls);
        count_create(*cls);
        break;
      }
      case Transaction::Op::Delete: {
        if (op.id == 1) fail(op, n, "the Database cannot be deleted");
        if (class_of(op.id) == nullptr) fail(op, n, "no instance #" + std::to_string(op.id));
        created_.erase(op.id);
        deleted_.insert(op.id, true);
        // A deleted instance holds no list, and is in none. (Its lists are found by their key; the
        // lists holding it are looked for only when it is in one: a recorded deletion erases it first.)
        for (auto it = lists_.lower_bound({op.id, nullptr}); it != lists_.end() && it->first.first == op.id;
             ++it) {
          for (Id id : it->second) listed(id, -1);
          it->second.clear();
        }
        if (const std::uint32_t* times = listed_.get(op.id); times != nullptr && *times != 0) {
          for (auto& [key, ids] : lists_) std::erase(ids, op.id);
          listed_.erase(op.id);
        }
        forget_edges(op.id);
        break;
      }
      case Transaction::Op::Set: {
        const MetaInstance* cls = class_of(op.id);
        if (cls == nullptr) fail(op, n, "no instance #" + std::to_string(op.id));
        const MetaProperty& p = property_of(op, n, *cls);
        if (p.has(Transient)) fail(op, n, "property '" + p.name() + "' is transient");
        check_value(op, n, p, op.old_value);
        auto ids = check_value(op, n, p, op.new_value);
        if (p.type().is_ref_list()) {
          auto& list = list_model(op.id, p);
          if (p.type().is_composite()) {
            for (Id old : list) remove_edge(op.id, old);
            for (Id now : ids) add_edge(op, n, op.id, now);
          }
          if (is_single_parent(p))
            for (Id now : ids) placed_.assign(now, Placement{op.op, op.offset, n, op.id, &p});
          for (Id old : list) listed(old, -1);
          for (Id now : ids) listed(now, +1);
          list = std::move(ids);
        } else if (p.type().is_composite()) {
          Id& held = single_model(op.id, p);
          if (held != null_id) remove_edge(op.id, held);
          held = ids.empty() ? null_id : ids.front();
          if (held != null_id) add_edge(op, n, op.id, held);
        }
        break;
      }
      case Transaction::Op::Insert:
      case Transaction::Op::Erase: {
        const MetaInstance* cls = class_of(op.id);
        if (cls == nullptr) fail(op, n, "no instance #" + std::to_string(op.id));
        const MetaProperty& p = property_of(op, n, *cls);
        if (!p.type().is_ref_list()) fail(op, n, "property '" + p.name() + "' is not a reference list");
        if (op.target == null_id) fail(op, n, "a reference list cannot hold null");
        check_target(op, n, op.target, p.type());
        auto& ids = list_model(op.id, p);
        if (op.op == Transaction::Op::Insert) {
          if (op.index > ids.size())
            fail(op, n,
                 "index " + std::to_string(op.index) + " is past the end (size " +
                     std::to_string(ids.size()) + ")");
          if (p.type().is_composite()) add_edge(op, n, op.id, op.target);
          if (is_single_parent(p)) placed_.assign(op.target, Placement{op.op, op.offset, n, op.id, &p});
          ids.insert(ids.begin() + static_cast<std::ptrdiff_t>(op.index), op.target);
          listed(op.target, +1);
        } else {
          if (op.index >= ids.size() || ids[op.index] != op.target)
            fail(op, n, "#" + std::to_string(op.target) + " is not at index " + std::to_string(op.index));
          ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(op.index));
          listed(op.target, -1);
          if (p.type().is_composite()) remove_edge(op.id, op.target);
        }
        break;
      }
    }
  }

  // ---- one parent: a bundle may not leave a node in two children lists (or twice in one) ----------------
  //
  // A node has one parent and an extension one owner. A move inserts before it erases, so this is checked
  // once the whole bundle has been seen, for the instances the bundle placed; the operation named is the
  // last that placed the instance.

  struct Placement {
    Transaction::Op op;
    std::size_t offset, n;
    Id holder;
    const MetaProperty* prop;
  };
  static bool is_single_parent(const MetaProperty& p) noexcept {
    return &p == &Node::vsd_prop_children() || &p == &NamedModelInstance::vsd_prop_extensions();
  }
  // The holders of @p child through children/extensions as the bundle leaves it.
  std::vector<Id> single_parents(Id child) const {
    std::vector<Id> of;
    for (const auto& [key, ids] : lists_)
      if (is_single_parent(*key.second) && !deleted_.contains(key.first))
        for (Id id : ids)
          if (id == child) of.push_back(key.first);
    if (!created_.contains(child))
      if (const SimStateInstance* x = s_.find(child))  // holders whose lists the bundle left alone
        for (const RefLink* l = x->composite_head_; l != nullptr; l = l->next)
          if (l->holder != nullptr && is_single_parent(*l->prop) && !deleted_.contains(l->holder->id()) &&
              !lists_.contains({l->holder->id(), l->prop}))
            of.push_back(l->holder->id());
    return of;
  }
  void check_one_parent() const {
    if (placed_.size() == 0) return;
    FlatIdMap<std::uint32_t> count;  // placed instance -> times listed in the lists the bundle touched
    for (const auto& [key, ids] : lists_) {
      if (!is_single_parent(*key.second) || deleted_.contains(key.first)) continue;
      for (Id id : ids)
        if (std::uint32_t* c = count.get(id)) {
          ++*c;
        } else if (placed_.contains(id)) {
          count.insert(id, 1);
        }
    }
    const Placement* worst = nullptr;  // the earliest placement that leaves two parents: reported
    Id child = null_id;
    placed_.for_each([&](Id id, const Placement& where) {
      if (deleted_.contains(id) || (worst != nullptr && where.n >= worst->n)) return;
      std::size_t n = count.find(id);
      if (n < 2 && !created_.contains(id))
        if (const SimStateInstance* x = s_.find(id))
          for (const RefLink* l = x->composite_head_; l != nullptr && n < 2; l = l->next)
            if (l->holder != nullptr && is_single_parent(*l->prop) && !deleted_.contains(l->holder->id()) &&
                !lists_.contains({l->holder->id(), l->prop}))
              ++n;
      if (n < 2) return;
      worst = &where;
      child = id;
    });
    if (worst == nullptr) return;
    const std::vector<Id> of = single_parents(child);
    const bool node = worst->prop == &Node::vsd_prop_children();
    std::string what = (node ? "node #" : "extension #") + std::to_string(child);
    if (of.size() == 2 && of[0] == of[1]) {
      what += " would be listed twice by #" + std::to_string(of[0]);
    } else {
      what += node ? " would be a child of " : " would be attached to ";
      for (std::size_t i = 0; i < of.size(); ++i)
        what += (i == 0 ? "#" : i + 1 == of.size() ? " and #" : ", #") + std::to_string(of[i]);
    }
    what += node ? ": a node has one parent" : ": an extension has one owner";
    TxOp op;
    op.op = worst->op;
    op.offset = worst->offset;
    op.id = worst->holder;
    op.name = worst->prop->name();
    fail(op, worst->n, what + " (a move erases it from the old one)");
  }

  // ---- composite edges: the dry run rejects a bundle that would make an instance its own ancestor ----

  Id& single_model(Id holder, const MetaProperty& p) {
    auto key = std::make_pair(holder, &p);
    if (auto it = singles_.find(key); it != singles_.end()) return it->second;
    Id now = null_id;
    if (!created_.contains(holder))
      if (const SimStateInstance* x = s_.find(holder)) now = static_cast<const RefBase*>(p.address(*x))->id();
    if (now != null_id && deleted_.contains(now)) now = null_id;
    return singles_.emplace(key, now).first->second;
  }
  // The instances holding @p child compositely, one entry per reference, as the bundle has left them.
  void holders_of(Id child, std::vector<Id>& out) const {
    out.clear();
    if (deleted_.contains(child)) return;
    if (!created_.contains(child))
      if (const SimStateInstance* x = s_.find(child))
        for (const RefLink* l = x->composite_head_; l != nullptr; l = l->next)
          if (l->holder != nullptr) out.push_back(l->holder->id());
    if (auto it = removed_up_.find(child); it != removed_up_.end())
      for (Id h : it->second)
        if (auto at = std::find(out.begin(), out.end(), h); at != out.end()) out.erase(at);
    if (const Id first = added_first_.find(child); first != null_id) out.push_back(first);
    if (auto it = added_more_.find(child); it != added_more_.end())
      out.insert(out.end(), it->second.begin(), it->second.end());
    std::erase_if(out, [&](Id h) { return deleted_.contains(h); });
  }
  bool holds_up(Id from, Id goal) const {  // is goal a composite ancestor of from (or from itself)?
    std::vector<Id> todo{from}, up;
    std::unordered_set<Id> seen;
    while (!todo.empty()) {
      const Id x = todo.back();
      todo.pop_back();
      if (x == goal) return true;
      if (!seen.insert(x).second) continue;
      holders_of(x, up);
      todo.insert(todo.end(), up.begin(), up.end());
    }
    return false;
  }
  // True when @p id was created by the bundle and has gained no composite reference of its own: then
  // it cannot be anybody's ancestor.
  bool holds_nothing(Id id) const { return created_.contains(id) && !holders_.contains(id); }
  void add_edge(const TxOp& op, std::size_t n, Id holder, Id child) {
    // Most edges of a big bundle point at instances it has just created and that hold nothing yet
    // (a load builds top down): no walk is needed for them.
    if (child == holder || (!holds_nothing(child) && holds_up(holder, child)))
      fail(op, n,
           "a composite reference from #" + std::to_string(holder) + " to #" + std::to_string(child) +
               " would make an instance its own ancestor");
    holders_.assign(holder, true);
    if (Id* first = added_first_.get(child); first == nullptr || *first == null_id) {
      added_first_.assign(child, holder);
    } else {
      added_more_[child].push_back(holder);
    }
  }
  void remove_edge(Id holder, Id child) {
    if (Id* first = added_first_.get(child); first != nullptr && *first == holder) {
      *first = null_id;
      return;
    }
    if (auto it = added_more_.find(child); it != added_more_.end())
      if (auto at = std::find(it->second.begin(), it->second.end(), holder); at != it->second.end()) {
        it->second.erase(at);
        return;
      }
    removed_up_[child].push_back(holder);
  }
  void forget_edges(Id gone) {  // a deleted instance neither holds nor is held any more
    added_first_.erase(gone);
    added_more_.erase(gone);
    removed_up_.erase(gone);
    singles_.erase(singles_.lower_bound({gone, nullptr}), singles_.lower_bound({gone + 1, nullptr}));
    // Edges where `gone` is the holder are skipped by holders_of() while it stays deleted; should its
    // id come back (an undo), such a stale edge can only make the check stricter.
  }
  Value decode(const MetaProperty& p, std::span<const std::uint8_t> bytes) const {
    StateResolver refs;
    refs.s = &s_;
    Value v(p.type());
    ByteReader r(bytes.data(), bytes.size());
    p.type().read_bytes(v.data(), r, &refs);
    return v;
  }

  // The dry run proved every id; only a listener that deletes instances while the bundle is applied can
  // take one away. That is reported (the bundle stops there) rather than dereferenced.
  SimStateInstance& live(const TxOp& op, Id id) const {
    SimStateInstance* x = s_.find(id);
    if (VSD_UNLIKELY(x == nullptr))
      throw Error("byte " + std::to_string(op.offset) + " (" + op_name(op) + "): instance #" +
                  std::to_string(id) +
                  " was deleted by a listener while the bundle was applied to SimState '" + s_.name() +
                  "'; the operations before this one were applied");
    return *x;
  }

  void apply(const TxOp& op) {
    switch (op.op) {
      case Transaction::Op::Create: {
        const MetaInstance& cls = *class_named(op.name);  // found by the dry run
        SimStateInstance& x = s_.make(cls, op.id);
        for (const auto& [name, bytes] : op.values) {
          const MetaProperty& p = *cls.find_property(name);
          void* at = const_cast<void*>(p.address(x));  // initial values: not changes
          const Value v = decode(p, bytes);
          p.type().assign(at, v.data());
        }
        s_.finish_create(x);
        break;
      }
      case Transaction::Op::Delete:
        s_.destroy(live(op, op.id));
        break;
      case Transaction::Op::Set: {
        SimStateInstance& x = live(op, op.id);
        const MetaProperty& p = *x.meta().find_property(op.name);
        const Value v = decode(p, op.new_value);
        p.assign_raw(x, v.data());
        break;
      }
      case Transaction::Op::Insert: {
        SimStateInstance& x = live(op, op.id);
        x.list_insert(*x.meta().find_property(op.name), op.index, live(op, op.target));
        break;
      }
      case Transaction::Op::Erase: {
        SimStateInstance& x = live(op, op.id);
        x.list_erase(*x.meta().find_property(op.name), op.index);
        break;
      }
    }
  }

  SimState& s_;
  const Transaction& t_;
  const MetaInstance* last_class_ = nullptr;
  std::size_t creates_ = 0;
  std::vector<std::pair<const MetaInstance*, std::size_t>> per_class_;  // creates by class
  FlatIdMap<const MetaInstance*> created_;
  FlatIdMap<bool> deleted_;
  std::map<std::pair<Id, const MetaProperty*>, std::vector<Id>> lists_;
  FlatIdMap<std::uint32_t> listed_;  // id -> how many times the lists of lists_ hold it
  std::pair<Id, const MetaProperty*> last_list_key_{null_id, nullptr};
  std::vector<Id>* last_list_ = nullptr;  // lists_[last_list_key_]
  std::map<std::pair<Id, const MetaProperty*>, Id> singles_;
  FlatIdMap<Id> added_first_;                           // child -> first composite holder gained
  std::unordered_map<Id, std::vector<Id>> added_more_;  // child -> further composite holders gained
  std::unordered_map<Id, std::vector<Id>> removed_up_;  // child -> real composite holders lost
  FlatIdMap<bool> holders_;                             // instances that gained composite references
  FlatIdMap<Placement> placed_;                         // instances put into a children/extensions list
};

}  // namespace detail

void SimState::apply(const Transaction& t) {
  if (t.empty()) return;
  detail::Applier(*this, t).run();
}

}  // namespace vsd
