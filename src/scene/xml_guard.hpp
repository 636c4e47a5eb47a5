// Guards in front of the third-party XML parsers vsd::scene hands text to (TinyXML under urdfdom, the
// COLLADA reader of assimp). Both recurse once per nesting level, so a document nested deep enough
// overflows the stack (100,000 levels: SIGSEGV) and long before that takes seconds; assimp's COLLADA
// reader also follows <instance_node> references by recursion, so a node that instances itself recurses
// without end and a chain of nodes each instancing the previous one twice doubles per link. The checks
// here walk the text once, without recursion and without building a document, and refuse what no real
// robot description or mesh needs, naming line and column.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

namespace vsd::scene::detail {

/// The shape limits of one XML document.
struct XmlLimits {
  std::size_t max_depth = 0;     ///< elements open at once
  std::size_t max_elements = 0;  ///< start tags in the whole document
  std::size_t max_bytes = 0;     ///< size of the text
};

/// One start or end tag.
struct XmlTag {
  bool end = false;             ///< </name>
  bool empty = false;           ///< <name ... />
  std::string_view name;        ///< without namespace handling: "instance_node"
  std::string_view attributes;  ///< the text between the name and the closing '>' or "/>"
  std::size_t position = 0;     ///< of the '<'
};

/// @brief Calls @p fn for every start and end tag of @p text, in order. Comments, CDATA sections,
/// processing instructions, declarations (<!DOCTYPE ...> with an internal subset) and quoted attribute
/// values are skipped as XML defines them, so a '<' inside them is no tag. Not a validator: malformed
/// text yields whatever tags it seems to hold, and an unterminated construct ends the walk.
void for_each_tag(std::string_view text, const std::function<void(const XmlTag&)>& fn);

/// @brief The value of attribute @p name in @p attributes (of an XmlTag), without its quotes; empty when
/// absent. Entities are not expanded.
std::string_view attribute(std::string_view attributes, std::string_view name);

/// @brief "line:col" of byte @p pos of @p text (both from 1; the column counts bytes).
std::string line_col(std::string_view text, std::size_t pos);

/// @brief Refuses @p text when it exceeds @p limits.
/// @param what names the document in the message ("URDF", "COLLADA mesh").
/// @throws vsd::Error "<origin>:<line>:<col>: <what> ..." at the element that crosses a limit (or, for the
/// size, without a position). Malformed XML within the limits passes and is left to the real parser.
void check_xml_shape(std::string_view text, std::string_view origin, std::string_view what,
                     const XmlLimits& limits);

/// @brief Refuses a COLLADA document whose node instancing cannot be expanded in bounds: a node that
/// instances itself through any chain of <instance_node> references and nested nodes, or more than
/// @p max_nodes nodes or more than @p max_floats geometry values once every instance is expanded
/// (a geometry counts the `count` of its <float_array>s; <instance_controller> counts the geometry its
/// <skin> or <morph> names).
/// @throws vsd::Error "<origin>:<line>:<col>: COLLADA mesh ..." naming the node or the scene.
void check_collada_instances(std::string_view text, std::string_view origin, std::size_t max_nodes,
                             std::size_t max_floats);

}  // namespace vsd::scene::detail
