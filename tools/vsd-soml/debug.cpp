// `vsd-soml debug`: the interactive terminal debugger over vsd::soml::Debugger. Commands come from stdin
// (one per line; echoed after the prompt when stdin is not a terminal, so a transcript reads like a
// session); everything it says goes to stdout, so ctest can compare a whole session with a golden file.
#include "debug.hpp"

#include <unistd.h>

#include <charconv>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/node.hpp"
#include "vsd/soml.hpp"

namespace {

namespace soml = vsd::soml;

constexpr const char* kHelp =
    "Commands (a word may be shortened to its first letter where shown):\n"
    "  break LINE | FILE:LINE   stop when that line runs (in a function, condition or action)    (b)\n"
    "  break NAME               stop before transition NAME (owner.name, or a bare name) fires\n"
    "  delete ID                remove breakpoint ID                                             (d)\n"
    "  breaks                   list the breakpoints\n"
    "  continue                 run until a breakpoint, or until no transition is enabled        (c)\n"
    "  step                     run to the next source line, into called functions              (s)\n"
    "  next                     run to the next line of this function; between firings: fire one (n)\n"
    "  finish                   run until the current function returned\n"
    "  bt                       the SOML++ call stack\n"
    "  frame N                  select frame N of the call stack for locals and print\n"
    "  locals                   parameters and local variables of the selected frame\n"
    "  print PATH               a local, this, mark, a property or an object, with .member steps (p)\n"
    "  marking                  the tokens in every place                                        (m)\n"
    "  trace on|off             print every firing (on at the start)\n"
    "  help                     this text                                                        (h)\n"
    "  quit                     leave the debugger                                               (q)\n";

struct Quit {};

std::string firing_text(const soml::Firing& f) {
  std::string s = "step " + std::to_string(f.step) + ": " + soml::net_node_label(f.transition);
  if (f.mark != 0) {
    const vsd::SimStateInstance* m = f.transition->state().find(f.mark);
    const auto* mn = m != nullptr ? m->as<vsd::Node>() : nullptr;
    s += " mark " + (mn != nullptr && !mn->name().empty() ? mn->name() : "#" + std::to_string(f.mark)) + " " +
         soml::net_node_label(f.from) + " -> " + soml::net_node_label(f.to);
  }
  std::string moves;
  for (const soml::TokenMove& m : f.taken)
    moves += (moves.empty() ? "" : ", ") + soml::net_node_label(m.place) + " -" + std::to_string(m.count);
  for (const soml::TokenMove& m : f.given)
    moves += (moves.empty() ? "" : ", ") + soml::net_node_label(m.place) + " +" + std::to_string(m.count);
  if (!moves.empty()) s += " (" + moves + ")";
  return s;
}

class Session {
 public:
  Session(soml::Program& p, std::string file, std::uint64_t limit)
      : program_(p), dbg_(p), file_(std::move(file)), limit_(limit), echo_(isatty(0) == 0) {
    dbg_.on_firing([this](const soml::Firing& f) {
      if (trace_) std::cout << firing_text(f) << "\n";
    });
    dbg_.on_stop([this](soml::Debugger&, const soml::Stop& s) { return stopped(s); });
  }

  void add_break(std::string_view what) {
    const bool is_line = !what.empty() && (std::isdigit(static_cast<unsigned char>(what.back())) != 0) &&
                         (what.find(':') != std::string_view::npos ||
                          what.find_first_not_of("0123456789") == std::string_view::npos);
    if (is_line) {
      const int id = dbg_.break_at(what);
      std::cout << "breakpoint " << id << " at " << file_ << ":" << dbg_.breakpoints().back().line << "\n";
    } else {
      const int id = dbg_.break_on_transition(what);
      std::cout << "breakpoint " << id << " on transition " << what << "\n";
    }
  }
  void add_transition_break(std::string_view what) {
    const int id = dbg_.break_on_transition(what);
    std::cout << "breakpoint " << id << " on transition " << what << "\n";
  }

  // The top level: between firings.
  int loop() {
    try {
      for (std::string line; read(line);) {
        auto [cmd, rest] = split_command(line);
        if (cmd.empty()) continue;
        if (cmd == "c" || cmd == "continue") {
          run(limit_ - std::min(limit_, program_.firings()), false);
        } else if (cmd == "s" || cmd == "step") {
          run(1, true);
        } else if (cmd == "n" || cmd == "next") {
          run(1, false);
        } else if (cmd == "finish") {
          std::cout << "finish: no function is running (continue runs the net)\n";
        } else if (cmd == "bt" || cmd == "locals" || cmd == "frame") {
          std::cout << cmd << ": no code is running (the program is between firings)\n";
        } else if (!common(cmd, rest)) {
          return 0;
        }
      }
    } catch (const Quit&) {
      return 0;
    }
    return 0;
  }

