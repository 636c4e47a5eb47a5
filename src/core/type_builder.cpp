// Run-time value types: enums, flags, structs and vectors of them (vsd/core/type_builder.hpp).
#include "vsd/core/type_builder.hpp"

#include <algorithm>
#include <cstring>
#include <functional>
#include <memory>
#include <new>
#include <utility>

#include "vsd/core/bytes.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/text.hpp"

namespace vsd {

namespace detail {

namespace {

// ---- enums and flags: an integer of the type's size, read and written as the C++ enums are -------------

void enum_construct(const MetaType& t, void* dst) { std::memset(dst, 0, t.size()); }
void enum_copy(const MetaType& t, void* dst, const void* src) { std::memcpy(dst, src, t.size()); }
void enum_move(const MetaType& t, void* dst, void* src) noexcept { std::memcpy(dst, src, t.size()); }
void enum_destroy(const MetaType&, void*) noexcept {}
void enum_assign(const MetaType& t, void* dst, const void* src) { std::memcpy(dst, src, t.size()); }
bool enum_equal(const MetaType& t, const void* a, const void* b) { return std::memcmp(a, b, t.size()) == 0; }
std::size_t enum_hash(const MetaType& t, const void* obj) {
  return std::hash<std::int64_t>{}(t.load_integer(obj));
}
void enum_text_out(const MetaType& t, const void* obj, std::string& out) { enum_write_text(t, obj, out); }
void enum_text_in(const MetaType& t, void* obj, TextReader& in, const RefResolver*) {
  enum_read_text(t, obj, in);
}
void enum_bytes_out(const MetaType& t, const void* obj, ByteWriter& out) { out.raw(obj, t.size()); }
void enum_bytes_in(const MetaType& t, void* obj, ByteReader& in, const RefResolver*) {
  in.raw(obj, t.size());
}

constexpr TypeOps enum_ops{&enum_construct, &enum_copy,      &enum_move,     &enum_destroy,
                           &enum_assign,    &enum_equal,     &enum_hash,     &enum_text_out,
                           &enum_text_in,   &enum_bytes_out, &enum_bytes_in, nullptr};

// ---- structs: fields at offsets, each handled by its own type ------------------------------------------

char* at(void* obj, const MetaType::Field& f) { return static_cast<char*>(obj) + f.offset; }
const char* at(const void* obj, const MetaType::Field& f) { return static_cast<const char*>(obj) + f.offset; }

// Constructs field by field; a field that throws destroys the ones before it.
template <class Make>
void construct_fields(const MetaType& t, void* dst, Make&& make) {
  std::size_t done = 0;
  try {
    for (const auto& f : t.fields()) {
      make(f);
      ++done;
    }
  } catch (...) {
    while (done-- > 0) t.fields()[done].type->destroy(at(dst, t.fields()[done]));
    throw;
  }
}

void struct_construct(const MetaType& t, void* dst) {
  construct_fields(t, dst, [&](const MetaType::Field& f) { f.type->construct(at(dst, f)); });
}
void struct_copy(const MetaType& t, void* dst, const void* src) {
  construct_fields(t, dst, [&](const MetaType::Field& f) { f.type->copy_construct(at(dst, f), at(src, f)); });
}
void struct_move(const MetaType& t, void* dst, void* src) noexcept {
  for (const auto& f : t.fields()) f.type->move_construct(at(dst, f), at(src, f));
}
void struct_destroy(const MetaType& t, void* obj) noexcept {
  for (const auto& f : t.fields()) f.type->destroy(at(obj, f));
}
void struct_assign(const MetaType& t, void* dst, const void* src) {
  for (const auto& f : t.fields()) f.type->assign(at(dst, f), at(src, f));
}

constexpr TypeOps struct_ops{&struct_construct, &struct_copy,        &struct_move,       &struct_destroy,
                             &struct_assign,    &struct_equal,       &struct_hash,       &struct_write_text,
                             &struct_read_text, &struct_write_bytes, &struct_read_bytes, nullptr};

// ---- vectors of run-time types: elements of the element type in one aligned block ------------------------

struct RtVector {
  unsigned char* data = nullptr;
  std::size_t size = 0;
  std::size_t capacity = 0;
};

RtVector& vec(void* obj) { return *static_cast<RtVector*>(obj); }
const RtVector& vec(const void* obj) { return *static_cast<const RtVector*>(obj); }
std::size_t stride(const MetaType& t) { return t.element()->size(); }  // sizes are multiples of alignment
void* element_at(const MetaType& t, const RtVector& v, std::size_t i) { return v.data + i * stride(t); }

unsigned char* allocate(const MetaType& t, std::size_t n) {
  return static_cast<unsigned char*>(
      ::operator new(n* stride(t), std::align_val_t(t.element()->alignment())));
}
void release(const MetaType& t, RtVector& v) noexcept {
  for (std::size_t i = 0; i < v.size; ++i) t.element()->destroy(element_at(t, v, i));
  if (v.data != nullptr) ::operator delete(v.data, std::align_val_t(t.element()->alignment()));
  v = RtVector{};
}

// Room for one more element (moved over to a larger block when full).
void reserve_one(const MetaType& t, RtVector& v) {
  if (v.size < v.capacity) return;
  const std::size_t cap = std::max<std::size_t>(4, v.capacity * 2);
  unsigned char* block = allocate(t, cap);
  for (std::size_t i = 0; i < v.size; ++i) {
    t.element()->move_construct(block + i * stride(t), element_at(t, v, i));
    t.element()->destroy(element_at(t, v, i));
  }
  if (v.data != nullptr) ::operator delete(v.data, std::align_val_t(t.element()->alignment()));
  v.data = block;
  v.capacity = cap;
}

void vector_construct(const MetaType&, void* dst) { ::new (dst) RtVector(); }
void vector_copy(const MetaType& t, void* dst, const void* src) {
  const RtVector& s = vec(src);
  RtVector& d = *::new (dst) RtVector();
  if (s.size == 0) return;
  d.data = allocate(t, s.size);
  d.capacity = s.size;
  try {
    for (; d.size < s.size; ++d.size)
      t.element()->copy_construct(element_at(t, d, d.size), element_at(t, s, d.size));
  } catch (...) {
    release(t, d);
    throw;
  }
}
void vector_move(const MetaType&, void* dst, void* src) noexcept {
  ::new (dst) RtVector(std::exchange(vec(src), RtVector{}));
}
void vector_destroy(const MetaType& t, void* obj) noexcept { release(t, vec(obj)); }
void vector_assign(const MetaType& t, void* dst, const void* src) {
  if (dst == src) return;
  alignas(RtVector) unsigned char copy[sizeof(RtVector)];
  vector_copy(t, copy, src);
  release(t, vec(dst));
  vec(dst) = vec(copy);
}
bool vector_equal(const MetaType& t, const void* a, const void* b) {
  const RtVector &x = vec(a), &y = vec(b);
  if (x.size != y.size) return false;
  for (std::size_t i = 0; i < x.size; ++i)
    if (!t.element()->equal(element_at(t, x, i), element_at(t, y, i))) return false;
  return true;
}
std::size_t vector_hash(const MetaType& t, const void* obj) {
  const RtVector& v = vec(obj);
  std::size_t h = v.size;
  for (std::size_t i = 0; i < v.size; ++i) h = hash_combine(h, t.element()->hash(element_at(t, v, i)));
  return h;
}
void vector_text_out(const MetaType& t, const void* obj, std::string& out) {
  const RtVector& v = vec(obj);
  out.push_back('[');
  for (std::size_t i = 0; i < v.size; ++i) {
    if (i != 0) out += ", ";
    t.element()->write_text(element_at(t, v, i), out);
  }
  out.push_back(']');
}
// Reads into a new vector; @p obj changes only when the whole value was read.
template <class ReadOne>
void vector_read(const MetaType& t, void* obj, ReadOne&& read_one) {
  RtVector result;
  try {
    while (true) {
      reserve_one(t, result);
      void* e = element_at(t, result, result.size);
      t.element()->construct(e);
      ++result.size;
      if (!read_one(e)) {
        t.element()->destroy(e);
        --result.size;
        break;
      }
    }
  } catch (...) {
    release(t, result);
    throw;
  }
  release(t, vec(obj));
  vec(obj) = result;
}
void vector_text_in(const MetaType& t, void* obj, TextReader& in, const RefResolver* refs) {
  TextReader::Nest nest(in);
  bool first = true;
  vector_read(t, obj, [&](void* e) {
    if (!vector_read_text_next(in, first)) return false;
    first = false;
    t.element()->read_text(e, in, refs);
    return true;
  });
}
void vector_bytes_out(const MetaType& t, const void* obj, ByteWriter& out) {
  const RtVector& v = vec(obj);
  vector_write_bytes_size(out, v.size);
  for (std::size_t i = 0; i < v.size; ++i) t.element()->write_bytes(element_at(t, v, i), out);
}
void vector_bytes_in(const MetaType& t, void* obj, ByteReader& in, const RefResolver* refs) {
  // Every element takes at least one byte (no struct is empty), so the count is checked against the rest.
  const std::size_t n = vector_read_bytes_size(in, 1);
  std::size_t i = 0;
  vector_read(t, obj, [&](void* e) {
    if (i == n) return false;
    ++i;
    t.element()->read_bytes(e, in, refs);
    return true;
  });
}

std::size_t vector_size(const MetaType&, const void* obj) noexcept { return vec(obj).size; }
void vector_get(const MetaType& t, const void* obj, std::size_t i, void* out) {
  t.element()->assign(out, element_at(t, vec(obj), i));
}
void vector_set(const MetaType& t, void* obj, std::size_t i, const void* in) {
  t.element()->assign(element_at(t, vec(obj), i), in);
}
void vector_push(const MetaType& t, void* obj, const void* in) {
  RtVector& v = vec(obj);
  reserve_one(t, v);
  t.element()->copy_construct(element_at(t, v, v.size), in);
  ++v.size;
}
constexpr VectorOps vector_access{&vector_size, &vector_get, &vector_set, &vector_push};

constexpr TypeOps vector_ops{&vector_construct, &vector_copy,      &vector_move,     &vector_destroy,
                             &vector_assign,    &vector_equal,     &vector_hash,     &vector_text_out,
                             &vector_text_in,   &vector_bytes_out, &vector_bytes_in, nullptr,
                             &vector_access};

bool is_identifier(std::string_view s) {
  if (s.empty()) return false;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    const bool alpha = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
    if (!alpha && (i == 0 || c < '0' || c > '9')) return false;
  }
  return true;
}

}  // namespace

std::unique_ptr<MetaType> make_runtime_vector(const MetaType& element) {
  if (element.is_reference()) throw_error("vector<" + element.name() + ">: a vector cannot hold references");
  if (element.depth() >= MetaType::max_depth)
    throw_error("vector<" + element.name() + ">: values would nest deeper than " +
                std::to_string(MetaType::max_depth) + " levels");
  auto t = std::make_unique<MetaType>("vector<" + element.name() + ">", TypeKind::Vector, sizeof(RtVector),
                                      alignof(RtVector), vector_ops);
  t->set_element(&element);
  return t;
}

bool same_definition(const MetaType& a, const MetaType& b) noexcept {
  if (&a == &b) return true;
  if (a.kind() != b.kind() || a.name() != b.name()) return false;
  switch (a.kind()) {
    case TypeKind::Enum:
    case TypeKind::Flags: {
      if (a.size() != b.size() || a.is_unsigned() != b.is_unsigned() ||
          a.enum_values().size() != b.enum_values().size())
        return false;
      for (const auto& v : a.enum_values()) {
        std::int64_t other = 0;
        if (!b.enum_value(v.name, other) || other != v.value) return false;
      }
      return true;
    }
    case TypeKind::Struct: {
      if (a.fields().size() != b.fields().size()) return false;
      for (std::size_t i = 0; i < a.fields().size(); ++i)
        if (a.fields()[i].name != b.fields()[i].name ||
            !same_definition(*a.fields()[i].type, *b.fields()[i].type))
          return false;
      return true;
    }
    case TypeKind::Vector:
      return same_definition(*a.element(), *b.element());
    default:  // built-in types of one name are one type
      return a.cpp_tag() == b.cpp_tag() && a.target() == b.target();
  }
}

}  // namespace detail

