/** @file
 *  @brief Internal: the little JSON the inspector needs — a writer that appends to a string, and a reader of
 *  request bodies (one flat object whose members are kept as raw JSON text, so that a property's value is
 *  parsed by its own MetaType, with line:col in every error).
 */
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "vsd/core/fwd.hpp"

namespace vsd::web::detail {

/// @brief Appends JSON to a string; commas are placed by the writer.
class JsonWriter {
 public:
  JsonWriter& begin_object();
  JsonWriter& end_object();
  JsonWriter& begin_array();
  JsonWriter& end_array();
  /// @brief A member name inside an object (the value follows).
  JsonWriter& key(std::string_view k);
  JsonWriter& string(std::string_view s);
  JsonWriter& number(double v);
  JsonWriter& number(std::int64_t v);
  JsonWriter& number(std::uint64_t v);
  JsonWriter& number(int v) { return number(static_cast<std::int64_t>(v)); }
  JsonWriter& boolean(bool v);
  JsonWriter& null();
  /// @brief Text that is JSON already (a value's text form).
  JsonWriter& raw(std::string_view json);
  /// @brief key(k) then the value.
  template <class T>
  JsonWriter& member(std::string_view k, const T& v) {
    key(k);
    return value(v);
  }
  JsonWriter& value(std::string_view s) { return string(s); }
  JsonWriter& value(const std::string& s) { return string(s); }
  JsonWriter& value(const char* s) { return string(s); }
  JsonWriter& value(double v) { return number(v); }
  JsonWriter& value(bool v) { return boolean(v); }
  JsonWriter& value(std::int64_t v) { return number(v); }
  JsonWriter& value(std::uint64_t v) { return number(v); }
  JsonWriter& value(int v) { return number(v); }
  JsonWriter& value(unsigned long long v) { return number(static_cast<std::uint64_t>(v)); }
  JsonWriter& value(long long v) { return number(static_cast<std::int64_t>(v)); }
  [[nodiscard]] const std::string& str() const noexcept { return out_; }
  [[nodiscard]] std::string take() { return std::move(out_); }

 private:
  void separate();
  std::string out_;
  std::vector<bool> first_;  // per open container: no member written yet
  bool after_key_ = false;
};

/// @brief A request body: one JSON object, its members as raw JSON text in order of appearance.
class JsonObject {
 public:
  /// @brief Parses @p body. @throws vsd::Error "request:line:col: what" unless it is exactly one object
  /// (duplicate members are refused too).
  static JsonObject parse(std::string_view body);
  /// @brief The raw text of member @p name, or nullptr.
  [[nodiscard]] const std::string_view* find(std::string_view name) const noexcept;
  /// @brief The raw text of member @p name. @throws vsd::Error naming the missing member.
  [[nodiscard]] std::string_view require(std::string_view name) const;
  /// @brief Member @p name as an integer id (a number or "@N"). @throws vsd::Error when absent or not one.
  [[nodiscard]] Id id(std::string_view name) const;
  /// @brief Member @p name as a string. @throws vsd::Error when absent or not a string.
  [[nodiscard]] std::string string(std::string_view name) const;
  /// @brief Member @p name as a bool. @throws vsd::Error when absent or not true/false.
  [[nodiscard]] bool boolean(std::string_view name) const;
  /// @brief Member @p name as an array of raw JSON values. @throws vsd::Error when absent or no array.
  [[nodiscard]] std::vector<std::string_view> array(std::string_view name) const;

 private:
  std::vector<std::pair<std::string, std::string_view>> members_;
};

/// @brief Parses an id from query or JSON text: digits, or "@digits". @throws vsd::Error otherwise.
[[nodiscard]] Id parse_id(std::string_view text, std::string_view what);
/// @brief Parses a non-negative count from a query parameter (clamped to @p max). @throws vsd::Error.
[[nodiscard]] std::size_t parse_count(std::string_view text, std::string_view what, std::size_t max);

}  // namespace vsd::web::detail
