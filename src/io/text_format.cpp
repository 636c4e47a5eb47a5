// The text format "vsd-text" (see vsd/io/snapshot.hpp and docs/file-formats.md): JSON written one property
// per line, and read into a LoadModel with line:col in every error.
//
// Each value is its type's own text form (MetaType::write_text, valid JSON by design), and is read back by
// MetaType::read_text on the same TextReader, so an error deep inside a value still names its line:col.
// The reader takes JSON's members in any order: the top level is scanned once for where each part starts,
// and an instance whose "@class" comes after some of its properties reads those when the class is known.
#include <algorithm>
#include <charconv>
#include <optional>

#include "formats.hpp"
#include "vsd/core/bytes.hpp"
#include "vsd/core/text.hpp"

namespace vsd::io::detail {

namespace {

constexpr std::string_view format_name = "vsd-text";
constexpr int format_version = 2;  // 2 adds "types"; files without run-time types are still written as 1

// ---- property flags as names ------------------------------------------------------------------------------

struct FlagName {
  std::string_view name;
  PropertyFlags flag;
};
constexpr FlagName flag_names[] = {{"Editable", Editable},
                                   {"Savable", Savable},
                                   {"Distributed", Distributed},
                                   {"ReadOnly", ReadOnly},
                                   {"Transient", Transient}};

std::string flags_text(PropertyFlags flags) {
  std::string out;
  auto add = [&](std::string_view name) {
    if (!out.empty()) out.push_back('|');
    out += name;
  };
  for (const FlagName& f : flag_names)
    if (flags.has(f.flag)) add(f.name);
  for (unsigned n = 0; n < 16; ++n)
    if (flags.has(UserFlag(n))) add("User" + std::to_string(n));
  return out;
}

// ---- writing ----------------------------------------------------------------------------------------------

void write_id(std::string& out, Id id) {
  if (id == null_id) {
    out += "null";
    return;
  }
  out += "\"@";
  out += std::to_string(id);
  out.push_back('"');
}

void write_key(std::string& out, std::string_view indent, std::string_view key) {
  out += indent;
  write_quoted(out, key);
  out += ": ";
}

// A run-time type on one line: {"type": "Color", "kind": "enum", "underlying": "int32", "values": [["Red",
// 0]]} or {"type": "Tag", "kind": "struct", "fields": [["label", "string"], ["color", "Color"]]}.
void write_type(std::string& out, const MetaType& t) {
  out += "    {";
  write_key(out, "", "type");
  write_quoted(out, t.name());
  write_key(out, ", ", "kind");
  if (t.kind() == TypeKind::Struct) {
    out += "\"struct\"";
    write_key(out, ", ", "fields");
    out.push_back('[');
    for (std::size_t i = 0; i < t.fields().size(); ++i) {
      out += i == 0 ? "[" : ", [";
      write_quoted(out, t.fields()[i].name);
      out += ", ";
      write_quoted(out, t.fields()[i].type->name());
      out.push_back(']');
    }
    out += "]}";
    return;
  }
  out += t.kind() == TypeKind::Flags ? "\"flags\"" : "\"enum\"";
  write_key(out, ", ", "underlying");
  write_quoted(out, (t.is_unsigned() ? "uint" : "int") + std::to_string(t.size() * 8));
  write_key(out, ", ", "values");
  out.push_back('[');
  for (std::size_t i = 0; i < t.enum_values().size(); ++i) {
    out += i == 0 ? "[" : ", [";
    write_quoted(out, t.enum_values()[i].name);
    out += ", ";
    out += std::to_string(t.enum_values()[i].value);
    out.push_back(']');
  }
  out += "]}";
}

void write_class(std::string& out, const MetaInstance& c) {
  out += "    {";
  write_key(out, "", "class");
  write_quoted(out, c.name());
  if (c.is_runtime()) {
    out += ",\n";
    write_key(out, "      ", "base");
    write_quoted(out, c.base()->name());
    out += ",\n";
    write_key(out, "      ", "abstract");
    out += c.is_abstract() ? "true" : "false";
    out += ",\n";
    write_key(out, "      ", "properties");
    out += "[";
    bool first = true;
    for (const MetaProperty* p : c.own_properties()) {
      out += first ? "\n        {" : ",\n        {";
      first = false;
      write_key(out, "", "name");
      write_quoted(out, p->name());
      write_key(out, ", ", "type");
      write_quoted(out, p->type().name());
      write_key(out, ", ", "flags");
      write_quoted(out, flags_text(p->flags()));
      write_key(out, ", ", "default");
      if (p->type().is_reference())
        out += p->type().is_ref_list() ? "[]" : "null";
      else
        p->type().write_text(p->default_value().data(), out);
      out.push_back('}');
    }
    out += first ? "]" : "\n      ]";
  }
  out += ",\n";
  write_key(out, "      ", "saved");
  out.push_back('{');
  bool first = true;
  for (const MetaProperty* p : c.properties()) {
    if (!is_saved(*p)) continue;
    if (!first) out += ", ";
    first = false;
    write_quoted(out, p->name());
    out += ": ";
    write_quoted(out, p->type().name());
  }
  out += "}}";
}

}  // namespace

std::vector<std::uint8_t> write_text(SaveSet& set) {
  std::string out;
  out += "{\n";
  write_key(out, "  ", "format");
  write_quoted(out, format_name);
  out += ",\n";
  write_key(out, "  ", "version");
  out += std::to_string(format_version_for(set));
  out += ",\n";
  write_key(out, "  ", "kind");
  out += set.kind() == kind_state ? "\"state\"" : "\"subtree\"";
  out += ",\n";
  if (!set.types().empty()) {
    write_key(out, "  ", "types");
    out += "[\n";
    for (std::size_t i = 0; i < set.types().size(); ++i) {
      write_type(out, *set.types()[i]);
      out += i + 1 < set.types().size() ? ",\n" : "\n";
    }
    out += "  ],\n";
  }
  write_key(out, "  ", "classes");
  out += "[\n";
  for (std::size_t i = 0; i < set.classes().size(); ++i) {
    write_class(out, *set.classes()[i]);
    out += i + 1 < set.classes().size() ? ",\n" : "\n";
  }
  out += "  ],\n";
  write_key(out, "  ", "instances");
  out += "[\n";
  std::vector<Id> ids;
  for (std::size_t i = 0; i < set.members().size(); ++i) {
    const SimStateInstance& x = *set.members()[i];
    out += "    {\"@id\": ";
    out += std::to_string(x.id());
    out += ", \"@class\": ";
    write_quoted(out, x.meta().name());
    for (const MetaProperty* p : x.meta().properties()) {
      if (!is_saved(*p)) continue;
      out += ",\n";
      write_key(out, "      ", p->name());
      if (p->type().is_reference()) {
        ids.clear();
        set.reference_ids(x, *p, ids);
        if (p->type().is_ref_list()) {
          out.push_back('[');
          for (std::size_t k = 0; k < ids.size(); ++k) {
            if (k != 0) out += ", ";
            write_id(out, ids[k]);
          }
          out.push_back(']');
        } else {
          write_id(out, ids.front());
        }
      } else {
        p->type().write_text(p->address(x), out);
      }
    }
    out += i + 1 < set.members().size() ? "},\n" : "}\n";
  }
  out += "  ],\n";
  write_key(out, "  ", "top");
  out.push_back('[');
  for (std::size_t i = 0; i < set.top().size(); ++i) {
    if (i != 0) out += ", ";
    write_id(out, set.top()[i]);
  }
  out += "]\n}\n";
  return {out.begin(), out.end()};
}

// ---- reading ----------------------------------------------------------------------------------------------

namespace {

std::string_view as_text(std::span<const std::uint8_t> bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

class TextSnapshotReader final : public LoadModel {
 public:
  TextSnapshotReader(Registry& registry, std::span<const std::uint8_t> bytes, std::string_view origin,
                     const LoadOptions& options)
      : LoadModel(registry, origin, options), in_(as_text(bytes), origin) {
    // A UTF-8 byte order mark is allowed before the JSON text.
    if (as_text(bytes).substr(0, 3) == "\xEF\xBB\xBF") in_.seek(3);
  }

  void read() {
    // The top level. Members are read where they stand when what they need is known (the format and
    // version before anything, the classes before the instances); a file that orders them otherwise is
    // read in two passes: such members are skipped, remembered, and read at the end.
    std::optional<std::size_t> types_at, classes_at, instances_at;
    bool has_format = false, has_version = false, has_kind = false, has_top = false;
    bool types_read = false, classes_read = false, instances_read = false;
    in_.expect('{');
    if (!in_.accept('}')) {
      do {
        const std::size_t key_at = in_.token_start();
        if (in_.peek() != '"') fail_at(key_at, "expected a quoted member name");
        const std::string key = in_.string();
        in_.expect(':');
        const std::size_t at = in_.token_start();
        auto once = [&](bool& seen) {
          if (seen) fail_at(key_at, "'" + key + "' is given twice");
          seen = true;
        };
        if (key == "format") {
          once(has_format);
          if (in_.peek() != '"' || in_.string() != format_name)
            fail_at(at, "not a vsd text file (\"format\" is not \"vsd-text\")");
        } else if (key == "version") {
          once(has_version);
          const std::int64_t version = in_.integer();
          if (version < 1 || version > format_version)
            fail_at(at, "format version " + std::to_string(version) + " is not supported (this reads 1 to " +
                            std::to_string(format_version) + ")");
          version_ = static_cast<int>(version);
        } else if (key == "kind") {
          once(has_kind);
          read_kind(at);
        } else if (key == "top") {
          once(has_top);
          read_top();
        } else if (key == "types" || key == "classes" || key == "instances") {
          std::optional<std::size_t>& slot = key == "types"     ? types_at
                                             : key == "classes" ? classes_at
                                                                : instances_at;
          if (slot) fail_at(key_at, "'" + key + "' is given twice");
          slot = at;
          // Classes need the types before them (a version 1 file has none), instances the classes.
          const bool ready = has_format && has_version &&
                             (key == "types" || (key == "classes" && (types_read || version_ < 2)) ||
                              (key == "instances" && classes_read));
          if (!ready) {
            in_.skip_value();
          } else if (key == "types") {
            read_types(at);
            types_read = true;
          } else if (key == "classes") {
            read_classes(at);
            classes_read = true;
          } else {
            read_instances(at);
            instances_read = true;
          }
        } else {
          warnings_.push_back(where(key_at) + ": unknown member '" + key + "' is ignored");
          in_.skip_value();
        }
      } while (in_.accept(','));
      in_.expect('}');
    }
    in_.expect_end();
    const std::size_t end = in_.position();
    if (!has_format) fail_at(0, "not a vsd text file (no \"format\": \"vsd-text\")");
    if (!has_version) fail_at(0, "the file names no format \"version\"");
    if (types_at && !types_read) read_types(*types_at);
    if (classes_at && !classes_read) read_classes(*classes_at);
    if (instances_at && !instances_read) read_instances(*instances_at);
    in_.seek(end);
    finish();
  }

 private:
  // A class as this file uses it: its properties' slots (one per saved property of today's class, plus
  // the file's properties it no longer has), found by name for each key of an instance.
  struct TextClass {
    ClassEntry* entry;
    // "saved": each property's name, type name and where the type was written, in file order.
    std::vector<std::string> saved_names, type_names;
    std::vector<std::size_t> type_at;
    std::unordered_map<std::string, std::size_t> file_types;  // property -> index in the vectors above
    std::vector<std::string> reported;                        // unknown keys already warned about
    // Per slot: the class's property (kept even when the slot drops its values), the name the file uses,
    // and where values are parsed (reset to the default each time).
    std::vector<const MetaProperty*> props;
    std::vector<std::string> names;
    std::vector<Value> scratch;
    // A wide class finds a key's slot by hash, not by a search through all of them (a narrow one searches:
    // that is quicker for a handful), and marks the slots an instance gave with the instance's number.
    std::unordered_map<const MetaProperty*, std::size_t> slot_of_prop;
    std::unordered_map<std::string, std::size_t> slot_of_name;  // slots of properties the class lacks
    std::vector<std::size_t> given_by;                          // per slot: the last instance + 1
  };
  static constexpr std::size_t wide_class = 16;

  [[nodiscard]] std::string where(std::size_t at) const override {
    // Counted on from the last position asked for: warnings come in file order, and a file with many of
    // them must not be scanned from its start for each.
    const std::string_view text = in_.text();
    at = std::min(at, text.size());
    if (at < where_.pos) where_ = {};
    for (; where_.pos < at; ++where_.pos)
      if (text[where_.pos] == '\n') {
        ++where_.line;
        where_.line_start = where_.pos + 1;
      }
    return std::string(origin_) + ":" + std::to_string(where_.line) + ":" +
           std::to_string(at - where_.line_start + 1);
  }
  [[nodiscard]] std::size_t list_element_at(std::size_t value_at, std::size_t k) const override {
    TextReader r = in_;  // the list was read before: it is well formed
    r.seek(value_at);
    r.expect('[');
    for (std::size_t i = 0; i < k; ++i) {
      r.skip_value();
      r.expect(',');
    }
    return r.token_start();
  }

  template <class F>
  void read_array(F&& each) {
    TextReader::Nest nest(in_);
    in_.expect('[');
    if (in_.accept(']')) return;
    do each();
    while (in_.accept(','));
    in_.expect(']');
  }

  template <class F>
  void read_object(F&& each_key) {
    TextReader::Nest nest(in_);
    in_.expect('{');
    if (in_.accept('}')) return;
    do {
      const std::size_t key_at = in_.token_start();
      if (in_.peek() != '"') fail_at(key_at, "expected a quoted member name");
      const std::string key = in_.string();
      in_.expect(':');
      each_key(key, key_at);
    } while (in_.accept(','));
    in_.expect('}');
  }

  // "@42" (also the bare @42 of the older value text) or null.
  Id read_id() {
    const std::size_t at = in_.token_start();
    const char c = in_.peek();
    if (c == '@') {
      in_.expect('@');
      return in_.unsigned_integer();
    }
    if (c == '"') {
      const std::string s = in_.string();
      Id id = 0;
      const char* first = s.data() + 1;
      const char* last = s.data() + s.size();
      if (s.size() < 2 || s[0] != '@' || std::from_chars(first, last, id).ptr != last || id == null_id)
        fail_at(at, "expected a reference \"@<id>\" or null, found \"" + s + "\"");
      return id;
    }
    if (c == 'n' && in_.identifier() == "null") return null_id;
    fail_at(at, "expected a reference \"@<id>\" or null");
  }

  std::string read_string(std::string_view what) {
    const std::size_t at = in_.token_start();
    if (in_.peek() != '"') fail_at(at, "expected " + std::string(what) + " (a quoted string)");
    return in_.string();
  }

  bool read_bool() {
    const std::size_t at = in_.token_start();
    const auto w = in_.identifier();
    if (w == "true") return true;
    if (w != "false") fail_at(at, "expected true or false");
    return false;
  }

  PropertyFlags read_flags() {
    const std::size_t at = in_.token_start();
    if (in_.peek() != '"') return PropertyFlags{static_cast<std::uint32_t>(in_.unsigned_integer())};
    const std::string text = in_.string();
    PropertyFlags flags;
    std::string_view rest = text;
    while (!rest.empty()) {
      const std::size_t bar = rest.find('|');
      const std::string_view name = rest.substr(0, bar);
      rest = bar == std::string_view::npos ? std::string_view{} : rest.substr(bar + 1);
      bool found = false;
      for (const FlagName& f : flag_names)
        if (f.name == name) flags = flags | f.flag, found = true;
      unsigned n = 0;
      if (!found && name.substr(0, 4) == "User" && name.size() > 4 &&
          std::from_chars(name.data() + 4, name.data() + name.size(), n).ptr == name.data() + name.size() &&
          n < 16)
        flags = flags | UserFlag(n), found = true;
      if (!found) fail_at(at, "unknown property flag '" + std::string(name) + "'");
    }
    return flags;
  }

  void read_kind(std::size_t at) {
    const std::string kind = read_string("a kind");
    if (kind == "state")
      kind_ = kind_state;
    else if (kind == "subtree")
      kind_ = kind_subtree;
    else
      fail_at(at, "unknown kind '" + kind + "' (state or subtree)");
  }

  void read_top() {
    has_top_ = true;
    top_at_ = in_.token_start();
    read_array([&] {
      top_offsets_.push_back(in_.token_start());
      const Id id = read_id();
      if (id == null_id) fail_at(top_offsets_.back(), "a top-level node cannot be null");
      top_.push_back(id);
    });
  }

  // ---- run-time types ----

  void read_types(std::size_t at) {
    in_.seek(at);
    read_array([&] { read_type(); });
  }

  void read_type() {
    const std::size_t at = in_.token_start();
    TypeDefinition def;
    std::optional<std::string> name, kind;
    std::size_t kind_at = at;
    std::optional<std::size_t> values_at, fields_at;
    read_object([&](const std::string& key, std::size_t key_at) {
      if (key == "type") {
        name = read_string("a type name");
      } else if (key == "kind") {
        kind_at = in_.token_start();
        kind = read_string("a kind of type");
      } else if (key == "underlying") {
        const std::size_t type_at = in_.token_start();
        def.underlying = &type_named(type_at, read_string("an integer type name"));
      } else if (key == "values") {
        values_at = in_.token_start();
        read_array([&] {
          TextReader::Nest nest(in_);
          in_.expect('[');
          std::string value_name = read_string("a value name");
          in_.expect(',');
          def.values.push_back({std::move(value_name), in_.integer()});
          in_.expect(']');
        });
      } else if (key == "fields") {
        fields_at = in_.token_start();
        read_array([&] {
          TextReader::Nest nest(in_);
          in_.expect('[');
          std::string field_name = read_string("a field name");
          in_.expect(',');
          const std::size_t type_at = in_.token_start();
          def.fields.emplace_back(std::move(field_name), &type_named(type_at, read_string("a type name")));
          in_.expect(']');
        });
      } else {
        warnings_.push_back(where(key_at) + ": unknown member '" + key + "' in a type is ignored");
        in_.skip_value();
      }
    });
    if (!name || !kind) fail_at(at, "a type needs a \"type\" name and a \"kind\"");
    def.name = *name;
    if (*kind == "struct") {
      def.kind = TypeKind::Struct;
      if (values_at) fail_at(*values_at, "struct '" + def.name + "' has fields, not values");
      if (def.underlying != nullptr) fail_at(at, "struct '" + def.name + "' has no underlying type");
    } else if (*kind == "enum" || *kind == "flags") {
      def.kind = *kind == "enum" ? TypeKind::Enum : TypeKind::Flags;
      if (fields_at) fail_at(*fields_at, *kind + " '" + def.name + "' has values, not fields");
    } else {
      fail_at(kind_at, "unknown kind of type '" + *kind + "' (enum, flags or struct)");
    }
    resolve_type(at, def);
  }

  // ---- classes ----

  void read_classes(std::size_t at) {
    in_.seek(at);
    read_array([&] { read_class(); });
  }

  void read_class() {
    const std::size_t at = in_.token_start();
    std::optional<std::string> name;
    std::optional<ClassDefinition> def;
    std::vector<std::pair<std::string, std::string>> saved;
    std::vector<std::size_t> saved_at;
    read_object([&](const std::string& key, std::size_t key_at) {
      if (key == "class") {
        name = read_string("a class name");
      } else if (key == "base") {
        if (!def) def.emplace();
        def->base = read_string("a class name");
      } else if (key == "abstract") {
        if (!def) def.emplace();
        def->abstract = read_bool();
      } else if (key == "properties") {
        if (!def) def.emplace();
        read_array([&] { def->properties.push_back(read_definition_property()); });
      } else if (key == "saved") {
        read_object([&](const std::string& prop, std::size_t) {
          saved_at.push_back(in_.token_start());
          saved.emplace_back(prop, read_string("a type name"));
        });
      } else {
        warnings_.push_back(where(key_at) + ": unknown member '" + key + "' in a class is ignored");
        in_.skip_value();
      }
    });
    if (!name) fail_at(at, "a class needs a \"class\" name");
    if (def) {
      def->name = *name;
      if (def->base.empty()) fail_at(at, "run-time class '" + *name + "' needs a \"base\"");
    }
    if (by_name_.count(*name) != 0) fail_at(at, "class '" + *name + "' is listed twice");
    std::vector<SavedProperty> listed(saved.size());
    for (std::size_t i = 0; i < saved.size(); ++i) listed[i] = {saved[i].first, saved[i].second, saved_at[i]};
    TextClass& tc = text_class(at, *name, def ? &*def : nullptr, listed);
    for (std::size_t i = 0; i < saved.size(); ++i) {
      if (!tc.file_types.emplace(saved[i].first, i).second)
        fail_at(saved_at[i], "property '" + saved[i].first + "' is listed twice");
      tc.saved_names.push_back(saved[i].first);
      tc.type_names.push_back(saved[i].second);
      tc.type_at.push_back(saved_at[i]);
    }
    make_slots(at, tc);
  }

  ClassDefinition::Property read_definition_property() {
    const std::size_t at = in_.token_start();
    std::optional<std::string> name;
    const MetaType* type = nullptr;
    PropertyFlags flags = DefaultFlags;
    std::optional<std::size_t> default_at;
    read_object([&](const std::string& key, std::size_t key_at) {
      if (key == "name") {
        name = read_string("a property name");
      } else if (key == "type") {
        const std::size_t type_at = in_.token_start();
        type = &type_named(type_at, read_string("a type name"));
      } else if (key == "flags") {
        flags = read_flags();
      } else if (key == "default") {
        default_at = in_.token_start();
        in_.skip_value();  // read once the type is known
      } else {
        warnings_.push_back(where(key_at) + ": unknown member '" + key +
                            "' in a property definition is ignored");
        in_.skip_value();
      }
    });
    if (!name || type == nullptr) fail_at(at, "a property definition needs a \"name\" and a \"type\"");
    Value value(*type);
    if (default_at && !type->is_reference()) {
      const std::size_t resume = in_.position();
      in_.seek(*default_at);
      type->read_text(value.data(), in_, nullptr);
      in_.seek(resume);
    }
    return {std::move(*name), type, flags, std::move(value)};
  }

  TextClass& text_class(std::size_t at, const std::string& name, const ClassDefinition* def,
                        std::span<const SavedProperty> saved = {}) {
    if (auto it = by_name_.find(name); it != by_name_.end()) return it->second;
    ClassEntry& entry = classes_.emplace_back();
    entry.cls = &resolve_class(at, name, def, saved);
    return by_name_.emplace(name, TextClass{&entry, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}})
        .first->second;
  }

  // One slot per saved property of today's class (with the file's type where it names one), then one for
  // each property the file lists that the class no longer has.
  void make_slots(std::size_t at, TextClass& tc) {
    ClassEntry& e = *tc.entry;
    std::vector<bool> used(tc.type_names.size());
    auto saved_index = [&](const MetaProperty& p) -> std::size_t {  // npos: the file does not say
      auto it = tc.file_types.find(p.name());
      for (std::size_t k = 0; it == tc.file_types.end() && k < p.aliases().size(); ++k)
        it = tc.file_types.find(p.aliases()[k]);
      return it == tc.file_types.end() ? std::string::npos : it->second;
    };
    for (const MetaProperty* p : e.cls->properties()) {
      if (!is_saved(*p)) continue;
      const std::size_t i = saved_index(*p);
      if (i == std::string::npos) {
        e.slots.push_back(make_slot(at, *e.cls, p->name(), {}));
      } else {
        used[i] = true;
        e.slots.push_back(make_slot(tc.type_at[i], *e.cls, p->name(), tc.type_names[i]));
      }
      tc.props.push_back(p);
      tc.names.push_back(p->name());
    }
    for (std::size_t i = 0; i < tc.saved_names.size(); ++i) {  // properties the class no longer has
      if (used[i] || e.cls->find_property(tc.saved_names[i]) != nullptr) continue;
      e.slots.push_back(make_slot(tc.type_at[i], *e.cls, tc.saved_names[i], tc.type_names[i]));
      tc.props.push_back(nullptr);
      tc.names.push_back(tc.saved_names[i]);
    }
    for (const Slot& s : e.slots)
      tc.scratch.emplace_back(s.prop == nullptr ? Value() : Value(s.convert ? *s.file_type : s.prop->type()));
    tc.given_by.assign(e.slots.size(), 0);
    if (e.slots.size() > wide_class)
      for (std::size_t i = 0; i < e.slots.size(); ++i) {
        if (tc.props[i] != nullptr)
          tc.slot_of_prop.emplace(tc.props[i], i);
        else
          tc.slot_of_name.emplace(tc.names[i], i);
      }
  }

  TextClass& class_named(std::size_t at, const std::string& name) {
    if (auto it = by_name_.find(name); it != by_name_.end()) return it->second;
    TextClass& tc = text_class(at, name, nullptr);  // not in the class table: today's class as it is
    make_slots(at, tc);
    return tc;
  }

  // ---- instances ----

  void read_instances(std::size_t at) {
    in_.seek(at);
    read_array([&] { read_instance(); });
  }

  void read_instance() {
    SavedInstance x{null_id, nullptr, in_.token_start(), values_.size(), 0};
    TextClass* tc = nullptr;
    std::vector<std::pair<std::string, std::size_t>> early;  // properties seen before "@class"
    bool has_id = false;
    read_object([&](const std::string& key, std::size_t key_at) {
      if (key == "@id") {
        if (has_id) fail_at(key_at, "\"@id\" is given twice");
        has_id = true;
        const std::size_t id_at = in_.token_start();
        x.id = in_.unsigned_integer();
        if (x.id == null_id) fail_at(id_at, "instance id 0 is not valid");
      } else if (key == "@class") {
        if (tc != nullptr) fail_at(key_at, "\"@class\" is given twice");
        const std::size_t class_at = in_.token_start();
        tc = &class_named(class_at, read_string("a class name"));
        x.entry = tc->entry;
        const std::size_t resume = in_.position();
        for (const auto& [name, value_at] : early) {
          in_.seek(value_at);
          read_property(*tc, name, value_at, x.offset);
        }
        in_.seek(resume);
      } else if (tc == nullptr) {
        early.emplace_back(key, in_.token_start());
        in_.skip_value();
      } else {
        read_property(*tc, key, key_at, x.offset);
      }
    });
    if (!has_id) fail_at(x.offset, "an instance needs an \"@id\"");
    if (tc == nullptr) fail_at(x.offset, "instance #" + std::to_string(x.id) + " names no \"@class\"");
    x.count = values_.size() - x.first;
    instances_.push_back(x);
  }

  void read_property(TextClass& tc, const std::string& key, std::size_t key_at, std::size_t instance_at) {
    const ClassEntry& e = *tc.entry;
    const MetaProperty* prop = e.cls->find_property(key);  // through aliases too
    std::size_t index = e.slots.size();
    if (e.slots.size() <= wide_class) {
      for (std::size_t i = 0; i < e.slots.size() && index == e.slots.size(); ++i)
        if (prop != nullptr ? tc.props[i] == prop : tc.names[i] == key) index = i;
    } else if (prop != nullptr) {
      if (auto it = tc.slot_of_prop.find(prop); it != tc.slot_of_prop.end()) index = it->second;
    } else if (auto it = tc.slot_of_name.find(key); it != tc.slot_of_name.end()) {
      index = it->second;
    }
    if (index == e.slots.size()) {  // neither a saved property of the class nor one the file declared
      if (std::find(tc.reported.begin(), tc.reported.end(), key) == tc.reported.end()) {
        tc.reported.push_back(key);
        warnings_.push_back(where(key_at) + ": class '" + e.cls->name() + "' has no saved property '" + key +
                            "': its values are dropped");
      }
      in_.skip_value();
      return;
    }
    const std::size_t instance = instances_.size() + 1;  // the number of the instance being read
    if (tc.given_by[index] == instance) fail_at(key_at, "property '" + key + "' is given twice");
    tc.given_by[index] = instance;
    const Slot& s = e.slots[index];
    if (s.prop == nullptr) {  // reported once per class, when the slots were made
      in_.skip_value();
      return;
    }
    const std::size_t at = in_.token_start();
    SavedValue v = new_value(s, instance_at, at);
    const MetaType& type = s.prop->type();
    if (type.is_ref_list()) {
      read_array([&] {
        const std::size_t id_at = in_.token_start();
        const Id id = read_id();
        if (id == null_id) fail_at(id_at, "a reference list cannot hold null");
        ids_.push_back(id);
      });
    } else if (type.is_reference()) {
      ids_.push_back(read_id());
    } else {
      Value& scratch = tc.scratch[index];
      const MetaType& read_as = s.convert ? *s.file_type : type;
      read_as.assign(scratch.data(), s.convert ? Value(read_as).data() : s.prop->default_value().data());
      read_as.read_text(scratch.data(), in_, nullptr);
      bytes_.clear();
      ByteWriter w(bytes_);
      if (s.convert) {
        Value converted;
        try {
          converted = scratch.convert_to(type);
        } catch (const Error& err) {
          fail_at(at, "value of " + s.prop->name() + ": " + err.what());
        }
        type.write_bytes(converted.data(), w);
      } else {
        type.write_bytes(scratch.data(), w);
      }
      set_bytes(v, own(bytes_), at);
    }
    keep_value(v);
  }

  TextReader in_;
  mutable struct {
    std::size_t pos = 0, line = 1, line_start = 0;
  } where_;  // where() counted lines up to pos
  std::unordered_map<std::string, TextClass> by_name_;
  std::vector<std::uint8_t> bytes_;
};

}  // namespace

std::unique_ptr<LoadModel> read_text(Registry& registry, std::span<const std::uint8_t> bytes,
                                     std::string_view origin, const LoadOptions& options) {
  auto reader = std::make_unique<TextSnapshotReader>(registry, bytes, origin, options);
  reader->read();
  return reader;
}

}  // namespace vsd::io::detail
