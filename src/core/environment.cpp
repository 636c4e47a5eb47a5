#include "vsd/core/environment.hpp"

#include <algorithm>

#include "vsd/core/error.hpp"

namespace vsd {

const char* service_name(Service service) noexcept {
  switch (service) {
    case Service::none: return "none";
    case Service::derived: return "derived";
    case Service::stepped: return "stepped";
  }
  return "unknown";
}

Service Module::default_service(const SimState& state) const {
  return state.is_main() ? Service::stepped : Service::derived;
}

Environment::Environment(std::uint16_t site, Registry& registry) : registry_(&registry), site_(site) {
  set_meta(static_meta());
  // The site number occupies the top 16 bits of every id made here.
  next_id_.store((static_cast<std::uint64_t>(site) << 48) | 2);
  states_.push_back(StateEntry{std::make_unique<SimState>(*this, "main"), {}});
  states_.front().state->main_ = true;
}

Environment::~Environment() {
  // Every state's services end (newest state first, modules in reverse order of use), then the modules
  // detach, then the states go.
  for (auto st = states_.rbegin(); st != states_.rend(); ++st)
    for (std::size_t m = modules_.size(); m-- > 0;) {
      try {
        change_service(m, *st, Service::none);
      } catch (...) {  // a module that throws while it stops serving cannot stop the teardown
      }
    }
  for (auto it = modules_.rbegin(); it != modules_.rend(); ++it) it->second->detach(*this);
  states_.clear();
  modules_.clear();
}

SimState& Environment::create_state(std::string name) {
  states_.push_back(StateEntry{std::make_unique<SimState>(*this, std::move(name)),
                               std::vector<Service>(modules_.size(), Service::none)});
  StateEntry& e = states_.back();
  std::size_t m = 0;
  try {
    for (; m < modules_.size(); ++m) change_service(m, e, modules_[m].second->default_service(*e.state));
  } catch (...) {
    while (m-- > 0) {
      try {
        change_service(m, e, Service::none);
      } catch (...) {
      }
    }
    states_.pop_back();
    throw;
  }
  return *e.state;
}

void Environment::remove_state(SimState& state) {
  if (&state == states_.front().state.get())
    detail::throw_error("the main SimState of an Environment cannot be removed");
  auto it = std::find_if(states_.begin(), states_.end(), [&](auto& e) { return e.state.get() == &state; });
  if (it == states_.end())
    detail::throw_error("SimState '" + state.name() + "' does not belong to this Environment");
  for (std::size_t m = modules_.size(); m-- > 0;) change_service(m, *it, Service::none);
  states_.erase(it);
}

std::vector<SimState*> Environment::states() const {
  std::vector<SimState*> out;
  out.reserve(states_.size());
  for (const auto& e : states_) out.push_back(e.state.get());
  return out;
}

// ---- services ---------------------------------------------------------------------------------------------

std::size_t Environment::module_position(const Module& m) const {
  for (std::size_t i = 0; i < modules_.size(); ++i)
    if (modules_[i].second.get() == &m) return i;
  detail::throw_error("module '" + std::string(m.name()) + "' is not used by this Environment");
}

Environment::StateEntry& Environment::entry_of(const SimState& s) {
  for (auto& e : states_)
    if (e.state.get() == &s) return e;
  detail::throw_error("SimState '" + s.name() + "' does not belong to this Environment");
}

void Environment::change_service(std::size_t module, StateEntry& entry, Service to) {
  const Service from = entry.services[module];
  if (from == to) return;
  modules_[module].second->serve(*entry.state, from, to);
  entry.services[module] = to;
}

void Environment::set_service(Module& module, SimState& state, Service service) {
  change_service(module_position(module), entry_of(state), service);
}

void Environment::set_service(SimState& state, Service service) {
  StateEntry& e = entry_of(state);
  if (service == Service::none) {
    for (std::size_t m = modules_.size(); m-- > 0;) change_service(m, e, service);
  } else {
    for (std::size_t m = 0; m < modules_.size(); ++m) change_service(m, e, service);
  }
}

Service Environment::service(const Module& module, const SimState& state) const noexcept {
  for (std::size_t i = 0; i < modules_.size(); ++i) {
    if (modules_[i].second.get() != &module) continue;
    for (const auto& e : states_)
      if (e.state.get() == &state) return e.services[i];
  }
  return Service::none;
}

std::vector<SimState*> Environment::states_served(const Module& module, Service level) const {
  std::vector<SimState*> out;
  const std::size_t m = module_position(module);
  for (const auto& e : states_)
    if (e.services[m] >= level && e.services[m] != Service::none) out.push_back(e.state.get());
  return out;
}

// ---- ids --------------------------------------------------------------------------------------------------

Id Environment::next_id() noexcept { return next_id_.fetch_add(1, std::memory_order_relaxed); }

Id Environment::next_ids(std::size_t count) noexcept {
  return next_id_.fetch_add(count, std::memory_order_relaxed);
}

void Environment::reserve_ids_through(Id id) noexcept {
  if ((id >> 48) != site_) return;  // another site's ids never meet ours
  Id current = next_id_.load(std::memory_order_relaxed);
  if (current > id) return;
  while (current <= id && !next_id_.compare_exchange_weak(current, id + 1, std::memory_order_relaxed)) {
  }
  // Blocks of ids that SimStates took earlier may hold the ids just reserved: make them take new ones.
  id_generation_.fetch_add(1, std::memory_order_release);
}

// ---- modules ----------------------------------------------------------------------------------------------

Module* Environment::find_module(std::type_index t) const noexcept {
  for (const auto& [type, m] : modules_)
    if (type == t) return m.get();
  return nullptr;
}

Module& Environment::required_module(std::type_index t) const {
  if (Module* m = find_module(t)) return *m;
  detail::throw_error(std::string("the module of type ") + t.name() + " is not used by this Environment");
}

void Environment::add_module(std::type_index t, std::unique_ptr<Module> m) {
  for (const auto& [type, other] : modules_)
    if (other->name() == m->name())
      detail::throw_error("two different modules are both named '" + std::string(m->name()) + "'");
  Module& ref = *m;
  ref.register_types(*registry_);
  modules_.emplace_back(t, std::move(m));
  for (auto& e : states_) e.services.push_back(Service::none);
  auto position = [&] {
    const auto at = std::find_if(modules_.begin(), modules_.end(), [&](auto& x) { return x.second.get() == &ref; });
    return static_cast<std::size_t>(at - modules_.begin());
  };
  auto remove = [&](std::size_t index) {
    auto entry = std::move(modules_[index]);
    modules_.erase(modules_.begin() + static_cast<std::ptrdiff_t>(index));
    for (auto& e : states_) e.services.erase(e.services.begin() + static_cast<std::ptrdiff_t>(index));
    return entry;
  };
  std::size_t served = 0;
  try {
    ref.attach(*this);
    // Modules that attach() used (scene for collision) came after this one: move it behind them, so
    // that states are served by what a module builds on first and released by it last.
    modules_.push_back(remove(position()));
    for (auto& e : states_) e.services.push_back(Service::none);
    const std::size_t pos = modules_.size() - 1;
    for (; served < states_.size(); ++served)
      change_service(pos, states_[served], ref.default_service(*states_[served].state));
  } catch (...) {
    const std::size_t pos = position();
    while (served-- > 0) {
      try {
        change_service(pos, states_[served], Service::none);
      } catch (...) {
      }
    }
    // attach() may have used other modules meanwhile: they stay (they are whole); this one goes.
    remove(pos);
    throw;
  }
}

std::vector<const Module*> Environment::modules() const {
  std::vector<const Module*> out;
  for (const auto& [t, m] : modules_) out.push_back(m.get());
  return out;
}

}  // namespace vsd
