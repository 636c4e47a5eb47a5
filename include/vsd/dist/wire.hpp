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

}  // namespace vsd::dist
