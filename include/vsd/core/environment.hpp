/** @file
 *  @brief Environment: the whole simulation — its SimStates, id allocation, modules and step loop.
 *
 *  Schema apart from state: the Registry (what types are) is shared; each SimState holds values.
 *  Ids come from one atomic counter per Environment, so SimStates filled in different threads can be
 *  merged without clashes; the 16-bit site number keeps ids of different machines apart.
 */
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <typeindex>
#include <utility>
#include <vector>

#include "vsd/core/module.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/scheduler.hpp"
#include "vsd/core/sim_state.hpp"

namespace vsd {

class Environment : public Instance {
  VSD_ABSTRACT_INSTANCE(Environment, Instance)

 public:
  /// @param site distinguishes environments that exchange transactions (machines, processes).
  explicit Environment(std::uint16_t site = 0, Registry& registry = Registry::global());
  ~Environment() override;

  [[nodiscard]] Registry& registry() const noexcept { return *registry_; }
  [[nodiscard]] std::uint16_t site() const noexcept { return site_; }
  /// @brief The first SimState, made with the environment.
  [[nodiscard]] SimState& main_state() const noexcept { return *states_.front().state; }
  /// @brief Makes another SimState (for a loader thread, a replica, a what-if copy, ...). Every module
  /// in use starts to serve it at its default service (Module::default_service: `derived` for all but
  /// the main state), before this returns. @throws what a module's serve() throws (nothing is left).
  SimState& create_state(std::string name);
  /// @brief Deletes a SimState other than the main one (the modules stop serving it first).
  void remove_state(SimState& state);

  /// @brief Changes what module @p module does for @p state (see Service). @throws vsd::Error when the
  /// module is not used by this environment or the state is not one of its states, and what the
  /// module's serve() throws (the service then stays as it was).
  void set_service(Module& module, SimState& state, Service service);
  /// @brief The same for module M. @throws vsd::Error when M is not used.
  template <class M>
  void set_service(SimState& state, Service service) {
    set_service(static_cast<Module&>(required_module(typeid(M))), state, service);
  }
  /// @brief The same for every module in use, in the order they were used (none: in reverse).
  void set_service(SimState& state, Service service);
  /// @brief What @p module does for @p state (none for a module not in use).
  [[nodiscard]] Service service(const Module& module, const SimState& state) const noexcept;
  /// @brief The states that @p module serves at @p level or more, main state first, then in the order
  /// they were made. A module's scheduler task steps `states_served(*this, Service::stepped)`.
  [[nodiscard]] std::vector<SimState*> states_served(const Module& module, Service level) const;
  [[nodiscard]] std::vector<SimState*> states() const;
  /// @brief A fresh id, unique in this environment. Thread-safe.
  [[nodiscard]] Id next_id() noexcept;
  /// @brief @p count consecutive fresh ids, unique in this environment; returns the first. Thread-safe.
  /// A SimState takes its ids in such blocks, so that creating an instance costs no atomic operation.
  [[nodiscard]] Id next_ids(std::size_t count) noexcept;
  /// @brief Changes whenever reserve_ids_through() moves the id counter: a block of ids taken before
  /// may then hold ids that arrived from outside, and its holder must take a new one. Thread-safe.
  [[nodiscard]] std::uint64_t id_generation() const noexcept {
    return id_generation_.load(std::memory_order_acquire);
  }
  /// @brief Makes sure next_id() never hands out @p id or a smaller id of this site (instances that
  /// arrive with their ids, e.g. from a file, keep them). Thread-safe.
  void reserve_ids_through(Id id) noexcept;

  /// @brief Uses module M: on first use registers its types and attaches it. Returns the module.
  template <class M, class... A>
  M& use(A&&... args) {
    if (Module* m = find_module(typeid(M))) return static_cast<M&>(*m);
    auto mod = std::make_unique<M>(std::forward<A>(args)...);
    M& ref = *mod;
    add_module(typeid(M), std::move(mod));
    return ref;
  }
  /// @brief The module of type M if it is used, else nullptr.
  template <class M>
  [[nodiscard]] M* module() const noexcept {
    return static_cast<M*>(find_module(typeid(M)));
  }
  [[nodiscard]] std::vector<const Module*> modules() const;

  [[nodiscard]] Scheduler& scheduler() noexcept { return scheduler_; }
  /// @brief Simulated time in seconds.
  [[nodiscard]] double time() const noexcept { return scheduler_.time(); }
  /// @brief One step of the scheduler.
  void step() { scheduler_.step(); }
  VSD_METHOD(step)
  /// @brief Steps for @p seconds of simulated time.
  void run_for(double seconds) { scheduler_.run_for(seconds); }
  VSD_METHOD(run_for)

 private:
  struct StateEntry {
    std::unique_ptr<SimState> state;
    std::vector<Service> services;  // per module, in the order of modules_
  };
  Module* find_module(std::type_index t) const noexcept;
  Module& required_module(std::type_index t) const;
  void add_module(std::type_index t, std::unique_ptr<Module> m);
  std::size_t module_position(const Module& m) const;
  StateEntry& entry_of(const SimState& s);
  void change_service(std::size_t module, StateEntry& entry, Service to);

  Registry* registry_;
  std::uint16_t site_;
  std::atomic<std::uint64_t> next_id_{2};  // 1 is every SimState's Database
  std::atomic<std::uint64_t> id_generation_{0};
  std::vector<StateEntry> states_;
  std::vector<std::pair<std::type_index, std::unique_ptr<Module>>> modules_;
  Scheduler scheduler_;
};

}  // namespace vsd
