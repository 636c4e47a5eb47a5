#include "vsd/core/text.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>

#include "vsd/core/error.hpp"

namespace vsd {

namespace {
constexpr int max_text_depth = 256;
bool ident_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0 || c == '_'; }
bool ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; }
bool number_start(char c) {
  return std::isdigit(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '+' || c == '.';
}

// NaN and the infinities by name (the sign '+' already dropped), or nothing.
template <class T>
std::optional<T> special_real(std::string_view s) {
  if (s == "nan" || s == "-nan") return std::numeric_limits<T>::quiet_NaN();
  if (s == "inf") return std::numeric_limits<T>::infinity();
  if (s == "-inf") return -std::numeric_limits<T>::infinity();
  return std::nullopt;
}
}  // namespace

TextReader::Nest::Nest(TextReader& r) : r_(r) {
  if (++r_.depth_ > max_text_depth) {
    --r_.depth_;
    r_.fail("values nested deeper than " + std::to_string(max_text_depth));
  }
}

void TextReader::skip_ws() noexcept {
  while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_])) != 0) ++pos_;
}

char TextReader::peek() noexcept {
  skip_ws();
  return pos_ < text_.size() ? text_[pos_] : '\0';
}

bool TextReader::at_end() noexcept {
  skip_ws();
  return pos_ >= text_.size();
}

bool TextReader::accept(char c) noexcept {
  if (peek() != c || at_end()) return false;
  ++pos_;
  return true;
}

void TextReader::expect(char c) {
  if (!accept(c)) {
    if (at_end()) fail(std::string("expected '") + c + "' but the text ended");
    fail(std::string("expected '") + c + "' but found '" + text_[pos_] + "'");
  }
}

std::string_view TextReader::identifier() {
  skip_ws();
  if (pos_ >= text_.size() || !ident_start(text_[pos_])) fail("expected a name");
  const std::size_t start = pos_;
  while (pos_ < text_.size()) {
    if (ident_char(text_[pos_])) {
      ++pos_;
    } else if (text_.substr(pos_, 2) == "::" && pos_ + 2 < text_.size() && ident_start(text_[pos_ + 2])) {
      pos_ += 2;  // qualified names such as vsd::Node
    } else {
      break;
    }
  }
  return text_.substr(start, pos_ - start);
}

std::string TextReader::string() {
  skip_ws();
  if (pos_ >= text_.size() || text_[pos_] != '"') fail("expected a quoted string");
  ++pos_;
  std::string out;
  while (true) {
    if (pos_ >= text_.size()) fail("unterminated string");
    const char c = text_[pos_++];
    if (c == '"') return out;
    if (c != '\\') {
      out.push_back(c);
      continue;
    }
    if (pos_ >= text_.size()) fail("unterminated escape in string");
    const char e = text_[pos_++];
    switch (e) {
      case '"':
        out.push_back('"');
        break;
      case '\\':
        out.push_back('\\');
        break;
      case '/':
        out.push_back('/');
        break;
      case 'n':
        out.push_back('\n');
        break;
      case 't':
        out.push_back('\t');
        break;
      case 'r':
        out.push_back('\r');
        break;
      case 'b':
        out.push_back('\b');
        break;
      case 'f':
        out.push_back('\f');
        break;
      case 'u': {
        const std::size_t escape = pos_ - 2;  // errors point at the backslash
        unsigned code = hex4();
        if (code >= 0xDC00 && code <= 0xDFFF) fail_at(escape, "lone low surrogate in a \\u escape");
        if (code >= 0xD800 && code <= 0xDBFF) {
          // JSON writes a character beyond the BMP as a surrogate pair; it is one 4-byte UTF-8 character.
          if (text_.substr(pos_, 2) != "\\u") fail_at(escape, "lone high surrogate in a \\u escape");
          pos_ += 2;
          const unsigned low = hex4();
          if (low < 0xDC00 || low > 0xDFFF) fail_at(escape, "lone high surrogate in a \\u escape");
          code = 0x10000 + ((code - 0xD800) << 10) + (low - 0xDC00);
        }
        if (code < 0x80) {
          out.push_back(static_cast<char>(code));
        } else if (code < 0x800) {
          out.push_back(static_cast<char>(0xC0 | (code >> 6)));
          out.push_back(static_cast<char>(0x80 | (code & 0x3F)));
        } else if (code < 0x10000) {
          out.push_back(static_cast<char>(0xE0 | (code >> 12)));
          out.push_back(static_cast<char>(0x80 | ((code >> 6) & 0x3F)));
          out.push_back(static_cast<char>(0x80 | (code & 0x3F)));
        } else {
          out.push_back(static_cast<char>(0xF0 | (code >> 18)));
          out.push_back(static_cast<char>(0x80 | ((code >> 12) & 0x3F)));
          out.push_back(static_cast<char>(0x80 | ((code >> 6) & 0x3F)));
          out.push_back(static_cast<char>(0x80 | (code & 0x3F)));
        }
        break;
      }
      default:
        --pos_;
        fail(std::string("unknown escape '\\") + e + "'");
    }
  }
}

// The four hex digits of a \u escape.
unsigned TextReader::hex4() {
  if (text_.size() - pos_ < 4) fail("truncated \\u escape");
  unsigned code = 0;
  auto [p, ec] = std::from_chars(text_.data() + pos_, text_.data() + pos_ + 4, code, 16);
  if (ec != std::errc() || p != text_.data() + pos_ + 4) fail("bad \\u escape");
  pos_ += 4;
  return code;
}

