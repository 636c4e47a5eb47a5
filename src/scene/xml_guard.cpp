#include "xml_guard.hpp"

#include <algorithm>
#include <string>

#include "vsd/core/error.hpp"

namespace vsd::scene::detail {

namespace {

// Line and column (both from 1, the column in bytes) of @p pos: counted only when an error is reported.
std::string position(std::string_view text, std::size_t pos) {
  const std::string_view before = text.substr(0, pos);
  const auto line = std::count(before.begin(), before.end(), '\n') + 1;
  const std::size_t last_newline = before.rfind('\n');
  const std::size_t col = last_newline == std::string_view::npos ? pos + 1 : pos - last_newline;
  return std::to_string(line) + ":" + std::to_string(col);
}

// The index just past @p end found from @p from, or the end of the text (unterminated: the parser reports it).
std::size_t skip_past(std::string_view text, std::size_t from, std::string_view end) {
  const std::size_t at = text.find(end, from);
  return at == std::string_view::npos ? text.size() : at + end.size();
}

// The index just past the '>' that ends a tag or declaration starting at @p from: quoted values are
// skipped, and in a declaration (<!DOCTYPE ...>) so is a bracketed internal subset with its own
// declarations and comments.
std::size_t skip_tag(std::string_view text, std::size_t from, bool declaration) {
  int brackets = 0;
  for (std::size_t i = from; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"' || c == '\'') {
      const std::size_t close = text.find(c, i + 1);
      if (close == std::string_view::npos) return text.size();
      i = close;
    } else if (declaration && text.compare(i, 4, "<!--") == 0) {
      i = skip_past(text, i + 4, "-->") - 1;
    } else if (declaration && c == '[') {
      ++brackets;
    } else if (declaration && c == ']') {
      brackets = std::max(0, brackets - 1);
    } else if (c == '>' && brackets == 0) {
      return i + 1;
    }
  }
  return text.size();
}

}  // namespace

void check_xml_shape(std::string_view text, std::string_view origin, std::string_view what,
                     const XmlLimits& limits) {
  const std::string name(origin);
  if (text.size() > limits.max_bytes)
    vsd::detail::throw_error(name + ": " + std::string(what) + " of " + std::to_string(text.size()) +
                             " bytes is larger than the limit of " + std::to_string(limits.max_bytes) +
                             " bytes; refused before parsing");
  std::size_t depth = 0;
  std::size_t elements = 0;
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t lt = text.find('<', i);
    if (lt == std::string_view::npos) break;
    const std::string_view rest = text.substr(lt);
    if (rest.starts_with("<!--")) {
      i = skip_past(text, lt + 4, "-->");
    } else if (rest.starts_with("<![CDATA[")) {
      i = skip_past(text, lt + 9, "]]>");
    } else if (rest.starts_with("<?")) {
      i = skip_past(text, lt + 2, "?>");
    } else if (rest.starts_with("<!")) {
      i = skip_tag(text, lt + 2, true);
    } else if (rest.starts_with("</")) {
      if (depth > 0) --depth;  // a mismatched end tag is the parser's to report
      i = skip_tag(text, lt + 2, false);
    } else {
      const std::size_t end = skip_tag(text, lt + 1, false);
      const bool empty_element = end >= 2 && end <= text.size() && text[end - 1] == '>' && text[end - 2] == '/';
      ++elements;
      if (!empty_element) ++depth;
      if (depth > limits.max_depth || (empty_element && depth + 1 > limits.max_depth))
        vsd::detail::throw_error(name + ":" + position(text, lt) + ": " + std::string(what) +
                                 " nests elements deeper than " + std::to_string(limits.max_depth) +
                                 " levels; refused before parsing");
      if (elements > limits.max_elements)
        vsd::detail::throw_error(name + ":" + position(text, lt) + ": " + std::string(what) +
                                 " has more than " + std::to_string(limits.max_elements) +
                                 " elements; refused before parsing");
      i = end;
    }
  }
}

}  // namespace vsd::scene::detail
