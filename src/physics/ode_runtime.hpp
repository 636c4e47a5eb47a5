// ODE's process-wide set-up, shared by every Simulation: dInitODE2/dCloseODE exactly once per period of
// use, and ODE's error, debug and message handlers redirected (errors throw vsd::Error, messages are kept).
#pragma once

#include <mutex>
#include <string>
#include <vector>

namespace vsd::physics::detail {

/// Holds ODE initialised while it lives: the first holder calls dInitODE2 (and installs the handlers),
/// the last one dCloseODE. Reference counted under a mutex, so Simulations may come and go in any order.
class OdeRuntime {
 public:
  OdeRuntime();
  ~OdeRuntime();
  OdeRuntime(const OdeRuntime&) = delete;
  OdeRuntime& operator=(const OdeRuntime&) = delete;
};

/// Held around every call into ODE that steps or collides: this libode is built without thread-local
/// collider data (dGetConfiguration() has no ODE_EXT_ou), so two threads must not run it at once.
std::mutex& ode_mutex();

/// Where ODE's dMessage output goes while held (a Simulation's warnings); restores the previous sink.
class MessageSink {
 public:
  explicit MessageSink(std::vector<std::string>& sink);
  ~MessageSink();
  MessageSink(const MessageSink&) = delete;
  MessageSink& operator=(const MessageSink&) = delete;

 private:
  std::vector<std::string>* previous_;
};

}  // namespace vsd::physics::detail
