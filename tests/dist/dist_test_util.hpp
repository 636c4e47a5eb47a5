// Shared by the vsd::dist tests: test classes, a DDS domain of its own per test, the loopback config.
#pragma once

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <string>
#include <vector>
#include <vsd/vsd.hpp>

#include "vsd/dist/participant.hpp"

namespace vsd_dist_test {

using namespace std::chrono_literals;

/// A robot arm as the two sides of the paper's example share it.
class DArm : public vsd::Node {
  VSD_INSTANCE(DArm, vsd::Node)
  VSD_PROPERTY(double, target, 0.0)    // set by the user interface
  VSD_PROPERTY(double, position, 0.0)  // set by the controller
  VSD_PROPERTY(int, counter, 0)        // a writer's running count
  VSD_PROPERTY(std::vector<double>, joints, {})
  VSD_PROPERTY(std::string, note, "", vsd::Editable | vsd::Savable)  // not Distributed: stays local
  VSD_PROPERTY(vsd::SharedRef<vsd::Node>, watched, nullptr)
  VSD_PROPERTY(vsd::SharedRefList<vsd::Node>, tools, {})  // a list two participants may edit at once
};

/// A DDS domain id for this test: tests of one run (and runs of ctest -j) must not hear each other.
inline std::uint32_t fresh_domain() {
  static std::atomic<std::uint32_t> n{0};
  return 1 + static_cast<std::uint32_t>((static_cast<std::uint32_t>(::getpid()) * 7U + n++ * 13U) % 220U);
}

inline vsd::dist::ParticipantOptions options(std::string name, std::uint32_t domain, bool seed = false,
                                             std::vector<std::string>* log = nullptr) {
  vsd::dist::ParticipantOptions o;
  o.name = std::move(name);
  o.domain = domain;
  o.seed = seed;
  o.config = std::string("file://") + VSD_DIST_LOOPBACK_CONFIG;
  o.request_interval = 50ms;
  if (log != nullptr) {
    o.log = [log](std::string_view line) { log->emplace_back(line); };
  } else {
    o.log = [](std::string_view) {};
  }
  return o;
}

/// Polls every participant until @p done or the timeout.
template <class F>
bool poll_all(std::initializer_list<vsd::dist::Participant*> ps, F done,
              std::chrono::milliseconds timeout = std::chrono::milliseconds(10000)) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    for (auto* p : ps) p->poll();
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

inline bool contains(const std::vector<std::string>& log, std::string_view what) {
  for (const auto& l : log)
    if (l.find(what) != std::string::npos) return true;
  return false;
}

}  // namespace vsd_dist_test
