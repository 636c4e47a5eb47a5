/** @file
 *  @brief Transaction: a bundle of recorded changes to a SimState, kept as bytes.
 *
 *  A recording SimState appends one operation per change: create (with the new instance's values),
 *  delete (with its last values), property set (old and new value), reference-list insert and erase.
 *  The bundle is its own serialised form, so applying it in the same thread, in another thread or on
 *  another machine is one code path. Old values make `inverted()` possible, which is undo.
 *
 *  Encoding: "VSDT", a version byte, then operations. Each operation is an opcode, the instance id
 *  (varint), and its fields; values are length-prefixed bytes of their MetaType's binary form.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "vsd/core/config.hpp"

namespace vsd {

class Transaction;
namespace detail {
Transaction make_transaction(std::vector<std::uint8_t> bytes, std::size_t ops);
}  // namespace detail

class Transaction {
 public:
  enum class Op : std::uint8_t { Create = 1, Delete = 2, Set = 3, Insert = 4, Erase = 5 };
  static constexpr std::uint8_t format_version = 1;

  /// @brief An empty bundle: bytes() is the header alone.
  Transaction();
  /// @brief A bundle from bytes received elsewhere. @throws vsd::Error when the header is wrong; the
  /// operations themselves are checked when the bundle is applied.
  static Transaction from_bytes(std::vector<std::uint8_t> bytes);

  /// @brief The serialised bundle (header included).
  [[nodiscard]] const std::vector<std::uint8_t>& bytes() const noexcept { return bytes_; }
  /// @brief Number of operations.
  [[nodiscard]] std::size_t size() const noexcept { return ops_; }
  [[nodiscard]] bool empty() const noexcept { return ops_ == 0; }

  /// @brief The bundle that undoes this one (operations inverted, in reverse order).
  [[nodiscard]] Transaction inverted() const;
  /// @brief One line per operation, for logs and tests.
  [[nodiscard]] std::string describe() const;

 private:
  friend class SimState;
  friend Transaction detail::make_transaction(std::vector<std::uint8_t> bytes, std::size_t ops);
  std::vector<std::uint8_t> bytes_;
  std::size_t ops_ = 0;
};

}  // namespace vsd
