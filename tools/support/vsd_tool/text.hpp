/** @file
 *  @brief Text the vsd-* tools print: names and messages made safe for a terminal, JSON strings.
 */
#pragma once

#include <string>
#include <string_view>

namespace vsd::tool {

/// @brief @p s with every control character shown as '?' (C0 but tab, DEL, and the C1 controls U+0080 to
/// U+009F, which some terminals obey), as the SOML++ diagnostics show them: a name or a message from a file
/// cannot move the cursor, clear the screen or fake a line of output. Other text, UTF-8 included, is kept.
std::string printable(std::string_view s);
/// @brief printable() that keeps line breaks: for multi-line messages (a SOML++ diagnostic with its source
/// line and caret).
std::string printable_lines(std::string_view s);

/// @brief @p s as a JSON string literal, quotes included, escaped as vsd::write_quoted() does ('"' and
/// '\\', control characters as \\n, \\t, \\r or \\u00XX); valid UTF-8 is kept, a byte that is not valid
/// UTF-8 becomes U+FFFD. The result is always valid JSON (RFC 8259) and valid UTF-8.
std::string json_string(std::string_view s);

}  // namespace vsd::tool
