#include "place_bounds.hpp"

#include <algorithm>
#include <map>
#include <numeric>

namespace vsd::analysis::detail {

namespace {

// A sparse vector: (index, value) pairs sorted by index, no zero values.
struct Entry {
  std::uint32_t index;
  std::int64_t value;
};
using Sparse = std::vector<Entry>;

// A row of the Farkas tableau: y (the place weights) and y^T C (one entry per transition), both sparse.
// Dense rows cost places x transitions: 3.2 GB for a net of 20,000 places and transitions.
struct Row {
  Sparse c;  // y^T C; the columns before the one being eliminated are all zero, so c's first entry is the
             // next column that is not
  Sparse y;
  std::size_t bytes() const { return (c.capacity() + y.capacity()) * sizeof(Entry) + sizeof(Row); }
};

constexpr std::size_t kMaxRows = 512;
constexpr std::uint64_t kMaxWork = 50'000'000;  // entry comparisons: a few tens of ms at most
constexpr std::int64_t kMaxMagnitude = std::int64_t{1} << 40;  // far from overflow in the products below

// out = a * x + b * y, without zeros; false when a value grows past kMaxMagnitude.
bool axpby(std::int64_t a, const Sparse& x, std::int64_t b, const Sparse& y, Sparse& out, std::int64_t& g) {
  out.clear();
  out.reserve(x.size() + y.size());
  std::size_t i = 0, k = 0;
  while (i < x.size() || k < y.size()) {
    std::uint32_t index = 0;
    std::int64_t v = 0;
    if (k == y.size() || (i < x.size() && x[i].index < y[k].index)) {
      index = x[i].index;
      v = a * x[i++].value;
    } else if (i == x.size() || y[k].index < x[i].index) {
      index = y[k].index;
      v = b * y[k++].value;
    } else {
      index = x[i].index;
      v = a * x[i++].value + b * y[k++].value;
    }
    if (v == 0) continue;
    if (v > kMaxMagnitude || v < -kMaxMagnitude) return false;
    out.push_back({index, v});
    g = std::gcd(g, v);
  }
  return true;
}

bool combine(const Row& p, std::int64_t ap, const Row& n, std::int64_t an, Row& out) {
  std::int64_t g = 0;
  if (!axpby(ap, p.c, an, n.c, out.c, g) || !axpby(ap, p.y, an, n.y, out.y, g)) return false;
  if (g > 1) {
    for (auto& e : out.c) e.value /= g;
    for (auto& e : out.y) e.value /= g;
  }
  return true;
}

// Rows whose support contains another row's support add nothing to the cover; dropping them keeps the
// Farkas algorithm small on nets with many overlapping invariants.
bool support_includes(const Sparse& big, const Sparse& small) {
  if (small.size() > big.size()) return false;
  std::size_t i = 0;
  for (const Entry& e : small) {
    while (i < big.size() && big[i].index < e.index) ++i;
    if (i == big.size() || big[i].index != e.index) return false;
  }
  return true;
}

}  // namespace

std::optional<std::vector<std::uint64_t>> place_bounds(const PtNet& net, std::size_t max_bytes) {
  const std::size_t P = net.place_count(), T = net.transition_count();
  std::uint64_t initial_sum = 0;
  for (const auto& p : net.places()) initial_sum += p.initial;
  bool never_adds = true;
  // The result, the rows, what they hold and their index by column: refused up front when the net alone
  // does not fit.
  constexpr std::size_t kIndexEntry = 64;  // a map node per row
  const std::size_t fixed = P * sizeof(std::uint64_t);
  std::size_t held = P * (sizeof(Row) + sizeof(Entry) + kIndexEntry + 1);
  for (const auto& t : net.transitions()) held += (t.inputs.size() + t.outputs.size()) * sizeof(Entry);
  if (fixed + held > max_bytes) return std::nullopt;
  std::vector<Row> rows(P);
  for (std::size_t p = 0; p < P; ++p) rows[p].y = {{static_cast<std::uint32_t>(p), 1}};
  for (std::size_t t = 0; t < T; ++t) {
    const auto tt = static_cast<std::uint32_t>(t);
    std::int64_t sum = 0;
    auto add = [&](std::uint32_t place, std::int64_t w) {
      Sparse& c = rows[place].c;
      if (!c.empty() && c.back().index == tt)
        c.back().value += w;  // an input and an output arc of t on one place
      else
        c.push_back({tt, w});
      sum += w;
    };
    for (const auto& a : net.transitions()[t].inputs) add(a.place, -static_cast<std::int64_t>(a.weight));
    for (const auto& a : net.transitions()[t].outputs) add(a.place, a.weight);
    never_adds = never_adds && sum <= 0;
  }
  held = 0;
  for (auto& r : rows) {
    std::erase_if(r.c, [](const Entry& e) { return e.value == 0; });
    held += r.bytes() + kIndexEntry + 1;
  }
  if (fixed + held > max_bytes) return std::nullopt;
  // Without adding transitions every place is bounded by the initial token count; the semiflows below
  // usually do better (1 for the places of a safe net), so they are tried either way.
  std::vector<std::uint64_t> bound(P, never_adds ? initial_sum : UINT64_MAX);
  auto result = [&]() -> std::optional<std::vector<std::uint64_t>> {
    if (std::find(bound.begin(), bound.end(), UINT64_MAX) != bound.end()) return std::nullopt;
    return bound;
  };

  // The columns are eliminated in increasing order; a row's first entry of c is the next column it takes
  // part in (the earlier ones are zero in every row left), so the rows are indexed by it and a column
  // costs what its own rows cost, not a pass over every row.
  std::map<std::uint32_t, std::vector<std::uint32_t>> by_column;
  std::vector<std::uint8_t> dead(rows.size(), 0);
  std::size_t live = rows.size();
  auto index_rows = [&] {
    by_column.clear();
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (!rows[i].c.empty()) by_column[rows[i].c.front().index].push_back(static_cast<std::uint32_t>(i));
  };
  index_rows();
  std::uint64_t work = 0;
  while (!by_column.empty()) {
    const std::vector<std::uint32_t> ids = std::move(by_column.begin()->second);
    by_column.erase(by_column.begin());
    std::vector<Row> pos, neg;
    std::size_t pos_entries = 0, neg_entries = 0, moved = 0;
    for (const std::uint32_t i : ids) {
      Row& r = rows[i];
      const bool positive = r.c.front().value > 0;
      (positive ? pos_entries : neg_entries) += r.c.size() + r.y.size();
      moved += r.bytes() + kIndexEntry + 1;
      (positive ? pos : neg).push_back(std::move(r));
      r = Row{};
      dead[i] = 1;
      --live;
    }
    // No new row: the rows left are a subset of rows of which none includes another's support, and so
    // are they. (Most columns of a large net are like this; the pruning below is quadratic.)
    if (pos.empty() || neg.empty()) {
      held -= moved;
      continue;
    }
    if (live + pos.size() * neg.size() > 8 * kMaxRows) return result();
    // The combinations at most hold every pair's entries: refused before they are made when that passes
    // the budget.
    const std::size_t combined = (neg.size() * pos_entries + pos.size() * neg_entries) * sizeof(Entry) +
                                 pos.size() * neg.size() * (sizeof(Row) + kIndexEntry);
    if (fixed + held + combined > max_bytes) return result();
    std::vector<Row> next;
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (!dead[i]) next.push_back(std::move(rows[i]));
    Row out;
    for (const auto& p : pos)
      for (const auto& n : neg) {
        if (!combine(p, -n.c.front().value, n, p.c.front().value, out)) return result();
        next.push_back(out);
      }
    pos.clear();
    neg.clear();
    // Keep the rows of minimal support only.
    std::sort(next.begin(), next.end(), [](const Row& a, const Row& b) { return a.y.size() < b.y.size(); });
    std::vector<Row> kept;
    for (auto& r : next) {
      bool redundant = false;
      for (const Row& k : kept) {
        work += r.y.size() + k.y.size();
        if (support_includes(r.y, k.y)) {
          redundant = true;
          break;
        }
      }
      if (work > kMaxWork) return result();
      if (!redundant) kept.push_back(std::move(r));
      if (kept.size() > kMaxRows) return result();
    }
    rows = std::move(kept);
    dead.assign(rows.size(), 0);
    live = rows.size();
    held = 0;
    for (const Row& r : rows) held += r.bytes() + kIndexEntry + 1;
    index_rows();
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (dead[i]) continue;
    std::uint64_t weighted = 0;  // y . M0
    for (const auto& [p, w] : rows[i].y) weighted += static_cast<std::uint64_t>(w) * net.places()[p].initial;
    for (const auto& [p, w] : rows[i].y) bound[p] = std::min(bound[p], weighted / static_cast<std::uint64_t>(w));
  }
  return result();
}

}  // namespace vsd::analysis::detail
