/** @file
 *  @brief Internal: FlatIdMap, a flat open-addressing map from instance id to a small value (IdMap: to
 *  the instance pointer).
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
#include "vsd/core/detail/huge_pages.hpp"

namespace vsd {
class SimStateInstance;
}

namespace vsd::detail {

/// Id 0 (null_id) is never a key: it marks empty slots.
template <class V>
class FlatIdMap {
 public:
  [[nodiscard]] std::size_t size() const noexcept { return size_; }

  /// The value of @p id, or a pointer-like "nothing" (V{}) when absent.
  [[nodiscard]] V find(Id id) const noexcept {
    const Entry* e = entry(id);
    return e != nullptr ? e->value : V{};
  }
  [[nodiscard]] bool contains(Id id) const noexcept { return entry(id) != nullptr; }
  /// The stored value of @p id, or nullptr.
  [[nodiscard]] V* get(Id id) noexcept {
    return entry(id) != nullptr ? &const_cast<Entry*>(entry(id))->value : nullptr;
  }

  /// Inserts; returns false (and changes nothing) when @p id is present.
  bool insert(Id id, V value) {
    VSD_ASSERT(id != null_id, "id 0 cannot be a key");
    if ((size_ + 1) * 2 > table_.size()) grow();
    for (std::size_t i = slot(id);; i = (i + 1) & mask_) {
      Entry& e = table_[i];
      if (e.id == null_id) {
        e = Entry{id, value};
        ++size_;
        note_reach(id, i);
        return true;
      }
      if (e.id == id) return false;
    }
  }
  /// Inserts @p id with an empty value and returns where its value goes (valid until the next insert),
  /// or nullptr (changing nothing) when @p id is present: one probe for a check and an insert.
  V* try_insert(Id id) {
    VSD_ASSERT(id != null_id, "id 0 cannot be a key");
    if ((size_ + 1) * 2 > table_.size()) grow();
    for (std::size_t i = slot(id);; i = (i + 1) & mask_) {
      Entry& e = table_[i];
      if (e.id == null_id) {
        e = Entry{id, V{}};
        ++size_;
        if (VSD_UNLIKELY(note_reach(id, i))) return get(id);  // the table was rebuilt
        return &e.value;
      }
      if (e.id == id) return nullptr;
    }
  }
  /// Makes room for @p count entries in all, so that inserting them does not grow the table.
  void reserve(std::size_t count) {
    std::size_t want = 16;
    while (want < count * 2) want *= 2;
    if (want > table_.size()) rehash(want);
  }
  /// Inserts or overwrites.
  void assign(Id id, V value) {
    if (V* v = get(id)) {
      *v = value;
    } else {
      insert(id, value);
    }
  }

  /// Removes @p id if present.
  void erase(Id id) noexcept {
    if (size_ == 0) return;
    std::size_t i = slot(id);
    while (table_[i].id != null_id && table_[i].id != id) i = (i + 1) & mask_;
    if (table_[i].id == null_id) return;
    // Backward-shift deletion: pull later entries of the probe run into the hole. An entry can fill it
    // when it sits at least as far from its home slot as from the hole; none sits farther than reach_,
    // so the scan ends reach_ slots past the hole. (Dense ids fill one long run, each entry at home: a
    // scan to the end of the run made erasing them in order quadratic.)
    for (std::size_t j = (i + 1) & mask_; table_[j].id != null_id && ((j - i) & mask_) <= reach_;
         j = (j + 1) & mask_) {
      if (((j - slot(table_[j].id)) & mask_) >= ((j - i) & mask_)) {
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
    reach_ = 0;
    mixed_ = false;
  }

  /// Calls @p fn(id, value) for every entry, in no particular order.
  template <class F>
  void for_each(F&& fn) const {
    for (const Entry& e : table_)
      if (e.id != null_id) fn(e.id, e.value);
  }

 private:
  struct Entry {
    Id id = null_id;
    V value{};
  };
  [[nodiscard]] const Entry* entry(Id id) const noexcept {
    if (size_ == 0) return nullptr;
    for (std::size_t i = slot(id);; i = (i + 1) & mask_) {
      const Entry& e = table_[i];
      if (e.id == null_id) return nullptr;
      if (e.id == id) return &e;
    }
  }
  [[nodiscard]] std::size_t slot(Id id) const noexcept {
    // Ids of one site are dense and handed out in order: their low bits are already a perfect hash,
    // and neighbouring ids land in neighbouring slots (instances made together are looked up
    // together). Only the site (top 16 bits) is mixed in, so that sites do not pile onto one run.
    // But ids only grow: once the live ones span more than the table, new ids land on the run of old
    // ones still there (a long-lived tree of 65,536 and a churn of others: every insert walked the run).
    // A probe that long switches the table to a mixing hash (note_reach), for good.
    const std::uint64_t site = id >> 48;
    if (VSD_UNLIKELY(mixed_)) return static_cast<std::size_t>((id * 0x9E3779B97F4A7C15ULL) >> shift_);
    return static_cast<std::size_t>(id ^ (site * 0x9E3779B97F4A7C15ULL)) & mask_;
  }
  // Keeps reach_ at least the distance of every entry from its home slot (a backward shift only brings
  // entries nearer home, so it stays a bound until the table is rebuilt).
  // Returns true when it rebuilt the table (entries moved).
  bool note_reach(Id id, std::size_t at) {
    const std::size_t d = (at - slot(id)) & mask_;
    if (d > reach_) reach_ = d;
    if (VSD_LIKELY(d <= long_probe || mixed_)) return false;
    mixed_ = true;
    rehash(table_.size());
    return true;
  }
  static constexpr std::size_t long_probe = 64;
  void grow() { rehash(table_.empty() ? 16 : table_.size() * 2); }
  void rehash(std::size_t capacity) {
    std::vector<Entry, HugeAllocator<Entry>> old;
    old.swap(table_);
    table_.assign(capacity, Entry{});
    mask_ = table_.size() - 1;
    shift_ = 64;
    for (std::size_t n = table_.size(); n > 1; n /= 2) --shift_;
    size_ = 0;
    reach_ = 0;
    for (const Entry& e : old)
      if (e.id != null_id) insert(e.id, e.value);
  }

  // A million ids take 32 MB: in huge pages (huge_pages.hpp), not 8 000 page faults.
  std::vector<Entry, HugeAllocator<Entry>> table_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
  std::size_t reach_ = 0;  // no entry sits farther than this from its home slot
  unsigned shift_ = 64;    // 64 - log2(table size): the mixing hash takes the top bits of a product
  bool mixed_ = false;     // slots by a mixing hash (see slot())
};

/// Instances of a SimState by id.
using IdMap = FlatIdMap<SimStateInstance*>;

}  // namespace vsd::detail
