/** @file
 *  @brief PNML (ISO/IEC 15909-2) place/transition nets: read into a PtNet, write a PtNet back.
 *
 *  Reading accepts one `<net>` of type `http://www.pnml.org/version-2009/grammar/ptnet` (any pages,
 *  nested pages, reference places and transitions). It keeps ids and names of the net, places and
 *  transitions, initial markings and arc weights (`<inscription>`), and arc ids. What it does not keep
 *  is reported in PnmlImport::notes, each with its line:col: `<toolspecific>` blocks (NUPN and others),
 *  `<graphics>`, unknown elements. Other net types (symmetric nets, high-level nets, ...) are refused.
 *
 *  Inhibitor arcs are not part of the P/T grammar of the standard; this reader and writer use the
 *  common extension `<arc ...><type value="inhibitor"/></arc>` (as the PNML Framework and several tools
 *  do), so that a net with inhibitor arcs survives a round trip.
 *
 *  Errors (malformed XML, a dangling arc end, a bad number, ...) throw vsd::Error whose message starts
 *  with `<source>:<line>:<col>:`. The XML parser is pugixml.
 */
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/analysis/pt_net.hpp"

namespace vsd::analysis {

/// @brief What read_pnml() returns: the net, and what was skipped (one human-readable line each).
struct PnmlImport {
  PtNet net;                       ///< The imported net.
  std::vector<std::string> notes;  ///< "<source>:<line>:<col>: skipped ..." for every element not kept.
};

/// @brief Parses PNML text.
/// @param text the document.
/// @param source the name used in messages (a file name).
/// @throws vsd::Error "<source>:<line>:<col>: ..." when the text is not well-formed XML, not PNML, not a
/// single place/transition net, or inconsistent (duplicate ids, arcs to unknown nodes, bad numbers).
PnmlImport read_pnml(std::string_view text, std::string_view source = "<pnml>");

/// @brief Reads PNML from @p in to its end (standard input, a pipe), then read_pnml().
/// @throws vsd::Error "<source>: read error", or as read_pnml().
PnmlImport read_pnml(std::istream& in, std::string_view source);

/// @brief Reads a PNML file (read_pnml() with the file name as source); a named pipe is read like a file.
/// @throws vsd::Error when the file cannot be read ("<path>: is a directory, not a file", "<path>: cannot
/// open the file for reading (<reason>)") or its content is refused.
PnmlImport read_pnml_file(const std::filesystem::path& path);

/// @brief Writes @p net as a PNML place/transition net (one page). Arcs without an id get a fresh one;
/// inhibitor arcs carry `<type value="inhibitor"/>`.
std::string write_pnml(const PtNet& net);

/// @brief write_pnml() to a file. @throws vsd::Error when the file cannot be written.
void write_pnml_file(const PtNet& net, const std::filesystem::path& path);

}  // namespace vsd::analysis
