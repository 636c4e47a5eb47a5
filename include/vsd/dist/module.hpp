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

#include <memory>
#include <string_view>
#include <vector>

#include "vsd/core/module.hpp"
#include "vsd/dist/participant.hpp"

namespace vsd::dist {

class Module : public vsd::Module {
 public:
  [[nodiscard]] std::string_view name() const override { return "dist"; }
  /// @brief Adds the scheduler task "dist poll" (every base step, priority -1000: before the algorithms,
  /// so they see the others' changes of the last step).
  void attach(vsd::Environment& env) override;
  /// @brief Leaves every domain (the participants are destroyed).
  void detach(vsd::Environment& env) override;

  /// @brief Makes a participant for @p state (a SimState of this module's Environment) that the step
  /// loop polls. @throws vsd::Error as Participant's constructor does.
  Participant& join(SimState& state, ParticipantOptions options);
  /// @brief The participants made by join(), in order.
  [[nodiscard]] const std::vector<std::unique_ptr<Participant>>& participants() const noexcept {
    return participants_;
  }

 private:
  std::vector<std::unique_ptr<Participant>> participants_;
  std::uint32_t task_ = 0;
};

}  // namespace vsd::dist
