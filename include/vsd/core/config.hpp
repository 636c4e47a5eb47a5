/** @file
 *  @brief Basic configuration of vsd: identifiers, branch hints and the internal assertion macro.
 */
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>

namespace vsd {

/// @brief Stable identifier of an instance, unique within its Environment (and equal across replicas).
using Id = std::uint64_t;

/// @brief The id that no instance carries; a null reference serialises as this id.
inline constexpr Id null_id = 0;

}  // namespace vsd

#if defined(__GNUC__) || defined(__clang__)
#define VSD_LIKELY(x) __builtin_expect(!!(x), 1)
#define VSD_UNLIKELY(x) __builtin_expect(!!(x), 0)
#define VSD_NOINLINE __attribute__((noinline, cold))
#else
#define VSD_LIKELY(x) (x)
#define VSD_UNLIKELY(x) (x)
#define VSD_NOINLINE
#endif

/// @brief Checks an invariant of vsd itself (a bug in vsd when it fires, never bad user input).
/// Active unless NDEBUG is defined or VSD_DISABLE_ASSERT is set.
#if defined(NDEBUG) || defined(VSD_DISABLE_ASSERT)
#define VSD_ASSERT(cond, msg) ((void)0)
#else
#define VSD_ASSERT(cond, msg)                                                                                \
  ((cond) ? (void)0                                                                                          \
          : (std::fprintf(stderr, "%s:%d: vsd assertion '%s' failed: %s\n", __FILE__, __LINE__, #cond, msg), \
             std::abort()))
#endif
