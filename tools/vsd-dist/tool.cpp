// vsd-dist (see tool.hpp).
#include "tool.hpp"

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <ostream>
#include <string>

#include "vsd/core.hpp"
#include "vsd/dist.hpp"
#include "vsd_tool/arguments.hpp"
#include "vsd_tool/input.hpp"
#include "vsd_tool/models.hpp"
#include "vsd_tool/runner.hpp"
#include "vsd_tool/text.hpp"

namespace vsd::tool::vsd_dist {

namespace {

constexpr std::string_view usage =
    "Usage: vsd-dist serve FILE --domain N [--topic T] [--config URI] [--for SECONDS]\n"
    "       vsd-dist watch --domain N [--topic T] [--config URI] [--for SECONDS]\n"
    "  serve     load FILE (vsd-text or VSDS; \"-\": standard input) and be the seed of the shared model in\n"
    "            DDS domain N\n"
    "  watch     join domain N, print the model when synchronised, then every change\n"
    "  --domain  the DDS domain id, 0 to 230 (required)\n"
    "  --topic   the topic (default: vsd)\n"
    "  --config  Cyclone DDS configuration (XML or file://...); default: CYCLONEDDS_URI\n"
    "  --for     stop after this many seconds, 0 to 31536000 (default: until interrupted)\n"
    "\n"
    "Exit status: 0 done, 1 a bad file or nobody answered, 2 a usage error.\n";

const Tool tool{"vsd-dist", usage, true};

volatile std::sig_atomic_t interrupted = 0;

void print_instance(std::ostream& out, const SimStateInstance& x) {
  out << "#" << x.id() << " " << printable(x.meta().name());
  for (const MetaProperty* p : x.meta().properties())
    if (p->has(Distributed) && !p->type().is_reference())
      out << " " << printable(p->name()) << "=" << printable(p->type().to_text(p->address(x)));
  out << "\n";
}

int body(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  if (args.empty()) throw UsageError("no command (serve or watch)");
  const std::string_view command = args[0];
  if (command != "serve" && command != "watch") throw UsageError("unknown command '" + printable(command) + "'");
  const Arguments a(args.subspan(1),
                    {with_value("--domain"), with_value("--topic"), with_value("--config"), with_value("--for")});
  if (command == "serve")
    a.expect_positional(1, 1, "one FILE");
  else
    a.expect_positional(0, 0, "no FILE");
  if (!a.has("--domain")) throw UsageError("--domain is required");
  const auto domain = static_cast<std::uint32_t>(a.integer("--domain", 0, 0, 230));
  const double seconds = a.real("--for", -1, 0, 31'536'000);
  const std::string topic(a.value("--topic").value_or("vsd"));
  const std::string config(a.value("--config").value_or(""));
  if (topic.empty()) throw UsageError("--topic needs a name");

  interrupted = 0;
  std::signal(SIGINT, [](int) { interrupted = 1; });
  std::signal(SIGTERM, [](int) { interrupted = 1; });
  // A site of its own (ids of instances it creates must not clash with other processes').
  Registry registry;
  register_classes(registry);
  Environment env(static_cast<std::uint16_t>(1000 + ::getpid() % 30000), registry);
  SimState& state = env.main_state();
  std::string served;
  if (command == "serve") {
    served = input_name(a.positional()[0]);
    print_warnings(load_vsd(state, a.positional()[0]).warnings, err);
  }
  dist::ParticipantOptions o;
  o.name = "vsd-dist " + std::string(command);
  o.domain = domain;
  o.topic = topic;
  o.config = config;
  o.seed = command == "serve";
  o.log = [&out](std::string_view l) { out << "[dist] " << printable(l) << "\n"; };
  dist::Participant p(state, o);
  if (command == "serve") {
    out << "serving " << state.size() << " instances of " << served << " in domain " << domain << "\n";
  } else {
    if (!p.wait_synced(std::chrono::seconds(10)))
      throw Error("nobody answered in domain " + std::to_string(domain) + " (topic '" + printable(topic) + "')");
    for (const SimStateInstance* x : state.instances()) print_instance(out, *x);
  }
  out.flush();
  auto changes = state.on_property_changed().connect([&out](SimStateInstance& x, const MetaProperty& prop) {
    out << "changed #" << x.id() << " " << printable(x.meta().name()) << "." << printable(prop.name()) << " = "
        << printable(prop.type().to_text(prop.address(x))) << "\n";
  });
  auto created = state.on_created().connect([&out](SimStateInstance& x) {
    out << "created ";
    print_instance(out, x);
  });
  auto deleted = state.on_deleted().connect([&out](SimStateInstance& x) {
    out << "deleted #" << x.id() << " " << printable(x.meta().name()) << "\n";
  });
  const auto end = std::chrono::steady_clock::now() +
                   std::chrono::milliseconds(static_cast<std::int64_t>(std::max(seconds, 0.0) * 1000));
  while (interrupted == 0 && (seconds < 0 || std::chrono::steady_clock::now() < end)) {
    p.poll_until([] { return interrupted != 0; }, std::chrono::milliseconds(100));
    out.flush();
  }
  return exit_ok;
}

}  // namespace

int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  return tool::run(tool, args, out, err, body);
}

}  // namespace vsd::tool::vsd_dist
