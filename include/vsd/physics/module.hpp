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
  /// @param priority the scheduler priority of the physics task (lower runs first).
  explicit Module(int priority = 20) : priority_(priority) {}
  ~Module() override;

  [[nodiscard]] std::string_view name() const override { return "physics"; }
  /// @brief Registers RigidBody, World, Joint and their enums.
  void register_types(vsd::Registry& registry) override;
  /// @brief Uses vsd::scene::Module, makes the Simulation of the main state and adds the task
  /// "physics" that advances it by every scheduler step's dt.
  void attach(vsd::Environment& env) override;
  void detach(vsd::Environment& env) override;

  /// @brief The simulation of the main state. @throws vsd::Error before attach().
  [[nodiscard]] Simulation& simulation() const;

 private:
  int priority_;
  std::unique_ptr<Simulation> simulation_;
  vsd::Environment* env_ = nullptr;
  vsd::Scheduler::TaskId task_ = 0;
};

}  // namespace vsd::physics
