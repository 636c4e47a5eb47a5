// Wire form of bundles: filter to Distributed properties, a per-bundle name table, no old values.
#include "vsd/dist/wire.hpp"

#include <cstring>
#include <string>
#include <string_view>
#include <unordered_map>

#include "vsd/core/bytes.hpp"
#include "vsd/core/detail/tx_codec.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/meta_instance.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/sim_state.hpp"

namespace vsd::dist {

namespace {

constexpr std::uint8_t wire_magic[4] = {'V', 'S', 'D', 'W'};
constexpr std::uint8_t wire_version = 2;
// Wire-only operation codes next to Transaction::Op's: reference-list edits in element form.
constexpr std::uint8_t element_insert = 6;
constexpr std::uint8_t element_erase = 7;

void write_element(ByteWriter& w, const ElementId& e) {
  w.varint(e.clock);
  w.fixed(e.who);
  w.varint(e.n);
}
ElementId read_element(ByteReader& r) {
  ElementId e;
  e.clock = r.varint();
  e.who = r.fixed<std::uint64_t>();
  e.n = r.varint();
  return e;
}

// Names in order of first use; an operation refers to a name by its index.
class NameTable {
 public:
  std::size_t index(std::string_view name) {
    auto [it, fresh] = index_.try_emplace(std::string(name), names_.size());
    if (fresh) names_.push_back(name);
    return it->second;
  }
  [[nodiscard]] const std::vector<std::string_view>& names() const noexcept { return names_; }

