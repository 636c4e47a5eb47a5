/** @file
 *  @brief vsd::collision::Module: uses vsd::scene and keeps one CollisionWorld per SimState (in the
 *  state's context, made on first use), optionally updated by the Scheduler at a fixed step.
 *
 *  Services: every state may have a world for queries (`derived`, the default for all states but the
 *  main one: a replica answers distance and ray queries); the update task computes contacts and emits
 *  their begin/end signals for the states served `stepped` (by default the main state). `none` drops the
 *  state's world.
 *
 *  @code
 *  vsd::Environment env;
 *  auto& collision = env.use<vsd::collision::Module>(0.01);   // update the stepped states every 10 ms
 *  auto c = collision.world(env.main_state()).on_contact_begin().connect(...);
 *  @endcode
 */
#pragma once

#include <memory>
#include <string_view>

#include "vsd/collision/collision_world.hpp"
#include "vsd/core/module.hpp"

namespace vsd::collision {

class Module : public vsd::Module {
 public:
  /// @brief A module whose stepped states' worlds the Scheduler updates every @p period seconds (never
  /// when @p period is 0: the program calls CollisionWorld::update() itself).
  explicit Module(double period = 0) : period_(period) {}
  ~Module() override;

  [[nodiscard]] std::string_view name() const override { return "collision"; }
  /// @brief Uses vsd::scene (whose classes the world reads) and adds the periodic update task.
  void attach(vsd::Environment& env) override;
  /// @brief Removes the update task.
  void detach(vsd::Environment& env) override;
  /// @brief Drops the state's world when its service becomes none.
  void serve(SimState& state, Service from, Service to) override;

  /// @brief The world over all collision hulls of @p state (kept in the state's context, so it dies with
  /// the state), made on first use with @p options (later calls return the same world and ignore
  /// @p options).
  CollisionWorld& world(SimState& state, const Options& options = {});

 private:
  double period_;
  std::uint32_t task_ = 0;
  vsd::Environment* env_ = nullptr;
};

}  // namespace vsd::collision
