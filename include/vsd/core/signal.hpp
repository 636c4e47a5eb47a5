/** @file
 *  @brief Signal<void(Args...)> and its RAII Connection: the messaging of the active database.
 *
 *  A signal keeps its listeners in one small array and calls them in a tight loop. Emitting with no
 *  listener costs one well-predicted branch, and emitting never allocates. Listeners may connect and
 *  disconnect any listener (themselves included) while the signal is being emitted: a disconnected slot
 *  is blanked at once and swept away when the outermost emit returns; a slot connected during an emit
 *  waits aside and is first called by the next emit.
 *
 *  Whoever owns a signal emits it; everybody else gets a Sink, which can connect but not emit
 *  (`state.on_deleted()` returns one), so no listener can fake an event of the database.
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
    void (*fn)() = nullptr;  // type-erased runner (void(*)() is the generic function pointer), see dispatch()
    void* ctx = nullptr;
    void (*drop)(void*) = nullptr;  // destroys a heap-held functor, if any
    std::uint32_t id = 0;
    bool dead = false;  // disconnected during an emit: fn is the signal's no-op until the sweep
  };
  std::vector<Slot> slots;            // never reallocated while an emit walks it
  std::vector<Slot> pending;          // connected during an emit; joins `slots` when the outermost emit ends
  void** live = nullptr;              // the owning signal's "live" pointer, null once the signal is gone
  void (*noop)() = nullptr;           // a runner that skips its slot, for slots blanked during an emit
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
      return add(&run<&call_inline<Fn>>, ctx, nullptr);
    } else {
      auto* held = new Fn(std::forward<F>(f));
      return add(&run<&call_held<Fn>>, held, [](void* p) { delete static_cast<Fn*>(p); });
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
    return add(&run<&call_member<Member, C>>, &object, nullptr);
  }

 private:
  using Slot = detail::SignalCore::Slot;
  using Call = void (*)(void*, Args...);
  // A runner calls the listener of slot `s` and then, inline, those of the slots right after it that
  // have the same runner (listeners of one type: the same lambda, functor class or member function).
  // It returns the first slot it did not run. So a signal whose listeners are of one kind costs one
  // indirect call per emit, not one per listener, and the listener's body is inlined into the loop.
  using Run = const Slot* (*)(const Slot*, const Slot*, Args...);

  template <class Fn>
  static void call_inline(void* c, Args... a) {
    alignas(Fn) unsigned char buf[sizeof(Fn)];
    std::memcpy(buf, &c, sizeof(Fn));  // a trivially copyable functor comes to life by its bytes
    (*std::launder(reinterpret_cast<Fn*>(buf)))(a...);
  }
  template <class Fn>
  static void call_held(void* c, Args... a) {
    (*static_cast<Fn*>(c))(a...);
  }
  template <auto Member, class C>
  static void call_member(void* c, Args... a) {
    (static_cast<C*>(c)->*Member)(a...);
  }
  template <Call call>
  static const Slot* run(const Slot* s, const Slot* end, Args... a) {
    const auto self = reinterpret_cast<void (*)()>(static_cast<Run>(&run<call>));
    // s->fn is read again for every slot: a listener that disconnects the next one blanks it (its
    // runner becomes the skipping one), which ends this run before that slot.
    do {
      call(s->ctx, a...);
      ++s;
    } while (s != end && s->fn == self);
    return s;
  }
  static const Slot* skip(const Slot* s, const Slot*, Args...) { return s + 1; }

  detail::SignalCore* core() {
    if (core_ == nullptr) {
      core_ = new detail::SignalCore;
      core_->live = reinterpret_cast<void**>(&live_);
      core_->noop = reinterpret_cast<void (*)()>(static_cast<Run>(&skip));
    }
    return core_;
  }

  Connection add(Run runner, void* ctx, void (*drop)(void*)) {
    detail::SignalCore* c = core();
    const bool first = live_ == nullptr;
    const std::uint32_t id = c->next_id++;
    const Slot slot{reinterpret_cast<void (*)()>(runner), ctx, drop, id};
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
    // No test for dead slots: a slot disconnected during an emit has the skipping runner until it is
    // swept. `slots` is never reallocated during an emit (connections made now wait in `pending`).
    for (const Slot *s = core->slots.data(), *end = s + core->slots.size(); s != end;)
      s = reinterpret_cast<Run>(s->fn)(s, end, args...);
  }

  detail::SignalCore* core_ = nullptr;
  void* live_ = nullptr;  // == core_ while at least one listener is connected
};

/// @brief The connecting side of a Signal: what an owner hands out so that others can listen but not emit
/// (EnTT's sink). A Sink is a small handle; it must not outlive its signal.
template <class Signature>
class Sink;

template <class... Args>
class Sink<void(Args...)> {
 public:
  using SignalType = Signal<void(Args...)>;
  explicit Sink(SignalType& signal) noexcept : signal_(&signal) {}

  /// @brief Connects any callable (lambda, function object, function pointer); see Signal::connect.
  template <class F>
  Connection connect(F&& f) const {
    return signal_->connect(std::forward<F>(f));
  }
  /// @brief Connects a member function of @p object without allocating: `sink.connect<&C::on_x>(obj)`.
  template <auto Member, class C>
  Connection connect(C& object) const {
    return signal_->template connect<Member>(object);
  }
  /// @brief True when at least one listener is connected.
  [[nodiscard]] bool has_listeners() const noexcept { return signal_->has_listeners(); }
  /// @brief Number of connected listeners.
  [[nodiscard]] std::size_t size() const noexcept { return signal_->size(); }

 private:
  SignalType* signal_;
};

}  // namespace vsd
