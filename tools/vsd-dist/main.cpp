// vsd-dist: join a vsd::dist domain from the command line (`vsd-dist --help`).
//
//   vsd-dist serve FILE --domain N [--topic T] [--config URI] [--for SECONDS]
//   vsd-dist watch --domain N [--topic T] [--config URI] [--for SECONDS]
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/core.hpp"
#include "vsd/dist.hpp"
#include "vsd/io/snapshot.hpp"

namespace {

constexpr std::string_view usage =
    "Usage: vsd-dist serve FILE --domain N [--topic T] [--config URI] [--for SECONDS]\n"
    "       vsd-dist watch --domain N [--topic T] [--config URI] [--for SECONDS]\n"
    "  serve  load FILE (vsd-text or VSDS) and be the seed of the shared model in DDS domain N\n"
    "  watch  join domain N, print the model when synchronised, then every change\n"
    "  --config  Cyclone DDS configuration (XML or file://...); default: CYCLONEDDS_URI\n"
    "  --for     stop after this many seconds (default: until interrupted)\n";

volatile std::sig_atomic_t interrupted = 0;

void print_instance(const vsd::SimStateInstance& x) {
  std::cout << "#" << x.id() << " " << x.meta().name();
  for (const vsd::MetaProperty* p : x.meta().properties())
    if (p->has(vsd::Distributed) && !p->type().is_reference())
      std::cout << " " << p->name() << "=" << p->type().to_text(p->address(x));
  std::cout << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string_view> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::cout << usage;
    return args.empty() ? 2 : 0;
  }
  const std::string_view command = args[0];
  std::string file, topic = "vsd", config;
  long domain = -1;
  double seconds = -1;
  for (std::size_t i = 1; i < args.size(); ++i) {
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) return {};
      return std::string(args[++i]);
    };
    if (args[i] == "--domain") {
      domain = std::strtol(value().c_str(), nullptr, 10);
    } else if (args[i] == "--topic") {
      topic = value();
    } else if (args[i] == "--config") {
      config = value();
    } else if (args[i] == "--for") {
      seconds = std::strtod(value().c_str(), nullptr);
    } else if (command == "serve" && file.empty() && !args[i].starts_with("--")) {
      file = std::string(args[i]);
    } else {
      std::cerr << "vsd-dist: unknown argument '" << args[i] << "'\n" << usage;
      return 2;
    }
  }
  if ((command != "serve" && command != "watch") || domain < 0 || (command == "serve" && file.empty())) {
    std::cerr << usage;
    return 2;
  }
  std::signal(SIGINT, [](int) { interrupted = 1; });
  std::signal(SIGTERM, [](int) { interrupted = 1; });
  try {
    // A site of its own (ids of instances it creates must not clash with other processes').
    vsd::Environment env(static_cast<std::uint16_t>(1000 + ::getpid() % 30000));
    vsd::SimState& state = env.main_state();
    if (command == "serve") {
      const auto report = vsd::io::load(state, file);
      for (const auto& w : report.warnings) std::cerr << "vsd-dist: warning: " << w << "\n";
    }
    vsd::dist::ParticipantOptions o;
    o.name = std::string("vsd-dist ") + std::string(command);
    o.domain = static_cast<std::uint32_t>(domain);
    o.topic = topic;
    o.config = config;
    o.seed = command == "serve";
    o.log = [](std::string_view l) { std::cout << "[dist] " << l << "\n"; };
    vsd::dist::Participant p(state, o);
    if (command == "serve") {
      std::cout << "serving " << state.size() << " instances of " << file << " in domain " << domain << "\n";
    } else {
      if (!p.wait_synced(std::chrono::seconds(10))) {
        std::cerr << "vsd-dist: nobody answered in domain " << domain << " (topic '" << topic << "')\n";
        return 1;
      }
      for (const vsd::SimStateInstance* x : state.instances()) print_instance(*x);
    }
    std::cout.flush();
    auto changes =
        state.on_property_changed().connect([](vsd::SimStateInstance& x, const vsd::MetaProperty& prop) {
          std::cout << "changed #" << x.id() << " " << x.meta().name() << "." << prop.name() << " = "
                    << prop.type().to_text(prop.address(x)) << "\n";
        });
    auto created = state.on_created().connect([](vsd::SimStateInstance& x) {
      std::cout << "created ";
      print_instance(x);
    });
    auto deleted = state.on_deleted().connect([](vsd::SimStateInstance& x) {
      std::cout << "deleted #" << x.id() << " " << x.meta().name() << "\n";
    });
    const auto end =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<long>(seconds * 1000));
    while (interrupted == 0 && (seconds < 0 || std::chrono::steady_clock::now() < end)) {
      p.poll_until([] { return interrupted != 0; }, std::chrono::milliseconds(100));
      std::cout.flush();
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "vsd-dist: " << e.what() << "\n";
    return 1;
  }
}
