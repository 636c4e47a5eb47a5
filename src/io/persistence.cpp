// The public persistence API (vsd/io/snapshot.hpp): what a save writes, and the choice of format.
#include <algorithm>
#include <cctype>
#include <new>

#include "formats.hpp"
#include "vsd/io/file.hpp"

namespace vsd::io {

namespace detail {

SaveSet::SaveSet(std::vector<const SimStateInstance*> members, std::uint8_t kind, std::vector<Id> top,
                 SaveReport* report)
    : members_(std::move(members)), kind_(kind), top_(std::move(top)), report_(report) {
  member_set_.reserve(members_.size());
  for (const SimStateInstance* x : members_) {
    member_set_.insert(x);
    add_class(x->meta());
  }
  if (report_ != nullptr) *report_ = SaveReport{members_.size(), 0};
}

void SaveSet::add_class(const MetaInstance& c) {
  if (index_.count(&c) != 0) return;
  if (c.is_runtime()) add_class(*c.base());  // a run-time base is defined before its subclasses
  index_.emplace(&c, classes_.size());
  classes_.push_back(&c);
  if (c.is_runtime())  // its definition names the types of all its own properties
    for (const MetaProperty* p : c.own_properties()) add_type(p->type());
}

void SaveSet::add_type(const MetaType& t) {
  if (t.is_reference() || t.cpp_tag() != nullptr || type_set_.count(&t) != 0) return;
  if (t.kind() == TypeKind::Vector) {  // "vector<E>": made from its element by name
    add_type(*t.element());
    return;
  }
  for (const auto& f : t.fields()) add_type(*f.type);  // what a struct holds is defined first
  type_set_.insert(&t);
  types_.push_back(&t);
}

Id SaveSet::member_id(const SimStateInstance* t) {
  if (t == nullptr) return null_id;
  if (member_set_.count(t) != 0) return t->id();
  if (report_ != nullptr) ++report_->cut_references;
  return null_id;
}

void SaveSet::reference_ids(const SimStateInstance& x, const MetaProperty& p, std::vector<Id>& out) {
  const void* at = p.address(x);
  if (!p.type().is_ref_list()) {
    out.push_back(member_id(static_cast<const RefBase*>(at)->get()));
    return;
  }
  const auto& list = *static_cast<const RefListBase*>(at);
  for (std::size_t i = 0; i < list.size(); ++i)
    if (const Id id = member_id(list.at(i)); id != null_id) out.push_back(id);
}

}  // namespace detail

namespace {

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

std::vector<std::uint8_t> write(detail::SaveSet& set, Format format) {
  return format == Format::Text ? detail::write_text(set) : detail::write_binary(set);
}

std::unique_ptr<detail::LoadModel> read(Registry& registry, std::span<const std::uint8_t> bytes,
                                        std::string_view origin, const LoadOptions& options) {
  return format_of(bytes, origin) == Format::Text ? detail::read_text(registry, bytes, origin, options)
                                                  : detail::read_binary(registry, bytes, origin, options);
}

// Runs @p f, turning running out of memory (a file whose model does not fit) into a vsd::Error that
// names the file, like every other reason a load fails.
template <class F>
auto out_of_memory_is_an_error(std::string_view origin, std::string_view doing, F&& f) {
  try {
    return f();
  } catch (const std::bad_alloc&) {
    throw Error(std::string(origin) + ": out of memory " + std::string(doing));
  }
}

LoadReport load_into(SimState& state, Node* parent, std::span<const std::uint8_t> bytes,
                     std::string_view origin, const LoadOptions& options = {}) {
  return out_of_memory_is_an_error(origin, "while loading", [&] {
    LoadReport report = read(state.environment().registry(), bytes, origin, options)->apply(state, parent);
    report.format = format_of(bytes, origin);
    return report;
  });
}

}  // namespace

Format format_for(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".json" ? Format::Text : Format::Binary;
}

Format format_of(std::span<const std::uint8_t> bytes, std::string_view origin) {
  // A binary snapshot starts with "VSDS" (a shorter start of it is a truncated one: its reader says so).
  const std::size_t head = std::min<std::size_t>(bytes.size(), 4);
  if (head > 0 && std::equal(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(head), "VSDS"))
    return Format::Binary;
  // Text: JSON, after an optional UTF-8 byte order mark and blanks, starts with '{'.
  std::size_t i = bytes.size() >= 3 && bytes[0] == 0xEF && bytes[1] == 0xBB && bytes[2] == 0xBF ? 3 : 0;
  while (i < bytes.size() && (bytes[i] == ' ' || bytes[i] == '\t' || bytes[i] == '\n' || bytes[i] == '\r'))
    ++i;
  if (i < bytes.size() && bytes[i] == '{') return Format::Text;
  throw Error(std::string(origin) +
              ": byte 0: not a vsd file: neither a binary snapshot (\"VSDS\") nor a text file (JSON, '{')");
}

std::vector<std::uint8_t> save_bytes(const SimState& state, Format format, SaveReport* report) {
  std::vector<const SimStateInstance*> members;
  for (SimStateInstance* x : state.instances()) members.push_back(x);
  std::vector<Id> top;
  for (const Node* n : state.database().children()) top.push_back(n->id());
  detail::SaveSet set(std::move(members), detail::kind_state, std::move(top), report);
  return write(set, format);
}

std::vector<std::uint8_t> save_bytes(const Node& root, Format format, SaveReport* report) {
  if (root.is_a<Database>()) return save_bytes(root.state(), format, report);
  detail::SaveSet set(composite_closure(root), detail::kind_subtree, {root.id()}, report);
  return write(set, format);
}

LoadReport check_bytes(std::span<const std::uint8_t> bytes, std::string_view origin, Registry& registry,
                       const LoadOptions& options) {
  return out_of_memory_is_an_error(origin, "while reading", [&] {
    LoadReport report = read(registry, bytes, origin, options)->summary();
    report.format = format_of(bytes, origin);
    return report;
  });
}

LoadReport load_bytes(SimState& state, std::span<const std::uint8_t> bytes, std::string_view origin) {
  return load_into(state, nullptr, bytes, origin);
}

LoadReport load_bytes(Node& parent, std::span<const std::uint8_t> bytes, std::string_view origin) {
  return load_into(parent.state(), &parent, bytes, origin);
}

LoadReport load_bytes(SimState& state, std::span<const std::uint8_t> bytes, std::string_view origin,
                      const LoadOptions& options) {
  return load_into(state, nullptr, bytes, origin, options);
}

LoadReport load_bytes(Node& parent, std::span<const std::uint8_t> bytes, std::string_view origin,
                      const LoadOptions& options) {
  return load_into(parent.state(), &parent, bytes, origin, options);
}

SaveReport save(const SimState& state, const std::filesystem::path& path, Format format) {
  SaveReport report;
  write_file_atomically(path, out_of_memory_is_an_error(path.string(), "while saving",
                                                        [&] { return save_bytes(state, format, &report); }));
  return report;
}

SaveReport save(const Node& root, const std::filesystem::path& path, Format format) {
  SaveReport report;
  write_file_atomically(path, out_of_memory_is_an_error(path.string(), "while saving",
                                                        [&] { return save_bytes(root, format, &report); }));
  return report;
}

SaveReport save(const SimState& state, const std::filesystem::path& path) {
  return save(state, path, format_for(path));
}

SaveReport save(const Node& root, const std::filesystem::path& path) {
  return save(root, path, format_for(path));
}

LoadReport load(SimState& state, const std::filesystem::path& path) {
  return load_bytes(state, read_file(path), path.string());
}

LoadReport load(Node& parent, const std::filesystem::path& path) {
  return load_bytes(parent, read_file(path), path.string());
}

LoadReport load(SimState& state, const std::filesystem::path& path, const LoadOptions& options) {
  return load_bytes(state, read_file(path), path.string(), options);
}

LoadReport load(Node& parent, const std::filesystem::path& path, const LoadOptions& options) {
  return load_bytes(parent, read_file(path), path.string(), options);
}

}  // namespace vsd::io
