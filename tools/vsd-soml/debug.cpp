// `vsd-soml debug`: the interactive terminal debugger over vsd::soml::Debugger. Commands come from stdin
// (one per line; echoed after the prompt when stdin is not a terminal, so a transcript reads like a
// session); everything it says goes to stdout, so ctest can compare a whole session with a golden file.
#include "debug.hpp"

#include <unistd.h>

#include <charconv>
#include <istream>
#include <ostream>
#include <sstream>
#include <string>
#include <utility>

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/node.hpp"
#include "vsd/soml.hpp"
#include "vsd_tool/arguments.hpp"
#include "vsd_tool/input.hpp"
#include "vsd_tool/models.hpp"
#include "vsd_tool/text.hpp"

namespace vsd::tool::vsd_soml {

namespace {

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
  Session(soml::Program& p, std::string file, std::uint64_t limit, std::istream& in, std::ostream& out)
      : in_(in), out_(out), program_(p), dbg_(p), file_(std::move(file)), limit_(limit), echo_(isatty(0) == 0) {
    dbg_.on_firing([this](const soml::Firing& f) {
      if (trace_) out_ << firing_text(f) << "\n";
    });
    dbg_.on_stop([this](soml::Debugger&, const soml::Stop& s) { return stopped(s); });
  }

  void add_break(std::string_view what) {
    const bool is_line = !what.empty() && (std::isdigit(static_cast<unsigned char>(what.back())) != 0) &&
                         (what.find(':') != std::string_view::npos ||
                          what.find_first_not_of("0123456789") == std::string_view::npos);
    if (is_line) {
      const int id = dbg_.break_at(what);
      out_ << "breakpoint " << id << " at " << file_ << ":" << dbg_.breakpoints().back().line << "\n";
    } else {
      const int id = dbg_.break_on_transition(what);
      out_ << "breakpoint " << id << " on transition " << what << "\n";
    }
  }
  void add_transition_break(std::string_view what) {
    const int id = dbg_.break_on_transition(what);
    out_ << "breakpoint " << id << " on transition " << what << "\n";
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
          out_ << "finish: no function is running (continue runs the net)\n";
        } else if (cmd == "bt" || cmd == "locals" || cmd == "frame") {
          out_ << cmd << ": no code is running (the program is between firings)\n";
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
    out_ << "(soml) " << std::flush;
    if (!std::getline(in_, line)) {
      out_ << (echo_ ? "end of input\n" : "\n");
      return false;
    }
    if (echo_) out_ << line << "\n";
    return true;
  }

  void run(std::uint64_t n, bool step_into) {
    if (n == 0) {
      out_ << "the firing limit (" << limit_ << ") is reached\n";
      return;
    }
    // Stepping ends when control comes back here: the next command starts afresh.
    if (step_into) dbg_.step_into_next(true);
    std::uint64_t fired = 0;
    try {
      fired = program_.step(n);
    } catch (const vsd::Error& e) {
      dbg_.step_into_next(false);
      out_ << e.what() << "\n";
      return;
    }
    dbg_.step_into_next(false);
    if (fired == 0) {
      out_ << "no transition is enabled: the net is quiet\n";
      return;
    }
    // step(n) ends early only when no transition is enabled.
    out_ << fired << (fired == 1 ? " firing" : " firings") << (fired < n ? ", quiet" : "") << "\n";
  }

  // Commands that work everywhere. False: quit.
  bool common(const std::string& cmd, const std::string& rest) {
    try {
      if (cmd == "b" || cmd == "break") {
        if (rest.empty())
          out_ << "break needs LINE, FILE:LINE or a transition name\n";
        else
          add_break(rest);
      } else if (cmd == "d" || cmd == "delete") {
        int id = 0;
        const auto r = std::from_chars(rest.data(), rest.data() + rest.size(), id);
        if (rest.empty() || r.ec != std::errc() || r.ptr != rest.data() + rest.size())
          out_ << "delete needs a breakpoint number\n";
        else if (dbg_.remove(id))
          out_ << "deleted breakpoint " << id << "\n";
        else
          out_ << "no breakpoint " << id << "\n";
      } else if (cmd == "breaks") {
        if (dbg_.breakpoints().empty()) out_ << "no breakpoints\n";
        for (const soml::Breakpoint& b : dbg_.breakpoints())
          out_ << "  " << b.id << ": "
                    << (b.line != 0 ? file_ + ":" + std::to_string(b.line) : "transition " + b.transition)
                    << ", " << b.hits << (b.hits == 1 ? " hit" : " hits") << "\n";
      } else if (cmd == "p" || cmd == "print") {
        if (rest.empty())
          out_ << "print needs a name\n";
        else
          out_ << dbg_.print(rest, frame_) << "\n";
      } else if (cmd == "m" || cmd == "marking") {
        out_ << dbg_.marking();
      } else if (cmd == "trace") {
        if (rest == "on" || rest == "off") {
          trace_ = rest == "on";
          out_ << "trace " << rest << "\n";
        } else {
          out_ << "trace takes on or off\n";
        }
      } else if (cmd == "h" || cmd == "help") {
        out_ << kHelp;
      } else if (cmd == "q" || cmd == "quit") {
        throw Quit{};
      } else {
        out_ << "unknown command '" << cmd << "' (help lists the commands)\n";
      }
    } catch (const vsd::Error& e) {
      std::string m = e.what();
      if (m.rfind("SOML++ debugger: ", 0) == 0) m = m.substr(17);
      out_ << m << "\n";
    }
    return true;
  }

