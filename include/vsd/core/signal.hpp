/** @file
 *  @brief Signal<void(Args...)> and its RAII Connection: the messaging of the active database.
 *
 *  A signal keeps its listeners in one small array and calls them in a tight loop. Emitting with no
 *  listener costs one well-predicted branch, and emitting never allocates. Listeners may connect and
 *  disconnect any listener (themselves included) while the signal is being emitted: a disconnected slot
 *  is blanked at once and swept away when the outermost emit returns; a slot connected during an emit is
 *  first called by the next emit.
 *
 *  Lifetime: a Connection may outlive its Signal (disconnecting then does nothing) and a Signal may be
 *  destroyed from inside one of its own listeners. Signals and connections belong to one thread at a
 *  time, like the SimState they live in.
 */
#pragma once

#include <cstdint>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "vsd/core/config.hpp"

namespace vsd {

namespace detail {

/// Shared state of a signal and its connections. Reference counted by hand (one thread at a time), so
/// that a connection can outlive its signal and a signal can die in the middle of its own emit.
struct SignalCore {
  struct Slot {
    void (*fn)() =
        nullptr;  // type-erased thunk (void(*)() is the generic function pointer); null once disconnected
    void* ctx = nullptr;
    void (*drop)(void*) = nullptr;  // destroys a heap-held functor, if any
    std::uint32_t id = 0;
  };
  std::vector<Slot> slots;
  void** live = nullptr;  // the owning signal's "live" pointer, null once the signal is gone
  std::uint32_t refs = 1;
  std::uint32_t depth = 0;  // nesting of emits in progress
  std::uint32_t next_id = 1;
  bool dirty = false;

  void update_live() noexcept;
  void disconnect(std::uint32_t id) noexcept;
  void sweep() noexcept;
  void release() noexcept;
  ~SignalCore();
};

}  // namespace detail

/// @brief Owns one listener of a signal; disconnects it when destroyed. Move-only.
class [[nodiscard]] Connection {
 public:
  Connection() noexcept = default;
  Connection(detail::SignalCore* core, std::uint32_t id) noexcept : core_(core), id_(id) { ++core_->refs; }
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;
  Connection(Connection&& o) noexcept : core_(std::exchange(o.core_, nullptr)), id_(o.id_) {}
  Connection& operator=(Connection&& o) noexcept {
    if (this != &o) {
      disconnect();
      core_ = std::exchange(o.core_, nullptr);
      id_ = o.id_;
    }
    return *this;
  }
  ~Connection() { disconnect(); }

  /// @brief Removes the listener now. Safe during an emit and after the signal is gone.
  void disconnect() noexcept {
    if (core_ != nullptr) {
      core_->disconnect(id_);
      std::exchange(core_, nullptr)->release();
    }
  }
  /// @brief Lets the listener live as long as the signal, and forgets it.
  void release() noexcept {
    if (core_ != nullptr) std::exchange(core_, nullptr)->release();
  }
  /// @brief True while this object still owns a listener of a living signal.
  [[nodiscard]] bool connected() const noexcept;

 private:
  detail::SignalCore* core_ = nullptr;
  std::uint32_t id_ = 0;
};

template <class Signature>
class Signal;

/// @brief A signal whose listeners take `Args...`. Not copyable and not movable: listeners refer to it.
template <class... Args>
class Signal<void(Args...)> {
  using Thunk = void (*)(void*, Args...);

 public:
  Signal() noexcept = default;
  Signal(const Signal&) = delete;
  Signal& operator=(const Signal&) = delete;
  ~Signal() {
    if (core_ != nullptr) {
      core_->live = nullptr;
      core_->release();
    }
  }

  /// @brief Calls every listener. Costs one branch when nobody listens.
  void emit(Args... args) const {
    if (VSD_LIKELY(live_ == nullptr)) return;
    dispatch(args...);
  }
  void operator()(Args... args) const { emit(args...); }

  /// @brief True when at least one listener is connected.
  [[nodiscard]] bool has_listeners() const noexcept { return live_ != nullptr; }
  /// @brief Number of connected listeners.
  [[nodiscard]] std::size_t size() const noexcept {
    std::size_t n = 0;
    if (core_ != nullptr)
      for (const auto& s : core_->slots) n += s.fn != nullptr ? 1 : 0;
    return n;
  }

  /// @brief Connects any callable (lambda, function object, function pointer).
  template <class F>
  Connection connect(F&& f) {
    using Fn = std::decay_t<F>;
    static_assert(std::is_invocable_v<Fn&, Args...>, "listener cannot be called with the signal's arguments");
    auto* held = new Fn(std::forward<F>(f));
    Thunk thunk = [](void* ctx, Args... a) { (*static_cast<Fn*>(ctx))(a...); };
    return add(thunk, held, [](void* p) { delete static_cast<Fn*>(p); });
  }

  /// @brief Connects a member function of @p object without allocating: `sig.connect<&C::on_x>(obj)`.
  template <auto Member, class C>
  Connection connect(C& object) {
    Thunk thunk = [](void* ctx, Args... a) { (static_cast<C*>(ctx)->*Member)(a...); };
    return add(thunk, &object, nullptr);
  }

 private:
  Connection add(Thunk thunk, void* ctx, void (*drop)(void*)) {
    if (core_ == nullptr) core_ = new detail::SignalCore;
    core_->live = reinterpret_cast<void**>(&live_);
    const std::uint32_t id = core_->next_id++;
    core_->slots.push_back({reinterpret_cast<void (*)()>(thunk), ctx, drop, id});
    core_->update_live();
    return Connection{core_, id};
  }

  void dispatch(Args... args) const {
    detail::SignalCore* core = core_;
    struct Depth {
      detail::SignalCore* c;
      ~Depth() {
        if (--c->depth == 0) {
          if (c->dirty) c->sweep();
          c->release();
        }
      }
    };
    if (core->depth++ == 0) ++core->refs;  // keep the core alive even if the signal dies meanwhile
    Depth guard{core};
    const std::size_t n = core->slots.size();  // listeners connected during this emit wait for the next
    for (std::size_t i = 0; i < n; ++i) {
      const auto& slot = core->slots[i];
      if (slot.fn != nullptr) reinterpret_cast<Thunk>(slot.fn)(slot.ctx, args...);
    }
  }

  detail::SignalCore* core_ = nullptr;
  void* live_ = nullptr;  // == core_ while at least one listener is connected
};

}  // namespace vsd
