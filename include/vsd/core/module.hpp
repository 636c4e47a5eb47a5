/** @file
 *  @brief Module: how an optional part of vsd (3D, physics, SOML++, robotics, ...) plugs into an
 *  Environment — it registers its classes and types and attaches its algorithms.
 *
 *  Modules are used explicitly, `env.use<vsd::scene::Module>()`, never through static initialisation,
 *  so a static link cannot drop them. A module may use other modules from its attach().
 */
#pragma once

#include <string_view>

namespace vsd {

class Environment;
class Registry;

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
  /// @brief Attaches algorithms to the environment: scheduler tasks, signal listeners.
  virtual void attach(Environment& env) { (void)env; }
  /// @brief Undoes attach(); called when the environment goes away, in reverse order of use.
  virtual void detach(Environment& env) { (void)env; }
};

}  // namespace vsd
