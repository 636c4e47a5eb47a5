// The place/transition abstraction of a SOML++ supervisor whose places hold black tokens but whose
// transitions have conditions and whose objects talk through communication arrows — what vsd::analysis's
// own converter (read_soml_net) refuses. Used to verify Multi Robot Control (multi_robot_control.soml).
//
// Derived mechanically from the checked script: every static instance (the script object and its objects,
// declared from scratch) contributes its places (id "object.place", initial marking as declared) and its
// transitions ("object.transition"); every arrow becomes an arc of its weight — a communication arrow an
// arc to the place its path names (it must name a place of a static object). Conditions and actions are
// dropped.
//
// How it corresponds to the real net: the real net's markings of these places change only by firings
// (its actions call plant methods and set properties, no `put`/`clear`), and a firing of the real net is
// a firing of the abstraction with the same arcs; a condition only removes firings. So every marking the
// real net reaches, the abstraction reaches too: a property of all reachable markings (the zone mutually
// exclusive) proven on the abstraction holds for the real net. Deadlock freedom of the abstraction says
// the net's structure never blocks; whether the real net moves on also depends on the plant delivering
// the σ events its conditions wait for, which the cell's run checks (deadlocks: 0).
#pragma once

#include <string>
#include <vector>

#include "vsd/analysis/pt_net.hpp"

namespace vsd_workcell {

/// @brief The abstraction of the SOML++ script at @p path, checked against the cell's classes (Robot,
/// Part, Orders, Conveyor, Station) and vsd's.
/// @param notes when given, receives what was dropped ("<n> conditions, <m> actions").
/// @throws vsd::Error when the script does not check, or uses object places, start places, substitution,
/// invocation, a communication arrow to a place that is not a static object's, or a place inside a
/// transition.
vsd::analysis::PtNet pt_abstraction(const std::string& path, std::vector<std::string>* notes = nullptr);

}  // namespace vsd_workcell
