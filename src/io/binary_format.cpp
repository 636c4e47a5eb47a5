// The binary snapshot format "VSDS" (see vsd/io/snapshot.hpp): writing, and reading into a LoadModel.
#include <algorithm>

#include "formats.hpp"
#include "vsd/core/bytes.hpp"

namespace vsd::io::detail {

namespace {

constexpr std::uint8_t magic[4] = {'V', 'S', 'D', 'S'};
constexpr std::uint8_t format_version = 2;  // 2 adds the type table; files without run-time types stay 1

// Kinds of run-time types in the type table.
constexpr std::uint8_t type_enum = 0;
constexpr std::uint8_t type_flags = 1;
constexpr std::uint8_t type_struct = 2;
void write_framed(ByteWriter& w, const std::vector<std::uint8_t>& value) {
  w.fixed(static_cast<std::uint32_t>(value.size()));
  w.raw(value.data(), value.size());
}

// ---- writing ----------------------------------------------------------------------------------------------

void write_class(ByteWriter& w, const MetaInstance& c) {
  w.string(c.name());
  w.u8(c.is_runtime() ? 1 : 0);
  std::vector<std::uint8_t> value;
  if (c.is_runtime()) {
    w.string(c.base()->name());
    w.u8(c.is_abstract() ? 1 : 0);
    const auto own = c.own_properties();
    w.varint(own.size());
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

void write_type(ByteWriter& w, const MetaType& t) {
  w.string(t.name());
  if (t.kind() == TypeKind::Struct) {
    w.u8(type_struct);
    w.varint(t.fields().size());
    for (const auto& f : t.fields()) {
      w.string(f.name);
      w.string(f.type->name());
    }
    return;
  }
  w.u8(t.kind() == TypeKind::Flags ? type_flags : type_enum);
  w.string((t.is_unsigned() ? "uint" : "int") + std::to_string(t.size() * 8));
  w.varint(t.enum_values().size());
  for (const auto& v : t.enum_values()) {
    w.string(v.name);
    w.fixed(v.value);
  }
}

// ---- reading ----------------------------------------------------------------------------------------------

class BinaryReader final : public LoadModel {
 public:
  BinaryReader(Registry& registry, std::span<const std::uint8_t> bytes, std::string_view origin,
               const LoadOptions& options)
      : LoadModel(registry, origin, options), bytes_(bytes), in_(bytes.data(), bytes.size()) {}

  void read() {
    try {
      read_all();
    } catch (const Error& e) {  // errors of the byte reader itself carry the offset but not the file
      const std::string msg = e.what();
      if (msg.rfind(std::string(origin_) + ":", 0) == 0) throw;
      throw Error(std::string(origin_) + ": " + msg);
    }
  }

 private:
  [[nodiscard]] std::string where(std::size_t at) const override {
    return std::string(origin_) + ": byte " + std::to_string(at);
  }
  [[nodiscard]] std::size_t list_element_at(std::size_t value_at, std::size_t k) const override {
    ByteReader r(bytes_.data() + value_at, bytes_.size() - value_at);  // read before: well formed
    (void)r.fixed<std::uint32_t>();                                    // the frame's length
    (void)r.varint();                                                  // the count
    for (std::size_t i = 0; i < k; ++i) (void)r.varint();
    return value_at + r.position();
  }

  void read_all() {
    std::uint8_t head[4];
    in_.raw(head, 4);
    if (!std::equal(head, head + 4, magic)) fail_at(0, "not a vsd snapshot (no VSDS header)");
    const std::uint8_t version = in_.u8();
    if (version < 1 || version > format_version)
      fail_at(4, "snapshot format version " + std::to_string(version) +
                     " is not supported (this reads 1 to " + std::to_string(format_version) + ")");
    version_ = version;
    kind_ = in_.u8();
    if (kind_ != kind_state && kind_ != kind_subtree)
      fail_at(5, "unknown snapshot kind " + std::to_string(kind_));
    if (version >= 2) {
      const std::size_t ntypes = in_.size_prefix(3);
      for (std::size_t i = 0; i < ntypes; ++i) read_type();
    }
    const std::size_t nclasses = in_.size_prefix(2);
    for (std::size_t i = 0; i < nclasses; ++i) read_class();
    // An instance takes at least its id, its class index and a 4-byte frame per saved property of the
    // narrowest class: a count the rest of the file cannot hold is refused before anything is reserved.
    std::size_t widest = 0, narrowest = classes_.empty() ? 0 : SIZE_MAX;
    for (const ClassEntry& c : classes_) {
      widest = std::max(widest, c.slots.size());
      narrowest = std::min(narrowest, c.slots.size());
    }
    const std::size_t ninstances = in_.size_prefix(2 + 4 * std::min<std::size_t>(narrowest, 1 << 20));
    instances_.reserve(ninstances);
    // Values: the widest class's count per instance, bounded by what the bytes left can hold (a frame
    // takes at least 4): growing a vector of millions by doubling costs more than the read itself.
    if (widest != 0) values_.reserve(std::min(ninstances, in_.remaining() / 4 / widest) * widest);
    for (std::size_t i = 0; i < ninstances; ++i) read_instance();
    has_top_ = true;
    top_at_ = in_.position();
    const std::size_t ntop = in_.size_prefix(1);
    for (std::size_t i = 0; i < ntop; ++i) {
      top_offsets_.push_back(in_.position());
      top_.push_back(in_.varint());
    }
    if (!in_.at_end())
      fail_at(in_.position(), std::to_string(in_.remaining()) + " unexpected bytes after the snapshot");
    finish();
  }

  void read_type() {
    const std::size_t at = in_.position();
    TypeDefinition def;
    def.name = in_.string();
    const std::size_t kind_at = in_.position();
    const std::uint8_t kind = in_.u8();
    if (kind == type_struct) {
      def.kind = TypeKind::Struct;
      const std::size_t n = in_.size_prefix(2);
      for (std::size_t i = 0; i < n; ++i) {
        std::string name = in_.string();
        const std::size_t type_at = in_.position();
        def.fields.emplace_back(std::move(name), &type_named(type_at, in_.string_view()));
      }
    } else if (kind == type_enum || kind == type_flags) {
      def.kind = kind == type_flags ? TypeKind::Flags : TypeKind::Enum;
      const std::size_t type_at = in_.position();
      def.underlying = &type_named(type_at, in_.string_view());
      const std::size_t n = in_.size_prefix(9);
      for (std::size_t i = 0; i < n; ++i) {
        std::string name = in_.string();
        def.values.push_back({std::move(name), in_.fixed<std::int64_t>()});
      }
    } else {
      fail_at(kind_at, "unknown kind " + std::to_string(kind) + " of type '" + def.name + "'");
    }
    resolve_type(at, def);
  }

  void read_class() {
    const std::size_t at = in_.position();
    const std::string name = in_.string();
    const bool runtime = in_.u8() != 0;
    ClassDefinition def;
    if (runtime) {
      def.name = name;
      def.base = in_.string();
      def.abstract = in_.u8() != 0;
      const std::size_t nprops = in_.size_prefix(7);
      for (std::size_t i = 0; i < nprops; ++i) {
        std::string prop = in_.string();
        const std::size_t type_at = in_.position();
        const MetaType& type = type_named(type_at, in_.string_view());
        const PropertyFlags flags{in_.fixed<std::uint32_t>()};
        const std::size_t value_at = in_.position();
        const auto frame = read_frame();
        Value value(type);
        if (!type.is_reference()) decode_into(value_at, type, frame, value);
        def.properties.push_back({std::move(prop), &type, flags, std::move(value)});
      }
    }
    // The saved properties first: a class nobody defines may become a stand-in made from them.
    const std::size_t nsaved = in_.size_prefix(2);
    std::vector<SavedProperty> saved(nsaved);
    for (SavedProperty& p : saved) {
      p.name = in_.string_view();
      p.at = in_.position();
      p.type = in_.string_view();
    }
    ClassEntry& entry = classes_.emplace_back();
    entry.cls = &resolve_class(at, name, runtime ? &def : nullptr, saved);
    entry.slots.reserve(nsaved);
    for (const SavedProperty& p : saved) entry.slots.push_back(make_slot(p.at, *entry.cls, p.name, p.type));
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

  void read_references(std::size_t frame_at, const MetaProperty& p, std::span<const std::uint8_t> frame) {
    ByteReader r(frame.data(), frame.size());
    try {
      if (p.type().is_ref_list()) {
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
      fail_at(frame_at + 4 + r.position(), "reference " + p.name() + ": " + e.what());
    }
  }

  void read_instance() {
    SavedInstance x;
    x.first = values_.size();
    x.offset = in_.position();
    x.id = in_.varint();
    if (x.id == null_id) fail_at(x.offset, "instance id 0 is not valid");
    const std::size_t at = in_.position();
    const std::uint64_t c = in_.varint();
    if (c >= classes_.size()) fail_at(at, "class index " + std::to_string(c) + " is out of the class table");
    x.entry = &classes_[c];
    for (const Slot& s : x.entry->slots) {
      const std::size_t frame_at = in_.position();
      const auto frame = read_frame();
      if (s.prop == nullptr) continue;  // reported once per class
      SavedValue v = new_value(s, x.offset, frame_at);
      const MetaType& type = s.prop->type();
      if (type.is_reference()) {
        read_references(frame_at, *s.prop, frame);
      } else if (s.convert) {
        Value file_value(*s.file_type);
        decode_into(frame_at, *s.file_type, frame, file_value);
        Value converted;
        try {
          converted = file_value.convert_to(type);
        } catch (const Error& e) {
          fail_at(frame_at, std::string("value of ") + s.prop->name() + ": " + e.what());
        }
        std::vector<std::uint8_t> bytes;
        ByteWriter w(bytes);
        type.write_bytes(converted.data(), w);
        set_bytes(v, own(bytes), frame_at);
      } else {
        check_value(frame_at, type, frame);
        set_bytes(v, frame, frame_at);
      }
      keep_value(v);
    }
    x.count = values_.size() - x.first;
    instances_.push_back(x);
  }

  std::span<const std::uint8_t> bytes_;
  ByteReader in_;
};

}  // namespace

std::vector<std::uint8_t> write_binary(SaveSet& set) {
  std::vector<std::uint8_t> out;
  ByteWriter w(out);
  for (const std::uint8_t b : magic) w.u8(b);  // (w.raw into the empty vector trips a GCC 12 false positive)
  const int version = format_version_for(set);
  w.u8(static_cast<std::uint8_t>(version));
  w.u8(set.kind());
  if (version >= 2) {
    w.varint(set.types().size());
    for (const MetaType* t : set.types()) write_type(w, *t);
  }
  w.varint(set.classes().size());
  for (const MetaInstance* c : set.classes()) write_class(w, *c);
  w.varint(set.members().size());
  std::vector<std::uint8_t> value;
  std::vector<Id> ids;
  for (const SimStateInstance* x : set.members()) {
    w.varint(x->id());
    w.varint(set.class_index(x->meta()));
    for (const MetaProperty* p : x->meta().properties()) {
      if (!is_saved(*p)) continue;
      value.clear();
      ByteWriter vw(value);
      if (p->type().is_reference()) {
        ids.clear();
        set.reference_ids(*x, *p, ids);
        if (p->type().is_ref_list()) vw.varint(ids.size());
        for (Id id : ids) vw.varint(id);
      } else {
        p->type().write_bytes(p->address(*x), vw);
      }
      write_framed(w, value);
    }
  }
  w.varint(set.top().size());
  for (Id id : set.top()) w.varint(id);
  return out;
}

std::unique_ptr<LoadModel> read_binary(Registry& registry, std::span<const std::uint8_t> bytes,
                                       std::string_view origin, const LoadOptions& options) {
  auto reader = std::make_unique<BinaryReader>(registry, bytes, origin, options);
  reader->read();
  return reader;
}

}  // namespace vsd::io::detail
