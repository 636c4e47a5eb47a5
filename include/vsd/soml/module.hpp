/** @file
 *  @brief vsd::soml::Module: the SOML++ classes, loading scripts into the states of an Environment and
 *  running their nets in the Scheduler's event-driven phase (Phase::nets).
 *
 *  A program loaded through the module belongs to its state (it lives in the state's context): it goes
 *  when the state goes or when the module stops serving the state (Service::none; its content stays in
 *  the database, and adopt() attaches to it again). Its nets fire only on states the module steps
 *  (Service::stepped: the main state by default); on a state it serves as `derived` (a replica, a copy)
 *  the program keeps its view of the markings current, and the nets run where the state is stepped.
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
  void serve(SimState& state, Service from, Service to) override;

  /// @brief Loads a script into @p state (see Program::load); its nets run in every step of the
  /// scheduler while the module steps @p state.
  /// @throws vsd::Error when the module does not serve @p state (Service::none), or what Program::load throws.
  Program& load(SimState& state, std::string name, std::string text, RunOptions options = {});
  /// @brief Attaches to a run already in @p state (see Program::attach), like load().
  Program& adopt(SimState& state, std::string name, std::string text, RunOptions options = {});
  /// @brief The programs of @p state, in the order they were loaded.
  [[nodiscard]] std::vector<Program*> programs(const SimState& state) const;
  /// @brief The programs of every state the module serves.
  [[nodiscard]] std::vector<Program*> programs() const;
  /// @brief Firings per step and state at most (a guard against nets that never become quiet).
  std::uint64_t step_limit = 1'000'000;

 private:
  void check_served(const SimState& state) const;
  Program& add(SimState& state, std::unique_ptr<Program> program);
  vsd::Environment* env_ = nullptr;
  vsd::Registry* registry_ = nullptr;  // swept of the programs' classes when the module goes
  std::uint32_t task_ = 0;
  bool has_task_ = false;
};

}  // namespace vsd::soml
