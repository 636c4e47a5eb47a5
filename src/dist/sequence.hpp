// Internal to vsd::dist: one reference list as a replicated sequence (an RGA, "replicated growable array"),
// so that concurrent insertions and erasures of one list merge alike on every participant
// (docs/dist.md, "Reference lists").
//
// Every entry has an ElementId that never changes and is never reused: the stamp of the bundle that
// inserted it (Lamport clock, participant id) and its number in that bundle. An insertion names the entry
// it follows (its origin); an erasure only marks its entry removed (a tombstone), so later edits that name
// it still find it. Integration rule: an entry goes right after its origin, past every entry there with a
// larger id. Lamport clocks make an entry's id larger than its origin's and than everything its inserter
// had seen, so entries inserted after the same origin concurrently end in descending id order everywhere,
// whatever order they arrive in, and a participant's own insertion lands exactly where it made it.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "vsd/core/config.hpp"
#include "vsd/dist/wire.hpp"

namespace vsd::dist::internal {

struct Element {
  ElementId id;
  Id target = null_id;
  bool removed = false;
  std::chrono::steady_clock::time_point removed_at{};  // here, for pruning (not sent)
};

class Sequence {
 public:
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);

  /// A list nobody edited through vsd::dist yet: entries (0, 0, 1), (0, 0, 2), ... in order (every
  /// participant holds the same value then, so every participant makes the same ids).
  static Sequence base(const std::vector<Id>& ids) {
    Sequence s;
    s.elems.reserve(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i) s.elems.push_back({ElementId{0, 0, i + 1}, ids[i], false});
    return s;
  }

  [[nodiscard]] std::size_t find(const ElementId& id) const noexcept {
    for (std::size_t i = 0; i < elems.size(); ++i)
      if (elems[i].id == id) return i;
    return npos;
  }
  /// The list index the entry at @p pos has (or would have, were it visible).
  [[nodiscard]] std::size_t index_of(std::size_t pos) const noexcept {
    std::size_t n = 0;
    for (std::size_t i = 0; i < pos; ++i) n += elems[i].removed ? 0 : 1;
    return n;
  }
  /// The position of the visible entry at list index @p index; npos past the end.
  [[nodiscard]] std::size_t position(std::size_t index) const noexcept {
    for (std::size_t i = 0; i < elems.size(); ++i)
      if (!elems[i].removed && index-- == 0) return i;
    return npos;
  }
  /// Places a new entry (see the file comment); npos when @p origin is unknown here (nothing changes).
  std::size_t integrate(const ElementId& id, const ElementId& origin, Id target, bool removed) {
    std::size_t pos = 0;
    if (origin != ElementId{}) {
      pos = find(origin);
      if (pos == npos) return npos;
      ++pos;
    }
    while (pos < elems.size() && id < elems[pos].id) ++pos;
    elems.insert(
        elems.begin() + static_cast<std::ptrdiff_t>(pos),
        Element{id, target, removed,
                removed ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{}});
    return pos;
  }
  /// Marks the entry at @p pos removed (it stays, as a tombstone, for edits that name it).
  void remove(std::size_t pos) {
    elems[pos].removed = true;
    elems[pos].removed_at = std::chrono::steady_clock::now();
  }
  /// Drops the tombstones removed before @p before (docs/dist.md, "Tombstones"): the visible entries and
  /// their order do not change. @return how many went.
  std::size_t prune(std::chrono::steady_clock::time_point before) {
    const std::size_t n = elems.size();
    std::erase_if(elems, [&](const Element& e) { return e.removed && e.removed_at < before; });
    return n - elems.size();
  }
  [[nodiscard]] std::vector<Id> visible() const {
    std::vector<Id> v;
    for (const Element& e : elems)
      if (!e.removed) v.push_back(e.target);
    return v;
  }

  std::vector<Element> elems;  // in list order, removed entries included
};

}  // namespace vsd::dist::internal
