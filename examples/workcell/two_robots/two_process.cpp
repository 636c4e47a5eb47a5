// The two-robot cell as a controller and a ui process over vsd::dist (two_process.hpp says what it is).
#include "two_process.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ostream>
#include <thread>

#include "vsd/dist/module.hpp"
#include "vsd/io.hpp"
#include "vsd/soml.hpp"

extern char** environ;

namespace vsd_workcell {

namespace {

using namespace std::chrono_literals;

vsd::dist::ParticipantOptions participant(const char* name, std::uint32_t domain, bool seed, std::ostream& out) {
  vsd::dist::ParticipantOptions p;
  p.name = name;
  p.domain = domain;
  p.seed = seed;
  const char* uri = std::getenv("CYCLONEDDS_URI");
  p.config = uri != nullptr && *uri != '\0' ? uri : std::string("file://") + VSD_DIST_LOOPBACK_CONFIG;
  p.log = [name, &out](std::string_view l) { out << name << ": [dist] " << l << '\n'; };
  return p;
}

template <class T>
T& node(vsd::SimState& s, const char* name) {
  auto* n = s.database().find_child(name);
  T* t = n != nullptr ? n->as<T>() : nullptr;
  if (t == nullptr) throw vsd::Error(std::string("the cell has no node '") + name + "'");
  return *t;
}

// The ui as a child process; killed when the controller gives up before it exits.
struct Child {
  pid_t pid = -1;
  ~Child() {
    if (pid > 0) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
  }
  int wait(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (pid > 0 && std::chrono::steady_clock::now() < end) {
      int status = 0;
      if (::waitpid(pid, &status, WNOHANG) == pid) {
        pid = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(5ms);
    }
    return -1;
  }
};

}  // namespace

std::string digest(const std::vector<std::uint8_t>& bytes) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (std::uint8_t b : bytes) h = (h ^ b) * 0x100000001b3ull;
  char s[64];
  std::snprintf(s, sizeof s, "%zu bytes, fnv1a %016llx", bytes.size(), static_cast<unsigned long long>(h));
  return s;
}

void take_process_options(std::vector<std::string>& args, ProcessOptions& p) {
  std::vector<std::string> rest;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw vsd::Error(a + ": needs a value");
      return args[++i];
    };
    if (a == "--processes") {
      const std::string& v = value();
      if (v != "1" && v != "2") throw vsd::Error("--processes: '" + v + "' is not 1 or 2");
      p.processes = v == "1" ? 1 : 2;
    } else if (a == "--role") {
      const std::string& v = value();
      if (v != "controller" && v != "ui") throw vsd::Error("--role: '" + v + "' is not controller or ui");
      p.role = v;
    } else if (a == "--domain") {
      const std::string& v = value();
      if (v.empty() || v.size() > 3 || v.find_first_not_of("0123456789") != std::string::npos ||
          std::stoi(v) > 230)
        throw vsd::Error("--domain: '" + v + "' is not a whole number in [0, 230]");
      p.domain = static_cast<std::uint32_t>(std::stoi(v));
      p.has_domain = true;
    } else if (a == "--no-commands") {
      p.commands = false;
    } else {
      rest.push_back(a);
    }
  }
  if (p.processes == 2 && !p.role.empty()) throw vsd::Error("--processes 2 and --role exclude each other");
  if (!p.role.empty() && !p.has_domain) throw vsd::Error("--role " + p.role + " needs --domain N");
  if (p.processes == 1 && p.role.empty() && p.has_domain)
    throw vsd::Error("--domain is for --processes 2 or --role");
  args = std::move(rest);
}