 private:
  // A command line as its first word and the rest, trimmed (both prompts read commands this way).
  static std::pair<std::string, std::string> split_command(const std::string& line) {
    std::istringstream in(line);
    std::string cmd, rest;
    in >> cmd;
    std::getline(in, rest);
    return {cmd, std::string(trim(rest))};
  }
  static std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())) != 0) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())) != 0) s.remove_suffix(1);
    return s;
  }

  bool read(std::string& line) {
    std::cout << "(soml) " << std::flush;
    if (!std::getline(std::cin, line)) {
      std::cout << (echo_ ? "end of input\n" : "\n");
      return false;
    }
    if (echo_) std::cout << line << "\n";
    return true;
  }

  void run(std::uint64_t n, bool step_into) {
    if (n == 0) {
      std::cout << "the firing limit (" << limit_ << ") is reached\n";
      return;
    }
    // Stepping ends when control comes back here: the next command starts afresh.
    if (step_into) dbg_.step_into_next(true);
    std::uint64_t fired = 0;
    try {
      fired = program_.step(n);
    } catch (const vsd::Error& e) {
      dbg_.step_into_next(false);
      std::cout << e.what() << "\n";
      return;
    }
    dbg_.step_into_next(false);
    if (fired == 0) {
      std::cout << "no transition is enabled: the net is quiet\n";
      return;
    }
    // step(n) ends early only when no transition is enabled.
    std::cout << fired << (fired == 1 ? " firing" : " firings") << (fired < n ? ", quiet" : "") << "\n";
  }

  // Commands that work everywhere. False: quit.
  bool common(const std::string& cmd, const std::string& rest) {
    try {
      if (cmd == "b" || cmd == "break") {
        if (rest.empty())
          std::cout << "break needs LINE, FILE:LINE or a transition name\n";
        else
          add_break(rest);
      } else if (cmd == "d" || cmd == "delete") {
        int id = 0;
        const auto r = std::from_chars(rest.data(), rest.data() + rest.size(), id);
        if (rest.empty() || r.ec != std::errc() || r.ptr != rest.data() + rest.size())
          std::cout << "delete needs a breakpoint number\n";
        else if (dbg_.remove(id))
          std::cout << "deleted breakpoint " << id << "\n";
        else
          std::cout << "no breakpoint " << id << "\n";
      } else if (cmd == "breaks") {
        if (dbg_.breakpoints().empty()) std::cout << "no breakpoints\n";
        for (const soml::Breakpoint& b : dbg_.breakpoints())
          std::cout << "  " << b.id << ": "
                    << (b.line != 0 ? file_ + ":" + std::to_string(b.line) : "transition " + b.transition)
                    << ", " << b.hits << (b.hits == 1 ? " hit" : " hits") << "\n";
      } else if (cmd == "p" || cmd == "print") {
        if (rest.empty())
          std::cout << "print needs a name\n";
        else
          std::cout << dbg_.print(rest, frame_) << "\n";
      } else if (cmd == "m" || cmd == "marking") {
        std::cout << dbg_.marking();
      } else if (cmd == "trace") {
        if (rest == "on" || rest == "off") {
          trace_ = rest == "on";
          std::cout << "trace " << rest << "\n";
        } else {
          std::cout << "trace takes on or off\n";
        }
      } else if (cmd == "h" || cmd == "help") {
        std::cout << kHelp;
      } else if (cmd == "q" || cmd == "quit") {
        throw Quit{};
      } else {
        std::cout << "unknown command '" << cmd << "' (help lists the commands)\n";
      }
    } catch (const vsd::Error& e) {
      std::string m = e.what();
      if (m.rfind("SOML++ debugger: ", 0) == 0) m = m.substr(17);
      std::cout << m << "\n";
    }
    return true;
  }

  soml::Resume stopped(const soml::Stop& s) {
    frame_ = 0;
    if (s.reason == soml::StopReason::Transition) {
      std::cout << "stopped before " << soml::net_node_label(s.transition) << " fires";
      if (s.mark != 0) std::cout << ", mark " << label(s.mark);
      std::cout << " (breakpoint " << s.breakpoint << ")\n";
    } else {
      std::cout << "stopped at " << file_ << ":" << s.line << " in " << s.function;
      if (s.breakpoint != 0) std::cout << " (breakpoint " << s.breakpoint << ")";
      std::cout << "\n" << s.line << "\t" << source_line(s.line) << "\n";
    }
    for (std::string line; read(line);) {
      auto [cmd, rest] = split_command(line);
      if (cmd.empty()) continue;
      if (cmd == "c" || cmd == "continue") return soml::Resume::Continue;
      if (cmd == "s" || cmd == "step") return soml::Resume::Step;
      if (cmd == "n" || cmd == "next") return soml::Resume::Next;
      if (cmd == "finish") return soml::Resume::Finish;
      if (cmd == "bt") {
        const auto stack = dbg_.call_stack();
        if (stack.empty()) std::cout << "no code is running (a transition is about to fire)\n";
        for (std::size_t i = 0; i < stack.size(); ++i) {
          std::cout << (i == frame_ ? "* " : "  ") << "#" << i << " " << stack[i].function << " ("
                    << stack[i].file << ":" << stack[i].line << ")";
          if (stack[i].mark != 0) std::cout << " mark " << label(stack[i].mark);
          std::cout << "\n";
        }
      } else if (cmd == "frame") {
        std::size_t k = 0;
        const auto r = std::from_chars(rest.data(), rest.data() + rest.size(), k);
        const std::size_t depth = dbg_.call_stack().size();
        if (rest.empty() || r.ec != std::errc() || r.ptr != rest.data() + rest.size() || k >= depth) {
          std::cout << "frame needs a number from 0 to " << (depth == 0 ? 0 : depth - 1) << "\n";
        } else {
          frame_ = k;
          const auto f = dbg_.call_stack()[k];
          std::cout << "#" << k << " " << f.function << " (" << f.file << ":" << f.line << ")\n";
        }
      } else if (cmd == "locals") {
        if (dbg_.call_stack().empty()) {
          std::cout << "no code is running (a transition is about to fire)\n";
          continue;
        }
        const auto vars = dbg_.locals(frame_);
        if (vars.empty()) std::cout << "no locals\n";
        for (const auto& v : vars) std::cout << "  " << v.type << " " << v.name << " = " << v.value << "\n";
      } else if (!common(cmd, rest)) {
        throw Quit{};
      }
    }
    throw Quit{};  // end of input while stopped
  }

  std::string label(vsd::Id id) const {
    const vsd::SimStateInstance* o = program_.root().state().find(id);
    const auto* n = o != nullptr ? o->as<vsd::Node>() : nullptr;
    return n != nullptr && !n->name().empty() ? n->name() : "#" + std::to_string(id);
  }

  std::string source_line(std::uint32_t line) const {
    std::istringstream in(text_);
    std::string l;
    for (std::uint32_t i = 0; i < line && std::getline(in, l); ++i) {
    }
    return l;
  }

 public:
  std::string text_;

 private:
  soml::Program& program_;
  soml::Debugger dbg_;
  std::string file_;
  std::uint64_t limit_;
  bool echo_;
  bool trace_ = true;
  std::size_t frame_ = 0;
};

}  // namespace

