// Printable names and messages, JSON strings (see vsd_tool/text.hpp).
#include "vsd_tool/text.hpp"

#include "vsd/core/text.hpp"

namespace vsd::tool {

namespace {

// The length of the valid UTF-8 sequence at s[i], or 0 when s[i] does not start one.
std::size_t utf8_length(std::string_view s, std::size_t i) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  if (c < 0x80) return 1;
  std::size_t n = 0;
  unsigned min = 0;
  unsigned cp = 0;
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2, min = 0x80, cp = c & 0x1Fu;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3, min = 0x800, cp = c & 0x0Fu;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4, min = 0x10000, cp = c & 0x07u;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((b(i + k) & 0xC0u) != 0x80u) return 0;
    cp = (cp << 6) | (b(i + k) & 0x3Fu);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

// A C1 control (U+0080..U+009F) in UTF-8: 0xC2 0x80..0x9F.
bool is_c1(std::string_view s, std::size_t i) {
  return i + 1 < s.size() && static_cast<unsigned char>(s[i]) == 0xC2 &&
         static_cast<unsigned char>(s[i + 1]) >= 0x80 && static_cast<unsigned char>(s[i + 1]) <= 0x9F;
}

std::string printable_impl(std::string_view s, bool keep_lines) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (is_c1(s, i)) {
      out += '?';
      ++i;
    } else if ((c < 0x20 && c != '\t' && !(keep_lines && c == '\n')) || c == 0x7f) {
      out += '?';
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

}  // namespace

std::string printable(std::string_view s) { return printable_impl(s, false); }

std::string printable_lines(std::string_view s) { return printable_impl(s, true); }

std::string json_string(std::string_view s) {
  // Bytes that are not UTF-8 become U+FFFD; the JSON escapes are the core's (write_quoted).
  std::string utf8;
  utf8.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t n = utf8_length(s, i);
    if (n == 0) {
      utf8 += "\xEF\xBF\xBD";
      ++i;
    } else {
      utf8.append(s.substr(i, n));
      i += n;
    }
  }
  std::string out;
  write_quoted(out, utf8);
  return out;
}

}  // namespace vsd::tool
