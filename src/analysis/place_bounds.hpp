// Structural bounds of a PtNet's places from its P-semiflows (internal).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "vsd/analysis/pt_net.hpp"

namespace vsd::analysis::detail {

/// A bound on every place valid in every reachable marking, when the net proves one: either no
/// transition adds tokens in total (bound: the initial token count), or every place lies in the support
/// of a P-semiflow y >= 0, y^T C = 0 (bound of p: y.M0 / y_p, the best over the semiflows found).
/// Semiflows come from the Farkas algorithm on sparse rows, abandoned (nullopt) when it grows past a fixed
/// budget of rows and work, or when its data would pass @p max_bytes, so the cost stays small on any net.
/// Inhibitor arcs move no tokens and change nothing here.
std::optional<std::vector<std::uint64_t>> place_bounds(const PtNet& net, std::size_t max_bytes);

}  // namespace vsd::analysis::detail