int debug_command(const std::vector<std::string_view>& args) {
  std::string file;
  std::vector<std::string> breaks, tbreaks;
  std::uint64_t limit = 1'000'000;
  soml::RunOptions options;
  auto number = [](std::string_view v, const char* what) {
    std::uint64_t n = 0;
    const auto r = std::from_chars(v.data(), v.data() + v.size(), n);
    if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size())
      throw std::invalid_argument(std::string(what) + " needs a number, not '" + std::string(v) + "'");
    return n;
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    auto value = [&]() {
      if (i + 1 >= args.size()) throw std::invalid_argument(std::string(args[i]) + " needs a value");
      return args[++i];
    };
    if (args[i] == "--break") {
      breaks.emplace_back(value());
    } else if (args[i] == "--break-transition") {
      tbreaks.emplace_back(value());
    } else if (args[i] == "--seed") {
      options.seed = number(value(), "--seed");
    } else if (args[i] == "--steps") {
      limit = number(value(), "--steps");
    } else if (!args[i].empty() && args[i][0] == '-') {
      throw std::invalid_argument("unknown option '" + std::string(args[i]) + "'");
    } else if (file.empty()) {
      file = std::string(args[i]);
    } else {
      throw std::invalid_argument("debug takes one FILE");
    }
  }
  if (file.empty()) throw std::invalid_argument("debug needs a FILE");
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    std::cerr << "vsd-soml: cannot read '" << file << "'\n";
    return 1;
  }
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  vsd::Registry registry;
  vsd::Environment env(0, registry);
  auto& module = env.use<soml::Module>();
  soml::Program* p = nullptr;
  try {
    p = &module.load(env.main_state(), file, text, options);
  } catch (const vsd::Error& e) {
    std::cerr << e.what() << (std::string(e.what()).ends_with("\n") ? "" : "\n");
    return 1;
  }
  Session session(*p, file, limit);
  session.text_ = text;
  std::cout << "vsd-soml debug: " << file << " loaded, " << p->places().size()
            << " places; help lists the commands\n";
  try {
    for (const auto& b : breaks) session.add_break(b);
    for (const auto& b : tbreaks) session.add_transition_break(b);
  } catch (const vsd::Error& e) {
    std::string m = e.what();
    if (m.rfind("SOML++ debugger: ", 0) == 0) m = m.substr(17);
    std::cerr << "vsd-soml: " << m << "\n";
    return 2;
  }
  return session.loop();
}
