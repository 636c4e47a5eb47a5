// Fault injection in the two-robot cell (issue 24, item 6; docs/workcell.md, "Faults"): what a fault is, the
// grammar of `--fault`, and what a run records about each fault it injected.
//
//   arm_a_silent@T+D      robot_a's arm stops answering on the UDP FRI-like link from simulated time T for
//   arm_b_silent@T+D      D seconds (its vsd_robot_simulator process is stopped; needs --hardware)
//   zone_sensor_drop@T+D  the shared zone's presence sensor delivers nothing from T for D seconds
//   slip@partN            partN slips from the gripper of the robot that grasps it first, as the lift begins
//   slip_a@partN          ... of robot_a (A's first grasp of it)
//   slip_b@partN          ... of robot_b (B's first grasp of it: a hand-over part, on the station)
//
// A slipped part falls back onto where it was picked from (the conveyor's stop, the station) and the
// robot's net picks it again (the `slipped` transitions of multi_robot_control.soml).
//
// T and D are decimal numbers of seconds with an optional `s` ("12", "12s", "0.5s"); D must be positive.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace vsd_workcell {

/// One injected fault, as parsed from its spec.
struct FaultSpec {
  enum class Kind { ArmSilent, ZoneSensorDrop, Slip };
  Kind kind = Kind::ArmSilent;
  int robot = 0;          ///< ArmSilent, Slip: 0 robot_a, 1 robot_b (Slip: -1 whichever grasps the part first)
  double at = 0;          ///< s of simulated time (ArmSilent, ZoneSensorDrop)
  double duration = 0;    ///< s (ArmSilent, ZoneSensorDrop)
  std::string part;       ///< Slip: the part's name ("part7")
  std::string spec;       ///< the text it was parsed from
  [[nodiscard]] bool active(double t) const { return kind != Kind::Slip && t >= at && t < at + duration; }
};

/// Parses one spec of the grammar above.
/// @throws vsd::Error "--fault 'SPEC': " and what is wrong (unknown kind, missing '@' or '+D', a bad number).
FaultSpec parse_fault(const std::string& spec);

/// What a run saw of one injected fault (CellReport::faults, in the order of the options).
struct FaultRecord {
  std::string spec;
  double began = -1;      ///< s: injected (the slip: the part left the gripper); -1: never happened
  double detected = -1;   ///< s: the cell saw it (the arm's binding in Fault, the sensor down, the gripper empty)
  double recovered = -1;  ///< s: the cell resumed (the binding Running again, the sensor back, the part re-grasped)
  /// m the affected robot's pad moved from the step the cell saw the fault to the step before it recovered
  /// (an arm's silence: while its binding held; the step of the recovery is left out — see docs/workcell.md)
  double affected_motion = 0;
  double other_motion = 0;  ///< m the other robot's pad moved meanwhile (it goes on where it can)
  int zone_entries = 0;        ///< zone_sensor_drop: times a net took the zone while the sensor was down
};

/// What the monitor sees of one robot in a step (the cell fills it in).
struct FaultView {
  std::string name;           ///< "robot_a"
  std::string adapter_fault;  ///< its HardwareBinding's fault; "" while it delivers (or without --hardware)
  bool delivering = true;     ///< its binding is Running (or there is none)
  std::string holding;        ///< the part in its gripper, "" for none
  double grasped_at = 0;      ///< s: when it grasped it
  double pad[3] = {0, 0, 0};  ///< m: its gripper pad
};

/// What the cell must do in this step because of the faults.
struct FaultActions {
  bool silent[2] = {false, false};  ///< robot's arm simulator stopped
  bool zone_sensor_down = false;    ///< the zone's presence sensor delivers nothing
  int slip = -1;                    ///< this robot's gripper loses its part now (0 A, 1 B)
};

/// Runs the faults of a run: switches them on and off by simulated time, sees the cell's reaction through
/// FaultView and writes the report lines (began, detected, recovered) into FaultRecord and lines().
class FaultMonitor {
 public:
  explicit FaultMonitor(std::vector<FaultSpec> specs);
  /// How long into the lift a part slips (s after its grasp).
  static constexpr double slip_after = 0.05;
  /// One step at simulated time @p t; @p zone_free: tokens on Multi Robot Control's zone.free.
  FaultActions step(double t, const FaultView (&robots)[2], int zone_free);
  [[nodiscard]] const std::vector<FaultSpec>& specs() const noexcept { return specs_; }
  [[nodiscard]] const std::vector<FaultRecord>& records() const noexcept { return records_; }
  /// The report lines so far ("t=12.00 s  fault arm_a_silent@12s+5s: ..."); a line is also written to the
  /// timeline when one is set.
  [[nodiscard]] const std::vector<std::string>& lines() const noexcept { return lines_; }
  std::ostream* timeline = nullptr;
  /// Lines for the faults that never happened (a slip of a part no robot grasped, a fault after the end).
  void finish(double t);

 private:
  void note(std::size_t i, double t, const std::string& what);
  std::vector<FaultSpec> specs_;
  std::vector<FaultRecord> records_;
  std::vector<int> robot_;        // the robot a slip happened to
  std::vector<bool> ended_;       // an arm's silence or the sensor's drop is over
  std::vector<std::string> lines_;
  double last_pad_[2][3] = {};
  bool have_pad_ = false;
  int zone_free_before_ = -1;
  double last_t_ = -1;  // the time of the last step()
};

}  // namespace vsd_workcell
