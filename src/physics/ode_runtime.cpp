#include "ode_runtime.hpp"

#include <ode/ode.h>

#include <cstdarg>
#include <cstdio>

#include "vsd/core/error.hpp"

namespace vsd::physics::detail {

namespace {

std::mutex init_mutex;
int users = 0;
thread_local std::vector<std::string>* message_sink = nullptr;
std::vector<std::string> orphan_messages;  // messages outside any advance(); kept for no one but bounded

std::string format(int num, const char* msg, va_list ap) {
  char text[512];
  std::vsnprintf(text, sizeof text, msg, ap);
  return "ODE " + std::to_string(num) + ": " + text;
}

// dError and dDebug are declared noreturn: ODE would abort() if the handler returned. Throwing instead
// unwinds through ODE's own (C++) frames; it is the last resort — vsd::physics validates what it hands
// ODE so that these handlers are not reached in normal use.
[[noreturn]] void on_error(int num, const char* msg, va_list ap) {
  throw vsd::Error("ODE error: " + format(num, msg, ap));
}
[[noreturn]] void on_debug(int num, const char* msg, va_list ap) {
  throw vsd::Error("ODE internal check failed: " + format(num, msg, ap));
}
// Called from inside ODE, which returns to its own frames: nothing may be thrown from here (a message
// that cannot be kept for want of memory is dropped).
void on_message(int num, const char* msg, va_list ap) noexcept {
  try {
    std::string text = format(num, msg, ap);
    if (message_sink != nullptr) {
      message_sink->push_back(std::move(text));
    } else if (orphan_messages.size() < 100) {
      orphan_messages.push_back(std::move(text));
    }
  } catch (...) {
  }
}

}  // namespace

OdeRuntime::OdeRuntime() {
  std::lock_guard lock(init_mutex);
  if (users++ == 0) {
    dInitODE2(0);
    dAllocateODEDataForThread(dAllocateMaskAll);
    dSetErrorHandler(&on_error);
    dSetDebugHandler(&on_debug);
    dSetMessageHandler(&on_message);
  }
}

OdeRuntime::~OdeRuntime() {
  std::lock_guard lock(init_mutex);
  if (--users == 0) dCloseODE();
}

std::mutex& ode_mutex() {
  static std::mutex m;
  return m;
}

MessageSink::MessageSink(std::vector<std::string>& sink) : previous_(message_sink) { message_sink = &sink; }
MessageSink::~MessageSink() { message_sink = previous_; }

}  // namespace vsd::physics::detail
