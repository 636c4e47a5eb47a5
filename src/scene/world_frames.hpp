// What keeps the world-frame caches of one SimState honest (private to vsd::scene).
#pragma once

#include "vsd/core/watch.hpp"

namespace vsd::scene {

/// An at-once Watch, kept in the state's context: a changed `frame` of a Node3D, or any node added to or
/// removed from a parent, invalidates the cached world frames below it. scene::Module makes it for
/// every state it serves; the first world-frame read of a state makes it where the module is not used.
struct WorldFrameWatch {
  explicit WorldFrameWatch(SimState& state);
  /// Forgets every cached world frame of the state (the tracking is about to go).
  ~WorldFrameWatch();
  Watch watch;
};

}  // namespace vsd::scene
