/** @file
 *  @brief Internal: writing and reading the operations of a Transaction (see transaction.hpp).
 */
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "vsd/core/transaction.hpp"

namespace vsd {
class SimState;
class SimStateInstance;
class MetaProperty;
}  // namespace vsd

namespace vsd::detail {

/// Bytes of the bundle header ("VSDT" and the version) that write_tx_header() writes.
inline constexpr std::size_t tx_header_size = 5;
void write_tx_header(std::vector<std::uint8_t>& out);
/// Create or Delete with the values of every non-reference, non-transient property.
void write_lifecycle(std::vector<std::uint8_t>& out, Transaction::Op op, const SimStateInstance& inst);
void write_set(std::vector<std::uint8_t>& out, const SimStateInstance& inst, const MetaProperty& p,
               const void* old_value, const void* new_value);
void write_list(std::vector<std::uint8_t>& out, Transaction::Op op, Id holder, const MetaProperty& p,
                std::size_t index, Id target);
/// A bundle made from raw parts (loaders): values are the binary form of each property's type.
using TxValue = std::pair<std::string_view, std::span<const std::uint8_t>>;
void write_create(std::vector<std::uint8_t>& out, Id id, std::string_view cls,
                  std::span<const TxValue> values);
void write_set(std::vector<std::uint8_t>& out, Id id, std::string_view prop,
               std::span<const std::uint8_t> old_value, std::span<const std::uint8_t> new_value);
void write_list(std::vector<std::uint8_t>& out, Transaction::Op op, Id holder, std::string_view prop,
                std::size_t index, Id target);
/// A Transaction holding @p bytes (header included) with @p ops operations, unchecked (apply checks).
Transaction make_transaction(std::vector<std::uint8_t> bytes, std::size_t ops);

/// True for the properties a transaction carries in Create/Delete payloads and compares.
bool carried_in_payload(const MetaProperty& p) noexcept;

/// One parsed operation; byte spans point into the bundle.
struct TxOp {
  Transaction::Op op{};
  std::size_t offset = 0;  // where the operation starts
  Id id = 0;               // instance (Create/Delete/Set) or holder (Insert/Erase)
  std::string_view name;   // class (Create/Delete) or property (Set/Insert/Erase)
  std::vector<std::pair<std::string_view, std::span<const std::uint8_t>>> values;  // Create/Delete
  std::span<const std::uint8_t> old_value, new_value;                              // Set
  std::size_t index = 0;                                                           // Insert/Erase
  Id target = 0;                                                                   // Insert/Erase
};

/// Reads a bundle's operations one at a time (no list of all of them is built).
class TxParser {
 public:
  explicit TxParser(const Transaction& t);
  /// Reads the next operation into @p op (reusing its storage); false at the end.
  /// @throws vsd::Error with the byte offset of malformed data.
  bool next(TxOp& op);

 private:
  const std::vector<std::uint8_t>* bytes_;
  std::size_t pos_ = 0;
};

/// Parses every operation of a bundle. @throws vsd::Error with the byte offset of malformed data.
std::vector<TxOp> parse_tx(const Transaction& t);

}  // namespace vsd::detail
