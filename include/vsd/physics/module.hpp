/** @file
 *  @brief vsd::physics::Module: registers the physics classes and runs a Simulation of the main
 *  SimState as a periodic task of the Environment's Scheduler.
 *
 *  @code
 *  vsd::Environment env;
 *  env.use<vsd::physics::Module>();           // uses vsd::scene::Module too
 *  auto& root = env.main_state().database();
 *  root.add_extension(env.main_state().create<vsd::physics::World>());
 *  // ... Node3Ds with RigidBody extensions and collision Hulls below root ...
 *  env.run_for(2.0);                          // every scheduler step advances ODE by the step's dt
 *  @endcode
 */
#pragma once

#include <memory>
#include <string_view>

#include "vsd/core/module.hpp"
#include "vsd/core/scheduler.hpp"
#include "vsd/physics/simulation.hpp"

namespace vsd::physics {

class Module : public vsd::Module {
 public:
  /// @param phase the scheduler phase of the physics task.
  explicit Module(vsd::Phase phase = vsd::Phase::dynamics) : phase_(phase) {}
  ~Module() override;

  [[nodiscard]] std::string_view name() const override { return "physics"; }
  /// @brief Registers RigidBody, World, Joint and their enums.
  void register_types(vsd::Registry& registry) override;
  /// @brief Uses vsd::scene::Module and adds the task "physics" that advances the Simulation of every
  /// state served `stepped` by every scheduler step's dt.
  void attach(vsd::Environment& env) override;
  void detach(vsd::Environment& env) override;
  /// @brief Physics runs only where it is asked to: `stepped` by default for the main state and `none`
  /// for every other state (a replica shows the poses the simulating state sends; a what-if copy that
  /// should simulate is switched to `stepped` with Environment::set_service). `stepped` makes the state's
  /// Simulation (in the state's context), `none` drops it; `derived` keeps it without stepping it.
  [[nodiscard]] vsd::Service default_service(const vsd::SimState& state) const override;
  void serve(vsd::SimState& state, vsd::Service from, vsd::Service to) override;

  /// @brief The simulation of the main state. @throws vsd::Error before attach() or when the main
  /// state is not served.
  [[nodiscard]] Simulation& simulation() const;
  /// @brief The simulation of @p state. @throws vsd::Error when the module does not serve it.
  [[nodiscard]] Simulation& simulation(vsd::SimState& state) const;

 private:
  vsd::Phase phase_;
  vsd::Environment* env_ = nullptr;
  std::uint32_t task_ = 0;
};

}  // namespace vsd::physics
