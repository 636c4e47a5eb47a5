/** @file
 *  @brief StateContext: the typed slots in which modules keep what belongs to one SimState — a
 *  collision world, an ODE world, a compiled kinematic model, a program's executor (EnTT's
 *  `registry.ctx()`).
 *
 *  Why slots and not database instances: this data mirrors the database for an algorithm (FCL and ODE
 *  objects, raw pointers, listener connections). It must not be saved, recorded or replicated, and it
 *  must be gone before the instances it points at. What a user configures (a physics World, a SOML++
 *  Executor) stays in the database as ordinary instances; their run-time mirrors live here.
 *
 *  Lifetime: an entry lives until it is erased or its SimState is destroyed. The SimState clears its
 *  context first, before any instance goes, newest entry first, so an entry may still read instances and
 *  disconnect from the state's signals in its destructor. One entry per type.
 *
 *  Threading: like its SimState, a context belongs to one thread at a time. Looking up an entry is an
 *  index into a small array (the type's key is a number taken once per type, thread-safely).
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <typeinfo>
#include <utility>
#include <vector>

#include "vsd/core/error.hpp"

namespace vsd {

namespace detail {
/// The next free context key (thread-safe).
std::size_t next_context_key() noexcept;
template <class T>
std::size_t context_key() noexcept {
  static const std::size_t key = next_context_key();
  return key;
}
[[noreturn]] void throw_context_entry_exists(const char* type_name);
[[noreturn]] void throw_context_entry_missing(const char* type_name);
}  // namespace detail

class StateContext {
 public:
  StateContext() = default;
  StateContext(const StateContext&) = delete;
  StateContext& operator=(const StateContext&) = delete;
  ~StateContext() { clear(); }

  /// @brief Makes the entry of type T from @p args. @throws vsd::Error when there is one already.
  template <class T, class... A>
  T& emplace(A&&... args) {
    const std::size_t k = detail::context_key<T>();
    if (k < slots_.size() && slots_[k] != npos) detail::throw_context_entry_exists(typeid(T).name());
    auto owned = std::make_unique<T>(std::forward<A>(args)...);
    if (slots_.size() <= k) slots_.resize(k + 1, npos);
    entries_.push_back(Entry{owned.get(), &destroy<T>, k});
    slots_[k] = entries_.size() - 1;
    return *owned.release();
  }
  /// @brief The entry of type T, or nullptr.
  template <class T>
  [[nodiscard]] T* find() const noexcept {
    const std::size_t k = detail::context_key<T>();
    return k < slots_.size() && slots_[k] != npos ? static_cast<T*>(entries_[slots_[k]].object) : nullptr;
  }
  /// @brief The entry of type T. @throws vsd::Error when there is none.
  template <class T>
  [[nodiscard]] T& get() const {
    if (T* t = find<T>()) return *t;
    detail::throw_context_entry_missing(typeid(T).name());
  }
  /// @brief The entry of type T, made from @p args when there is none yet.
  template <class T, class... A>
  T& get_or_emplace(A&&... args) {
    if (T* t = find<T>()) return *t;
    return emplace<T>(std::forward<A>(args)...);
  }
  /// @brief Destroys the entry of type T; returns false when there was none.
  template <class T>
  bool erase() noexcept {
    const std::size_t k = detail::context_key<T>();
    if (k >= slots_.size() || slots_[k] == npos) return false;
    erase_at(slots_[k]);
    return true;
  }
  /// @brief Destroys every entry, newest first.
  void clear() noexcept {
    while (!entries_.empty()) erase_at(entries_.size() - 1);
  }
  [[nodiscard]] bool empty() const noexcept { return entries_.empty(); }
  [[nodiscard]] std::size_t size() const noexcept { return entries_.size(); }

 private:
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);
  struct Entry {
    void* object;
    void (*destroy)(void*) noexcept;
    std::size_t key;
  };
  template <class T>
  static void destroy(void* p) noexcept {
    delete static_cast<T*>(p);
  }
  void erase_at(std::size_t i) noexcept {
    // Unlinked before it is destroyed: a destructor that looks itself up finds nothing.
    const Entry e = entries_[i];
    entries_.erase(entries_.begin() + static_cast<std::ptrdiff_t>(i));
    slots_[e.key] = npos;
    for (std::size_t j = i; j < entries_.size(); ++j) slots_[entries_[j].key] = j;
    e.destroy(e.object);
  }

  std::vector<Entry> entries_;      // in the order they were made
  std::vector<std::size_t> slots_;  // context key -> index in entries_, or npos
};

}  // namespace vsd
