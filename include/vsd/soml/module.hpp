/** @file
 *  @brief vsd::soml::Module: the SOML++ classes, loading scripts into an Environment and running their
 *  nets in the Scheduler's event-driven phase.
 *
 *  @code
 *  vsd::Environment env;
 *  auto& soml = env.use<vsd::soml::Module>();
 *  soml.load(env.main_state(), "phil.soml", text);
 *  env.step();   // fires the enabled transitions of every loaded program until quiet
 *  @endcode
 */
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/core/module.hpp"
#include "vsd/soml/runtime.hpp"

namespace vsd::soml {

class Module : public vsd::Module {
 public:
  Module();
  ~Module() override;
  [[nodiscard]] std::string_view name() const override { return "soml"; }
  void register_types(vsd::Registry& registry) override;
  void attach(vsd::Environment& env) override;
  void detach(vsd::Environment& env) override;

  /// @brief Loads a script (see Program::load) and runs its nets in every step of the scheduler.
  Program& load(SimState& state, std::string name, std::string text, RunOptions options = {});
  /// @brief Attaches to a run already in @p state (see Program::attach) and runs its nets in every step
  /// of the scheduler, like load().
  Program& adopt(SimState& state, std::string name, std::string text, RunOptions options = {});
  /// @brief The programs loaded so far.
  [[nodiscard]] const std::vector<std::unique_ptr<Program>>& programs() const noexcept { return programs_; }
  /// @brief Firings per step at most (a guard against nets that never become quiet).
  std::uint64_t step_limit = 1'000'000;

 private:
  Program& add(std::unique_ptr<Program> program);
  vsd::Environment* env_ = nullptr;
  std::uint32_t task_ = 0;
  bool has_task_ = false;
  std::vector<std::unique_ptr<Program>> programs_;
};

}  // namespace vsd::soml
