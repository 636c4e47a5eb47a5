/** @file
 *  @brief Module: how an optional part of vsd (3D, physics, SOML++, robotics, ...) plugs into an
 *  Environment — it registers its classes and types, attaches its algorithms, and serves each SimState.
 *
 *  Modules are used explicitly, `env.use<vsd::scene::Module>()`, never through static initialisation,
 *  so a static link cannot drop them. A module may use other modules from its attach().
 *
 *  Schema apart from state: register_types() runs once per use, attach() adds the module's scheduler
 *  tasks, and serve() is called for every SimState of the Environment — those that exist when the module
 *  is used and every one created later (a what-if copy, a state a file is loaded into, a vsd::dist
 *  replica). What the module keeps for one state lives in that state's context (SimState::context()) and
 *  dies with it; a module keeps no table of states of its own.
 */
#pragma once

#include <cstdint>
#include <string_view>

namespace vsd {

class Environment;
class Registry;
class SimState;

/// @brief What a module does for one SimState. Chosen per state and module (Environment::set_service);
/// each module says what it does at each level.
enum class Service : std::uint8_t {
  none,     ///< nothing: the module keeps no data for the state
  derived,  ///< keeps data derived from the state current (world frames, joint frames, a collision
            ///< world for queries, a loaded program's marking), but never steps the state
  stepped,  ///< also runs its algorithms on the state in every scheduler step (physics, controllers,
            ///< contacts, nets)
};

/// @brief "none", "derived" or "stepped".
[[nodiscard]] const char* service_name(Service service) noexcept;

class Module {
 public:
  Module() = default;
  Module(const Module&) = delete;
  Module& operator=(const Module&) = delete;
  virtual ~Module() = default;

  /// @brief A short unique name ("scene", "physics", ...).
  [[nodiscard]] virtual std::string_view name() const = 0;
  /// @brief Registers the module's MetaInstances and MetaTypes.
  virtual void register_types(Registry& registry) { (void)registry; }
  /// @brief Attaches algorithms to the environment: scheduler tasks. Called once, before serve().
  virtual void attach(Environment& env) { (void)env; }
  /// @brief Undoes attach(); called when the environment goes away, in reverse order of use, after
  /// every state's service has gone to none.
  virtual void detach(Environment& env) { (void)env; }

  /// @brief The service a state gets unless its user chooses another. The default: `stepped` for the
  /// main state, `derived` for every other state (a replica or a loaded copy shows derived data but is
  /// not simulated twice).
  [[nodiscard]] virtual Service default_service(const SimState& state) const;
  /// @brief Called when the module's service of @p state changes from @p from to @p to: from none when a
  /// state is created or the module is used, to none before a state is removed or the module detached.
  /// A module that throws leaves the service at @p from.
  virtual void serve(SimState& state, Service from, Service to) {
    (void)state;
    (void)from;
    (void)to;
  }
};

}  // namespace vsd
