/** @file
 *  @brief detail::sincos: sine and cosine of one angle at once, with one range reduction (Cephes'
 *  polynomials, accurate to about 1e-16 for |x| < 1e5; std::sin/std::cos beyond). Forward kinematics
 *  spends most of its time here with the library functions.
 */
#pragma once

#include <cmath>
#include <cstdint>

namespace vsd::robotics::detail {

/// @brief Sets @p s = sin(@p x) and @p c = cos(@p x).
inline void sincos(double x, double& s, double& c) noexcept {
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
  double y = std::floor(ax * four_over_pi);
  auto j = static_cast<std::int64_t>(y);
  if (j & 1) {
    ++j;
    y += 1.0;
  }
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
  const int quadrant = static_cast<int>((j >> 1) & 3);
  double sv, cv;
  switch (quadrant) {
    case 0:
      sv = sp;
      cv = cp;
      break;
    case 1:
      sv = cp;
      cv = -sp;
      break;
    case 2:
      sv = -sp;
      cv = -cp;
      break;
    default:
      sv = -cp;
      cv = sp;
      break;
  }
  s = x < 0 ? -sv : sv;
  c = cv;
}

}  // namespace vsd::robotics::detail
