#include "vsd/core/meta_type.hpp"

#include <cstring>
#include <limits>
#include <string>

#include "vsd/core/bytes.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/text.hpp"

namespace vsd {

std::string_view MetaType::enum_name(std::int64_t v) const noexcept {
  for (const auto& e : enum_values_)
    if (e.value == v) return e.name;
  return {};
}

bool MetaType::enum_value(std::string_view n, std::int64_t& out) const noexcept {
  for (const auto& e : enum_values_) {
    if (e.name == n) {
      out = e.value;
      return true;
    }
  }
  return false;
}

bool MetaType::integer_fits(std::int64_t v) const noexcept {
  if (size_ >= 8) return !unsigned_ || v >= 0 || kind_ == TypeKind::Flags;
  const int bits = static_cast<int>(size_ * 8);
  if (unsigned_ || kind_ == TypeKind::Flags) return v >= 0 && v < (std::int64_t{1} << bits);
  return v >= -(std::int64_t{1} << (bits - 1)) && v < (std::int64_t{1} << (bits - 1));
}

std::int64_t MetaType::load_integer(const void* obj) const noexcept {
  const bool is_unsigned = unsigned_ || kind_ == TypeKind::Flags || kind_ == TypeKind::Bool;
  switch (size_) {
    case 1: {
      std::uint8_t v;
      std::memcpy(&v, obj, 1);
      return is_unsigned ? static_cast<std::int64_t>(v)
                         : static_cast<std::int64_t>(static_cast<std::int8_t>(v));
    }
    case 2: {
      std::uint16_t v;
      std::memcpy(&v, obj, 2);
      return is_unsigned ? static_cast<std::int64_t>(v)
                         : static_cast<std::int64_t>(static_cast<std::int16_t>(v));
    }
    case 4: {
      std::uint32_t v;
      std::memcpy(&v, obj, 4);
      return is_unsigned ? static_cast<std::int64_t>(v)
                         : static_cast<std::int64_t>(static_cast<std::int32_t>(v));
    }
    default: {
      std::int64_t v;
      std::memcpy(&v, obj, 8);
      return v;
    }
  }
}

void MetaType::store_integer(void* obj, std::int64_t v) const noexcept {
  switch (size_) {
    case 1: {
      auto x = static_cast<std::uint8_t>(v);
      std::memcpy(obj, &x, 1);
      break;
    }
    case 2: {
      auto x = static_cast<std::uint16_t>(v);
      std::memcpy(obj, &x, 2);
      break;
    }
    case 4: {
      auto x = static_cast<std::uint32_t>(v);
      std::memcpy(obj, &x, 4);
      break;
    }
    default:
      std::memcpy(obj, &v, 8);
  }
}

std::string MetaType::to_text(const void* obj) const {
  std::string out;
  write_text(obj, out);
  return out;
}

namespace {
const VectorOps& vector_access(const MetaType& t) {
  if (t.ops().vector == nullptr) detail::throw_error("type '" + t.name() + "' is not a vector");
  return *t.ops().vector;
}
void check_index(const MetaType& t, const VectorOps& ops, const void* vec, std::size_t i) {
  const std::size_t n = ops.size(t, vec);
  if (i >= n)
    detail::throw_error(t.name() + ": index " + std::to_string(i) + " out of range (size " +
                        std::to_string(n) + ")");
}
}  // namespace

std::size_t MetaType::vector_size(const void* vec) const { return vector_access(*this).size(*this, vec); }
void MetaType::vector_get(const void* vec, std::size_t i, void* out) const {
  const VectorOps& ops = vector_access(*this);
  check_index(*this, ops, vec, i);
  ops.get(*this, vec, i, out);
}
void MetaType::vector_set(void* vec, std::size_t i, const void* in) const {
  const VectorOps& ops = vector_access(*this);
  check_index(*this, ops, vec, i);
  ops.set(*this, vec, i, in);
}
void MetaType::vector_push(void* vec, const void* in) const { vector_access(*this).push(*this, vec, in); }

void MetaType::from_text(void* obj, std::string_view text, const RefResolver* refs,
                         std::string_view origin) const {
  const std::string fallback = origin.empty() ? "<" + name_ + " value>" : std::string();
  TextReader in(text, origin.empty() ? std::string_view(fallback) : origin);
  read_text(obj, in, refs);
  in.expect_end();
}

namespace detail {

std::size_t hash_combine(std::size_t seed, std::size_t v) noexcept {
  return seed ^ (v + 0x9e3779b97f4a7c15ULL + (seed << 6) + (seed >> 2));
}

namespace {

// A field's value is reached in place when it has an offset, else copied through get/set into a
// temporary of the field's type.
class FieldValue {
 public:
  FieldValue(const MetaType::Field& f, const void* obj) : f_(f) {
    if (f.offset != MetaType::npos) {
      ptr_ = static_cast<const char*>(obj) + f.offset;
    } else {
      VSD_ASSERT(f.type->size() <= sizeof(buf_) && f.type->alignment() <= alignof(std::max_align_t),
                 "get/set field too large for the scratch buffer");
      f.type->construct(buf_);
      owned_ = true;
      f.get(obj, buf_);
      ptr_ = buf_;
    }
  }
  ~FieldValue() {
    if (owned_) f_.type->destroy(buf_);
  }
  FieldValue(const FieldValue&) = delete;
  FieldValue& operator=(const FieldValue&) = delete;
  [[nodiscard]] const void* get() const noexcept { return ptr_; }
  [[nodiscard]] void* mut() noexcept { return const_cast<void*>(ptr_); }
  void store(void* obj) const {
    if (owned_) f_.set(obj, buf_);
  }

