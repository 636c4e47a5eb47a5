// The conveyor's infeed of the two-robot cell (docs/workcell.md, "The cell"): where an arriving part waits
// until Meta Control sends it down one of the conveyor's two lanes — lane A ends at robot A's pick point,
// lane B at robot B's. The infeed is the nets' interface to that choice: σ `waiting` (a part is there) and
// the lanes' queues, γ `divert(lane)`. The plant (cell.cpp) moves the diverted part onto its lane in its
// next sensor step.
#pragma once

#include <cstdint>
#include <cstdio>
#include <ostream>

#include "vsd/core/error.hpp"
#include "vsd/scene.hpp"

namespace vsd_workcell {

class Infeed : public vsd::scene::Node3D {
  VSD_INSTANCE(Infeed, vsd::scene::Node3D)
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, waiting, nullptr)  // σ: the part at the infeed, on no lane yet
  VSD_PROPERTY(std::int64_t, queued_a, 0)  // parts on lane A's belt or at its stop, not yet picked
  VSD_PROPERTY(std::int64_t, queued_b, 0)  // the same for lane B

 public:
  std::ostream* log = nullptr;
  const double* clock = nullptr;
  std::int64_t chosen = 0;  // the lane of the last divert (1: A, 2: B), until the plant moved the part

  /// γ: sends the waiting part down lane 1 (A) or 2 (B).
  void divert(std::int64_t lane) {
    if (!waiting()) throw vsd::Error("infeed.divert: no part is waiting");
    if (lane != 1 && lane != 2)
      throw vsd::Error("infeed.divert: lane " + std::to_string(lane) + " (the lanes are 1: A and 2: B)");
    if (log != nullptr) {
      char t[32];
      std::snprintf(t, sizeof t, "%.2f", clock != nullptr ? *clock : 0.0);
      *log << "t=" << t << " s  γ infeed.divert(" << waiting()->name() << ", lane " << (lane == 1 ? "A" : "B")
           << ")\n";
    }
    chosen = lane;
    set_waiting(nullptr);
  }
  VSD_METHOD(divert)
};

}  // namespace vsd_workcell
