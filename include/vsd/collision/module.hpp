/** @file
 *  @brief vsd::collision::Module: uses vsd::scene and keeps one CollisionWorld per SimState on demand,
 *  optionally updated by the Scheduler at a fixed step.
 *
 *  @code
 *  vsd::Environment env;
 *  auto& collision = env.use<vsd::collision::Module>(0.01);   // update the main state's world every 10 ms
 *  auto c = collision.world(env.main_state()).on_contact_begin().connect(...);
 *  @endcode
 */
#pragma once

#include <memory>
#include <string_view>
#include <unordered_map>

#include "vsd/collision/collision_world.hpp"
#include "vsd/core/module.hpp"

namespace vsd::collision {

class Module : public vsd::Module {
 public:
  /// @brief A module whose main-state world the Scheduler updates every @p period seconds (never
  /// when @p period is 0: the program calls CollisionWorld::update() itself).
  explicit Module(double period = 0) : period_(period) {}
  ~Module() override;

  [[nodiscard]] std::string_view name() const override { return "collision"; }
  /// @brief Uses vsd::scene (whose classes the world reads) and adds the periodic update task.
  void attach(vsd::Environment& env) override;
  /// @brief Drops every world (before the SimStates go).
  void detach(vsd::Environment& env) override;

  /// @brief The world over all collision hulls of @p state, made on first use with @p options (later
  /// calls return the same world and ignore @p options).
  CollisionWorld& world(SimState& state, const Options& options = {});

 private:
  double period_;
  std::unordered_map<const SimState*, std::unique_ptr<CollisionWorld>> worlds_;
};

}  // namespace vsd::collision