 private:
  std::unordered_map<std::string, std::size_t> index_;
  std::vector<std::string_view> names_;  // views into the source bundle, which outlives the table
};

}  // namespace

WireBundle encode_bundle(const Transaction& t, const SimState& state) {
  return encode_bundle(t, state, ListEncoder{});
}

WireBundle encode_bundle(const Transaction& t, const SimState& state, const ListEncoder& lists) {
  const Registry& registry = state.environment().registry();
  const auto ops = detail::parse_tx(t);
  // The class of every instance the bundle creates or deletes: it may be gone from the state by now
  // (a bundle that sets a property and then deletes the instance).
  std::unordered_map<Id, const MetaInstance*> classes;
  auto class_named = [&](std::string_view name) {
    const MetaInstance* c = registry.find_class_exact(name);
    if (c == nullptr) throw Error("dist: bundle names unknown class '" + std::string(name) + "'");
    return c;
  };
  for (const auto& op : ops)
    if (op.op == Transaction::Op::Create || op.op == Transaction::Op::Delete)
      classes.try_emplace(op.id, class_named(op.name));
  auto class_of = [&](Id id) -> const MetaInstance& {
    if (auto it = classes.find(id); it != classes.end()) return *it->second;
    if (const SimStateInstance* x = state.find(id)) return x->meta();
    throw Error("dist: bundle names instance #" + std::to_string(id) + ", unknown to SimState '" +
                state.name() + "'");
  };
  auto distributed = [](const MetaInstance& cls, std::string_view prop) {
    const MetaProperty* p = cls.find_property(prop);
    return p != nullptr && p->has(Distributed) && !p->has(Transient);
  };

  NameTable names;
  std::vector<std::uint8_t> body;
  ByteWriter w(body);
  WireBundle out;
  for (const auto& op : ops) {
    switch (op.op) {
      case Transaction::Op::Create: {
        const MetaInstance& cls = class_of(op.id);
        w.u8(static_cast<std::uint8_t>(op.op));
        w.varint(op.id);
        w.varint(names.index(op.name));
        std::size_t n = 0;
        for (const auto& [name, value] : op.values) n += distributed(cls, name) ? 1 : 0;
        w.varint(n);
        for (const auto& [name, value] : op.values) {
          if (!distributed(cls, name)) continue;
          w.varint(names.index(name));
          w.varint(value.size());
          w.raw(value.data(), value.size());
        }
        break;
      }
      case Transaction::Op::Delete:  // the receiver needs the id only; the last values are for undo
        w.u8(static_cast<std::uint8_t>(op.op));
        w.varint(op.id);
        w.varint(names.index(op.name));
        out.deleted.push_back(op.id);
        break;
      case Transaction::Op::Set:
        if (!distributed(class_of(op.id), op.name)) {
          ++out.dropped;
          continue;
        }
        w.u8(static_cast<std::uint8_t>(op.op));
        w.varint(op.id);
        w.varint(names.index(op.name));
        w.varint(op.new_value.size());
        w.raw(op.new_value.data(), op.new_value.size());
        out.sets.emplace_back(op.id, op.name);
        break;
      case Transaction::Op::Insert:
      case Transaction::Op::Erase:
        if (!distributed(class_of(op.id), op.name)) {
          ++out.dropped;
          continue;
        }
        out.list_edits = true;
        if (lists) {
          const ElementEdit e = lists(op.op, op.id, op.name, op.index, op.target);
          const bool insert = op.op == Transaction::Op::Insert;
          w.u8(insert ? element_insert : element_erase);
          w.varint(op.id);
          w.varint(names.index(op.name));
          if (insert) {
            w.varint(e.element.n);  // the element's clock and who are the bundle's stamp
            write_element(w, e.origin);
          } else {
            write_element(w, e.element);
          }
          w.varint(op.target);
          break;
        }
        w.u8(static_cast<std::uint8_t>(op.op));
        w.varint(op.id);
        w.varint(names.index(op.name));
        w.varint(op.index);
        w.varint(op.target);
        break;
    }
    ++out.ops;
  }

  ByteWriter head(out.bytes);
  head.raw(wire_magic, 4);
  head.u8(wire_version);
  head.varint(names.names().size());
  for (std::string_view n : names.names()) head.string(n);
  head.varint(out.ops);
  head.raw(body.data(), body.size());
  return out;
}

Transaction decode_bundle(std::span<const std::uint8_t> bytes) { return decode_bundle(bytes, OpFilter{}); }

Transaction decode_bundle(std::span<const std::uint8_t> bytes, const OpFilter& keep) {
  DecodeHooks hooks;
  hooks.keep = keep;
  return decode_bundle(bytes, hooks);
}

Transaction decode_bundle(std::span<const std::uint8_t> bytes, const DecodeHooks& hooks) {
  const OpFilter& keep = hooks.keep;
  ByteReader r(bytes.data(), bytes.size());
  try {
    if (bytes.size() < 5 || std::memcmp(bytes.data(), wire_magic, 4) != 0)
      r.fail("not a vsd wire bundle (no VSDW header)");
    r.skip(4);
    if (const std::uint8_t v = r.u8(); v != wire_version)
      r.fail_at(4, "wire bundle version " + std::to_string(v) + " is not supported (this is " +
                       std::to_string(wire_version) + ")");
    const std::size_t name_count = r.size_prefix(1);
    std::vector<std::string_view> names;
    names.reserve(name_count);
    for (std::size_t i = 0; i < name_count; ++i) names.push_back(r.string_view());
    auto name = [&]() {
      const std::size_t at = r.position();
      const std::uint64_t i = r.varint();
      if (i >= names.size())
        r.fail_at(at, "name index " + std::to_string(i) + " is past the name table (" +
                          std::to_string(names.size()) + " names)");
      return names[static_cast<std::size_t>(i)];
    };
    auto value = [&]() {
      const std::size_t n = r.size_prefix(1);
      return std::span<const std::uint8_t>(r.skip(n), n);
    };

    std::vector<std::uint8_t> out;
    detail::write_tx_header(out);
    const std::size_t op_count = r.size_prefix(3);  // an operation takes at least 3 bytes
    std::size_t kept = op_count;
    std::vector<detail::TxValue> values;
    for (std::size_t i = 0; i < op_count; ++i) {
      const std::size_t at = r.position();
      const std::uint8_t code = r.u8();
      const Id id = r.varint();
      const std::string_view n = name();
      switch (code) {
        case static_cast<std::uint8_t>(Transaction::Op::Create): {
          const std::size_t count = r.size_prefix(2);
          values.clear();
          for (std::size_t k = 0; k < count; ++k) {
            const std::string_view prop = name();
            values.emplace_back(prop, value());
          }
          if (hooks.created) hooks.created(id, n);
          detail::write_create(out, id, n, values);
          break;
        }
        case static_cast<std::uint8_t>(Transaction::Op::Delete): {
          if (keep && !keep(Transaction::Op::Delete, id, {})) {
            --kept;
            break;
          }
          if (hooks.before_delete) hooks.before_delete(id, out, kept);
          ByteWriter w(out);  // the VSDT layout of a deletion (transaction.hpp), without last values
          w.u8(static_cast<std::uint8_t>(Transaction::Op::Delete));
          w.varint(id);
          w.string(n);
          w.varint(0);
          break;
        }
        case static_cast<std::uint8_t>(Transaction::Op::Set): {
          auto v = value();
          if (keep && !keep(Transaction::Op::Set, id, n)) {
            --kept;
            break;
          }
          if (hooks.set_value) v = hooks.set_value(id, n, v);
          detail::write_set(out, id, n, v, v);
          break;
        }
        case static_cast<std::uint8_t>(Transaction::Op::Insert):
        case static_cast<std::uint8_t>(Transaction::Op::Erase): {
          const std::uint64_t index = r.varint();
          const Id target = r.varint();
          if (keep && !keep(static_cast<Transaction::Op>(code), id, n)) {
            --kept;
            break;
          }
          detail::write_list(out, static_cast<Transaction::Op>(code), id, n, static_cast<std::size_t>(index),
                             target);
          break;
        }
        case element_insert:
        case element_erase: {
          ElementEdit e;
          e.holder = id;
          e.property = n;
          if (code == element_insert) {
            e.op = Transaction::Op::Insert;
            e.element.n = r.varint();
            e.origin = read_element(r);
          } else {
            e.op = Transaction::Op::Erase;
            e.element = read_element(r);
          }
          e.target = r.varint();
          --kept;  // the hook counts what it writes
          if (keep && !keep(e.op, id, n)) break;
          if (!hooks.list) r.fail_at(at, "an element-form list edit needs a list decoder");
          hooks.list(e, out, kept);
          break;
        }
        default:
          r.fail_at(at, "unknown operation code " + std::to_string(code));
      }
    }
    if (!r.at_end()) r.fail(std::to_string(r.remaining()) + " unexpected bytes after the last operation");
    if (hooks.finish) hooks.finish(out, kept);
    return detail::make_transaction(std::move(out), kept);
  } catch (const Error& e) {
    throw Error(std::string("wire bundle ") + e.what());
  }
}

}  // namespace vsd::dist
