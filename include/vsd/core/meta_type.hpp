/** @file
 *  @brief MetaType (the paper's MetaTypeVal): describes every type a property can hold.
 *
 *  A MetaType knows the size and alignment of its values and a table of operations on them:
 *  construct, copy, destroy, assign, compare, hash, text and binary conversion. Built-in types are bool,
 *  the signed and unsigned integers, float, double, std::string, Eigen vectors, quaternions and
 *  Isometry3d frames, std::vector of any of these, and references. Users add enums (VSD_ENUM), flags
 *  (VSD_FLAGS) and simple structs (VSD_STRUCT). `vsd::meta_type<T>()` returns the one MetaType of T.
 *
 *  MetaTypes are immutable once built and live for the whole program.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "vsd/core/config.hpp"
#include "vsd/core/detail/pp.hpp"

namespace vsd {

class MetaType;
class MetaInstance;
class MetaProperty;
class SimStateInstance;
class TextReader;
class ByteWriter;
class ByteReader;

/// @brief What kind of value a MetaType describes.
enum class TypeKind : std::uint8_t {
  Bool,
  Int,
  UInt,
  Float,
  Double,
  String,
  Enum,
  Flags,
  Struct,
  Vector,
  Ref,        ///< composite reference (counted)
  SharedRef,  ///< shared reference (not counted, nulled when the target dies)
  RefList,    ///< list of composite references
  SharedRefList
};

/// @brief Resolves instance ids while references are read from text or bytes.
class RefResolver {
 public:
  /// @brief The instance with id @p id, or nullptr when there is none.
  [[nodiscard]] virtual SimStateInstance* resolve(Id id) const = 0;

 protected:
  ~RefResolver() = default;
};

/// @brief Element access of a Vector MetaType (std::vector<T> and run-time vectors alike). Elements go in
/// and out by copy, so that std::vector<bool> is served too; indices are in range (MetaType checks).
struct VectorOps {
  std::size_t (*size)(const MetaType&, const void* vec) noexcept;
  void (*get)(const MetaType&, const void* vec, std::size_t i, void* out);  ///< assigns to a live value
  void (*set)(const MetaType&, void* vec, std::size_t i, const void* in);
  void (*push)(const MetaType&, void* vec, const void* in);  ///< appends a copy
};

/// @brief The operations of a MetaType. One table may serve several MetaTypes (e.g. all enums of a size).
struct TypeOps {
  void (*construct)(const MetaType&, void* dst);  ///< default value into raw memory
  void (*copy_construct)(const MetaType&, void* dst, const void* src);
  void (*move_construct)(const MetaType&, void* dst, void* src) noexcept;
  void (*destroy)(const MetaType&, void* obj) noexcept;
  void (*assign)(const MetaType&, void* dst, const void* src);
  bool (*equal)(const MetaType&, const void* a, const void* b);  ///< references compare by id
  std::size_t (*hash)(const MetaType&, const void* obj);
  void (*write_text)(const MetaType&, const void* obj, std::string& out);
  void (*read_text)(const MetaType&, void* obj, TextReader& in, const RefResolver* refs);
  void (*write_bytes)(const MetaType&, const void* obj, ByteWriter& out);
  void (*read_bytes)(const MetaType&, void* obj, ByteReader& in, const RefResolver* refs);
  /// For reference kinds: binds the storage to the instance and property that hold it.
  void (*bind)(const MetaType&, void* obj, SimStateInstance* holder, const MetaProperty* prop) = nullptr;
  /// For Vector types: element access.
  const VectorOps* vector = nullptr;
  /// For types whose binary form always has one size (numbers, bools, enums, Eigen vectors, quaternions and
  /// frames): that size, and a writer of exactly what write_bytes writes into raw memory. Recording frames a
  /// set's old and new value with it in one step (transaction.cpp); 0 and null for the other types.
  std::size_t fixed_bytes = 0;
  void (*write_fixed)(const void* obj, std::uint8_t* out) noexcept = nullptr;
};

/// @brief Describes a value type. See the file comment.
class MetaType {
 public:
  /// @brief One named value of an enum or flags type.
  struct EnumValue {
    std::string name;
    std::int64_t value;
  };
  /// @brief One field of a struct type, reached by offset or, where no offset exists, by get/set.
  struct Field {
    std::string name;
    const MetaType* type;
    std::size_t offset;                       ///< npos when get/set are used
    void (*get)(const void* obj, void* out);  ///< copies the field out (assigns into a live value)
    void (*set)(void* obj, const void* in);
  };
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);

  MetaType(std::string name, TypeKind kind, std::size_t size, std::size_t align, const TypeOps& ops)
      : name_(std::move(name)), ops_(&ops), size_(size), align_(align), kind_(kind) {}
  MetaType(const MetaType&) = delete;
  MetaType& operator=(const MetaType&) = delete;
  MetaType(MetaType&&) = default;

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] TypeKind kind() const noexcept { return kind_; }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] std::size_t alignment() const noexcept { return align_; }
  [[nodiscard]] const TypeOps& ops() const noexcept { return *ops_; }
  /// @brief Identity of the C++ type behind this MetaType (null for types made at run time).
  [[nodiscard]] const void* cpp_tag() const noexcept { return tag_; }
  /// @brief True when this is the MetaType of C++ type T (cheap: no call).
  template <class T>
  [[nodiscard]] bool is() const noexcept;

  [[nodiscard]] bool is_reference() const noexcept { return kind_ >= TypeKind::Ref; }
  [[nodiscard]] bool is_ref_list() const noexcept {
    return kind_ == TypeKind::RefList || kind_ == TypeKind::SharedRefList;
  }
  [[nodiscard]] bool is_composite() const noexcept {
    return kind_ == TypeKind::Ref || kind_ == TypeKind::RefList;
  }
  [[nodiscard]] bool is_arithmetic() const noexcept {
    return kind_ <= TypeKind::Double && kind_ != TypeKind::Bool;
  }
  /// @brief True for unsigned integers and for enums and flags whose underlying type is unsigned.
  [[nodiscard]] bool is_unsigned() const noexcept { return unsigned_; }
  /// @brief True when @p v is representable by this integer, enum or flags type.
  [[nodiscard]] bool integer_fits(std::int64_t v) const noexcept;

  /// @brief Named values of an Enum or Flags type.
  [[nodiscard]] const std::vector<EnumValue>& enum_values() const noexcept { return enum_values_; }
  /// @brief Fields of a Struct type.
  [[nodiscard]] const std::vector<Field>& fields() const noexcept { return fields_; }
  /// @brief Element type of a Vector type.
  [[nodiscard]] const MetaType* element() const noexcept { return element_; }
  /// @brief How deeply a value nests: 1 for a value without parts, one more than its deepest field for a
  /// struct, one more than its element for a vector. Run-time types are limited to max_depth, so that
  /// the recursive operations on values (copy, compare, read, write) stay shallow whatever a file defines.
  [[nodiscard]] std::size_t depth() const noexcept { return depth_; }
  static constexpr std::size_t max_depth = 64;
  /// @brief Class a reference type points to.
  [[nodiscard]] const MetaInstance* target() const {
    return target_ != nullptr ? target_ : (target_fn_ != nullptr ? &target_fn_() : nullptr);
  }

  /// @brief Name of the enum value @p v, or empty when none has it.
  [[nodiscard]] std::string_view enum_name(std::int64_t v) const noexcept;
  /// @brief Value of the enum name @p n; false when there is none.
  bool enum_value(std::string_view n, std::int64_t& out) const noexcept;
  /// @brief Reads an Enum/Flags/Int/UInt/Bool value as a 64-bit integer.
  [[nodiscard]] std::int64_t load_integer(const void* obj) const noexcept;
  /// @brief Writes an Enum/Flags/Int/UInt/Bool value from a 64-bit integer (truncating to size()).
  void store_integer(void* obj, std::int64_t v) const noexcept;

  // Operations (thin wrappers over the ops table).
  void construct(void* dst) const { ops_->construct(*this, dst); }
  void copy_construct(void* dst, const void* src) const { ops_->copy_construct(*this, dst, src); }
  void move_construct(void* dst, void* src) const noexcept { ops_->move_construct(*this, dst, src); }
  void destroy(void* obj) const noexcept { ops_->destroy(*this, obj); }
  void assign(void* dst, const void* src) const { ops_->assign(*this, dst, src); }
  [[nodiscard]] bool equal(const void* a, const void* b) const { return ops_->equal(*this, a, b); }
  [[nodiscard]] std::size_t hash(const void* obj) const { return ops_->hash(*this, obj); }
  void write_text(const void* obj, std::string& out) const { ops_->write_text(*this, obj, out); }
  void read_text(void* obj, TextReader& in, const RefResolver* refs = nullptr) const {
    ops_->read_text(*this, obj, in, refs);
  }
  void write_bytes(const void* obj, ByteWriter& out) const { ops_->write_bytes(*this, obj, out); }
  void read_bytes(void* obj, ByteReader& in, const RefResolver* refs = nullptr) const {
    ops_->read_bytes(*this, obj, in, refs);
  }
  /// @brief The text form of a value.
  [[nodiscard]] std::string to_text(const void* obj) const;

  // Element access of a Vector type (element(): the MetaType of the elements; @p out and @p in point to
  // live values of it). @throws vsd::Error when this is no vector or @p i is out of range.
  /// @brief The number of elements of the vector at @p vec.
  [[nodiscard]] std::size_t vector_size(const void* vec) const;
  /// @brief Assigns element @p i of the vector at @p vec to @p out.
  void vector_get(const void* vec, std::size_t i, void* out) const;
  /// @brief Assigns @p in to element @p i of the vector at @p vec.
  void vector_set(void* vec, std::size_t i, const void* in) const;
  /// @brief Appends a copy of @p in to the vector at @p vec.
  void vector_push(void* vec, const void* in) const;
  /// @brief Parses a whole text into @p obj.
  /// @param origin names the text in errors (a file, "property speed", ...); empty: "<TYPE value>".
  /// @throws vsd::Error "origin:line:col: what" on bad text.
  void from_text(void* obj, std::string_view text, const RefResolver* refs = nullptr,
                 std::string_view origin = {}) const;

  // Building (used by the declaration macros and by run-time type creation).
  MetaType& add_enum_value(std::string name, std::int64_t value) {
    enum_values_.push_back({std::move(name), value});
    return *this;
  }
  MetaType& add_field(Field f) {
    deepen(*f.type);
    fields_.push_back(std::move(f));
    return *this;
  }
  MetaType& set_cpp_tag(const void* tag) noexcept {
    tag_ = tag;
    return *this;
  }
  MetaType& set_unsigned(bool u) noexcept {
    unsigned_ = u;
    return *this;
  }
  MetaType& set_element(const MetaType* e) noexcept {
    element_ = e;
    if (e != nullptr) deepen(*e);
    return *this;
  }
  MetaType& set_target(const MetaInstance* t) noexcept {
    target_ = t;
    return *this;
  }
  /// @brief Sets the target class through a function, so a class can hold references to itself.
  MetaType& set_target(const MetaInstance& (*fn)()) noexcept {
    target_fn_ = fn;
    return *this;
  }

 private:
  void deepen(const MetaType& part) noexcept {
    if (part.depth_ >= depth_ && part.depth_ < 0xFFFF) depth_ = static_cast<std::uint16_t>(part.depth_ + 1);
  }

  std::string name_;
  const TypeOps* ops_;
  std::size_t size_;
  std::size_t align_;
  TypeKind kind_;
  bool unsigned_ = false;
  std::uint16_t depth_ = 1;  // (in the padding after kind_ and unsigned_)
  const void* tag_ = nullptr;
  std::vector<EnumValue> enum_values_;
  std::vector<Field> fields_;
  const MetaType* element_ = nullptr;
  const MetaInstance* target_ = nullptr;
  const MetaInstance& (*target_fn_)() = nullptr;
};

namespace detail {
/// One object per C++ type whose address identifies the type at compile time: type checks on hot paths
/// compare against a constant instead of calling meta_type<T>().
template <class T>
inline constexpr char type_tag{};
}  // namespace detail

template <class T>
struct TypeTraits;  // specialised below for built-in types; user types use the ADL hook vsd_meta_type(T*)

namespace detail {
template <class T>
concept HasTraits = requires {
  TypeTraits<T>::make();
};
template <class T>
concept HasAdlType = requires(T* p) {
  { vsd_meta_type(p) } -> std::same_as<const MetaType&>;
};
}  // namespace detail

namespace detail {
/// The fixed-width integer with the size and signedness of T: `long long` and `long` (or `char` and
/// `signed char`) share one MetaType, as they share one representation.
template <class T>
using CanonicalInt = std::conditional_t<
    std::is_signed_v<T>,
    std::conditional_t<sizeof(T) == 1, std::int8_t,
                       std::conditional_t<sizeof(T) == 2, std::int16_t,
                                          std::conditional_t<sizeof(T) == 4, std::int32_t, std::int64_t>>>,
    std::conditional_t<sizeof(T) == 1, std::uint8_t,
                       std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                          std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>>;
/// The tag a C++ type's MetaType carries (integers of one representation share one).
template <class T>
constexpr const void* tag_of() noexcept {
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    return &type_tag<CanonicalInt<T>>;
  } else {
    return &type_tag<T>;
  }
}
}  // namespace detail

template <class T>
bool MetaType::is() const noexcept {
  return tag_ == detail::tag_of<T>();
}

/// @brief The MetaType of C++ type T (built-in, or declared with VSD_ENUM / VSD_FLAGS / VSD_STRUCT).
template <class T>
const MetaType& meta_type() {
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool> &&
                !std::is_same_v<T, detail::CanonicalInt<T>>) {
    return meta_type<detail::CanonicalInt<T>>();
  } else if constexpr (detail::HasTraits<T>) {
    static const MetaType type = TypeTraits<T>::make();
    return type;
  } else {
    static_assert(detail::HasAdlType<T>,
                  "vsd::meta_type<T>: T is unknown to the meta-information system; declare it with "
                  "VSD_ENUM, VSD_FLAGS or VSD_STRUCT next to its definition");
    return vsd_meta_type(static_cast<T*>(nullptr));
  }
}

/// @brief True when T is known to the meta-information system.
template <class T>
inline constexpr bool is_meta_type_v = detail::HasTraits<T> || detail::HasAdlType<T>;

namespace detail {

// ---- generic operations, one instantiation per C++ type -------------------------------------------------

template <class T>
bool equal_values(const T& a, const T& b);
template <class T>
std::size_t hash_value(const T& v);
template <class T>
void text_out(const MetaType& t, const T& v, std::string& out);
template <class T>
void text_in(const MetaType& t, T& v, TextReader& in, const RefResolver* refs);
template <class T>
void bytes_out(const MetaType& t, const T& v, ByteWriter& out);
template <class T>
void bytes_in(const MetaType& t, T& v, ByteReader& in, const RefResolver* refs);

// Generic struct and enum operations over the MetaType description (meta_type.cpp).
bool struct_equal(const MetaType& t, const void* a, const void* b);
std::size_t struct_hash(const MetaType& t, const void* obj);
void struct_write_text(const MetaType& t, const void* obj, std::string& out);
void struct_read_text(const MetaType& t, void* obj, TextReader& in, const RefResolver* refs);
void struct_write_bytes(const MetaType& t, const void* obj, ByteWriter& out);
void struct_read_bytes(const MetaType& t, void* obj, ByteReader& in, const RefResolver* refs);
void enum_write_text(const MetaType& t, const void* obj, std::string& out);
void enum_read_text(const MetaType& t, void* obj, TextReader& in);
void vector_write_text_open(std::string& out);
bool vector_read_text_next(TextReader& in, bool first);  // consumes '[' / ',' / ']'; false at ']'
std::size_t vector_read_bytes_size(ByteReader& in, std::size_t min_element_bytes);
void vector_write_bytes_size(ByteWriter& out, std::size_t n);
std::size_t hash_combine(std::size_t seed, std::size_t v) noexcept;

/// The value a default-constructed T has in vsd (Eigen types specialise it: they start uninitialised).
template <class T>
struct DefaultValue {
  static T make() { return T{}; }
};

/// The element access of std::vector<E> (none for other types).
template <class T>
struct VectorAccess {
  static constexpr const VectorOps* ops = nullptr;
};
template <class E, class A>
struct VectorAccess<std::vector<E, A>> {
  using V = std::vector<E, A>;
  static std::size_t size(const MetaType&, const void* v) noexcept {
    return static_cast<const V*>(v)->size();
  }
  static void get(const MetaType&, const void* v, std::size_t i, void* out) {
    *static_cast<E*>(out) = (*static_cast<const V*>(v))[i];
  }
  static void set(const MetaType&, void* v, std::size_t i, const void* in) {
    (*static_cast<V*>(v))[i] = *static_cast<const E*>(in);
  }
  static void push(const MetaType&, void* v, const void* in) {
    static_cast<V*>(v)->push_back(*static_cast<const E*>(in));
  }
  static constexpr VectorOps table{&size, &get, &set, &push};
  static constexpr const VectorOps* ops = &table;
};

/// The binary form of T when every value has the same size (TypeOps::fixed_bytes): here numbers, bools
/// and enums, whose bytes_out is their memory; meta_type_eigen.hpp adds the Eigen types. `write` must put
/// exactly the bytes of bytes_out<T> (tests/core/meta_type_test.cpp compares them for every built-in type).
template <class T, class = void>
struct FixedBytes {
  static constexpr std::size_t size = 0;
  static constexpr void (*write)(const void*, std::uint8_t*) noexcept = nullptr;
};
template <class T>
struct FixedBytes<T, std::enable_if_t<std::is_arithmetic_v<T> || std::is_enum_v<T>>> {
  static constexpr std::size_t size = sizeof(T);
  static void write(const void* obj, std::uint8_t* out) noexcept {
    if constexpr (std::is_same_v<T, bool>) {
      static_assert(sizeof(bool) == 1);
      *out = *static_cast<const bool*>(obj) ? 1 : 0;  // the value, whatever the object representation
    } else {
      std::memcpy(out, obj, sizeof(T));  // little-endian hosts only, as ByteWriter::fixed
    }
  }
};

/// The ops table of a C++ type T, made from the generic operations above.
template <class T>
struct ValueOps {
  static void construct(const MetaType&, void* dst) { ::new (dst) T(DefaultValue<T>::make()); }
  static void copy_construct(const MetaType&, void* dst, const void* src) {
    ::new (dst) T(*static_cast<const T*>(src));
  }
  static void move_construct(const MetaType&, void* dst, void* src) noexcept {
    ::new (dst) T(std::move(*static_cast<T*>(src)));
  }
  static void destroy(const MetaType&, void* obj) noexcept { static_cast<T*>(obj)->~T(); }
  static void assign(const MetaType&, void* dst, const void* src) {
    *static_cast<T*>(dst) = *static_cast<const T*>(src);
  }
  static bool equal(const MetaType&, const void* a, const void* b) {
    return equal_values(*static_cast<const T*>(a), *static_cast<const T*>(b));
  }
  static std::size_t hash(const MetaType&, const void* obj) {
    return hash_value(*static_cast<const T*>(obj));
  }
  static void write_text(const MetaType& t, const void* obj, std::string& out) {
    text_out(t, *static_cast<const T*>(obj), out);
  }
  static void read_text(const MetaType& t, void* obj, TextReader& in, const RefResolver* refs) {
    text_in(t, *static_cast<T*>(obj), in, refs);
  }
  static void write_bytes(const MetaType& t, const void* obj, ByteWriter& out) {
    bytes_out(t, *static_cast<const T*>(obj), out);
  }
  static void read_bytes(const MetaType& t, void* obj, ByteReader& in, const RefResolver* refs) {
    bytes_in(t, *static_cast<T*>(obj), in, refs);
  }
  static constexpr TypeOps table{&construct,  &copy_construct, &move_construct,     &destroy,   &assign,
                                 &equal,      &hash,           &write_text,         &read_text, &write_bytes,
                                 &read_bytes, nullptr,         VectorAccess<T>::ops, FixedBytes<T>::size,
                                 FixedBytes<T>::write};
};

/// Makes the MetaType of a C++ type with ValueOps<T>.
template <class T>
MetaType make_type(std::string name, TypeKind kind) {
  MetaType t(std::move(name), kind, sizeof(T), alignof(T), ValueOps<T>::table);
  t.set_cpp_tag(tag_of<T>());
  if constexpr (std::is_enum_v<T>) {
    t.set_unsigned(std::is_unsigned_v<std::underlying_type_t<T>>);
  } else if constexpr (std::is_integral_v<T>) {
    t.set_unsigned(std::is_unsigned_v<T>);
  }
  return t;
}

template <class T>
struct is_std_vector : std::false_type {};
template <class T, class A>
struct is_std_vector<std::vector<T, A>> : std::true_type {};

}  // namespace detail

// ---- built-in types ---------------------------------------------------------------------------------------

template <>
struct TypeTraits<bool> {
  static MetaType make() { return detail::make_type<bool>("bool", TypeKind::Bool); }
};
template <>
struct TypeTraits<float> {
  static MetaType make() { return detail::make_type<float>("float", TypeKind::Float); }
};
template <>
struct TypeTraits<double> {
  static MetaType make() { return detail::make_type<double>("double", TypeKind::Double); }
};
template <>
struct TypeTraits<std::string> {
  static MetaType make() { return detail::make_type<std::string>("string", TypeKind::String); }
};
template <class T>
requires(std::is_integral_v<T> && !std::is_same_v<T, bool>) struct TypeTraits<T> {
  static MetaType make() {
    std::string name = std::is_signed_v<T> ? "int" : "uint";
    name += std::to_string(sizeof(T) * 8);
    return detail::make_type<T>(std::move(name), std::is_signed_v<T> ? TypeKind::Int : TypeKind::UInt);
  }
};
template <class T>
requires is_meta_type_v<T>
struct TypeTraits<std::vector<T>> {
  static MetaType make() {
    MetaType t = detail::make_type<std::vector<T>>("vector<" + meta_type<T>().name() + ">", TypeKind::Vector);
    t.set_element(&meta_type<T>());
    return t;
  }
};

}  // namespace vsd

// ---- declaring user types ---------------------------------------------------------------------------------

#define VSD_DETAIL_ENUM_VALUE(E, v) t.add_enum_value(#v, static_cast<std::int64_t>(E::v));

/// @brief Declares enum (or enum class) @p E with its named values to the meta-information system.
/// Write it in the namespace of E: `VSD_ENUM(Color, Red, Green, Blue)`.
#define VSD_ENUM(E, ...)                                               \
  [[maybe_unused]] inline const ::vsd::MetaType& vsd_meta_type(E*) {   \
    static const ::vsd::MetaType type = [] {                           \
      auto t = ::vsd::detail::make_type<E>(#E, ::vsd::TypeKind::Enum); \
      VSD_PP_FOR_EACH(VSD_DETAIL_ENUM_VALUE, E, __VA_ARGS__)           \
      return t;                                                        \
    }();                                                               \
    return type;                                                       \
  }

/// @brief Declares a flags enum @p E whose values are single bits: `VSD_FLAGS(Access, Read, Write)`.
/// Its text form is `Read|Write`; combine values with the enum's own operators.
#define VSD_FLAGS(E, ...)                                               \
  [[maybe_unused]] inline const ::vsd::MetaType& vsd_meta_type(E*) {    \
    static const ::vsd::MetaType type = [] {                            \
      auto t = ::vsd::detail::make_type<E>(#E, ::vsd::TypeKind::Flags); \
      VSD_PP_FOR_EACH(VSD_DETAIL_ENUM_VALUE, E, __VA_ARGS__)            \
      return t;                                                         \
    }();                                                                \
    return type;                                                        \
  }

#define VSD_DETAIL_STRUCT_FIELD(S, f) \
  t.add_field({#f, &::vsd::meta_type<decltype(S::f)>(), offsetof(S, f), nullptr, nullptr});

/// @brief Declares a simple struct @p S (standard layout, default constructible, fields of known types)
/// with the fields to describe: `VSD_STRUCT(Pose2d, x, y, theta)`. Write it in the namespace of S.
#define VSD_STRUCT(S, ...)                                                                    \
  [[maybe_unused]] inline const ::vsd::MetaType& vsd_meta_type(S*) {                          \
    static_assert(std::is_standard_layout_v<S>, "VSD_STRUCT needs a standard-layout struct"); \
    static const ::vsd::MetaType type = [] {                                                  \
      auto t = ::vsd::detail::make_type<S>(#S, ::vsd::TypeKind::Struct);                      \
      VSD_PP_FOR_EACH(VSD_DETAIL_STRUCT_FIELD, S, __VA_ARGS__)                                \
      return t;                                                                               \
    }();                                                                                      \
    return type;                                                                              \
  }

#include "vsd/core/detail/value_ops.hpp"
#include "vsd/core/meta_type_eigen.hpp"