// ---- EnumBuilder
// --------------------------------------------------------------------------------------------

EnumBuilder::EnumBuilder(std::string name, TypeKind kind)
    : name_(std::move(name)),
      kind_(kind),
      underlying_(kind == TypeKind::Flags ? &meta_type<std::uint32_t>() : &meta_type<std::int32_t>()) {
  if (kind != TypeKind::Enum && kind != TypeKind::Flags)
    detail::throw_error("EnumBuilder '" + name_ + "': the kind is Enum or Flags");
}

EnumBuilder& EnumBuilder::underlying(const MetaType& integer) {
  if (integer.kind() != TypeKind::Int && integer.kind() != TypeKind::UInt)
    detail::throw_error("enum '" + name_ + "': its underlying type must be an integer type, not " +
                        integer.name());
  underlying_ = &integer;
  return *this;
}

EnumBuilder& EnumBuilder::value(std::string name, std::int64_t value) {
  values_.push_back({std::move(name), value});
  return *this;
}

const MetaType& EnumBuilder::define(Registry& registry) {
  const std::string what = (kind_ == TypeKind::Flags ? "flags '" : "enum '") + name_ + "'";
  if (name_.empty()) detail::throw_error("an enum needs a name");
  auto t = std::make_unique<MetaType>(name_, kind_, underlying_->size(), underlying_->alignment(),
                                      detail::enum_ops);
  t->set_unsigned(underlying_->is_unsigned());
  for (const auto& v : values_) {
    if (!detail::is_identifier(v.name))
      detail::throw_error(what + ": value name '" + v.name + "' is not an identifier");
    std::int64_t existing = 0;
    if (t->enum_value(v.name, existing))
      detail::throw_error(what + ": value '" + v.name + "' is given twice");
    if (!t->integer_fits(v.value))
      detail::throw_error(what + ": value " + v.name + " = " + std::to_string(v.value) + " does not fit " +
                          underlying_->name());
    t->add_enum_value(v.name, v.value);
  }
  return registry.define(std::move(t));
}

