/** @file
 *  @brief detail::sincos: sine and cosine of one angle at once, with one range reduction to a table of
 *  128 points (accurate to about 3e-16 for |x| < 1e5; std::sin/std::cos beyond, and for NaN and
 *  infinities). Forward kinematics spends a large part of its time here with the library functions.
 *
 *  x = k * pi/64 + z with |z| <= pi/128; sin(k pi/64) and cos(k pi/64) come from the table (correctly
 *  rounded, generated with mpmath at 60 digits), sin z and cos z - 1 from short Taylor polynomials (three
 *  terms each: the next ones are below 1e-20), and the angle-addition formulas put them together. No
 *  quadrant logic: k modulo 128 indexes the whole circle.
 */
#pragma once

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>

namespace vsd::robotics::detail {

/// sin and cos of k * pi / 64, k = 0..127, correctly rounded.
inline constexpr double sincos_table[128][2] = {
    {0.0, 0x1.0000000000000p+0},
    {0x1.91f65f10dd814p-5, 0x1.ff621e3796d7ep-1},
    {0x1.917a6bc29b42cp-4, 0x1.fd88da3d12526p-1},
    {0x1.2c8106e8e613ap-3, 0x1.fa7557f08a517p-1},
    {0x1.8f8b83c69a60bp-3, 0x1.f6297cff75cb0p-1},
    {0x1.f19f97b215f1bp-3, 0x1.f0a7efb9230d7p-1},
    {0x1.294062ed59f06p-2, 0x1.e9f4156c62ddap-1},
    {0x1.58f9a75ab1fddp-2, 0x1.e212104f686e5p-1},
    {0x1.87de2a6aea963p-2, 0x1.d906bcf328d46p-1},
    {0x1.b5d1009e15cc0p-2, 0x1.ced7af43cc773p-1},
    {0x1.e2b5d3806f63bp-2, 0x1.c38b2f180bdb1p-1},
    {0x1.073879922ffeep-1, 0x1.b728345196e3ep-1},
    {0x1.1c73b39ae68c8p-1, 0x1.a9b66290ea1a3p-1},
    {0x1.30ff7fce17035p-1, 0x1.9b3e047f38741p-1},
    {0x1.44cf325091dd6p-1, 0x1.8bc806b151741p-1},
    {0x1.57d69348ceca0p-1, 0x1.7b5df226aafafp-1},
    {0x1.6a09e667f3bcdp-1, 0x1.6a09e667f3bcdp-1},
    {0x1.7b5df226aafafp-1, 0x1.57d69348ceca0p-1},
    {0x1.8bc806b151741p-1, 0x1.44cf325091dd6p-1},
    {0x1.9b3e047f38741p-1, 0x1.30ff7fce17035p-1},
    {0x1.a9b66290ea1a3p-1, 0x1.1c73b39ae68c8p-1},
    {0x1.b728345196e3ep-1, 0x1.073879922ffeep-1},
    {0x1.c38b2f180bdb1p-1, 0x1.e2b5d3806f63bp-2},
    {0x1.ced7af43cc773p-1, 0x1.b5d1009e15cc0p-2},
    {0x1.d906bcf328d46p-1, 0x1.87de2a6aea963p-2},
    {0x1.e212104f686e5p-1, 0x1.58f9a75ab1fddp-2},
    {0x1.e9f4156c62ddap-1, 0x1.294062ed59f06p-2},
    {0x1.f0a7efb9230d7p-1, 0x1.f19f97b215f1bp-3},
    {0x1.f6297cff75cb0p-1, 0x1.8f8b83c69a60bp-3},
    {0x1.fa7557f08a517p-1, 0x1.2c8106e8e613ap-3},
    {0x1.fd88da3d12526p-1, 0x1.917a6bc29b42cp-4},
    {0x1.ff621e3796d7ep-1, 0x1.91f65f10dd814p-5},
    {0x1.0000000000000p+0, 0.0},
    {0x1.ff621e3796d7ep-1, -0x1.91f65f10dd814p-5},
    {0x1.fd88da3d12526p-1, -0x1.917a6bc29b42cp-4},
    {0x1.fa7557f08a517p-1, -0x1.2c8106e8e613ap-3},
    {0x1.f6297cff75cb0p-1, -0x1.8f8b83c69a60bp-3},
    {0x1.f0a7efb9230d7p-1, -0x1.f19f97b215f1bp-3},
    {0x1.e9f4156c62ddap-1, -0x1.294062ed59f06p-2},
    {0x1.e212104f686e5p-1, -0x1.58f9a75ab1fddp-2},
    {0x1.d906bcf328d46p-1, -0x1.87de2a6aea963p-2},
    {0x1.ced7af43cc773p-1, -0x1.b5d1009e15cc0p-2},
    {0x1.c38b2f180bdb1p-1, -0x1.e2b5d3806f63bp-2},
    {0x1.b728345196e3ep-1, -0x1.073879922ffeep-1},
    {0x1.a9b66290ea1a3p-1, -0x1.1c73b39ae68c8p-1},
    {0x1.9b3e047f38741p-1, -0x1.30ff7fce17035p-1},
    {0x1.8bc806b151741p-1, -0x1.44cf325091dd6p-1},
    {0x1.7b5df226aafafp-1, -0x1.57d69348ceca0p-1},
    {0x1.6a09e667f3bcdp-1, -0x1.6a09e667f3bcdp-1},
    {0x1.57d69348ceca0p-1, -0x1.7b5df226aafafp-1},
    {0x1.44cf325091dd6p-1, -0x1.8bc806b151741p-1},
    {0x1.30ff7fce17035p-1, -0x1.9b3e047f38741p-1},
    {0x1.1c73b39ae68c8p-1, -0x1.a9b66290ea1a3p-1},
    {0x1.073879922ffeep-1, -0x1.b728345196e3ep-1},
    {0x1.e2b5d3806f63bp-2, -0x1.c38b2f180bdb1p-1},
    {0x1.b5d1009e15cc0p-2, -0x1.ced7af43cc773p-1},
    {0x1.87de2a6aea963p-2, -0x1.d906bcf328d46p-1},
    {0x1.58f9a75ab1fddp-2, -0x1.e212104f686e5p-1},
    {0x1.294062ed59f06p-2, -0x1.e9f4156c62ddap-1},
    {0x1.f19f97b215f1bp-3, -0x1.f0a7efb9230d7p-1},
    {0x1.8f8b83c69a60bp-3, -0x1.f6297cff75cb0p-1},
    {0x1.2c8106e8e613ap-3, -0x1.fa7557f08a517p-1},
    {0x1.917a6bc29b42cp-4, -0x1.fd88da3d12526p-1},
    {0x1.91f65f10dd814p-5, -0x1.ff621e3796d7ep-1},
    {0.0, -0x1.0000000000000p+0},
    {-0x1.91f65f10dd814p-5, -0x1.ff621e3796d7ep-1},
    {-0x1.917a6bc29b42cp-4, -0x1.fd88da3d12526p-1},
    {-0x1.2c8106e8e613ap-3, -0x1.fa7557f08a517p-1},
    {-0x1.8f8b83c69a60bp-3, -0x1.f6297cff75cb0p-1},
    {-0x1.f19f97b215f1bp-3, -0x1.f0a7efb9230d7p-1},
    {-0x1.294062ed59f06p-2, -0x1.e9f4156c62ddap-1},
    {-0x1.58f9a75ab1fddp-2, -0x1.e212104f686e5p-1},
    {-0x1.87de2a6aea963p-2, -0x1.d906bcf328d46p-1},
    {-0x1.b5d1009e15cc0p-2, -0x1.ced7af43cc773p-1},
    {-0x1.e2b5d3806f63bp-2, -0x1.c38b2f180bdb1p-1},
    {-0x1.073879922ffeep-1, -0x1.b728345196e3ep-1},
    {-0x1.1c73b39ae68c8p-1, -0x1.a9b66290ea1a3p-1},
    {-0x1.30ff7fce17035p-1, -0x1.9b3e047f38741p-1},
    {-0x1.44cf325091dd6p-1, -0x1.8bc806b151741p-1},
    {-0x1.57d69348ceca0p-1, -0x1.7b5df226aafafp-1},
    {-0x1.6a09e667f3bcdp-1, -0x1.6a09e667f3bcdp-1},
    {-0x1.7b5df226aafafp-1, -0x1.57d69348ceca0p-1},
    {-0x1.8bc806b151741p-1, -0x1.44cf325091dd6p-1},
    {-0x1.9b3e047f38741p-1, -0x1.30ff7fce17035p-1},
    {-0x1.a9b66290ea1a3p-1, -0x1.1c73b39ae68c8p-1},
    {-0x1.b728345196e3ep-1, -0x1.073879922ffeep-1},
    {-0x1.c38b2f180bdb1p-1, -0x1.e2b5d3806f63bp-2},
    {-0x1.ced7af43cc773p-1, -0x1.b5d1009e15cc0p-2},
    {-0x1.d906bcf328d46p-1, -0x1.87de2a6aea963p-2},
    {-0x1.e212104f686e5p-1, -0x1.58f9a75ab1fddp-2},
    {-0x1.e9f4156c62ddap-1, -0x1.294062ed59f06p-2},
    {-0x1.f0a7efb9230d7p-1, -0x1.f19f97b215f1bp-3},
    {-0x1.f6297cff75cb0p-1, -0x1.8f8b83c69a60bp-3},
    {-0x1.fa7557f08a517p-1, -0x1.2c8106e8e613ap-3},
    {-0x1.fd88da3d12526p-1, -0x1.917a6bc29b42cp-4},
    {-0x1.ff621e3796d7ep-1, -0x1.91f65f10dd814p-5},
    {-0x1.0000000000000p+0, 0.0},
    {-0x1.ff621e3796d7ep-1, 0x1.91f65f10dd814p-5},
    {-0x1.fd88da3d12526p-1, 0x1.917a6bc29b42cp-4},
    {-0x1.fa7557f08a517p-1, 0x1.2c8106e8e613ap-3},
    {-0x1.f6297cff75cb0p-1, 0x1.8f8b83c69a60bp-3},
    {-0x1.f0a7efb9230d7p-1, 0x1.f19f97b215f1bp-3},
    {-0x1.e9f4156c62ddap-1, 0x1.294062ed59f06p-2},
    {-0x1.e212104f686e5p-1, 0x1.58f9a75ab1fddp-2},
    {-0x1.d906bcf328d46p-1, 0x1.87de2a6aea963p-2},
    {-0x1.ced7af43cc773p-1, 0x1.b5d1009e15cc0p-2},
    {-0x1.c38b2f180bdb1p-1, 0x1.e2b5d3806f63bp-2},
    {-0x1.b728345196e3ep-1, 0x1.073879922ffeep-1},
    {-0x1.a9b66290ea1a3p-1, 0x1.1c73b39ae68c8p-1},
    {-0x1.9b3e047f38741p-1, 0x1.30ff7fce17035p-1},
    {-0x1.8bc806b151741p-1, 0x1.44cf325091dd6p-1},
    {-0x1.7b5df226aafafp-1, 0x1.57d69348ceca0p-1},
    {-0x1.6a09e667f3bcdp-1, 0x1.6a09e667f3bcdp-1},
    {-0x1.57d69348ceca0p-1, 0x1.7b5df226aafafp-1},
    {-0x1.44cf325091dd6p-1, 0x1.8bc806b151741p-1},
    {-0x1.30ff7fce17035p-1, 0x1.9b3e047f38741p-1},
    {-0x1.1c73b39ae68c8p-1, 0x1.a9b66290ea1a3p-1},
    {-0x1.073879922ffeep-1, 0x1.b728345196e3ep-1},
    {-0x1.e2b5d3806f63bp-2, 0x1.c38b2f180bdb1p-1},
    {-0x1.b5d1009e15cc0p-2, 0x1.ced7af43cc773p-1},
    {-0x1.87de2a6aea963p-2, 0x1.d906bcf328d46p-1},
    {-0x1.58f9a75ab1fddp-2, 0x1.e212104f686e5p-1},
    {-0x1.294062ed59f06p-2, 0x1.e9f4156c62ddap-1},
    {-0x1.f19f97b215f1bp-3, 0x1.f0a7efb9230d7p-1},
    {-0x1.8f8b83c69a60bp-3, 0x1.f6297cff75cb0p-1},
    {-0x1.2c8106e8e613ap-3, 0x1.fa7557f08a517p-1},
    {-0x1.917a6bc29b42cp-4, 0x1.fd88da3d12526p-1},
    {-0x1.91f65f10dd814p-5, 0x1.ff621e3796d7ep-1},
};

inline constexpr double sincos_64_over_pi = 0x1.45f306dc9c883p+4;
// pi/64 in two parts: the first has 30 significant bits, so y * hi is exact for |y| < 2^22 (|x| < 1e5).
inline constexpr double sincos_pi_64_hi = 0x1.921fb54000000p-5;
inline constexpr double sincos_pi_64_lo = 0x1.10b4611a62633p-35;
// Adding 1.5 * 2^52 rounds to an integer, which is then in the low bits of the mantissa.
inline constexpr double sincos_shifter = 0x1.8p52;
inline constexpr double sincos_limit = 1e5;
// Taylor coefficients: sin z = z + z^3 (s1 + z^2 (s2 + z^2 s3)), cos z - 1 = z^2 (c1 + z^2 (c2 + z^2 c3)).
inline constexpr double sincos_s1 = -1.0 / 6.0, sincos_s2 = 1.0 / 120.0, sincos_s3 = -1.0 / 5040.0;
inline constexpr double sincos_c1 = -0.5, sincos_c2 = 1.0 / 24.0, sincos_c3 = -1.0 / 720.0;

/// @brief Sets @p s = sin(@p x) and @p c = cos(@p x).
[[gnu::always_inline]] inline void sincos(double x, double& s, double& c) noexcept {
  if (!(x < sincos_limit && x > -sincos_limit)) {  // also NaN
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  const double r = x * sincos_64_over_pi + sincos_shifter;
  const double y = r - sincos_shifter;
  const auto k = static_cast<std::size_t>(std::bit_cast<std::uint64_t>(r) & 127U);
  const double z = (x - y * sincos_pi_64_hi) - y * sincos_pi_64_lo;
  const double zz = z * z;
  const double sz = z + (z * zz) * ((sincos_s3 * zz + sincos_s2) * zz + sincos_s1);
  const double cm1 = zz * ((sincos_c3 * zz + sincos_c2) * zz + sincos_c1);
  const double st = sincos_table[k][0], ct = sincos_table[k][1];
  // The table value last: the small corrections are rounded on their own scale.
  s = st + (st * cm1 + ct * sz);
  c = ct + (ct * cm1 - st * sz);
}

#if defined(__GNUC__)
/// @brief @p N doubles in one vector (GCC and Clang vector extensions). A member typedef: in a function
/// template GCC drops a vector_size that depends on a template parameter.
template <std::size_t N>
struct sincos_vector {
  typedef double type __attribute__((vector_size(N * sizeof(double))));
};
#endif

/// @brief sincos() of @p n values, sizeof...(L) angles per vector operation (GCC and Clang vector
/// extensions) when every |x| < 1e5; the scalar form otherwise. The same operations in every lane, so the
/// same results for any lane count. Always inlined: the caller's target decides the instructions
/// (sincos_batch(): two lanes, SSE2; the AVX form of forward kinematics: four lanes, AVX).
/// @param lanes std::make_index_sequence<lanes per operation>{}
template <std::size_t... L>
[[gnu::always_inline]] inline void sincos_lanes([[maybe_unused]] std::index_sequence<L...> lanes,
                                                const double* x, double* s, double* c,
                                                std::size_t n) noexcept {
  std::size_t i = 0;
#if defined(__GNUC__)
  constexpr std::size_t width = sizeof...(L);
  using V = typename sincos_vector<width>::type;
  const V zero = {};
  auto ok = zero == zero;  // lanes of all ones
  for (; i + width <= n; i += width) {
    V xv;
    std::memcpy(&xv, x + i, sizeof xv);
    ok &= (xv < sincos_limit) & (xv > -sincos_limit);  // lanes of all ones or zero; zero for NaN
    const V r = xv * sincos_64_over_pi + sincos_shifter;
    const V y = r - sincos_shifter;
    const V z = (xv - y * sincos_pi_64_hi) - y * sincos_pi_64_lo;
    const V zz = z * z;
    const V sz = z + (z * zz) * ((sincos_s3 * zz + sincos_s2) * zz + sincos_s1);
    const V cm1 = zz * ((sincos_c3 * zz + sincos_c2) * zz + sincos_c1);
    const std::size_t k[width] = {static_cast<std::size_t>(std::bit_cast<std::uint64_t>(r[L]) & 127U)...};
    const V st = {sincos_table[k[L]][0]...};
    const V ct = {sincos_table[k[L]][1]...};
    const V sv = st + (st * cm1 + ct * sz);
    const V cv = ct + (ct * cm1 - st * sz);
    std::memcpy(s + i, &sv, sizeof sv);
    std::memcpy(c + i, &cv, sizeof cv);
  }
  if (!(ok[L] && ...)) i = 0;  // a value out of range: redo everything with the scalar form
#endif
  for (; i < n; ++i) sincos(x[i], s[i], c[i]);
}

/// @brief sincos() of @p n values: the same results, two angles per SSE2 instruction (GCC and Clang vector
/// extensions) when every |x| < 1e5; the scalar form otherwise.
inline void sincos_batch(const double* x, double* s, double* c, std::size_t n) noexcept {
  sincos_lanes(std::make_index_sequence<2>{}, x, s, c, n);
}

}  // namespace vsd::robotics::detail
