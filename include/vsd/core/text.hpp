/** @file
 *  @brief TextReader: the small scanner behind MetaType::from_text, with line:col in every error.
 *
 *  The text form of every value is one JSON value (RFC 8259), so whole files can be built by joining them:
 *  `true`, `-12`, `0.5`, `"quoted \"string\""` (JSON escapes; control characters as `\u00XX`), the
 *  floating-point specials as the strings `"nan"`, `"inf"`, `"-inf"`, enum names `"Red"` (a value without
 *  a name as a number), flags `"Read|Write"` (unnamed bits as a number inside the string, nothing set
 *  as `0`), structs `{"x": 1, "name": "a"}` (all-numeric structs and vectors as lists `[1, 2, 3]`),
 *  references `"@42"` or `null`, reference lists `["@1", "@2"]`, frames
 *  `{"translation": [x, y, z], "rotation": [[r00, r01, r02], [r10, r11, r12], [r20, r21, r22]]}`.
 *
 *  The reader also takes the older, not quite JSON forms: bare keys `{x: 1}`, bare names `Red` and
 *  `Read|Write`, bare references `@42`, bare `nan`/`inf`, and a frame's rotation as a quaternion.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace vsd {

/// @brief Reads the text form of values; throws vsd::Error("where:line:col: what") on bad input.
class TextReader {
 public:
  /// @param text the text to read; @param origin names the source in error messages (file name, ...).
  explicit TextReader(std::string_view text, std::string_view origin = {}) noexcept
      : text_(text), origin_(origin) {}

  void skip_ws() noexcept;
  /// @brief Next non-blank character, or '\0' at the end.
  [[nodiscard]] char peek() noexcept;
  [[nodiscard]] bool at_end() noexcept;
  /// @brief Consumes @p c if it is next (after blanks) and says so.
  bool accept(char c) noexcept;
  /// @brief Consumes @p c or throws.
  void expect(char c);
  /// @brief Reads an identifier: [A-Za-z_][A-Za-z0-9_]*, parts joined by '::'.
  std::string_view identifier();
  /// @brief Reads a quoted string with JSON escapes (a `\u` surrogate pair is one UTF-8 character).
  std::string string();
  /// @brief Reads an object key: a quoted string, or a bare identifier (the older form).
  std::string key();
  /// @brief Reads a number token (sign, digits, '.', exponent, nan, inf) without converting it.
  std::string_view number_token();
  std::int64_t integer();
  std::uint64_t unsigned_integer();
  double real();
  /// @brief Reads a number as a float (the shortest float text reads back exactly; overflow throws).
  float real_float();
  /// @brief Skips exactly one value of any form: a JSON object, array, string, number, true, false or
  /// null, or an older vsd form (bare names incl. `A|B`, `@42`, bare nan/inf). Nesting is guarded as in
  /// reading (Nest): too deep a value throws instead of overflowing the stack; bad input throws.
  void skip_value();
  /// @brief Moves the read position to @p pos (clamped to the end), e.g. to read a value whose key was
  /// seen earlier: position() or token_start() taken then is the @p pos to come back to.
  void seek(std::size_t pos) noexcept { pos_ = pos < text_.size() ? pos : text_.size(); }
  /// @brief The whole text being read.
  [[nodiscard]] std::string_view text() const noexcept { return text_; }
  /// @brief Throws vsd::Error that names origin:line:col and @p what.
  [[noreturn]] void fail(std::string_view what) const;
  /// @brief Like fail(), reporting the position @p pos (where the offending token started).
  [[noreturn]] void fail_at(std::size_t pos, std::string_view what) const;
  /// @brief Position of the next non-blank character (the start of the next token).
  std::size_t token_start() noexcept {
    skip_ws();
    return pos_;
  }
  /// @brief Throws unless only blanks remain.
  void expect_end();

  [[nodiscard]] std::size_t position() const noexcept { return pos_; }
  [[nodiscard]] std::size_t line() const noexcept;
  [[nodiscard]] std::size_t column() const noexcept;

  /// @brief Nesting guard for recursive values: throws beyond a fixed depth instead of overflowing.
  class Nest {
   public:
    explicit Nest(TextReader& r);
    ~Nest() { --r_.depth_; }
    Nest(const Nest&) = delete;
    Nest& operator=(const Nest&) = delete;

   private:
    TextReader& r_;
  };

 private:
  template <class T>
  T number(const char* what);
  unsigned hex4();
  void skip_bare();

  std::string_view text_;
  std::string_view origin_;
  std::size_t pos_ = 0;
  int depth_ = 0;
};

/// @brief Appends @p s to @p out as a quoted, escaped string.
void write_quoted(std::string& out, std::string_view s);
/// @brief Appends the shortest text that reads back as exactly @p v; NaN and the infinities are written
/// as the JSON strings "nan", "inf" and "-inf" (real() and real_float() read them quoted or bare).
void write_real(std::string& out, double v);
void write_real(std::string& out, float v);

}  // namespace vsd
