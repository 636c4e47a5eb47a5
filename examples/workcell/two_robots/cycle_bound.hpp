// The two-robot cell's throughput bound from its parameters (docs/workcell.md, "The analytic bound"):
// every part costs the robot that handles it the motion times of its job, a hand-over costs both robots
// and the shared zone, and parts arrive one per mean arrival gap. Whichever of the four — robot A, robot B,
// the zone, the arrivals — is loaded most per part sets the cycle time, and no schedule of the nets can
// do better than one part per that cycle (each robot does one job at a time, the zone holds one robot).
#pragma once

#include <string>
#include <vector>

namespace vsd_workcell {

/// What the bound is made of, all in seconds of simulated time per job (or per part).
struct CycleParameters {
  double arrival_gap = 4.0;  ///< mean gap between two parts' arrivals (the seed's gaps: 2 to 6 s)
  double direct_a = 0;       ///< robot A's cycle for a part of route 1 (lane A to dest_a)
  double direct_b = 0;       ///< robot B's cycle for a part of route 3 (lane B to dest_b)
  double give_a = 0;         ///< robot A's cycle for its half of a hand-over (lane A to the station)
  double take_b = 0;         ///< robot B's cycle for its half (the station to dest_b)
  double zone_a = 0;         ///< the time A holds the shared zone per hand-over
  double zone_b = 0;         ///< the time B holds it per hand-over
  double share_direct_a = 0.5;  ///< shares of the parts taking route 1, 2 and 3 (they add up to 1)
  double share_handover = 0;
  double share_direct_b = 0.5;
};

/// The bound and what sets it.
struct CycleBound {
  double parts_per_hour = 0;  ///< 3600 / cycle
  double cycle = 0;           ///< s per part: the largest of the loads below
  double load_a = 0;          ///< s of robot A's time per part (of all routes)
  double load_b = 0;          ///< s of robot B's time per part
  double load_zone = 0;       ///< s of the shared zone's time per part
  std::string limit;          ///< "robot A", "robot B", "the shared zone" or "the arrivals"
};

/// The bound for @p p. @throws vsd::Error when a time is negative or not finite, the arrival gap is not
/// positive, or the shares are negative or do not add up to 1 (within 1e-9).
CycleBound cycle_bound(const CycleParameters& p);

/// The time from commanding a move of @p duration (s, the planned trajectory) until the nets command the
/// next one, when the cell steps every @p step seconds: the nets command in a step's net phase, the
/// controller advances the trajectory from the next step on, and the sensors of the step in which it
/// ends set `arrived`, on which the nets fire in that same step — so the duration rounded up to whole
/// steps (at least one). @throws vsd::Error for step <= 0 or a negative duration.
double move_cycle(double duration, double step);

}  // namespace vsd_workcell
