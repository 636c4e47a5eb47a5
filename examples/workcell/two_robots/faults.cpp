// Fault injection in the two-robot cell: the `--fault` grammar and the run's fault records (faults.hpp).
#include "faults.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ostream>
#include <utility>

#include "vsd/core/error.hpp"

namespace vsd_workcell {

namespace {

// "12", "12s", "0.5s": seconds, finite and not negative. @p what names the number in the error.
double seconds(const std::string& spec, const std::string& text, const char* what) {
  std::string t = text;
  if (!t.empty() && t.back() == 's') t.pop_back();
  char* end = nullptr;
  const double v = t.empty() ? NAN : std::strtod(t.c_str(), &end);
  if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v) || v < 0 ||
      t.find_first_not_of("0123456789.") != std::string::npos)
    throw vsd::Error("--fault '" + spec + "': " + what + " '" + text +
                     "' is not a number of seconds (like 12, 12s or 0.5s)");
  return v;
}

std::string two_decimals(double v) {
  char s[32];
  std::snprintf(s, sizeof s, "%.2f", v);
  return s;
}

}  // namespace

FaultSpec parse_fault(const std::string& spec) {
  FaultSpec f;
  f.spec = spec;
  const auto at = spec.find('@');
  if (at == std::string::npos)
    throw vsd::Error("--fault '" + spec + "': no '@' (KIND@T+D, or slip@partN)");
  const std::string kind = spec.substr(0, at);
  const std::string when = spec.substr(at + 1);
  if (kind == "slip" || kind == "slip_a" || kind == "slip_b") {
    f.kind = FaultSpec::Kind::Slip;
    f.robot = kind == "slip" ? -1 : kind == "slip_a" ? 0 : 1;
    const bool ok = when.size() > 4 && when.rfind("part", 0) == 0 &&
                    when.find_first_not_of("0123456789", 4) == std::string::npos && when[4] != '0' &&
                    when.size() <= 13;
    if (!ok) throw vsd::Error("--fault '" + spec + "': '" + when + "' is not a part name partN (N from 1)");
    f.part = when;
    return f;
  }
  if (kind == "arm_a_silent" || kind == "arm_b_silent") {
    f.kind = FaultSpec::Kind::ArmSilent;
    f.robot = kind == "arm_a_silent" ? 0 : 1;
  } else if (kind == "zone_sensor_drop") {
    f.kind = FaultSpec::Kind::ZoneSensorDrop;
  } else {
    throw vsd::Error("--fault '" + spec + "': unknown fault '" + kind +
                     "' (arm_a_silent, arm_b_silent, zone_sensor_drop, slip, slip_a or slip_b)");
  }
  const auto plus = when.find('+');
  if (plus == std::string::npos)
    throw vsd::Error("--fault '" + spec + "': no duration: " + kind + "@T+D (T when, D how long, in seconds)");
  f.at = seconds(spec, when.substr(0, plus), "the start");
  f.duration = seconds(spec, when.substr(plus + 1), "the duration");
  if (!(f.duration > 0)) throw vsd::Error("--fault '" + spec + "': the duration must be positive");
  return f;
}

FaultMonitor::FaultMonitor(std::vector<FaultSpec> specs)
    : specs_(std::move(specs)), records_(specs_.size()), robot_(specs_.size(), -1), ended_(specs_.size(), false) {
  for (std::size_t i = 0; i < specs_.size(); ++i) records_[i].spec = specs_[i].spec;
}

void FaultMonitor::note(std::size_t i, double t, const std::string& what) {
  lines_.push_back("t=" + two_decimals(t) + " s  fault " + specs_.at(i).spec + ": " + what);
  if (timeline != nullptr) *timeline << lines_.back() << '\n';
}