  soml::Resume stopped(const soml::Stop& s) {
    frame_ = 0;
    if (s.reason == soml::StopReason::Transition) {
      out_ << "stopped before " << soml::net_node_label(s.transition) << " fires";
      if (s.mark != 0) out_ << ", mark " << label(s.mark);
      out_ << " (breakpoint " << s.breakpoint << ")\n";
    } else {
      out_ << "stopped at " << file_ << ":" << s.line << " in " << s.function;
      if (s.breakpoint != 0) out_ << " (breakpoint " << s.breakpoint << ")";
      out_ << "\n" << s.line << "\t" << source_line(s.line) << "\n";
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
        if (stack.empty()) out_ << "no code is running (a transition is about to fire)\n";
        for (std::size_t i = 0; i < stack.size(); ++i) {
          out_ << (i == frame_ ? "* " : "  ") << "#" << i << " " << stack[i].function << " ("
                    << stack[i].file << ":" << stack[i].line << ")";
          if (stack[i].mark != 0) out_ << " mark " << label(stack[i].mark);
          out_ << "\n";
        }
      } else if (cmd == "frame") {
        std::size_t k = 0;
        const auto r = std::from_chars(rest.data(), rest.data() + rest.size(), k);
        const std::size_t depth = dbg_.call_stack().size();
        if (rest.empty() || r.ec != std::errc() || r.ptr != rest.data() + rest.size() || k >= depth) {
          out_ << "frame needs a number from 0 to " << (depth == 0 ? 0 : depth - 1) << "\n";
        } else {
          frame_ = k;
          const auto f = dbg_.call_stack()[k];
          out_ << "#" << k << " " << f.function << " (" << f.file << ":" << f.line << ")\n";
        }
      } else if (cmd == "locals") {
        if (dbg_.call_stack().empty()) {
          out_ << "no code is running (a transition is about to fire)\n";
          continue;
        }
        const auto vars = dbg_.locals(frame_);
        if (vars.empty()) out_ << "no locals\n";
        for (const auto& v : vars) out_ << "  " << v.type << " " << v.name << " = " << v.value << "\n";
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
  std::istream& in_;
  std::ostream& out_;
  soml::Program& program_;
  soml::Debugger dbg_;
  std::string file_;
  std::uint64_t limit_;
  bool echo_;
  bool trace_ = true;
  std::size_t frame_ = 0;
};

}  // namespace

int debug_command(std::span<const std::string_view> args, std::istream& in, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {repeated("--break"), repeated("--break-transition"), with_value("--seed"),
                           with_value("--steps")});
  a.expect_positional(1, 1, "one FILE");
  const std::string_view path = a.positional()[0];
  if (path == "-") throw UsageError("debug reads its commands from standard input: give the script as a file");
  soml::RunOptions options;
  options.seed = a.unsigned_integer("--seed", options.seed, UINT64_MAX);
  const std::uint64_t limit = a.unsigned_integer("--steps", 1'000'000, UINT64_MAX);
  const std::string file(path);
  const std::string text = read_text_input(path, soml::max_source_bytes);
  Workspace ws;
  auto& module = ws.env().use<soml::Module>();
  soml::Program* p = nullptr;
  try {
    p = &module.load(ws.state(), file, text, options);
  } catch (const vsd::Error& e) {
    const std::string m = printable_lines(e.what());
    err << m << (m.ends_with("\n") ? "" : "\n");
    return 1;
  }
  Session session(*p, file, limit, in, out);
  session.text_ = text;
  out << "vsd-soml debug: " << printable(file) << " loaded, " << p->places().size()
      << " places; help lists the commands\n";
  try {
    for (const std::string_view b : a.values("--break")) session.add_break(b);
    for (const std::string_view b : a.values("--break-transition")) session.add_transition_break(b);
  } catch (const vsd::Error& e) {
    std::string m = e.what();
    if (m.rfind("SOML++ debugger: ", 0) == 0) m = m.substr(17);
    err << "vsd-soml: " << printable(m) << "\n";
    return 2;
  }
  return session.loop();
}

}  // namespace vsd::tool::vsd_soml
