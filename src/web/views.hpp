/** @file
 *  @brief Internal: the two views that know classes by name — the 3D scene (vsd::scene's Node3D, Hull,
 *  Geometry, Material) and the nets (vsd::soml's Place, Transition, Arrow, Executor). Everything else the
 *  inspector shows comes from the meta-information alone.
 */
#pragma once

#include <vector>

#include "vsd/core/fwd.hpp"
#include "vsd/core/watch.hpp"

namespace vsd::soml {
class Program;
}

namespace vsd::web::detail {

class JsonWriter;

/// @brief `{"nodes": [...], "hulls": [...]}` of every Node3D of @p state (docs/web.md).
void write_scene(JsonWriter& out, const SimState& state);
/// @brief `{"id", "positions", "indices"}` of mesh Geometry @p id. @throws vsd::Error when @p id is no
/// Geometry of @p state.
void write_mesh(JsonWriter& out, const SimState& state, Id id);
/// @brief The world frames that @p reports moved: of each Node3D whose frame or parent changed or that
/// was created, and of the Node3Ds below it. Writes `"frames": [...]` as a member.
void write_frames(JsonWriter& out, const SimState& state, const std::vector<Watch::Report>& reports);

/// @brief The SOML++ programs of @p state, in the order they were loaded (none without the module).
[[nodiscard]] std::vector<soml::Program*> programs_of(Environment& env, const SimState& state);
/// @brief `{"nets": [...]}`: every place and transition of @p state grouped by the node that owns them.
void write_nets(JsonWriter& out, const SimState& state);
/// @brief Fires transition @p id if one of the state's programs has it enabled. @return false when it is
/// not enabled. @throws vsd::Error when @p id is no transition or the firing fails (undone whole).
bool fire_transition(Environment& env, SimState& state, Id id);
/// @brief Lets every program of @p state re-test what changed (enabled transitions current in the state).
void refresh_programs(Environment& env, SimState& state);
/// @brief Firings of every program of @p state so far.
[[nodiscard]] std::uint64_t firings(Environment& env, const SimState& state);

}  // namespace vsd::web::detail
