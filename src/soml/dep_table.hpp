// What the executor's tests read, by (instance id, property): the transitions to re-test when that
// property of that instance changes (a null property: any property — the test called a C++ method of the
// instance). Looked up on every change a SOML++ program hears, so it is an open-addressing table (linear
// probing, power-of-two size, at most half full) rather than std::unordered_map, whose prime-modulo
// bucket and node hop cost as much as the rest of the setter.
//
// A key whose last watcher leaves stays in the table, dormant (no watchers, its list's capacity kept):
// an object token that moves on changes the first token its transitions read, so the same few keys lose
// and regain their watcher on almost every firing, and erasing them cost a free, then a malloc and a
// vector growth when the key came back. Dormant keys are dropped when the table rehashes (it is
// rebuilt at its size, not doubled, when they make most of it), so keys of deleted instances do not
// pile up.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "vsd/core/meta_property.hpp"

namespace vsd::soml {

struct DepKey {
  std::uint64_t id;  // never 0: 0 marks an empty slot
  const MetaProperty* prop;
  bool operator==(const DepKey&) const = default;
};

class DepTable {
 public:
  using Watchers = std::vector<std::uint32_t>;  // transition entries, in transition order

  /// True when no key has a watcher.
  [[nodiscard]] bool empty() const noexcept { return live_ == 0; }
  /// The keys with at least one watcher (dormant keys do not count).
  [[nodiscard]] std::size_t size() const noexcept { return live_; }
  /// The slots in use, dormant keys included (for tests of the reuse).
  [[nodiscard]] std::size_t used_slots() const noexcept { return used_; }
  [[nodiscard]] std::size_t capacity() const noexcept { return slots_.size(); }

  /// The watchers of @p key (possibly none: a dormant key), or nullptr.
  [[nodiscard]] const Watchers* find(const DepKey& key) const noexcept {
    if (used_ == 0) return nullptr;
    for (std::size_t i = slot(key);; i = (i + 1) & mask_) {
      const Entry& e = slots_[i];
      if (e.key.id == 0) return nullptr;
      if (e.key == key) return &e.watchers;
    }
  }
  /// Adds transition entry @p ti to the watchers of @p key, keeping them in ascending (transition)
  /// order; returns true when the key had none before (it was absent or dormant).
  bool add(const DepKey& key, std::uint32_t ti) {
    Watchers& w = slot_for(key);
    const bool first = w.empty();
    if (first) ++live_;
    w.insert(std::upper_bound(w.begin(), w.end(), ti), ti);
    return first;
  }
  /// Removes transition entry @p ti from the watchers of @p key (nothing when absent); the key stays,
  /// dormant, when that was its last watcher.
  void remove(const DepKey& key, std::uint32_t ti) noexcept {
    Watchers* w = find_mutable(key);
    if (w == nullptr || w->empty()) return;
    w->erase(std::remove(w->begin(), w->end(), ti), w->end());
    if (w->empty()) --live_;
  }
  /// Calls @p fn(key, watchers) for every key with watchers (it may change them, keeping them sorted),
  /// then drops the keys left without watchers.
  template <class F>
  void update_all(F&& fn) {
    if (slots_.empty()) return;
    for (Entry& e : slots_)
      if (e.key.id != 0 && !e.watchers.empty()) fn(e.key, e.watchers);
    rehash(slots_.size());  // recounts live_ and drops the dormant keys
  }
  /// Calls @p fn(key, watchers) for every key with watchers.
  template <class F>
  void for_each(F&& fn) const {
    for (const Entry& e : slots_)
      if (e.key.id != 0 && !e.watchers.empty()) fn(e.key, e.watchers);
  }

 private:
  struct Entry {
    DepKey key{0, nullptr};
    Watchers watchers;
  };
  [[nodiscard]] std::size_t slot(const DepKey& k) const noexcept {
    // Fibonacci hashing of both fields: ids are dense and properties 8-byte aligned; the product's
    // upper half mixes every input bit.
    const std::uint64_t h = (k.id ^ (reinterpret_cast<std::uintptr_t>(k.prop) >> 3) * 0xBF58476D1CE4E5B9ULL) *
                            0x9E3779B97F4A7C15ULL;
    return static_cast<std::size_t>(h >> 32) & mask_;
  }
  Watchers* find_mutable(const DepKey& key) noexcept {
    return const_cast<Watchers*>(std::as_const(*this).find(key));
  }
  // The watchers of @p key, an empty (new) entry when absent.
  Watchers& slot_for(const DepKey& key) {
    if (Watchers* w = find_mutable(key)) return *w;
    if ((used_ + 1) * 2 > slots_.size()) {
      // Full: rebuilt without the dormant keys, at a size that leaves the live ones at most a quarter
      // of it (so a table of mostly dormant keys is rebuilt at its size, not doubled).
      std::size_t capacity = slots_.empty() ? 16 : slots_.size();
      while ((live_ + 1) * 4 > capacity) capacity *= 2;
      rehash(capacity);
    }
    std::size_t i = slot(key);
    while (slots_[i].key.id != 0) i = (i + 1) & mask_;
    slots_[i].key = key;
    ++used_;
    return slots_[i].watchers;
  }
  // Rebuilds with @p capacity slots (a power of two), leaving out keys without watchers.
  void rehash(std::size_t capacity) {
    std::vector<Entry> old(capacity);
    old.swap(slots_);
    mask_ = slots_.size() - 1;
    used_ = 0;
    for (Entry& e : old)
      if (e.key.id != 0 && !e.watchers.empty()) {
        std::size_t i = slot(e.key);
        while (slots_[i].key.id != 0) i = (i + 1) & mask_;
        slots_[i] = std::move(e);
        ++used_;
      }
    live_ = used_;
  }
  std::vector<Entry> slots_;
  std::size_t mask_ = 0;
  std::size_t used_ = 0;  // keys in the table, dormant ones included
  std::size_t live_ = 0;  // keys with watchers
};

}  // namespace vsd::soml
