#include "vsd/core/environment.hpp"

#include <algorithm>

#include "vsd/core/error.hpp"

namespace vsd {

Environment::Environment(std::uint16_t site, Registry& registry) : registry_(&registry), site_(site) {
  set_meta(static_meta());
  // The site number occupies the top 16 bits of every id made here.
  next_id_.store((static_cast<std::uint64_t>(site) << 48) | 2);
  states_.push_back(std::make_unique<SimState>(*this, "main"));
}

Environment::~Environment() {
  for (auto it = modules_.rbegin(); it != modules_.rend(); ++it) it->second->detach(*this);
  states_.clear();
  modules_.clear();
}

SimState& Environment::create_state(std::string name) {
  states_.push_back(std::make_unique<SimState>(*this, std::move(name)));
  return *states_.back();
}

void Environment::remove_state(SimState& state) {
  if (&state == states_.front().get())
    detail::throw_error("the main SimState of an Environment cannot be removed");
  auto it = std::find_if(states_.begin(), states_.end(), [&](auto& s) { return s.get() == &state; });
  if (it == states_.end())
    detail::throw_error("SimState '" + state.name() + "' does not belong to this Environment");
  states_.erase(it);
}

std::vector<SimState*> Environment::states() const {
  std::vector<SimState*> out;
  for (const auto& s : states_) out.push_back(s.get());
  return out;
}

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

Module* Environment::find_module(std::type_index t) const noexcept {
  for (const auto& [type, m] : modules_)
    if (type == t) return m.get();
  return nullptr;
}

void Environment::add_module(std::type_index t, std::unique_ptr<Module> m) {
  for (const auto& [type, other] : modules_)
    if (other->name() == m->name())
      detail::throw_error("two different modules are both named '" + std::string(m->name()) + "'");
  Module& ref = *m;
  ref.register_types(*registry_);
  modules_.emplace_back(t, std::move(m));
  try {
    ref.attach(*this);
  } catch (...) {
    modules_.pop_back();
    throw;
  }
}

std::vector<const Module*> Environment::modules() const {
  std::vector<const Module*> out;
  for (const auto& [t, m] : modules_) out.push_back(m.get());
  return out;
}

}  // namespace vsd
