// What the executor's tests read, by (instance id, property): the transitions to re-test when that
// property of that instance changes (a null property: any property — the test called a C++ method of the
// instance). Looked up on every change a SOML++ program hears, so it is an open-addressing table (linear
// probing, power-of-two size, load at most 1/2, backward-shift erase) rather than std::unordered_map,
// whose prime-modulo bucket and node hop cost as much as the rest of the setter.
#pragma once

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

  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }

  /// The watchers of @p key, or nullptr.
  [[nodiscard]] Watchers* find(const DepKey& key) noexcept {
    if (size_ == 0) return nullptr;
    for (std::size_t i = slot(key);; i = (i + 1) & mask_) {
      Entry& e = slots_[i];
      if (e.key.id == 0) return nullptr;
      if (e.key == key) return &e.watchers;
    }
  }
  /// The watchers of @p key, made empty when absent (valid until the next insert or erase).
  Watchers& operator[](const DepKey& key) {
    if ((size_ + 1) * 2 > slots_.size()) rehash(slots_.empty() ? 16 : slots_.size() * 2);
    for (std::size_t i = slot(key);; i = (i + 1) & mask_) {
      Entry& e = slots_[i];
      if (e.key == key) return e.watchers;
      if (e.key.id == 0) {
        e.key = key;
        ++size_;
        return e.watchers;
      }
    }
  }
  /// Removes @p key (nothing when absent).
  void erase(const DepKey& key) noexcept {
    if (size_ == 0) return;
    std::size_t i = slot(key);
    while (!(slots_[i].key == key)) {
      if (slots_[i].key.id == 0) return;
      i = (i + 1) & mask_;
    }
    // Backward shift: pull later entries of the run into the hole unless they would leave their home.
    for (std::size_t j = (i + 1) & mask_; slots_[j].key.id != 0; j = (j + 1) & mask_) {
      const std::size_t home = slot(slots_[j].key);
      if (((j - home) & mask_) >= ((j - i) & mask_)) {
        slots_[i] = std::move(slots_[j]);
        i = j;
      }
    }
    slots_[i] = Entry{};
    --size_;
  }
  /// Calls @p fn(key, watchers) for every entry (it may change the watchers), then drops the entries
  /// left without watchers.
  template <class F>
  void update_all(F&& fn) {
    bool emptied = false;
    for (Entry& e : slots_)
      if (e.key.id != 0) {
        fn(e.key, e.watchers);
        emptied = emptied || e.watchers.empty();
      }
    if (emptied) rehash(slots_.size());
  }
  template <class F>
  void for_each(F&& fn) const {
    for (const Entry& e : slots_)
      if (e.key.id != 0) fn(e.key, e.watchers);
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
  // Rebuilds with @p capacity slots (a power of two), leaving out entries without watchers.
  void rehash(std::size_t capacity) {
    std::vector<Entry> old(capacity);
    old.swap(slots_);
    mask_ = slots_.size() - 1;
    size_ = 0;
    for (Entry& e : old)
      if (e.key.id != 0 && !e.watchers.empty()) {
        std::size_t i = slot(e.key);
        while (slots_[i].key.id != 0) i = (i + 1) & mask_;
        slots_[i] = std::move(e);
        ++size_;
      }
  }
  std::vector<Entry> slots_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

}  // namespace vsd::soml
