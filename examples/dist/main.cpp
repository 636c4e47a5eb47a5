// The paper's simulation-based control (section 4.2): the user interface and the robot control run in
// different processes (on different computers in the paper), both with the same model, kept in sync by
// vsd::dist. The user interface owns the set-points, the robot control owns the joint positions.
//
//   vsd_dist_example                     runs both: starts "robot" as a child process, then is "ui"
//   vsd_dist_example robot|ui DOMAIN     one side only (start the robot first)
//
// The Cyclone DDS configuration comes from CYCLONEDDS_URI when set, else the repository's loopback file.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vsd/dist/module.hpp>
#include <vsd/vsd.hpp>

extern char** environ;

namespace {

using namespace std::chrono_literals;

class Axis : public vsd::Node {
  VSD_INSTANCE(Axis, vsd::Node)
  VSD_PROPERTY(double, target, 0.0)      // set-point: the user interface's
  VSD_PROPERTY(double, position, 0.0)    // joint position: the robot control's
  VSD_PROPERTY(bool, running, true)      // the user interface ends the session
  VSD_PROPERTY(std::string, status, "")  // the robot control's report
};

vsd::dist::ParticipantOptions options(const char* name, std::uint32_t domain, bool seed) {
  vsd::dist::ParticipantOptions o;
  o.name = name;
  o.domain = domain;
  o.seed = seed;
  const char* uri = std::getenv("CYCLONEDDS_URI");
  o.config = uri != nullptr && *uri != '\0' ? uri : std::string("file://") + VSD_DIST_LOOPBACK_CONFIG;
  o.log = [name](std::string_view l) {
    std::printf("%s: [dist] %.*s\n", name, static_cast<int>(l.size()), l.data());
  };
  return o;
}

Axis* find_axis(vsd::SimState& s) {
  for (auto* n : s.database().children())
    if (auto* a = n->as<Axis>()) return a;
  return nullptr;
}

// The robot control: the seed of the model; moves the axis towards its target, 0.1 per step.
int robot(std::uint32_t domain) {
  vsd::Environment env{1};
  auto& dist = env.use<vsd::dist::Module>();
  vsd::SimState& s = env.main_state();
  auto& axis = s.create<Axis>();
  axis.set_name("axis1");
  s.database().add_child(axis);
  auto& p = dist.join(s, options("robot", domain, true));
  p.claim(axis, "position");
  p.claim(axis, "status");
  const auto end = std::chrono::steady_clock::now() + 60s;
  double shown_target = axis.target();
  while (axis.running() && std::chrono::steady_clock::now() < end) {
    env.step();  // the module's task publishes what the last step changed and applies the ui's changes
    if (axis.target() != shown_target) {
      shown_target = axis.target();
      std::printf("robot: sees new target %.2f (at %.2f)\n", shown_target, axis.position());
    }
    const double d = axis.target() - axis.position();
    if (std::abs(d) > 1e-9) {
      axis.set_position(std::abs(d) <= 0.1 ? axis.target() : axis.position() + std::copysign(0.1, d));
      if (axis.position() == axis.target()) {
        char text[32];
        std::snprintf(text, sizeof text, "reached %.2f", axis.target());
        axis.set_status(text);
        std::printf("robot: %s\n", axis.status().c_str());
      }
    }
    std::this_thread::sleep_for(5ms);
  }
  env.step();
  std::printf("robot: %s\n", axis.running() ? "timed out" : "stopped by the ui");
  return axis.running() ? 1 : 0;
}

// The user interface: joins, sets two targets, watches the robot reach them, ends the session.
int ui(std::uint32_t domain) {
  vsd::Environment env{2};
  auto& dist = env.use<vsd::dist::Module>();
  vsd::SimState& s = env.main_state();
  auto& p = dist.join(s, options("ui", domain, false));
  if (!p.wait_synced(30s)) {
    std::printf("ui: the robot did not answer\n");
    return 1;
  }
  Axis* axis = find_axis(s);
  if (axis == nullptr) return 1;
  std::printf("ui: joined, sees %s at %.2f\n", axis->name().c_str(), axis->position());
  p.claim(*axis, "target");
  p.claim(*axis, "running");
  auto watch = s.on_property_changed().connect([&](vsd::SimStateInstance& x, const vsd::MetaProperty& prop) {
    if (&x == axis && prop.name() == "status") std::printf("ui: robot says '%s'\n", axis->status().c_str());
  });
  for (double target : {0.5, -0.3}) {
    axis->set_target(target);
    std::printf("ui: target %.2f\n", target);
    const auto end = std::chrono::steady_clock::now() + 30s;
    while (axis->position() != target && std::chrono::steady_clock::now() < end) {
      env.step();
      std::this_thread::sleep_for(2ms);
    }
    if (axis->position() != target) {
      std::printf("ui: the robot did not reach %.2f\n", target);
      return 1;
    }
    std::printf("ui: sees the robot at %.2f\n", axis->position());
  }
  // The ui may not move the joint itself: the robot owns it. The change is undone and reported.
  auto conflicts =
      p.on_conflict().connect([](const vsd::dist::Conflict& c) { std::printf("ui: %s\n", c.text.c_str()); });
  axis->set_position(2.0);
  env.step();
  std::printf("ui: position after the rejected write: %.2f\n", axis->position());
  axis->set_running(false);
  env.step();
  p.poll_until([] { return false; }, 200ms);  // let the robot read it
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    if (argc == 3) {
      const auto domain = static_cast<std::uint32_t>(std::atoi(argv[2]));
      if (std::string(argv[1]) == "robot") return robot(domain);
      if (std::string(argv[1]) == "ui") return ui(domain);
    }
    if (argc != 1) {
      std::fprintf(stderr, "usage: vsd_dist_example [robot|ui DOMAIN]\n");
      return 2;
    }
    // Both: the robot in a child process, the ui here. A domain of our own (pid-based) avoids cross-talk.
    const std::string domain = std::to_string(100 + ::getpid() % 100);
    std::string self = argv[0], role = "robot";
    char* child_argv[] = {self.data(), role.data(), const_cast<char*>(domain.c_str()), nullptr};
    pid_t child = 0;
    if (posix_spawn(&child, self.c_str(), nullptr, nullptr, child_argv, environ) != 0) {
      std::perror("posix_spawn");
      return 1;
    }
    const int rc = ui(static_cast<std::uint32_t>(std::stoul(domain)));
    int status = 0;
    waitpid(child, &status, 0);
    const bool robot_ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    std::printf("ui and robot %s\n", rc == 0 && robot_ok ? "finished" : "FAILED");
    return rc == 0 && robot_ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::printf("error: %s\n", e.what());
    return 1;
  }
}
