// The picture of a SOML++ net as Graphviz DOT, made from the checked script (not drawn by hand): for the
// nets of docs/workcell.md (docs/img/*.svg, made by scripts/net-pictures.sh).
//
// Every static object is a cluster; a place is a circle labelled with its name and initial tokens
// (`place<Job>` for an object place), a transition a box labelled with its name and, when it has them,
// "σ" (a condition) and "γ" (an action); arrows are solid arcs, communication arrows dashed, inhibitor
// arcs end in a circle. Object classes with a start place show as a note with an arc to that place.
#pragma once

#include <string>

namespace vsd_workcell {

/// DOT of the script at @p path, checked against the cell's classes.
/// @throws vsd::Error when the script cannot be read or does not check.
std::string net_dot(const std::string& path);

}  // namespace vsd_workcell
