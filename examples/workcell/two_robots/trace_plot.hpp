// The two-robot cell's picture on request (`--png FILE`, docs/workcell.md "What it prints"): both pads'
// positions over time and who occupies the shared zone, drawn with png_image.hpp (no plotting library).
#pragma once

#include <string>
#include <vector>

namespace vsd_workcell {

/// One step of the run as the picture needs it.
struct TraceSample {
  double t = 0;              ///< s simulated
  double a[3] = {0, 0, 0};   ///< robot A's pad (m, world)
  double b[3] = {0, 0, 0};   ///< robot B's pad
  bool a_in_zone = false;    ///< from the zone sensor's geometry
  bool b_in_zone = false;
};

/// Collects samples (at most one per 20 ms of simulated time, and every change of the zone's occupancy;
/// fewer in a run so long that it would need more than max_samples) and draws them: three panels over a common time axis (grid lines every 10 s, every 60 s beyond 10
/// minutes) — the pads' y (the rails' direction; grey lines at the pick points, the station and the
/// destinations), the pads' x (the shared zone's x range shaded) and the zone's occupancy (A's row, B's
/// row, both at once in black); robot A red, robot B blue.
class TracePlot {
 public:
  static constexpr std::size_t max_samples = 100'000;
  void add(const TraceSample& s);
  std::size_t size() const { return samples_.size(); }
  /// Writes the picture as a PNG (through a temporary file renamed over @p path).
  /// @throws vsd::Error "cannot write PATH: REASON"; an existing file at @p path is left as it was.
  void write(const std::string& path) const;

 private:
  std::vector<TraceSample> samples_;
  double interval_ = 0.02;  // s between samples
};

/// Checks before a run that @p path can be written (creates and removes PATH.tmp), so that a bad
/// `--png` fails at once, not after the run. @throws vsd::Error "cannot write PATH: REASON".
void check_writable(const std::string& path);

}  // namespace vsd_workcell
