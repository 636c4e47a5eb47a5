/** @file
 *  @brief detail::sincos: sine and cosine of one angle at once, with one range reduction (Cephes'
 *  polynomials, accurate to about 1e-16 for |x| < 1e5; std::sin/std::cos beyond). Forward kinematics
 *  spends most of its time here with the library functions.
 */
#pragma once

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace vsd::robotics::detail {

/// @brief Sets @p s = sin(@p x) and @p c = cos(@p x).
[[gnu::always_inline]] inline void sincos(double x, double& s, double& c) noexcept {
  double ax = x < 0 ? -x : x;
  if (!(ax < 1e5)) {  // also NaN
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  // x = z + k * pi/2 with |z| <= pi/4 (pi/4 split in three parts, Cody–Waite).
  constexpr double four_over_pi = 1.27323954473516268615;
  constexpr double dp1 = 7.85398125648498535156e-1, dp2 = 3.77489470793079817668e-8,
                   dp3 = 2.69515142907905952645e-15;
  // Truncation is floor for 0 <= ax < 1e5, and a plain conversion (std::floor is a library call without
  // SSE4.1).
  auto j = static_cast<std::int64_t>(ax * four_over_pi);
  j += j & 1;  // round up to even: |z| <= pi/4 (no branch)
  const double y = static_cast<double>(j);
  const double z = ((ax - y * dp1) - y * dp2) - y * dp3;
  const double zz = z * z;
  const double sp = z + z * zz *
                            ((((((1.58962301576546568060e-10 * zz - 2.50507477628578072866e-8) * zz +
                                 2.75573136213857245213e-6) *
                                    zz -
                                1.98412698295895385996e-4) *
                                   zz +
                               8.33333333332211858878e-3) *
                                  zz -
                              1.66666666666666307295e-1));
  const double cp = 1.0 - 0.5 * zz +
                    zz * zz *
                        (((((-1.13585365213876817300e-11 * zz + 2.08757008419747316778e-9) * zz -
                            2.75573141792967388112e-7) *
                               zz +
                           2.48015872888517045348e-5) *
                              zz -
                          1.38888888888730564116e-3) *
                             zz +
                         4.16666666666665929218e-2);
  // Quadrant selection without branches (random joint values would mispredict them): swap sine and
  // cosine in odd quadrants, then fix the signs. Bit masks keep the selected values exact.
  const auto q = static_cast<std::uint64_t>(j >> 1);
  const std::uint64_t swap = 0 - (q & 1);  // all ones in quadrants 1 and 3
  const auto bs = std::bit_cast<std::uint64_t>(sp), bc = std::bit_cast<std::uint64_t>(cp);
  const double sv = std::bit_cast<double>((bs & ~swap) | (bc & swap));
  const double cv = std::bit_cast<double>((bc & ~swap) | (bs & swap));
  const std::uint64_t sign_bit = std::uint64_t{1} << 63;
  // sin is negative in quadrants 2 and 3 (and for negative x), cos in quadrants 1 and 2.
  const std::uint64_t s_neg = (((q >> 1) & 1) ^ (x < 0 ? 1u : 0u)) << 63;
  const std::uint64_t c_neg = (((q + 1) >> 1) & 1) << 63;
  s = std::bit_cast<double>(std::bit_cast<std::uint64_t>(sv) ^ (s_neg & sign_bit));
  c = std::bit_cast<double>(std::bit_cast<std::uint64_t>(cv) ^ (c_neg & sign_bit));
}

}  // namespace vsd::robotics::detail

namespace vsd::robotics::detail {

/// @brief sincos() of @p n values at once: the same results, in a loop without branches that the compiler
/// vectorises (two angles per SSE2 instruction) when every |x| < 1e5.
inline void sincos_batch(const double* x, double* s, double* c, std::size_t n) noexcept {
  bool small = true;
  for (std::size_t i = 0; i < n; ++i) small &= (x[i] < 1e5) & (x[i] > -1e5);  // false for NaN too
  if (!small) {
    for (std::size_t i = 0; i < n; ++i) sincos(x[i], s[i], c[i]);
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double xi = x[i];
    const double ax = xi < 0 ? -xi : xi;
    auto j = static_cast<std::int32_t>(ax * 1.27323954473516268615);
    j += j & 1;
    const double y = static_cast<double>(j);
    const double z = ((ax - y * 7.85398125648498535156e-1) - y * 3.77489470793079817668e-8) -
                     y * 2.69515142907905952645e-15;
    const double zz = z * z;
    const double sp = z + z * zz *
                              ((((((1.58962301576546568060e-10 * zz - 2.50507477628578072866e-8) * zz +
                                   2.75573136213857245213e-6) *
                                      zz -
                                  1.98412698295895385996e-4) *
                                     zz +
                                 8.33333333332211858878e-3) *
                                    zz -
                                1.66666666666666307295e-1));
    const double cp = 1.0 - 0.5 * zz +
                      zz * zz *
                          (((((-1.13585365213876817300e-11 * zz + 2.08757008419747316778e-9) * zz -
                              2.75573141792967388112e-7) *
                                 zz +
                             2.48015872888517045348e-5) *
                                zz -
                            1.38888888888730564116e-3) *
                               zz +
                           4.16666666666665929218e-2);
    const std::int32_t q = j >> 1;
    const bool swap = (q & 1) != 0;
    const double sv = swap ? cp : sp;
    const double cv = swap ? sp : cp;
    const bool s_neg = ((q & 2) != 0) != (xi < 0);
    s[i] = s_neg ? -sv : sv;
    c[i] = ((q + 1) & 2) != 0 ? -cv : cv;
  }
}

}  // namespace vsd::robotics::detail
