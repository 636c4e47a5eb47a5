// Hand-made nets with known state spaces, shared by the analysis tests.
#pragma once

#include <string>

#include "vsd/analysis/pt_net.hpp"

namespace vsd::analysis::test {

/// A ring of n places p0..p{n-1} with k tokens on p0 and transitions t_i: p_i -> p_{(i+1) mod n}.
/// Reachable markings: every way to put k tokens on n places, C(n+k-1, k); firings: n * C(n+k-2, k-1)
/// (transition t_i is enabled in the markings with p_i marked: one token there, k-1 anywhere).
inline PtNet ring(unsigned n, unsigned k) {
  PtNet net("ring" + std::to_string(n) + "_" + std::to_string(k));
  for (unsigned i = 0; i < n; ++i) net.add_place("p" + std::to_string(i), {}, i == 0 ? k : 0);
  for (unsigned i = 0; i < n; ++i) {
    const auto t = net.add_transition("t" + std::to_string(i));
    net.add_input(t, i);
    net.add_output(t, (i + 1) % n);
  }
  return net;
}

inline std::uint64_t binomial(std::uint64_t n, std::uint64_t k) {
  std::uint64_t r = 1;
  for (std::uint64_t i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

}  // namespace vsd::analysis::test
