// vsd-web (see tool.hpp).
#include "tool.hpp"

#include <signal.h>

#include <atomic>
#include <cstdint>
#include <chrono>
#include <ostream>
#include <string>
#include <thread>

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/robotics/module.hpp"
#include "vsd/scene/module.hpp"
#include "vsd/soml/module.hpp"
#include "vsd/soml/source.hpp"
#include "vsd/web/server.hpp"
#include "vsd_tool/arguments.hpp"
#include "vsd_tool/input.hpp"
#include "vsd_tool/models.hpp"
#include "vsd_tool/runner.hpp"
#include "vsd_tool/scene_input.hpp"
#include "vsd_tool/text.hpp"

namespace vsd::tool::vsd_web {

namespace {

constexpr std::string_view usage =
    R"(vsd-web: show a vsd file, a SOML++ script or a robot description in the browser

Usage:
  vsd-web <file> [--port N] [--bind ADDRESS] [--token T] [--run] [--dt SECONDS] [--seconds S]
      <file> is a state saved by vsd::io (.json vsd-text, .vsds binary), a SOML++ script (.soml) or a
      URDF (.urdf, .xml); "-" reads standard input (XML is taken as a URDF, anything else as a vsd file).
      Serves the inspector (docs/web.md) on http://ADDRESS:N/ — 127.0.0.1 and 8080 by default; N = 0
      picks a free port — and prints "vsd-web: serving URL" and "vsd-web: write token: T". Editing needs
      the token (a random one unless --token is given); an address other than a loopback one needs
      --token. The simulation is paused until the page starts it (or --run is given); it then steps in
      real time, SECONDS per step (default 0.01, from 0.0001 to 1), each step firing at most 100
      transitions of a script (a net that never becomes quiet goes on in the next step). Stops on
      Ctrl-C or SIGTERM, or after
      S seconds of wall time (--seconds, for scripts and tests).
  vsd-web --help

Exit status: 0 stopped, 1 the file could not be loaded or the address not bound, 2 a usage error.
)";

const Tool tool{"vsd-web", usage};

constexpr std::uint64_t firings_per_step = 100;

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

/// Blocks SIGINT and SIGTERM in this thread (the server's threads, started after, inherit it) and waits
/// for them on a thread of its own; restores the mask when it goes (the tests run the tool in-process).
class StopOnSignal {
 public:
  explicit StopOnSignal(web::Server& server) {
    sigemptyset(&set_);
    sigaddset(&set_, SIGINT);
    sigaddset(&set_, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &set_, &old_);
    waiter_ = std::thread([this, &server] {
      const timespec tick{0, 100'000'000};
      while (!done_) {
        if (sigtimedwait(&set_, nullptr, &tick) > 0) {
          server.stop();
          return;
        }
      }
    });
  }
  ~StopOnSignal() {
    done_ = true;
    waiter_.join();
    pthread_sigmask(SIG_SETMASK, &old_, nullptr);
  }
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;

 private:
  sigset_t set_{}, old_{};
  std::atomic<bool> done_{false};
  std::thread waiter_;
};

int body(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {with_value("--port"), with_value("--bind"), with_value("--token"), flag("--run"),
                           with_value("--dt"), with_value("--seconds")});
  a.expect_positional(1, 1, "one file");
  web::Options options;
  options.port = static_cast<int>(a.integer("--port", 8080, 0, 65535));
  if (const auto b = a.value("--bind")) options.bind = std::string(*b);
  if (const auto t = a.value("--token")) {
    if (t->size() < 8) throw UsageError("--token must have at least 8 characters");
    options.token = std::string(*t);
  }
  const double dt = a.real("--dt", 0.01, 1e-4, 1.0);
  const double seconds = a.real("--seconds", 0.0, 0.0, 1e9);
  const std::string_view path = a.positional()[0];

  Workspace ws;
  Environment& env = ws.env();
  env.scheduler().set_base_step(dt);
  env.use<scene::Module>();
  env.use<robotics::Module>();
  auto& soml = env.use<vsd::soml::Module>();
  // A net that never becomes quiet (the dining philosophers) fires this often per step, so that steps
  // end, the page sees the tokens move, and requests and signals are served.
  soml.step_limit = firings_per_step;
  SimState& state = ws.state();
  if (ends_with(path, ".soml")) {
    const std::string file(path);
    soml.load(state, file, read_text_input(path, vsd::soml::max_source_bytes));
    out << "loaded SOML++ script " << printable(file) << "\n";
  } else {
    const SceneInput in = load_scene_input(state, path, scene::UrdfOptions{});
    if (in.urdf) out << "loaded " << in.urdf->links << " links, " << in.urdf->joints << " joints\n";
    if (in.saved) out << "loaded " << in.saved->instances << " instances\n";
    print_warnings(in.warnings, err);
  }

  web::Server server(env, state, options);
  server.pause(!a.has("--run"));
  std::optional<StopOnSignal> signals;
  signals.emplace(server);
  server.start();
  out << "vsd-web: serving " << server.url() << "\n"
      << "vsd-web: write token: " << server.token() << "\n"
      << std::flush;
  std::thread timer;
  std::atomic<bool> over{false};
  if (seconds > 0) {
    timer = std::thread([&] {
      const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
      while (!over && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(20));
      server.stop();
    });
  }
  try {
    server.run();
  } catch (...) {
    over = true;
    server.stop();
    if (timer.joinable()) timer.join();
    throw;
  }
  over = true;
  if (timer.joinable()) timer.join();
  out << "vsd-web: stopped\n";
  return exit_ok;
}

}  // namespace

int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  return tool::run(tool, args, out, err, body);
}

}  // namespace vsd::tool::vsd_web
