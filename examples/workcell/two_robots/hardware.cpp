// The two-robot cell's hardware adapters: simulator processes, binding configurations (hardware.hpp).
#include "hardware.hpp"

#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <utility>

#include "faults.hpp"
#include "simulator_process.hpp"
#include "vsd/core/error.hpp"
#include "vsd/robotics.hpp"

namespace vsd_workcell {

struct CellHardware::Process {
  Process(const std::string& program, const std::vector<std::string>& args) : process(program, args) {}
  vsd_example::SimulatorProcess process;
};

bool take_hardware_option(const std::vector<std::string>& args, std::size_t& i, HardwareOptions& o) {
  const std::string& a = args[i];
  auto value = [&]() -> const std::string& {
    if (i + 1 >= args.size()) throw vsd::Error(a + ": needs a value");
    return args[++i];
  };
  if (a == "--hardware") {
    o.enabled = true;
  } else if (a == "--simulator") {
    o.simulator = value();
  } else if (a == "--arm-a" || a == "--arm-b") {
    const std::string& v = value();
    const auto colon = v.rfind(':');
    const std::string port = colon == std::string::npos ? "" : v.substr(colon + 1);
    if (colon == std::string::npos || colon == 0 || port.empty() ||
        port.find_first_not_of("0123456789") != std::string::npos || port.size() > 5 || std::stoi(port) < 1 ||
        std::stoi(port) > 65535)
      throw vsd::Error(a + ": '" + v + "' is not HOST:PORT (a loopback address and a port 1 to 65535)");
    const std::string host = v.substr(0, colon);
    if (host != "localhost" && host.rfind("127.", 0) != 0)
      throw vsd::Error(a + ": '" + host + "' is not a loopback address (127.x.y.z or localhost): the UDP adapter "
                       "talks to robots on this machine only");
    o.arm[a == "--arm-a" ? 0 : 1] = v;
  } else if (a == "--hardware-timeout") {
    const std::string& v = value();
    char* end = nullptr;
    const double t = std::strtod(v.c_str(), &end);
    if (v.empty() || end != v.c_str() + v.size() || !(t >= 0.001 && t <= 1))
      throw vsd::Error(a + ": '" + v + "' is not a number in [0.001, 1] (seconds)");
    o.timeout = t;
  } else {
    return false;
  }
  return true;
}

void check_faults(const std::vector<FaultSpec>& faults, const HardwareOptions& o) {
  for (const FaultSpec& f : faults)
    if (f.kind == FaultSpec::Kind::ArmSilent && (!o.enabled || !o.arm[f.robot].empty()))
      throw vsd::Error("--fault '" + f.spec + "': needs --hardware with the arm's simulator started here (not " +
                       (f.robot == 0 ? "--arm-a" : "--arm-b") + ")");
}

CellHardware::CellHardware(HardwareOptions options) : options_(std::move(options)) {
  if (options_.simulator.empty()) {
    // Next to this program (both are built into build/examples).
    std::error_code ec;
    const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
    options_.simulator = ec ? "vsd_robot_simulator" : (self.parent_path() / "vsd_robot_simulator").string();
  }
}

CellHardware::~CellHardware() = default;  // kills the simulators it started (SIGKILL ends a stopped one too)

std::string CellHardware::summary(int i) const {
  std::string out;
  const vsd::robotics::HardwareBinding& b = *bindings_[i];
  for (std::size_t k = 0; k < b.adapter_count(); ++k) {
    const auto& st = b.adapter(k).stats();
    out += (k > 0 ? "; " : "") + b.adapter(k).describe() + ": cycles " + std::to_string(st.cycles) + ", missed " +
           std::to_string(st.missed) + ", rejected " + std::to_string(st.rejected) + ", faults " +
           std::to_string(st.faults) + ", recoveries " + std::to_string(st.recoveries);
  }
  return out;
}

void CellHardware::connect(double dt) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(options_.connect_timeout);
  for (;;) {
    bool running = true;
    for (vsd::robotics::HardwareBinding* b : bindings_) {
      b->cycle(dt);
      running = running && b->status() == vsd::robotics::BindingStatus::Running;
    }
    if (running) return;
    if (std::chrono::steady_clock::now() > end)
      for (int i = 0; i < 2; ++i)
        if (bindings_[i]->status() != vsd::robotics::BindingStatus::Running)
          throw vsd::Error("--hardware: robot_" + std::string(i == 0 ? "a" : "b") + "'s adapters do not deliver (" +
                           (bindings_[i]->fault().empty() ? std::string("still connecting") : bindings_[i]->fault()) +
                           ")");
  }
}

bool CellHardware::started(int i) const { return processes_[i] != nullptr; }

void CellHardware::silence(int i, bool silent) {
  if (!processes_[i] || silent_[i] == silent) return;
  silent_[i] = silent;
  processes_[i]->process.signal(silent ? SIGSTOP : SIGCONT);
}

vsd::robotics::HardwareBinding& CellHardware::attach(int i, vsd::Node& arm, vsd::robotics::KinematicTree& tree) {
  const auto& layout = tree.model().layout();
  std::string joints, initial;
  std::string rail;
  const std::vector<double> q = tree.positions();
  for (std::size_t k = 0; k < layout.size(); ++k) {
    const std::string& name = layout[k].name;
    if (name == "world_iiwa_joint") {
      rail = name;
      continue;
    }
    joints += (joints.empty() ? "" : ",") + name;
    std::ostringstream v;
    v.precision(17);
    v << q[k];
    initial += (initial.empty() ? "" : ",") + v.str();
  }
  if (rail.empty()) throw vsd::Error("the robot has no linear axis 'world_iiwa_joint' for the fieldbus adapter");
  std::string endpoint = options_.arm[i];
  if (endpoint.empty()) {
    try {
      processes_[i] = std::make_unique<Process>(
          options_.simulator,
          std::vector<std::string>{"--port", "0", "--dof", "7", "--initial", initial, "--idle-exit", "120"});
    } catch (const std::exception& e) {
      throw vsd::Error(std::string("--hardware: ") + e.what() + " (the robot simulator: " + options_.simulator +
                       "; --simulator names another)");
    }
    endpoint = "127.0.0.1:" + std::to_string(processes_[i]->process.port());
  }
  std::ostringstream timeout;
  timeout << options_.timeout;
  // The rail's travel and speed as the URDF's prismatic joint has them (eight_axis_urdf.hpp: ±1.2 m, 1 m/s
  // in the cell); the drive's own speed limit is above it, so the drive follows the controller's profile.
  // The drive faults when one cycle's target is further than `following_error` from where it stands: at
  // 1 m/s and a step of up to 0.05 s a target moves 5 cm per cycle, so 0.2 m.
  configs_[i] = "udp://" + endpoint + "?joints=" + joints + "&timeout=" + timeout.str() +
                "&max_missed=3;fieldbus://?joints=" + rail + "&velocity=2&lower=-1.3&upper=1.3&following_error=0.2";
  auto& binding = arm.state().create<vsd::robotics::HardwareBinding>();
  binding.set_config(configs_[i]);
  arm.add_extension(binding);
  bindings_[i] = &binding;
  return binding;
}

}  // namespace vsd_workcell
