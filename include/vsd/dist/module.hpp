/** @file
 *  @brief vsd::dist::Module: distribution as a module — joins SimStates of the Environment to DDS domains
 *  and polls their participants once per scheduler step.
 *
 *  @code
 *  vsd::Environment env(2);
 *  auto& dist = env.use<vsd::dist::Module>();
 *  vsd::dist::ParticipantOptions o;
 *  o.name = "robot";
 *  o.seed = true;
 *  dist.join(env.main_state(), o);   // from now on every env.step() publishes and applies bundles
 *  @endcode
 */
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "vsd/core/module.hpp"
#include "vsd/dist/participant.hpp"

namespace vsd::dist {

class Module : public vsd::Module {
 public:
  [[nodiscard]] std::string_view name() const override { return "dist"; }
  /// @brief Adds the scheduler task "dist poll" (every base step, phase inputs: before the algorithms,
  /// so they see the others' changes of the last step). It polls every participant made by join(), on
  /// whichever of the environment's states it was made.
  void attach(vsd::Environment& env) override;
  void detach(vsd::Environment& env) override;
  /// @brief A state's participants leave their domains when its service becomes none (when the state
  /// is removed or the environment goes).
  void serve(SimState& state, Service from, Service to) override;

  /// @brief Makes a participant for @p state (a SimState of this module's Environment) that the step
  /// loop polls. It lives in the state's context: it leaves its domain with the state.
  /// @throws vsd::Error as Participant's constructor does, and when the module does not serve @p state.
  Participant& join(SimState& state, ParticipantOptions options);
  /// @brief The participants made by join() on every state, in the order of the states, then of joining.
  [[nodiscard]] std::vector<Participant*> participants() const;

 private:
  vsd::Environment* env_ = nullptr;
  std::uint32_t task_ = 0;
};

}  // namespace vsd::dist