 private:
  const MetaType::Field& f_;
  const void* ptr_ = nullptr;
  alignas(std::max_align_t) unsigned char buf_[128];
  bool owned_ = false;
};

bool all_numeric(const MetaType& t) {
  for (const auto& f : t.fields())
    if (!f.type->is_arithmetic()) return false;
  return !t.fields().empty();
}

}  // namespace

bool struct_equal(const MetaType& t, const void* a, const void* b) {
  for (const auto& f : t.fields()) {
    FieldValue fa(f, a), fb(f, b);
    if (!f.type->equal(fa.get(), fb.get())) return false;
  }
  return true;
}

std::size_t struct_hash(const MetaType& t, const void* obj) {
  std::size_t h = t.fields().size();
  for (const auto& f : t.fields()) {
    FieldValue fv(f, obj);
    h = hash_combine(h, f.type->hash(fv.get()));
  }
  return h;
}

void struct_write_text(const MetaType& t, const void* obj, std::string& out) {
  const bool positional = all_numeric(t);
  out.push_back(positional ? '[' : '{');
  bool first = true;
  for (const auto& f : t.fields()) {
    if (!first) out += ", ";
    first = false;
    if (!positional) {
      write_quoted(out, f.name);  // JSON keys are strings
      out += ": ";
    }
    FieldValue fv(f, obj);
    f.type->write_text(fv.get(), out);
  }
  out.push_back(positional ? ']' : '}');
}

void struct_read_text(const MetaType& t, void* obj, TextReader& in, const RefResolver* refs) {
  TextReader::Nest nest(in);
  const auto& fields = t.fields();
  if (in.accept('[')) {  // positional form: every field, in declaration order
    for (std::size_t i = 0; i < fields.size(); ++i) {
      if (i != 0) in.expect(',');
      FieldValue fv(fields[i], obj);
      fields[i].type->read_text(fv.mut(), in, refs);
      fv.store(obj);
    }
    if (in.peek() != ']') in.fail(t.name() + " has " + std::to_string(fields.size()) + " fields");
    in.expect(']');
    return;
  }
  if (in.peek() != '{') in.fail("expected '{' or '[' to start a " + t.name());
  in.expect('{');
  if (in.accept('}')) return;
  do {
    const std::size_t at = in.token_start();
    const std::string name = in.key();  // "x" or, in the older form, x
    const MetaType::Field* field = nullptr;
    for (const auto& f : fields)
      if (f.name == name) field = &f;
    if (field == nullptr) in.fail_at(at, t.name() + " has no field '" + std::string(name) + "'");
    in.expect(':');
    FieldValue fv(*field, obj);
    field->type->read_text(fv.mut(), in, refs);
    fv.store(obj);
  } while (in.accept(','));
  in.expect('}');
}

void struct_write_bytes(const MetaType& t, const void* obj, ByteWriter& out) {
  for (const auto& f : t.fields()) {
    FieldValue fv(f, obj);
    f.type->write_bytes(fv.get(), out);
  }
}

void struct_read_bytes(const MetaType& t, void* obj, ByteReader& in, const RefResolver* refs) {
  for (const auto& f : t.fields()) {
    FieldValue fv(f, obj);
    f.type->read_bytes(fv.mut(), in, refs);
    fv.store(obj);
  }
}

namespace {

std::string enum_number_text(const MetaType& t, std::int64_t v) {
  return t.is_unsigned() ? std::to_string(static_cast<std::uint64_t>(v)) : std::to_string(v);
}

// One number of an enum or flags text; unsigned 64-bit types take their whole range.
std::int64_t enum_number(const MetaType& t, TextReader& in) {
  const std::size_t at = in.token_start();
  if (in.peek() == '-') {
    const std::int64_t v = in.integer();
    if (!t.integer_fits(v)) in.fail_at(at, std::to_string(v) + " is out of range for " + t.name());
    return v;
  }
  const std::uint64_t u = in.unsigned_integer();
  const auto v = static_cast<std::int64_t>(u);
  const bool fits = u <= static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())
                        ? t.integer_fits(v)
                        : t.size() >= 8 && (t.is_unsigned() || t.kind() == TypeKind::Flags);
  if (!fits) in.fail_at(at, std::to_string(u) + " is out of range for " + t.name());
  return v;
}

// One name or number of an enum or flags text.
std::int64_t enum_part(const MetaType& t, TextReader& in) {
  const std::size_t at = in.token_start();
  const char c = in.peek();
  if (c == '-' || c == '+' || (c >= '0' && c <= '9')) return enum_number(t, in);
  const auto name = in.identifier();
  std::int64_t v = 0;
  if (!t.enum_value(name, v)) in.fail_at(at, "'" + std::string(name) + "' is not a value of " + t.name());
  return v;
}

}  // namespace

void enum_write_text(const MetaType& t, const void* obj, std::string& out) {
  const std::int64_t v = t.load_integer(obj);
  if (t.kind() == TypeKind::Enum) {
    const auto name = t.enum_name(v);
    if (!name.empty()) {
      write_quoted(out, name);
    } else {
      out += enum_number_text(t, v);  // a value without a name still round-trips
    }
    return;
  }
  // Flags: names of the set bits joined by '|' in one string, unnamed bits as a number at its end; no
  // named bit set (nothing set, or only unnamed bits) is a plain number.
  auto rest = static_cast<std::uint64_t>(v);
  std::string names;
  for (const auto& e : t.enum_values()) {
    const auto bit = static_cast<std::uint64_t>(e.value);
    if (bit != 0 && (rest & bit) == bit) {
      if (!names.empty()) names.push_back('|');
      names += e.name;
      rest &= ~bit;
    }
  }
  if (names.empty()) {
    out += std::to_string(rest);
    return;
  }
  if (rest != 0) names += "|" + std::to_string(rest);
  write_quoted(out, names);
}

void enum_read_text(const MetaType& t, void* obj, TextReader& in) {
  // Written "Red" or "Read|Write" (or a number); the older bare forms Red and Read|Write read too. A
  // quoted text is scanned in place rather than unquoted first, so an error points at the offending name.
  const bool quoted = in.accept('"');
  const bool flags = t.kind() == TypeKind::Flags;
  std::int64_t total = 0;
  do {
    const std::int64_t v = enum_part(t, in);
    total = flags ? (total | v) : v;
  } while (flags && in.accept('|'));
  if (quoted) in.expect('"');
  t.store_integer(obj, total);
}

bool vector_read_text_next(TextReader& in, bool first) {
  if (first) {
    in.expect('[');
    return !in.accept(']');
  }
  if (in.accept(']')) return false;
  in.expect(',');
  return true;
}

std::size_t vector_read_bytes_size(ByteReader& in, std::size_t min_element_bytes) {
  return in.size_prefix(min_element_bytes);
}

void vector_write_bytes_size(ByteWriter& out, std::size_t n) { out.varint(n); }

void make_quaternion_fields(MetaType& t) {
  using Q = Eigen::Quaterniond;
  t.add_field({"w", &meta_type<double>(), MetaType::npos,
               [](const void* o, void* out) { *static_cast<double*>(out) = static_cast<const Q*>(o)->w(); },
               [](void* o, const void* in) { static_cast<Q*>(o)->w() = *static_cast<const double*>(in); }});
  t.add_field({"x", &meta_type<double>(), MetaType::npos,
               [](const void* o, void* out) { *static_cast<double*>(out) = static_cast<const Q*>(o)->x(); },
               [](void* o, const void* in) { static_cast<Q*>(o)->x() = *static_cast<const double*>(in); }});
  t.add_field({"y", &meta_type<double>(), MetaType::npos,
               [](const void* o, void* out) { *static_cast<double*>(out) = static_cast<const Q*>(o)->y(); },
               [](void* o, const void* in) { static_cast<Q*>(o)->y() = *static_cast<const double*>(in); }});
  t.add_field({"z", &meta_type<double>(), MetaType::npos,
               [](const void* o, void* out) { *static_cast<double*>(out) = static_cast<const Q*>(o)->z(); },
               [](void* o, const void* in) { static_cast<Q*>(o)->z() = *static_cast<const double*>(in); }});
}

void make_isometry_fields(MetaType& t) {
  using I = Eigen::Isometry3d;
  t.add_field({"translation", &meta_type<Eigen::Vector3d>(), MetaType::npos,
               [](const void* o, void* out) {
                 *static_cast<Eigen::Vector3d*>(out) = static_cast<const I*>(o)->translation();
               },
               [](void* o, const void* in) {
                 static_cast<I*>(o)->translation() = *static_cast<const Eigen::Vector3d*>(in);
               }});
  t.add_field({"rotation", &meta_type<Eigen::Quaterniond>(), MetaType::npos,
               [](const void* o, void* out) {
                 *static_cast<Eigen::Quaterniond*>(out) =
                     Eigen::Quaterniond(static_cast<const I*>(o)->linear());
               },
               [](void* o, const void* in) {
                 static_cast<I*>(o)->linear() =
                     static_cast<const Eigen::Quaterniond*>(in)->normalized().toRotationMatrix();
               }});
}

namespace {

// A frame's rotation: 3 rows of 3 numbers, taken exactly as the linear part, or a quaternion ([w, x, y, z]
// or {"w": ...}; the older form) normalised into a rotation matrix as the rotation field does.
void read_rotation(Eigen::Matrix3d& linear, TextReader& in) {
  const std::size_t start = in.token_start();
  if (in.accept('[') && in.peek() == '[') {
    TextReader::Nest nest(in);
    const auto next = [&](int i) {  // the ',' before element i, or an error when the list ends early
      if (i == 0) return;
      if (in.peek() == ']') in.fail("a rotation matrix is 3 rows of 3 numbers");
      in.expect(',');
    };
    const auto close = [&] {
      if (in.peek() != ']') in.fail("a rotation matrix is 3 rows of 3 numbers");
      in.expect(']');
    };
    for (int r = 0; r < 3; ++r) {
      next(r);
      TextReader::Nest row(in);
      in.expect('[');
      for (int c = 0; c < 3; ++c) {
        next(c);
        linear(r, c) = in.real();
      }
      close();
    }
    close();
    return;
  }
  in.seek(start);
  Eigen::Quaterniond q(linear);
  meta_type<Eigen::Quaterniond>().read_text(&q, in);
  linear = q.normalized().toRotationMatrix();
}

}  // namespace

void isometry_write_text(const Eigen::Isometry3d& v, std::string& out) {
  out += "{\"translation\": [";
  for (int i = 0; i < 3; ++i) {
    if (i != 0) out += ", ";
    write_real(out, v.translation()[i]);
  }
  out += "], \"rotation\": [";
  for (int r = 0; r < 3; ++r) {
    if (r != 0) out += ", ";
    out.push_back('[');
    for (int c = 0; c < 3; ++c) {
      if (c != 0) out += ", ";
      write_real(out, v.linear()(r, c));
    }
    out.push_back(']');
  }
  out += "]}";
}

void isometry_read_text(Eigen::Isometry3d& v, TextReader& in) {
  TextReader::Nest nest(in);
  // Fields not given keep their value, as in any struct; v changes only once the whole text is read.
  Eigen::Vector3d translation = v.translation();
  Eigen::Matrix3d linear = v.linear();
  const MetaType& vector = meta_type<Eigen::Vector3d>();
  if (in.accept('[')) {  // positional [translation, rotation], as the generic struct form took it
    vector.read_text(&translation, in);
    in.expect(',');
    read_rotation(linear, in);
    if (in.peek() != ']') in.fail("Isometry3d has 2 fields");
    in.expect(']');
  } else {
    if (in.peek() != '{') in.fail("expected '{' or '[' to start a Isometry3d");
    in.expect('{');
    if (!in.accept('}')) {
      do {
        const std::size_t at = in.token_start();
        const std::string name = in.key();
        const bool is_translation = name == "translation";
        if (!is_translation && name != "rotation") in.fail_at(at, "Isometry3d has no field '" + name + "'");
        in.expect(':');
        if (is_translation) {
          vector.read_text(&translation, in);
        } else {
          read_rotation(linear, in);
        }
      } while (in.accept(','));
      in.expect('}');
    }
  }
  v.setIdentity();
  v.translation() = translation;
  v.linear() = linear;
}

}  // namespace detail

}  // namespace vsd
