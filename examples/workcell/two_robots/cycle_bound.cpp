#include "cycle_bound.hpp"

#include <algorithm>
#include <cmath>

#include "vsd/core/error.hpp"

namespace vsd_workcell {

CycleBound cycle_bound(const CycleParameters& p) {
  const double times[] = {p.direct_a, p.direct_b, p.give_a, p.take_b, p.zone_a, p.zone_b};
  for (double t : times)
    if (!(t >= 0) || !std::isfinite(t)) throw vsd::Error("cycle_bound: a motion time is negative or not finite");
  if (!(p.arrival_gap > 0) || !std::isfinite(p.arrival_gap))
    throw vsd::Error("cycle_bound: the arrival gap must be positive");
  const double shares[] = {p.share_direct_a, p.share_handover, p.share_direct_b};
  for (double s : shares)
    if (!(s >= 0)) throw vsd::Error("cycle_bound: a route's share is negative");
  if (std::abs(p.share_direct_a + p.share_handover + p.share_direct_b - 1) > 1e-9)
    throw vsd::Error("cycle_bound: the routes' shares do not add up to 1");
  CycleBound b;
  b.load_a = p.share_direct_a * p.direct_a + p.share_handover * p.give_a;
  b.load_b = p.share_direct_b * p.direct_b + p.share_handover * p.take_b;
  b.load_zone = p.share_handover * (p.zone_a + p.zone_b);
  b.cycle = p.arrival_gap;
  b.limit = "the arrivals";
  const std::pair<double, const char*> loads[] = {
      {b.load_a, "robot A"}, {b.load_b, "robot B"}, {b.load_zone, "the shared zone"}};
  for (const auto& [load, who] : loads)
    if (load > b.cycle) b.cycle = load, b.limit = who;
  b.parts_per_hour = 3600.0 / b.cycle;
  return b;
}

double move_cycle(double duration, double step) {
  if (!(step > 0)) throw vsd::Error("move_cycle: the step must be positive");
  if (!(duration >= 0)) throw vsd::Error("move_cycle: the duration must not be negative");
  return std::max(1.0, std::ceil(duration / step - 1e-9)) * step;
}

}  // namespace vsd_workcell
