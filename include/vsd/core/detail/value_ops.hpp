/** @file
 *  @brief Definitions of the per-C++-type value operations declared in meta_type.hpp.
 */
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "vsd/core/bytes.hpp"
#include "vsd/core/meta_type.hpp"
#include "vsd/core/text.hpp"

namespace vsd::detail {

template <class T>
bool equal_values(const T& a, const T& b) {
  if constexpr (std::is_floating_point_v<T>) {
    return a == b || (a != a && b != b);  // NaN equals NaN here: "unchanged" and deep equality need it
  } else if constexpr (is_std_vector<T>::value) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (!equal_values(a[i], b[i])) return false;
    return true;
  } else if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T> || std::is_same_v<T, std::string>) {
    return a == b;
  } else {
    return struct_equal(meta_type<T>(), &a, &b);
  }
}

template <class T>
std::size_t hash_value(const T& v) {
  if constexpr (std::is_floating_point_v<T>) {
    if (v != v) return 0x7ff8000000000000ULL;     // every NaN equals every NaN here, so they hash alike
    return std::hash<T>{}(v == T(0) ? T(0) : v);  // +0 and -0 are equal, so they hash alike
  } else if constexpr (is_std_vector<T>::value) {
    std::size_t h = v.size();
    for (const auto& e : v) h = hash_combine(h, hash_value(e));
    return h;
  } else if constexpr (std::is_enum_v<T>) {
    return std::hash<std::underlying_type_t<T>>{}(static_cast<std::underlying_type_t<T>>(v));
  } else if constexpr (std::is_arithmetic_v<T> || std::is_same_v<T, std::string>) {
    return std::hash<T>{}(v);
  } else {
    return struct_hash(meta_type<T>(), &v);
  }
}

template <class T>
void text_out(const MetaType& t, const T& v, std::string& out) {
  if constexpr (std::is_same_v<T, bool>) {
    out += v ? "true" : "false";
  } else if constexpr (std::is_integral_v<T>) {
    out += std::to_string(v);
  } else if constexpr (std::is_floating_point_v<T>) {
    write_real(out, v);  // the shortest text for T itself: 0.1f prints as 0.1
  } else if constexpr (std::is_same_v<T, std::string>) {
    write_quoted(out, v);
  } else if constexpr (std::is_enum_v<T>) {
    enum_write_text(t, &v, out);
  } else if constexpr (is_std_vector<T>::value) {
    using E = typename T::value_type;
    const MetaType& et = meta_type<E>();
    out.push_back('[');
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (i != 0) out += ", ";
      text_out<E>(et, v[i], out);
    }
    out.push_back(']');
  } else {
    struct_write_text(t, &v, out);
  }
}

template <class T>
void text_in(const MetaType& t, T& v, TextReader& in, const RefResolver* refs) {
  if constexpr (std::is_same_v<T, bool>) {
    const std::size_t at = in.token_start();
    const auto id = in.identifier();
    if (id == "true") {
      v = true;
    } else if (id == "false") {
      v = false;
    } else {
      in.fail_at(at, "expected true or false, found '" + std::string(id) + "'");
    }
  } else if constexpr (std::is_integral_v<T>) {
    const std::size_t at = in.token_start();
    if constexpr (std::is_signed_v<T>) {
      const std::int64_t x = in.integer();
      if (x < std::numeric_limits<T>::min() || x > std::numeric_limits<T>::max())
        in.fail_at(at, std::to_string(x) + " is out of range for " + t.name());
      v = static_cast<T>(x);
    } else {
      const std::uint64_t x = in.unsigned_integer();
      if (x > std::numeric_limits<T>::max())
        in.fail_at(at, std::to_string(x) + " is out of range for " + t.name());
      v = static_cast<T>(x);
    }
  } else if constexpr (std::is_same_v<T, float>) {
    v = in.real_float();
  } else if constexpr (std::is_floating_point_v<T>) {
    v = static_cast<T>(in.real());
  } else if constexpr (std::is_same_v<T, std::string>) {
    v = in.string();
  } else if constexpr (std::is_enum_v<T>) {
    enum_read_text(t, &v, in);
  } else if constexpr (is_std_vector<T>::value) {
    using E = typename T::value_type;
    const MetaType& et = meta_type<E>();
    TextReader::Nest nest(in);
    T result;
    for (bool first = true; vector_read_text_next(in, first); first = false) {
      E e = DefaultValue<E>::make();
      text_in<E>(et, e, in, refs);
      result.push_back(std::move(e));
    }
    v = std::move(result);
  } else {
    struct_read_text(t, &v, in, refs);
  }
}

template <class T>
void bytes_out(const MetaType& t, const T& v, ByteWriter& out) {
  if constexpr (std::is_same_v<T, bool>) {
    out.u8(v ? 1 : 0);
  } else if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>) {
    out.fixed(v);
  } else if constexpr (std::is_same_v<T, std::string>) {
    out.string(v);
  } else if constexpr (is_std_vector<T>::value) {
    using E = typename T::value_type;
    const MetaType& et = meta_type<E>();
    vector_write_bytes_size(out, v.size());
    if constexpr (std::is_arithmetic_v<E> && !std::is_same_v<E, bool>) {
      out.raw(v.data(), v.size() * sizeof(E));
    } else {
      for (const auto& e : v) bytes_out<E>(et, e, out);
    }
  } else {
    struct_write_bytes(t, &v, out);
  }
}

template <class T>
void bytes_in(const MetaType& t, T& v, ByteReader& in, const RefResolver* refs) {
  if constexpr (std::is_same_v<T, bool>) {
    const std::size_t at = in.position();
    const auto b = in.u8();
    if (b > 1) in.fail_at(at, "a bool must be 0 or 1, found " + std::to_string(b));
    v = b != 0;
  } else if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>) {
    v = in.fixed<T>();
  } else if constexpr (std::is_same_v<T, std::string>) {
    v = in.string();
  } else if constexpr (is_std_vector<T>::value) {
    using E = typename T::value_type;
    const MetaType& et = meta_type<E>();
    if constexpr (std::is_arithmetic_v<E> && !std::is_same_v<E, bool>) {
      const std::size_t n = vector_read_bytes_size(in, sizeof(E));
      T result(n);
      in.raw(result.data(), n * sizeof(E));
      v = std::move(result);
    } else {
      const std::size_t n = vector_read_bytes_size(in, 1);
      T result;
      // The count is checked against one byte per element, but an element may take far more memory than
      // that (a frame: 128 bytes): past a megabyte, memory grows with what is really read.
      result.reserve(std::min(n, (std::size_t{1} << 20) / sizeof(E) + 1));
      for (std::size_t i = 0; i < n; ++i) {
        E e = DefaultValue<E>::make();
        bytes_in<E>(et, e, in, refs);
        result.push_back(std::move(e));
      }
      v = std::move(result);
    }
  } else {
    (void)t;
    struct_read_bytes(t, &v, in, refs);
  }
}

}  // namespace vsd::detail
