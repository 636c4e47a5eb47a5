/** @file
 *  @brief Internal: IdMap, a flat open-addressing map from instance id to instance pointer.
 *
 *  Linear probing in a power-of-two table kept at most half full, deletion by backward shift (no
 *  tombstones): a lookup is a hash and, almost always, one or two probes; inserting and erasing never
 *  allocate except when the table grows.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "vsd/core/config.hpp"

namespace vsd {
class SimStateInstance;
}

namespace vsd::detail {

class IdMap {
 public:
  [[nodiscard]] std::size_t size() const noexcept { return size_; }

  [[nodiscard]] SimStateInstance* find(Id id) const noexcept {
    if (size_ == 0) return nullptr;
    for (std::size_t i = slot(id);; i = (i + 1) & mask_) {
      const Entry& e = table_[i];
      if (e.value == nullptr) return nullptr;
      if (e.id == id) return e.value;
    }
  }
  [[nodiscard]] bool contains(Id id) const noexcept { return find(id) != nullptr; }

  /// Inserts; returns false (and changes nothing) when @p id is present.
  bool insert(Id id, SimStateInstance* value) {
    if ((size_ + 1) * 2 > table_.size()) grow();
    for (std::size_t i = slot(id);; i = (i + 1) & mask_) {
      Entry& e = table_[i];
      if (e.value == nullptr) {
        e = Entry{id, value};
        ++size_;
        return true;
      }
      if (e.id == id) return false;
    }
  }

  /// Removes @p id if present.
  void erase(Id id) noexcept {
    if (size_ == 0) return;
    std::size_t i = slot(id);
    while (table_[i].value != nullptr && table_[i].id != id) i = (i + 1) & mask_;
    if (table_[i].value == nullptr) return;
    // Backward-shift deletion: pull later entries of the probe run into the hole.
    for (std::size_t j = (i + 1) & mask_; table_[j].value != nullptr; j = (j + 1) & mask_) {
      const std::size_t home = slot(table_[j].id);
      const bool movable = i <= j ? (home <= i || home > j) : (home <= i && home > j);
      if (movable) {
        table_[i] = table_[j];
        i = j;
      }
    }
    table_[i] = Entry{};
    --size_;
  }

  void clear() noexcept {
    table_.clear();
    mask_ = 0;
    size_ = 0;
  }

  /// Calls @p fn(id, value) for every entry, in no particular order.
  template <class F>
  void for_each(F&& fn) const {
    for (const Entry& e : table_)
      if (e.value != nullptr) fn(e.id, e.value);
  }

 private:
  struct Entry {
    Id id = 0;
    SimStateInstance* value = nullptr;
  };
  [[nodiscard]] std::size_t slot(Id id) const noexcept {
    std::uint64_t h = id * 0x9E3779B97F4A7C15ULL;  // Fibonacci hashing: ids are dense, spread them
    return static_cast<std::size_t>(h >> 32) & mask_;
  }
  void grow() {
    std::vector<Entry> old;
    old.swap(table_);
    table_.assign(old.empty() ? 16 : old.size() * 2, Entry{});
    mask_ = table_.size() - 1;
    size_ = 0;
    for (const Entry& e : old)
      if (e.value != nullptr) insert(e.id, e.value);
  }

  std::vector<Entry> table_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

}  // namespace vsd::detail
