#include "vsd/core/signal.hpp"

#include <algorithm>

namespace vsd {

namespace detail {

void SignalCore::update_live() noexcept {
  if (live == nullptr) return;
  auto alive = [](const Slot& s) { return !s.dead; };
  const bool any =
      std::any_of(slots.begin(), slots.end(), alive) || std::any_of(pending.begin(), pending.end(), alive);
  *live = any ? this : nullptr;
}

void SignalCore::disconnect(std::uint32_t id) noexcept {
  auto match = [id](const Slot& s) { return s.id == id && !s.dead; };
  if (auto it = std::find_if(pending.begin(), pending.end(), match); it != pending.end()) {
    if (it->drop != nullptr) it->drop(it->ctx);  // never called yet, so not running
    pending.erase(it);
  } else if (auto jt = std::find_if(slots.begin(), slots.end(), match); jt != slots.end()) {
    if (depth > 0) {
      // An emit is walking the array: blank the slot now, sweep it (and free its functor, which may be
      // the very listener running) when the outermost emit returns.
      jt->fn = noop;
      jt->dead = true;
      dirty = true;
    } else {
      if (jt->drop != nullptr) jt->drop(jt->ctx);
      slots.erase(jt);
    }
  } else {
    return;
  }
  update_live();
}

void SignalCore::finish_dispatch() noexcept {
  if (refs == 0) {  // the signal died during the emit and no connection is left
    delete this;
    return;
  }
  dirty = false;
  auto dead = std::stable_partition(slots.begin(), slots.end(), [](const Slot& s) { return !s.dead; });
  for (auto it = dead; it != slots.end(); ++it)
    if (it->drop != nullptr) it->drop(it->ctx);
  slots.erase(dead, slots.end());
  slots.insert(slots.end(), pending.begin(), pending.end());
  pending.clear();
}

void SignalCore::release() noexcept {
  if (--refs == 0 && depth == 0) delete this;
}

bool SignalCore::has(std::uint32_t id) const noexcept {
  auto match = [id](const Slot& s) { return s.id == id && !s.dead; };
  return std::any_of(slots.begin(), slots.end(), match) || std::any_of(pending.begin(), pending.end(), match);
}

SignalCore::~SignalCore() {
  for (auto& s : slots)
    if (s.drop != nullptr) s.drop(s.ctx);
  for (auto& s : pending)
    if (s.drop != nullptr) s.drop(s.ctx);
}

}  // namespace detail

bool Connection::connected() const noexcept {
  return core_ != nullptr && core_->live != nullptr && core_->has(id_);
}

}  // namespace vsd
