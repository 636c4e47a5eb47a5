#include "vsd/core/signal.hpp"

#include <algorithm>

namespace vsd {

namespace detail {

void SignalCore::update_live() noexcept {
  if (live == nullptr) return;
  const bool any = std::any_of(slots.begin(), slots.end(), [](const Slot& s) { return s.fn != nullptr; });
  *live = any ? this : nullptr;
}

void SignalCore::disconnect(std::uint32_t id) noexcept {
  for (auto it = slots.begin(); it != slots.end(); ++it) {
    if (it->id != id || it->fn == nullptr) continue;
    if (depth > 0) {
      // An emit is walking the array: blank the slot now, sweep it (and free its functor, which may be
      // the very listener running) when the outermost emit returns.
      it->fn = nullptr;
      dirty = true;
    } else {
      if (it->drop != nullptr) it->drop(it->ctx);
      slots.erase(it);
    }
    update_live();
    return;
  }
}

void SignalCore::sweep() noexcept {
  dirty = false;
  auto dead =
      std::stable_partition(slots.begin(), slots.end(), [](const Slot& s) { return s.fn != nullptr; });
  for (auto it = dead; it != slots.end(); ++it)
    if (it->drop != nullptr) it->drop(it->ctx);
  slots.erase(dead, slots.end());
}

void SignalCore::release() noexcept {
  if (--refs == 0 && depth == 0) delete this;
}

SignalCore::~SignalCore() {
  for (auto& s : slots)
    if (s.drop != nullptr) s.drop(s.ctx);
}

}  // namespace detail

bool Connection::connected() const noexcept {
  if (core_ == nullptr || core_->live == nullptr) return false;
  return std::any_of(core_->slots.begin(), core_->slots.end(),
                     [this](const detail::SignalCore::Slot& s) { return s.id == id_ && s.fn != nullptr; });
}

}  // namespace vsd
