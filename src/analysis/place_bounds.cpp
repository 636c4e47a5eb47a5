#include "place_bounds.hpp"

#include <algorithm>
#include <numeric>

namespace vsd::analysis::detail {

namespace {

struct Row {
  std::vector<std::int64_t> c;                            // y^T C, one entry per transition
  std::vector<std::pair<std::uint32_t, std::int64_t>> y;  // the place weights, sorted by place
  std::vector<std::uint64_t> support;                     // the places of y as a bitset
};

void set_support(Row& r, std::size_t places) {
  r.support.assign((places + 63) / 64, 0);
  for (const auto& [p, w] : r.y) r.support[p >> 6] |= std::uint64_t{1} << (p & 63);
}

constexpr std::size_t kMaxRows = 512;
constexpr std::uint64_t kMaxWork = 50'000'000;  // support comparisons: a few tens of ms at most
constexpr std::int64_t kMaxMagnitude = std::int64_t{1} << 40;  // far from overflow in the products below

bool combine(const Row& p, std::int64_t ap, const Row& n, std::int64_t an, Row& out) {
  out.c.resize(p.c.size());
  std::int64_t g = 0;
  for (std::size_t j = 0; j < p.c.size(); ++j) {
    out.c[j] = ap * p.c[j] + an * n.c[j];
    if (out.c[j] > kMaxMagnitude || out.c[j] < -kMaxMagnitude) return false;
    g = std::gcd(g, out.c[j]);
  }
  out.y.clear();
  std::size_t i = 0, k = 0;
  while (i < p.y.size() || k < n.y.size()) {
    if (k == n.y.size() || (i < p.y.size() && p.y[i].first < n.y[k].first)) {
      out.y.emplace_back(p.y[i].first, ap * p.y[i].second);
      ++i;
    } else if (i == p.y.size() || n.y[k].first < p.y[i].first) {
      out.y.emplace_back(n.y[k].first, an * n.y[k].second);
      ++k;
    } else {
      out.y.emplace_back(p.y[i].first, ap * p.y[i].second + an * n.y[k].second);
      ++i;
      ++k;
    }
    if (out.y.back().second > kMaxMagnitude) return false;
    g = std::gcd(g, out.y.back().second);
  }
  if (g > 1) {
    for (auto& v : out.c) v /= g;
    for (auto& v : out.y) v.second /= g;
  }
  out.support.resize(p.support.size());
  for (std::size_t w = 0; w < p.support.size(); ++w) out.support[w] = p.support[w] | n.support[w];
  return true;
}

// Rows whose support contains another row's support add nothing to the cover; dropping them keeps the
// Farkas algorithm small on nets with many overlapping invariants.
bool support_includes(const Row& big, const Row& small) {
  for (std::size_t w = 0; w < big.support.size(); ++w)
    if ((small.support[w] & ~big.support[w]) != 0) return false;
  return true;
}

}  // namespace

std::optional<std::vector<std::uint64_t>> place_bounds(const PtNet& net) {
  const std::size_t P = net.place_count(), T = net.transition_count();
  std::uint64_t initial_sum = 0;
  for (const auto& p : net.places()) initial_sum += p.initial;
  bool never_adds = true;
  std::vector<Row> rows(P);
  for (std::size_t p = 0; p < P; ++p) {
    rows[p].c.assign(T, 0);
    rows[p].y = {{static_cast<std::uint32_t>(p), 1}};
    set_support(rows[p], P);
  }
  for (std::size_t t = 0; t < T; ++t) {
    std::int64_t sum = 0;
    for (const auto& a : net.transitions()[t].inputs) {
      rows[a.place].c[t] -= a.weight;
      sum -= a.weight;
    }
    for (const auto& a : net.transitions()[t].outputs) {
      rows[a.place].c[t] += a.weight;
      sum += a.weight;
    }
    never_adds = never_adds && sum <= 0;
  }
  // Without adding transitions every place is bounded by the initial token count; the semiflows below
  // usually do better (1 for the places of a safe net), so they are tried either way.
  std::vector<std::uint64_t> bound(P, never_adds ? initial_sum : UINT64_MAX);
  auto result = [&]() -> std::optional<std::vector<std::uint64_t>> {
    if (std::find(bound.begin(), bound.end(), UINT64_MAX) != bound.end()) return std::nullopt;
    return bound;
  };

  std::uint64_t work = 0;
  for (std::size_t j = 0; j < T; ++j) {
    std::vector<Row> next, pos, neg;
    for (auto& r : rows) {
      if (r.c[j] == 0)
        next.push_back(std::move(r));
      else
        (r.c[j] > 0 ? pos : neg).push_back(std::move(r));
    }
    if (next.size() + pos.size() * neg.size() > 8 * kMaxRows) return result();
    // No new row: the rows left are a subset of rows of which none includes another's support, and so
    // are they. (Most columns of a large net are like this; the pruning below is quadratic.)
    if (pos.empty() || neg.empty()) {
      rows = std::move(next);
      continue;
    }
    Row out;
    for (const auto& p : pos)
      for (const auto& n : neg) {
        if (!combine(p, -n.c[j], n, p.c[j], out)) return result();
        next.push_back(out);
      }
    // Keep the rows of minimal support only.
    std::sort(next.begin(), next.end(), [](const Row& a, const Row& b) { return a.y.size() < b.y.size(); });
    std::vector<Row> kept;
    for (auto& r : next) {
      work += kept.size() * r.y.size();
      if (work > kMaxWork) return result();
      const bool redundant =
          std::any_of(kept.begin(), kept.end(), [&](const Row& k) { return support_includes(r, k); });
      if (!redundant) kept.push_back(std::move(r));
      if (kept.size() > kMaxRows) return result();
    }
    rows = std::move(kept);
  }
  for (const auto& r : rows) {
    std::uint64_t weighted = 0;  // y . M0
    for (const auto& [p, w] : r.y) weighted += static_cast<std::uint64_t>(w) * net.places()[p].initial;
    for (const auto& [p, w] : r.y) bound[p] = std::min(bound[p], weighted / static_cast<std::uint64_t>(w));
  }
  return result();
}

}  // namespace vsd::analysis::detail
