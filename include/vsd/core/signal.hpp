/** @file
 *  @brief Signal<void(Args...)> and its RAII Connection: the messaging of the active database.
 *
 *  A signal keeps its listeners in one small array and calls them in a tight loop. Emitting with no
 *  listener costs one well-predicted branch, and emitting never allocates. Listeners may connect and
 *  disconnect any listener (themselves included) while the signal is being emitted: a disconnected slot
 *  is blanked at once and swept away when the outermost emit returns; a slot connected during an emit
 *  waits aside and is first called by the next emit.
 *
 *  Lifetime: a Connection may outlive its Signal (disconnecting then does nothing) and a Signal may be
 *  destroyed from inside one of its own listeners. Signals and connections belong to one thread at a
 *  time, like the SimState they live in.
 */
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
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
    void (*fn)() = nullptr;  // type-erased thunk (void(*)() is the generic function pointer)
    void* ctx = nullptr;
    void (*drop)(void*) = nullptr;  // destroys a heap-held functor, if any
    std::uint32_t id = 0;
    bool dead = false;  // disconnected during an emit: fn is the signal's no-op until the sweep
  };
  std::vector<Slot> slots;            // never reallocated while an emit walks it
  std::vector<Slot> pending;          // connected during an emit; joins `slots` when the outermost emit ends
  void** live = nullptr;              // the owning signal's "live" pointer, null once the signal is gone
  void (*noop)() = nullptr;           // a thunk that does nothing, for slots blanked during an emit
  void (*on_first)(void*) = nullptr;  // called when the signal gains a listener after having none
  void* on_first_ctx = nullptr;
  std::uint32_t refs = 1;
  std::uint32_t depth = 0;  // nesting of emits in progress
  std::uint32_t next_id = 1;
  bool dirty = false;  // blanked or pending slots to tidy up after the emit

  void update_live() noexcept;
  void disconnect(std::uint32_t id) noexcept;
  void finish_dispatch() noexcept;  // after the outermost emit: tidy up, or free an orphaned core
  void release() noexcept;
  [[nodiscard]] bool has(std::uint32_t id) const noexcept;
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
    if (core_ != nullptr) {
      for (const auto& s : core_->slots) n += s.dead ? 0 : 1;
      for (const auto& s : core_->pending) n += s.dead ? 0 : 1;
    }
    return n;
  }

  /// @brief Connects any callable (lambda, function object, function pointer).
  template <class F>
  Connection connect(F&& f) {
    using Fn = std::decay_t<F>;
    static_assert(std::is_invocable_v<Fn&, Args...>, "listener cannot be called with the signal's arguments");
    if constexpr (sizeof(Fn) <= sizeof(void*) && std::is_trivially_copyable_v<Fn>) {
      // A functor that fits in a pointer (a lambda capturing one pointer or reference, a function
      // pointer) is kept in the slot itself: no allocation, one load less per call.
      void* ctx = nullptr;
      std::memcpy(&ctx, &f, sizeof(Fn));
      Thunk thunk = [](void* c, Args... a) {
        alignas(Fn) unsigned char buf[sizeof(Fn)];
        std::memcpy(buf, &c, sizeof(Fn));  // a trivially copyable functor comes to life by its bytes
        (*std::launder(reinterpret_cast<Fn*>(buf)))(a...);
      };
      return add(thunk, ctx, nullptr);
    } else {
      auto* held = new Fn(std::forward<F>(f));
      Thunk thunk = [](void* ctx, Args... a) { (*static_cast<Fn*>(ctx))(a...); };
      return add(thunk, held, [](void* p) { delete static_cast<Fn*>(p); });
    }
  }

  /// @brief Calls @p hook(@p ctx) whenever the signal gains a listener after having none. The owner of
  /// the signal uses it to switch on work that is only worth doing while somebody listens.
  void on_first_listener(void (*hook)(void*), void* ctx) {
    core();
    core_->on_first = hook;
    core_->on_first_ctx = ctx;
  }

  /// @brief Connects a member function of @p object without allocating: `sig.connect<&C::on_x>(obj)`.
  template <auto Member, class C>
  Connection connect(C& object) {
    Thunk thunk = [](void* ctx, Args... a) { (static_cast<C*>(ctx)->*Member)(a...); };
    return add(thunk, &object, nullptr);
  }

 private:
  static void noop(void*, Args...) {}

  detail::SignalCore* core() {
    if (core_ == nullptr) {
      core_ = new detail::SignalCore;
      core_->live = reinterpret_cast<void**>(&live_);
      core_->noop = reinterpret_cast<void (*)()>(static_cast<Thunk>(&noop));
    }
    return core_;
  }

  Connection add(Thunk thunk, void* ctx, void (*drop)(void*)) {
    detail::SignalCore* c = core();
    const bool first = live_ == nullptr;
    const std::uint32_t id = c->next_id++;
    const detail::SignalCore::Slot slot{reinterpret_cast<void (*)()>(thunk), ctx, drop, id};
    if (c->depth > 0) {  // an emit is walking `slots`: do not move it under its feet
      c->pending.push_back(slot);
      c->dirty = true;
    } else {
      c->slots.push_back(slot);
    }
    c->update_live();
    if (first && c->on_first != nullptr) c->on_first(c->on_first_ctx);
    return Connection{c, id};
  }

  void dispatch(Args... args) const {
    detail::SignalCore* core = core_;
    struct Depth {  // a core whose signal died during the emit is freed by the outermost one
      detail::SignalCore* c;
      ~Depth() {
        if (--c->depth == 0 && (c->dirty || c->refs == 0)) c->finish_dispatch();
      }
    };
    ++core->depth;
    Depth guard{core};
    // No test per slot: a slot disconnected during an emit calls a no-op until it is swept.
    for (const auto *s = core->slots.data(), *end = s + core->slots.size(); s != end; ++s)
      reinterpret_cast<Thunk>(s->fn)(s->ctx, args...);
  }

  detail::SignalCore* core_ = nullptr;
  void* live_ = nullptr;  // == core_ while at least one listener is connected
};

}  // namespace vsd
