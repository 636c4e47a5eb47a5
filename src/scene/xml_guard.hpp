// A guard in front of the third-party XML parsers vsd::scene hands text to (TinyXML under urdfdom, the
// COLLADA reader of assimp): both recurse once per nesting level, so a document nested deep enough
// overflows the stack (100,000 levels: SIGSEGV) and long before that takes seconds. check_xml_shape()
// walks the text once, without recursion and without building anything, and refuses what no real
// robot description or mesh needs, naming line and column.
#pragma once

#include <cstddef>
#include <string_view>

namespace vsd::scene::detail {

/// The shape limits of one XML document.
struct XmlLimits {
  std::size_t max_depth = 0;     ///< elements open at once
  std::size_t max_elements = 0;  ///< start tags in the whole document
  std::size_t max_bytes = 0;     ///< size of the text
};

/// @brief Refuses @p text when it exceeds @p limits.
/// @param what names the document in the message ("URDF", "COLLADA mesh").
/// @throws vsd::Error "<origin>:<line>:<col>: <what> ..." at the element that crosses a limit (or, for the
/// size, without a position). Not a validator: malformed XML within the limits passes and is left to the
/// real parser. Comments, CDATA sections, processing instructions, declarations (<!DOCTYPE ...> with an
/// internal subset) and quoted attribute values are skipped as XML defines them, so a '<' inside them
/// counts for nothing.
void check_xml_shape(std::string_view text, std::string_view origin, std::string_view what,
                     const XmlLimits& limits);

}  // namespace vsd::scene::detail