std::string TextReader::key() {
  const char c = peek();
  if (c == '"') return string();
  if (!ident_start(c)) fail("expected a key (a quoted name)");
  return std::string(identifier());
}

std::string_view TextReader::number_token() {
  skip_ws();
  const std::size_t start = pos_;
  if (pos_ < text_.size() && (text_[pos_] == '-' || text_[pos_] == '+')) ++pos_;
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '.' ||
        ((c == '-' || c == '+') && (text_[pos_ - 1] == 'e' || text_[pos_ - 1] == 'E')))
      ++pos_;
    else
      break;
  }
  if (pos_ == start) fail("expected a number");
  return text_.substr(start, pos_ - start);
}

// One number token converted to T with from_chars; the error names the token and points at its start.
template <class T>
T TextReader::number(const char* what) {
  const std::size_t at = token_start();
  if constexpr (std::is_floating_point_v<T>) {
    if (peek() == '"') {  // JSON has no NaN or infinity: they are written as strings
      const std::string s = string();
      std::string_view name = s;
      if (!name.empty() && name[0] == '+') name.remove_prefix(1);
      if (const auto special = special_real<T>(name)) return *special;
      std::string shown;
      write_quoted(shown, s);
      fail_at(at, "expected a number, found the string " + shown);
    }
  }
  auto tok = number_token();
  if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);
  if constexpr (std::is_floating_point_v<T>) {
    if (const auto special = special_real<T>(tok)) return *special;
  }
  T v{};
  auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (ec == std::errc::result_out_of_range)
    fail_at(at, "'" + std::string(tok) + "' is out of the range of " + what);
  if (ec != std::errc() || p != tok.data() + tok.size())
    fail_at(at, "'" + std::string(tok) + "' is not " + what);
  return v;
}

std::int64_t TextReader::integer() { return number<std::int64_t>("an integer"); }
std::uint64_t TextReader::unsigned_integer() { return number<std::uint64_t>("an unsigned integer"); }
double TextReader::real() { return number<double>("a number"); }
float TextReader::real_float() { return number<float>("a float"); }

void TextReader::skip_value() {
  const char c = peek();
  if (at_end()) fail("expected a value but the text ended");
  if (c == '{') {
    Nest nest(*this);
    ++pos_;
    if (accept('}')) return;
    do {
      (void)key();
      expect(':');
      skip_value();
    } while (accept(','));
    expect('}');
  } else if (c == '[') {
    Nest nest(*this);
    ++pos_;
    if (accept(']')) return;
    do {
      skip_value();
    } while (accept(','));
    expect(']');
  } else if (c == '"') {
    (void)string();  // checks the escapes as reading would
  } else if (c == '@') {
    ++pos_;
    (void)unsigned_integer();
  } else {
    while (true) {  // older flags join names and numbers with '|'
      skip_bare();
      const std::size_t end = pos_;
      if (!accept('|')) {
        pos_ = end;  // the blanks after the value are not part of it
        break;
      }
    }
  }
}

// A number, true/false/null, or an older bare name (also nan/inf).
void TextReader::skip_bare() {
  const std::size_t at = token_start();
  if (pos_ < text_.size() && ident_start(text_[pos_])) {
    (void)identifier();
    return;
  }
  if (pos_ >= text_.size() || !number_start(text_[pos_])) {
    if (pos_ >= text_.size()) fail("expected a value but the text ended");
    fail(std::string("expected a value, found '") + text_[pos_] + "'");
  }
  auto tok = number_token();
  if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);
  if (special_real<double>(tok)) return;
  double v = 0;
  auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  // A number beyond double's range is still one well-formed value to skip.
  if ((ec != std::errc() && ec != std::errc::result_out_of_range) || p != tok.data() + tok.size())
    fail_at(at, "'" + std::string(tok) + "' is not a number");
}

void TextReader::expect_end() {
  if (!at_end()) fail(std::string("unexpected '") + text_[pos_] + "' after the value");
}

std::size_t TextReader::line() const noexcept {
  std::size_t l = 1;
  for (std::size_t i = 0; i < pos_ && i < text_.size(); ++i) l += text_[i] == '\n' ? 1 : 0;
  return l;
}

std::size_t TextReader::column() const noexcept {
  std::size_t c = 1;
  for (std::size_t i = 0; i < pos_ && i < text_.size(); ++i) c = text_[i] == '\n' ? 1 : c + 1;
  return c;
}

void TextReader::fail(std::string_view what) const {
  std::string msg;
  if (!origin_.empty()) msg.append(origin_).push_back(':');
  msg += std::to_string(line()) + ":" + std::to_string(column()) + ": " + std::string(what);
  throw Error(msg);
}

void TextReader::fail_at(std::size_t pos, std::string_view what) const {
  TextReader at = *this;
  at.pos_ = pos;
  at.fail(what);
}

void write_quoted(std::string& out, std::string_view s) {
  out.push_back('"');
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
          out += buf;
        } else {
          out.push_back(c);
        }
    }
  }
  out.push_back('"');
}

namespace {
template <class F>
void write_floating(std::string& out, F v) {
  // JSON has no NaN or infinity; strings keep the text one valid JSON value.
  if (std::isnan(v)) {
    out += "\"nan\"";
    return;
  }
  if (std::isinf(v)) {
    out += v < 0 ? "\"-inf\"" : "\"inf\"";
    return;
  }
  char buf[32];
  auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);
  (void)ec;
  out.append(buf, p);
}
}  // namespace

void write_real(std::string& out, double v) { write_floating(out, v); }
void write_real(std::string& out, float v) { write_floating(out, v); }

}  // namespace vsd