FaultActions FaultMonitor::step(double t, const FaultView (&robots)[2], int zone_free) {
  FaultActions act;
  double moved[2] = {0, 0};
  for (int r = 0; r < 2; ++r) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (robots[r].pad[k] - last_pad_[r][k]) * (robots[r].pad[k] - last_pad_[r][k]);
    moved[r] = have_pad_ ? std::sqrt(d2) : 0;
    for (int k = 0; k < 3; ++k) last_pad_[r][k] = robots[r].pad[k];
  }
  have_pad_ = true;
  const bool zone_taken = zone_free_before_ > 0 && zone_free == 0;
  zone_free_before_ = zone_free;
  const double last_t = last_t_;  // the last step's time (-1 before the first)
  last_t_ = t;
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    const FaultSpec& f = specs_[i];
    FaultRecord& rec = records_[i];
    const bool on = f.active(t);
    switch (f.kind) {
      case FaultSpec::Kind::ArmSilent: {
        const FaultView& v = robots[f.robot];
        act.silent[f.robot] = act.silent[f.robot] || on;
        if (on && rec.began < 0) {
          rec.began = t;
          note(i, t, v.name + "'s arm stops answering on its UDP link (its simulator process is stopped for " +
                         two_decimals(f.duration) + " s)");
        }
        if (rec.began >= 0 && rec.detected < 0 && !v.adapter_fault.empty()) {
          rec.detected = t;
          note(i, t, v.name + " holds where it is (its binding is in Fault: " + v.adapter_fault +
                         "); its net takes no new job and does not enter the zone");
        }
        if (rec.began >= 0 && !on && !ended_[i]) {
          ended_[i] = true;
          note(i, t, v.name + "'s arm answers again");
        }
        if (ended_[i] && rec.recovered < 0 && v.delivering && v.adapter_fault.empty()) {
          rec.recovered = t;
          note(i, t, v.name + "'s adapters deliver again: it resumes from where it stands");
        }
        break;
      }
      case FaultSpec::Kind::ZoneSensorDrop: {
        act.zone_sensor_down = act.zone_sensor_down || on;
        if (on && rec.began < 0) {
          rec.began = rec.detected = t;
          note(i, t, "the shared zone's presence sensor drops out: it reads as occupied (fail-safe), so no "
                     "robot enters the zone; a robot in it finishes and leaves");
        }
        // zone.free as seen now was taken by a firing of the last step, which read the sensor of the last step.
        if (zone_taken && last_t >= 0 && f.active(last_t)) {
          ++rec.zone_entries;
          note(i, t, "a robot took the zone while its sensor was down");
        }
        if (rec.began >= 0 && !on && !ended_[i]) {
          ended_[i] = true;
          rec.recovered = t;
          note(i, t, "the zone's presence sensor is back: the robots may enter again");
        }
        break;
      }
      case FaultSpec::Kind::Slip: {
        if (rec.began < 0) {
          for (int r = 0; r < 2; ++r)
            if ((f.robot < 0 || f.robot == r) && robots[r].holding == f.part && t - robots[r].grasped_at >= slip_after - 1e-9 && act.slip < 0) {
              act.slip = r;
              robot_[i] = r;
              rec.began = rec.detected = t;
              note(i, t, f.part + " slips from " + robots[r].name + "'s gripper during the lift; " +
                             robots[r].name + "'s gripper is empty, its net picks the part again");
            }
        } else if (rec.recovered < 0 && robots[robot_[i]].holding == f.part) {
          rec.recovered = t;
          note(i, t, robots[robot_[i]].name + " picked " + f.part + " again");
        }
        break;
      }
    }
    // From the step the cell saw the fault until the step before it recovered: how far the pads went.
    const int affected = f.kind == FaultSpec::Kind::ArmSilent ? f.robot : robot_[i];
    if (affected >= 0 && rec.detected >= 0 && rec.recovered < 0) {
      rec.affected_motion += moved[affected];
      rec.other_motion += moved[1 - affected];
    }
  }
  return act;
}

void FaultMonitor::finish(double t) {
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    if (records_[i].began < 0)
      note(i, t, specs_[i].kind == FaultSpec::Kind::Slip ? "never happened: no robot grasped " + specs_[i].part
                                                          : "never happened: the run ended before it");
    else if (records_[i].recovered < 0)
      note(i, t, "NOT recovered when the run ended");
  }
}

}  // namespace vsd_workcell
