/** @file
 *  @brief Property flags: how a property is exposed (editable, savable, ...) and distributed.
 */
#pragma once

#include <cstdint>

namespace vsd {

/// @brief A set of property flags; combine with `|`, test with `has()`.
class PropertyFlags {
 public:
  constexpr PropertyFlags() noexcept = default;
  constexpr explicit PropertyFlags(std::uint32_t bits) noexcept : bits_(bits) {}

  /// @brief The raw bits.
  [[nodiscard]] constexpr std::uint32_t bits() const noexcept { return bits_; }
  /// @brief True when every flag of @p other is set here.
  [[nodiscard]] constexpr bool has(PropertyFlags other) const noexcept {
    return (bits_ & other.bits_) == other.bits_;
  }
  constexpr PropertyFlags operator|(PropertyFlags o) const noexcept { return PropertyFlags{bits_ | o.bits_}; }
  constexpr PropertyFlags operator&(PropertyFlags o) const noexcept { return PropertyFlags{bits_ & o.bits_}; }
  constexpr PropertyFlags operator~() const noexcept { return PropertyFlags{~bits_}; }
  constexpr bool operator==(const PropertyFlags&) const noexcept = default;

 private:
  std::uint32_t bits_ = 0;
};

inline constexpr PropertyFlags NoFlags{0};
/// @brief Shown to and changeable by a user interface.
inline constexpr PropertyFlags Editable{1U << 0};
/// @brief Written by persistence.
inline constexpr PropertyFlags Savable{1U << 1};
/// @brief Kept in sync across distributed SimStates.
inline constexpr PropertyFlags Distributed{1U << 2};
/// @brief Cannot be set through the generic (by handle / by name) path.
inline constexpr PropertyFlags ReadOnly{1U << 3};
/// @brief Not recorded in transactions: a value local to this SimState (caches, scratch data).
inline constexpr PropertyFlags Transient{1U << 4};
/// @brief First of 16 bits left to the user (`UserFlag(0)` ... `UserFlag(15)`).
constexpr PropertyFlags UserFlag(unsigned n) noexcept { return PropertyFlags{1U << (16U + n)}; }

/// @brief The flags a property gets when its declaration names none.
inline constexpr PropertyFlags DefaultFlags = Editable | Savable | Distributed;

}  // namespace vsd
