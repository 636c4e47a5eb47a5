// SimulatorProcess: starts vsd_robot_simulator (robot_simulator.cpp) as a child process, reads the port it
// listens on from its first line, and kills it. Used by the eight_axis example and the robotics tests.
#pragma once

#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

extern char** environ;

namespace vsd_example {

class SimulatorProcess {
 public:
  /// Starts @p program with @p args and waits (up to 10 s) for its "listening on 127.0.0.1:PORT" line.
  SimulatorProcess(const std::string& program, const std::vector<std::string>& args) {
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error("pipe failed");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    std::vector<std::string> all{program};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int rc = ::posix_spawn(&pid_, program.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[1]);
    out_ = fds[0];
    if (rc != 0) {
      ::close(out_);
      throw std::runtime_error("cannot start " + program);
    }
    const std::string line = read_line(std::chrono::seconds(10));
    const std::string key = "127.0.0.1:";
    const auto at = line.find(key);
    if (at == std::string::npos) {
      kill();
      throw std::runtime_error("robot simulator did not report its port (got '" + line + "')");
    }
    port_ = static_cast<std::uint16_t>(std::stoi(line.substr(at + key.size())));
  }
  ~SimulatorProcess() {
    kill();
    if (out_ >= 0) ::close(out_);
  }
  SimulatorProcess(const SimulatorProcess&) = delete;
  SimulatorProcess& operator=(const SimulatorProcess&) = delete;

  [[nodiscard]] std::uint16_t port() const noexcept { return port_; }
  [[nodiscard]] bool running() const noexcept { return pid_ > 0; }
  /// Sends @p sig (SIGSTOP: the robot stops answering without going away; SIGCONT: it answers again).
  void signal(int sig) const noexcept {
    if (pid_ > 0) ::kill(pid_, sig);
  }
  /// Kills the process (SIGKILL: a crash, no goodbye) and reaps it.
  void kill() noexcept {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
  }
  /// Waits up to @p timeout for the process to exit by itself; true when it did.
  bool wait_exit(std::chrono::milliseconds timeout) noexcept {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (pid_ > 0 && std::chrono::steady_clock::now() < end) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_)
        pid_ = -1;
      else
        ::usleep(1000);
    }
    return pid_ <= 0;
  }

 private:
  std::string read_line(std::chrono::milliseconds timeout) {
    std::string line;
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      pollfd p{out_, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      char c = 0;
      if (::read(out_, &c, 1) != 1) break;
      if (c == '\n') break;
      line += c;
    }
    return line;
  }

  pid_t pid_ = -1;
  int out_ = -1;
  std::uint16_t port_ = 0;
};

}  // namespace vsd_example