TwoProcessReport run_controller(const CellOptions& options, std::uint32_t domain, const std::string& ui_program,
                                bool ui_commands, std::ostream& out, const std::vector<std::string>& ui_args) {
  TwoProcessReport result;
  Child child;
  if (!ui_program.empty()) {
    std::vector<std::string> args{ui_program, "--role", "ui", "--domain", std::to_string(domain),
                                  "--urdf", options.urdf, "--meta", options.meta_script,
                                  "--robots", options.robot_script};
    if (!ui_commands) args.emplace_back("--no-commands");
    args.insert(args.end(), ui_args.begin(), ui_args.end());
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    if (::posix_spawn(&child.pid, ui_program.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
      child.pid = -1;
      throw vsd::Error("cannot start the ui process " + ui_program);
    }
  }
  CellOptions o = options;
  vsd::dist::Participant* p = nullptr;
  o.on_built = [&, built = options.on_built](vsd::Environment& env) {
    vsd::SimState& s = env.main_state();
    p = &env.use<vsd::dist::Module>().join(s, participant("controller", domain, true, out));
    p->claim(node<vsd::Node>(s, "session"));
    auto& op = node<vsd::Node>(s, "operator");
    // The cell starts when the ui has claimed the operator node and said it is ready.
    if (!p->poll_until([&] { return p->owner(op.id()) != 0 && op.meta().property("ready").get<bool>(op); }, 30s))
      throw vsd::Error("the ui did not join domain " + std::to_string(domain) + " within 30 s");
    out << "controller: the ui joined domain " << domain << '\n';
    if (built) built(env);
  };
  o.on_finished = [&, finished = options.on_finished](vsd::Environment& env, bool completed) {
    if (finished) finished(env, completed);
    if (p == nullptr) return;
    vsd::SimState& s = env.main_state();
    auto& session = node<vsd::Node>(s, "session");
    auto& op = node<vsd::Node>(s, "operator");
    const vsd::MetaProperty& sent = op.meta().property("replica_digest");
    session.meta().property("finished").set(session, true);
    // Every write of the ui before its digest has been applied here when the digest arrives (one
    // sender's bundles apply in order), and the digest itself is not saved: both saves are final.
    if (!p->poll_until([&] { return !sent.get<std::string>(op).empty(); }, 30s)) {
      out << "controller: the ui sent no digest of its replica within 30 s\n";
      return;
    }
    result.replica_digest = sent.get<std::string>(op);
    result.controller_digest = digest(vsd::io::save_bytes(s));
    result.replica_equal = result.replica_digest == result.controller_digest;
    session.meta().property("verdict").set(session, std::string(result.replica_equal ? "equal" : "DIFFERENT"));
    p->poll_until([] { return false; }, 300ms);  // the verdict reaches the ui
  };
  result.cell = run_cell(o);
  if (!ui_program.empty()) {
    result.ui_exit = child.wait(30s);
    if (result.ui_exit < 0) out << "controller: the ui process did not exit within 30 s\n";
  }
  out << "controller state: " << result.controller_digest << '\n'
      << "ui replica:       " << result.replica_digest << '\n'
      << "replica: " << (result.replica_equal ? "byte-equal to the controller's state" : "NOT EQUAL") << '\n';
  return result;
}

int run_ui(const CellOptions& o, std::uint32_t domain, bool commands, std::ostream& out, const UiHooks& hooks) {
  vsd::Environment env(2);  // a site of its own
  add_cell_modules(env);
  define_net_classes(env, o);
  auto& dist = env.use<vsd::dist::Module>();
  vsd::SimState& s = env.create_state("replica");  // served `derived`: nothing is simulated here
  auto& p = dist.join(s, participant("ui", domain, false, out));
  if (!p.wait_synced(30s)) throw vsd::Error("no controller answered in domain " + std::to_string(domain));
  auto& op = node<vsd::Node>(s, "operator");
  auto& session = node<vsd::Node>(s, "session");
  vsd::Node* conveyor_node = node<vsd::Node>(s, "cell").find_child("conveyor");
  if (conveyor_node == nullptr) throw vsd::Error("the cell has no node 'cell/conveyor'");
  vsd::Node& conveyor = *conveyor_node;
  auto set = [](vsd::Node& n, const char* prop, const auto& v) { n.meta().property(prop).set(n, v); };
  p.claim(op);  // the operator's commands are the ui's: nobody else may write them
  out << "ui: joined domain " << domain << ", owns the operator's commands\n";
  // Whatever the hook attaches lets go before the Environment goes, also when the run throws.
  struct Finish {
    const UiHooks& hooks;
    vsd::Environment& env;
    bool equal = false;
    ~Finish() {
      if (hooks.finished) hooks.finished(env, equal);
    }
  } finish{hooks, env};
  if (hooks.joined) hooks.joined(env, s);
  if (commands) {
    set(op, "inject_kind", std::int64_t{2});
    set(op, "injections", std::int64_t{1});
    out << "ui: inject a part of kind 2\n";
  }
  set(op, "ready", true);
  bool paused = false, resumed = false, moved = false;
  std::int64_t replies = 0;
  const auto end = std::chrono::steady_clock::now() + 30min;
  while (!session.meta().property("finished").get<bool>(session)) {
    if (std::chrono::steady_clock::now() > end) throw vsd::Error("the controller did not finish within 30 min");
    env.step();  // publishes the commands, applies the controller's changes
    if (session.meta().property("replies").get<std::int64_t>(session) != replies) {
      replies = session.meta().property("replies").get<std::int64_t>(session);
      out << "ui: the controller says '" << session.meta().property("reply").get<std::string>(session) << "'\n";
    }
    const double t = conveyor.meta().property("time").get<double>(conveyor);
    if (commands && !paused && t >= 2.0) {
      set(op, "pause_b", true);
      out << "ui: pause robot_b (seen t=" << t << " s)\n";
      paused = true;
    } else if (commands && paused && !resumed && t >= 6.0) {
      set(op, "pause_b", false);
      out << "ui: resume robot_b (seen t=" << t << " s)\n";
      resumed = true;
    }
    if (auto part = conveyor.meta().property("at_sensor").get<vsd::SharedRef<vsd::Node>>(conveyor); commands && !moved && part) {
      set(op, "move_part", part);
      set(op, "move_dx", 0.01);
      set(op, "moves", std::int64_t{1});
      out << "ui: move " << part->name() << " by 1 cm\n";
      moved = true;
    }
    std::this_thread::sleep_for(1ms);
  }
  const std::string d = digest(vsd::io::save_bytes(s));
  out << "ui: the controller finished; replica " << d << '\n';
  set(op, "replica_digest", d);
  if (!p.poll_until([&] { return !session.meta().property("verdict").get<std::string>(session).empty(); }, 30s))
    throw vsd::Error("the controller did not compare the replica within 30 s");
  const std::string verdict = session.meta().property("verdict").get<std::string>(session);
  out << "ui: the controller finds the replica " << verdict << '\n';
  finish.equal = verdict == "equal";
  return finish.equal ? 0 : 1;
}

}  // namespace vsd_workcell