const MetaType& EnumBuilder::define() { return define(Registry::global()); }

// ---- StructBuilder
// ------------------------------------------------------------------------------------------

StructBuilder::StructBuilder(std::string name) : name_(std::move(name)) {}

StructBuilder& StructBuilder::field(std::string name, const MetaType& type) {
  fields_.emplace_back(std::move(name), &type);
  return *this;
}

const MetaType& StructBuilder::define(Registry& registry) {
  if (name_.empty()) detail::throw_error("a struct needs a name");
  if (fields_.empty()) detail::throw_error("struct '" + name_ + "' has no fields");
  std::size_t size = 0, align = 1;
  std::vector<MetaType::Field> fields;
  for (const auto& [name, type] : fields_) {
    if (name.empty()) detail::throw_error("struct '" + name_ + "': a field needs a name");
    if (type->is_reference())
      detail::throw_error("struct '" + name_ + "': field '" + name + "' cannot be a reference (" +
                          type->name() + ")");
    for (const auto& f : fields)
      if (f.name == name) detail::throw_error("struct '" + name_ + "': field '" + name + "' is given twice");
    const std::size_t a = type->alignment();
    size = (size + a - 1) / a * a;
    fields.push_back({name, type, size, nullptr, nullptr});
    size += type->size();
    align = std::max(align, a);
  }
  size = (size + align - 1) / align * align;
  auto t = std::make_unique<MetaType>(name_, TypeKind::Struct, size, align, detail::struct_ops);
  for (auto& f : fields) t->add_field(std::move(f));
  if (t->depth() > MetaType::max_depth)
    detail::throw_error("struct '" + name_ + "': values would nest deeper than " +
                        std::to_string(MetaType::max_depth) + " levels");
  return registry.define(std::move(t));
}

const MetaType& StructBuilder::define() { return define(Registry::global()); }

}  // namespace vsd
