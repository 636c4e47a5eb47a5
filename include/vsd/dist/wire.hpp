/** @file
 *  @brief The wire form of a transaction bundle: only Distributed properties, each class and property
 *  name once per bundle (a name table), no old values.
 *
 *  vsd::dist publishes one bundle per DDS sample in this form and turns it back into an ordinary
 *  Transaction ("VSDT") on the receiving side, which SimState::apply checks and applies as always. The
 *  encoding lives here rather than in the core's VSDT format because it is lossy on purpose: it drops
 *  what a replica must not or need not receive (non-Distributed values, the old values of sets, the last
 *  values of deletions), so the result can no longer be inverted — a VSDT bundle must stay invertible
 *  (undo). Layout in docs/dist.md, "Wire format".
 */
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "vsd/core/transaction.hpp"

namespace vsd {
class SimState;
}  // namespace vsd

namespace vsd::dist {

/// @brief The identity of one entry of a reference list as vsd::dist merges lists: the stamp (Lamport
/// clock, participant id) of the bundle that inserted it and its number among that bundle's insertions.
/// Entries that were in a list before anyone edited it through vsd::dist are (0, 0, 1), (0, 0, 2), ...;
/// (0, 0, 0) is the list's head (the origin of an entry inserted at the front).
struct ElementId {
  std::uint64_t clock = 0;
  std::uint64_t who = 0;
  std::uint64_t n = 0;
  auto operator<=>(const ElementId&) const = default;
};

/// @brief A reference-list edit in element form (docs/dist.md, "Reference lists"): an insertion names the
/// entry it comes after (@p origin) and gets a new @p element; an erasure names the entry it removes.
struct ElementEdit {
  Transaction::Op op = Transaction::Op::Insert;  ///< Insert or Erase
  Id holder = null_id;                           ///< the instance holding the list
  std::string_view property;                     ///< the list property
  /// Insert: the new entry (decoded: clock and who 0, they are the bundle's stamp); Erase: the entry removed
  ElementId element;
  ElementId origin;     ///< Insert: the entry it follows ((0, 0, 0): the front)
  Id target = null_id;  ///< the instance the entry refers to
};

/// @brief Turns a recorded, index-based list edit (in recording order) into its element form.
using ListEncoder = std::function<ElementEdit(Transaction::Op op, Id holder, std::string_view property,
                                              std::size_t index, Id target)>;

/// @brief What encode_bundle() made.
struct WireBundle {
  std::vector<std::uint8_t> bytes;  ///< "VSDW", version, name table, operations
  std::size_t ops = 0;              ///< operations kept (0: nothing to send)
  std::size_t dropped = 0;          ///< operations dropped (non-Distributed properties)
  /// (instance, property) of every set kept, in order; the views point into the encoded Transaction
  std::vector<std::pair<Id, std::string_view>> sets;
  std::vector<Id> deleted;  ///< the instances the bundle deletes
  bool list_edits = false;  ///< true when a reference-list edit (insert, erase) was kept
};

/// @brief encode_bundle(), writing every kept reference-list edit in element form as @p lists returns it
/// (vsd::dist's participants do; without it, edits keep their index form, as in snapshots).
[[nodiscard]] WireBundle encode_bundle(const Transaction& t, const SimState& state, const ListEncoder& lists);

/// @brief Encodes @p t, recorded by @p state, in wire form, keeping only Distributed properties.
/// @p state resolves the classes of instances the bundle does not create or delete itself.
/// @throws vsd::Error when an operation names an instance or class that cannot be resolved.
[[nodiscard]] WireBundle encode_bundle(const Transaction& t, const SimState& state);

/// @brief Decodes a wire bundle into an ordinary Transaction (sets carry the new value as old value).
/// @throws vsd::Error "wire bundle byte N: ..." for a wrong header, a bad name index, a count the bytes
/// cannot hold, truncated or trailing data. The operations themselves are checked by SimState::apply.
[[nodiscard]] Transaction decode_bundle(std::span<const std::uint8_t> bytes);

/// @brief Decides, for each deletion, property set and list edit of a wire bundle, whether it is kept
/// (vsd::dist drops sets that lost to a concurrent write with a later stamp, and changes to instances
/// deleted concurrently: docs/dist.md, "Concurrent writes"). @p property is empty for a deletion.
using OpFilter = std::function<bool(Transaction::Op op, Id instance, std::string_view property)>;

/// @brief decode_bundle(), keeping only the deletions, sets and list edits for which @p keep returns true
/// (creations are always kept). @p keep sees every such operation, in order, even when the bundle turns
/// out malformed later. @throws vsd::Error as decode_bundle().
[[nodiscard]] Transaction decode_bundle(std::span<const std::uint8_t> bytes, const OpFilter& keep);

/// @brief How decode_bundle() turns a wire bundle into a Transaction, beyond the plain copy: every hook may
/// be empty.
struct DecodeHooks {
  /// Decides which deletions, sets and list edits (index or element form) are kept, as for decode_bundle().
  OpFilter keep;
  /// Writes the index-based operations (detail::write_list) that carry out a kept element-form edit here,
  /// adding their number to @p ops. Required when the bundle holds element-form edits.
  std::function<void(const ElementEdit& edit, std::vector<std::uint8_t>& out, std::size_t& ops)> list;
  /// Called for every creation, with the instance's class name.
  std::function<void(Id id, std::string_view cls)> created;
  /// Called before a kept deletion of @p id is written: may write operations that must come first.
  std::function<void(Id id, std::vector<std::uint8_t>& out, std::size_t& ops)> before_delete;
  /// May replace the new value of a kept set (the returned bytes must outlive the call).
  std::function<std::span<const std::uint8_t>(Id instance, std::string_view property,
                                              std::span<const std::uint8_t> value)>
      set_value;
  /// Called after the last operation: may write operations that must come last.
  std::function<void(std::vector<std::uint8_t>& out, std::size_t& ops)> finish;
};

/// @brief decode_bundle() with @p hooks. @throws vsd::Error as decode_bundle(), and "wire bundle byte N:
/// an element-form list edit needs a list decoder" when @p hooks has no list hook for such an edit.
[[nodiscard]] Transaction decode_bundle(std::span<const std::uint8_t> bytes, const DecodeHooks& hooks);

}  // namespace vsd::dist
