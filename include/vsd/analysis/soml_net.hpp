/** @file
 *  @brief SOML++ scripts as place/transition nets, and back: what `vsd-soml analyze` and
 *  `vsd-soml convert` run on.
 *
 *  **SOML++ → PtNet.** The net of a script is the net of every instance that exists when the script is
 *  loaded: the script object and its objects (nested ones too), each with the places, transitions and
 *  arrows of its own declaration and of its script base classes. Their ids are paths from the script
 *  object (`free`, `cell.free`, `cell.arm.busy`); names are the same. Only black-token nets are state
 *  spaces the analysis can count, so these are refused, each with file:line:col, the source line and a
 *  caret (all in one vsd::Error): object places and start places (object tokens), transition and arrow
 *  conditions, communication arrows, substitution and invocation, and actions that change a marking
 *  (`put`/`clear` on a place, directly or through the script functions they call). Other actions (prints,
 *  property changes) do not change which markings are reachable: they are ignored, with a note. The nets
 *  of classes belong to instances created at run time and are not part of the static net (a note says so).
 *
 *  **PtNet → SOML++.** write_soml() writes one script: the places (initial markings as initialisers),
 *  the transitions, then the arrows transition by transition (inputs, outputs, inhibitors, weights as
 *  `* w`). Ids that are not SOML++ identifiers (or are keywords) are renamed; the original id and name are
 *  kept in a comment on the line. Reading the result back gives the same net up to ids and names.
 *
 *  **PtNet → database.** import_net() loads that script into a SimState through the SOML++ module: a PNML
 *  net becomes ordinary database content (a script object with `soml::Place` nodes holding the initial
 *  marking in `tokens`, `soml::Transition` nodes, `soml::Arrow` nodes with their weights), run by the
 *  module's executor like any SOML++ net, saved and replicated like any data.
 */
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/core/fwd.hpp"
#include "vsd/analysis/pt_net.hpp"

namespace vsd::soml {
struct CheckResult;
class Module;
class Program;
}

namespace vsd::analysis {

/// @brief What read_soml_net() returns: the net, and notes on what was ignored.
struct SomlNetImport {
  PtNet net;                       ///< Places and transitions in declaration order (depth first).
  std::vector<std::string> notes;  ///< "<file>:<line>:<col>: ..." for ignored actions, class nets, ...
};

/// @brief Converts a checked script (see check_source()) into its static P/T net.
/// @throws vsd::Error when the script has errors (the formatted diagnostics), or uses constructs outside
/// place/transition nets (every one listed with its position).
[[nodiscard]] SomlNetImport net_from_soml(const soml::CheckResult& checked);

/// @brief Checks SOML++ @p text (shown as @p source in messages) and converts it (net_from_soml()).
[[nodiscard]] SomlNetImport read_soml_net(std::string_view text, std::string_view source = "<soml>");
/// @brief read_soml_net() on the text of @p in up to its end (standard input, a pipe).
/// @throws vsd::Error "<source>: read error", or as read_soml_net().
[[nodiscard]] SomlNetImport read_soml_net(std::istream& in, std::string_view source);
/// @brief read_soml_net() on a file (a named pipe too).
/// @throws vsd::Error when it cannot be read ("<path>: is a directory, not a file", ...), or as
/// read_soml_net().
[[nodiscard]] SomlNetImport read_soml_net_file(const std::filesystem::path& path);

/// @brief Writes @p net as a SOML++ script (see the file comment).
/// @param notes when given, receives one line per renamed id.
[[nodiscard]] std::string write_soml(const PtNet& net, std::vector<std::string>* notes = nullptr);
/// @brief write_soml() to a file. @throws vsd::Error when the file cannot be written.
void write_soml_file(const PtNet& net, const std::filesystem::path& path, std::vector<std::string>* notes = nullptr);

/// @brief Imports @p net into @p state as a SOML++ net (write_soml(), then soml::Module::load), named
/// after the net's id.
/// @param notes when given, receives one line per renamed id.
/// @return the loaded program, owned by @p soml (run by it in every scheduler step).
/// @throws vsd::Error when the module cannot load it (see soml::Module::load).
soml::Program& import_net(soml::Module& soml, SimState& state, const PtNet& net,
                          std::vector<std::string>* notes = nullptr);

}  // namespace vsd::analysis
