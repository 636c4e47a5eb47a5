// vsd-soml (see tool.hpp): runs SOML++ scripts, analyses the state spaces of PNML and SOML++ nets, and
// converts between the two.
#include "tool.hpp"

#include <filesystem>
#include <iostream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "debug.hpp"
#include "vsd/analysis.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/soml.hpp"
#include "vsd_tool/arguments.hpp"
#include "vsd_tool/input.hpp"
#include "vsd_tool/models.hpp"
#include "vsd_tool/runner.hpp"
#include "vsd_tool/text.hpp"

namespace vsd::tool::vsd_soml {

namespace {

namespace an = vsd::analysis;

constexpr std::string_view usage =
    "Usage: vsd-soml analyze FILE [--json] [--threads N] [--limit-mem SIZE] [--progress | --no-progress]\n"
    "       vsd-soml run FILE [--steps N] [--trace] [--seed S] [--native LIB]\n"
    "       vsd-soml debug FILE [--break FILE:LINE]... [--break-transition NAME]... [--seed S] [--steps N]\n"
    "       vsd-soml convert IN OUT\n"
    "       vsd-soml disasm FILE\n"
    "       vsd-soml compile FILE... -o DIR\n"
    "       vsd-soml --help\n"
    "\n"
    "run      Loads the SOML++ script FILE into a database and fires its transitions: N firings, or until\n"
    "         none is enabled (at most 1000000). print() writes to stdout; at the end the marking of\n"
    "         every place is printed. Errors in the script are printed with file:line:col. A PNML file\n"
    "         (.pnml) is imported as the SOML++ net `convert` writes for it.\n"
    "  --steps N         fire at most N transitions\n"
    "  --trace           print every firing: step, transition, the token it moved, from where to where\n"
    "  --seed S          the seed of the choice among enabled transitions (default 1)\n"
    "  --native LIB      run the functions the native library LIB holds for FILE natively (made by\n"
    "                    compile from the same FILE; another version of FILE is refused)\n"
    "\n"
    "debug    Loads FILE like run and reads debugger commands from stdin: break, delete, step, next,\n"
    "         finish, continue, bt, frame, locals, print, marking, trace, quit (`help` lists them).\n"
    "         Every firing is printed as with --trace.\n"
    "  --break LOC             stop when line LOC (FILE:LINE or LINE) runs; repeatable\n"
    "  --break-transition T    stop before transition T (owner.name or name) fires; repeatable\n"
    "  --steps N               fire at most N transitions in all (default 1000000)\n"
    "\n"
    "analyze  Explores the state space of the net in FILE and prints a summary: reachable markings\n"
    "         (states), firings (edges: one per reachable marking and transition enabled in it, as the\n"
    "         Model Checking Contest counts them), most tokens in one place and in one marking, whether a\n"
    "         dead marking is reachable with a shortest firing sequence to one, and boundedness (an\n"
    "         unbounded net is reported as such, not explored forever).\n"
    "         FILE is a PNML place/transition net (ISO/IEC 15909-2, .pnml; tool-specific blocks are\n"
    "         skipped with a note on stderr) or a SOML++ script (.soml) whose objects' places hold black\n"
    "         tokens (conditions, object tokens, communication arrows, substitution and invocation are\n"
    "         refused with their positions; actions that change no marking are ignored with a note).\n"
    "  --json            one JSON object on stdout: {\"states\", \"edges\", \"deadlock\", "
    "\"max_tokens_place\",\n"
    "                    \"max_tokens_marking\", \"status\", \"bounded\", \"dead_trace\", ...}\n"
    "  --threads N       worker threads (default 1; 0 = all hardware threads); results do not depend on N\n"
    "  --limit-mem SIZE  stop with a message when the exploration needs more, e.g. 512M, 8G\n"
    "                    (default: three quarters of the available memory)\n"
    "  --progress        always write a progress line on stderr (default: only when stderr is a terminal)\n"
    "  --no-progress     never write it\n"
    "\n"
    "convert  Converts the net in IN to OUT; the formats follow the extensions (.pnml or .xml: PNML,\n"
    "         anything else: SOML++). PNML ids that are not SOML++ identifiers are renamed (a note on\n"
    "         stderr; the original id stays in a comment). OUT is written atomically: a write that fails\n"
    "         leaves the old file whole; OUT \"-\" writes to stdout.\n"
    "\n"
    "disasm   Loads the SOML++ script FILE as run does (without firing) and prints its bytecode: per\n"
    "         function its name, FILE:LINE, parameters, registers and locals (slot, name, type, the\n"
    "         instructions where visible), then each instruction: index, opcode, operands (r register,\n"
    "         # immediate, k constant, s string, p property, f function, c class, m method, -> target) and\n"
    "         the line:column it computes, with what an operand names; then the constants and strings.\n"
    "         Errors in the script are printed with file:line:col.\n"
    "\n"
    "compile  Loads each SOML++ script FILE as disasm does and writes DIR/soml_native.cpp: C++ of the\n"
    "         functions that have a native translation (int and double arithmetic, comparisons, loops,\n"
    "         calls of such functions, print of numbers), one module per FILE. Build it as a shared\n"
    "         library (c++ -std=c++20 -O2 -fPIC -shared -I<vsd include dir>; CMake: vsd_add_soml_module)\n"
    "         and load it with `run --native` or Program::load_native. DIR must exist.\n"
    "\n"
    "FILE and IN may be \"-\" (standard input; a net in XML is taken as PNML) or a pipe, except for debug,\n"
    "which reads its commands there. vsd-soml knows vsd's own classes (Node, the scene, robotics and\n"
    "physics classes, ...); a script that uses the C++ classes of its program runs in that program (see\n"
    "examples/soml/supervisor.cpp).\n"
    "\n"
    "Exit status: 0 analysed (bounded or unbounded), 1 the file is bad or the memory limit was reached,\n"
    "2 usage error.\n";

const Tool tool{"vsd-soml", usage, true};

bool has_pnml_extension(std::string_view path) { return has_extension(path, ".pnml") || has_extension(path, ".xml"); }

std::string as_text(const std::vector<std::uint8_t>& bytes) { return {bytes.begin(), bytes.end()}; }

struct Net {
  an::PtNet net;
  std::vector<std::string> notes;
};

// A PNML or SOML++ file as a net; its notes go to @p err.
Net read_net(std::string_view path, std::ostream& err) {
  const std::vector<std::uint8_t> bytes = read_input(path);
  const std::string name = input_name(path);
  Net n;
  if (has_pnml_extension(path) || looks_like_xml(bytes)) {
    an::PnmlImport i = an::read_pnml(as_text(bytes), name);
    n = {std::move(i.net), std::move(i.notes)};
  } else {
    an::SomlNetImport i = an::read_soml_net(as_text(bytes), name);
    n = {std::move(i.net), std::move(i.notes)};
  }
  for (const auto& note : n.notes) err << "note: " << printable_lines(note) << "\n";
  return n;
}

int convert(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {});
  a.expect_positional(2, 2, "IN and OUT");
  const std::string_view target = a.positional()[1];
  const Net in = read_net(a.positional()[0], err);
  if (has_pnml_extension(target)) {
    write_output(target, an::write_pnml(in.net), out);
  } else {
    std::vector<std::string> renamed;
    const std::string text = an::write_soml(in.net, &renamed);
    for (const auto& r : renamed) err << "note: " << printable(r) << "\n";
    write_output(target, text, out);
  }
  return exit_ok;
}

std::string node_label(const vsd::Node* n) { return vsd::soml::net_node_label(n); }

// The classes a failed load's diagnostics call undefined ("undefined class 'Tank' (...)").
std::set<std::string> undefined_classes(std::string_view message) {
  std::set<std::string> names;
  constexpr std::string_view key = "undefined class '";
  for (std::size_t at = message.find(key); at != std::string_view::npos; at = message.find(key, at)) {
    at += key.size();
    const std::size_t end = message.find('\'', at);
    if (end == std::string_view::npos) break;
    names.insert(std::string(message.substr(at, end - at)));
  }
  return names;
}

int run_script(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {with_value("--steps"), with_value("--seed"), flag("--trace"), with_value("--native")});
  a.expect_positional(1, 1, "one FILE");
  const std::string_view path = a.positional()[0];
  const std::uint64_t steps = a.unsigned_integer("--steps", 1'000'000, UINT64_MAX);
  vsd::soml::RunOptions options;
  options.seed = a.unsigned_integer("--seed", options.seed, UINT64_MAX);
  const bool trace = a.has("--trace");
  const std::vector<std::uint8_t> bytes = read_input(path);
  const std::string file = path == "-" ? "<stdin>" : std::string(path);
  std::string text = as_text(bytes);
  if (has_pnml_extension(path) || looks_like_xml(bytes)) {  // a P/T net: run as the SOML++ net convert makes
    const an::PnmlImport imported = an::read_pnml(text, input_name(path));
    for (const auto& note : imported.notes) err << "note: " << printable_lines(note) << "\n";
    std::vector<std::string> renamed;
    text = an::write_soml(imported.net, &renamed);
    for (const auto& r : renamed) err << "note: " << printable(r) << "\n";
  }
  Workspace ws;
  auto& soml = ws.env().use<vsd::soml::Module>();
  vsd::soml::Program* p = nullptr;
  try {
    p = &soml.load(ws.state(), file, text, options);
  } catch (const vsd::Error& e) {
    const std::string m = printable_lines(e.what());
    err << m << (m.ends_with("\n") ? "" : "\n");
    const std::set<std::string> host = undefined_classes(e.what());
    if (!host.empty()) {
      std::string names;
      for (const std::string& n : host) names += (names.empty() ? "" : ", ") + printable(n);
      err << "note: vsd-soml knows vsd's own classes, not " << names
          << ": a script that uses the C++ classes of its program runs in that program, which registers "
             "them and loads the script (see examples/soml/supervisor.cpp and \"Binding a script to C++ "
             "objects\" in README.md)\n";
    }
    return exit_failure;
  }
  if (const auto lib = a.value("--native")) {
    try {
      p->load_native(std::string(*lib));
    } catch (const vsd::Error& e) {
      err << printable_lines(e.what()) << "\n";
      return exit_failure;
    }
  }
  if (trace)
    p->on_firing([&out](const vsd::soml::Firing& f) {
      out << "step " << f.step << ": " << node_label(f.transition);
      if (f.mark != 0) {
        const vsd::SimStateInstance* m = f.transition->state().find(f.mark);
        const auto* mn = m != nullptr ? m->as<vsd::Node>() : nullptr;
        out << " mark " << (mn != nullptr && !mn->name().empty() ? printable(mn->name()) : "#" + std::to_string(f.mark))
            << " " << node_label(f.from) << " -> " << node_label(f.to);
      }
      // Net invocation: the first half, the finish and the invoking transition's completion.
      static constexpr const char* kinds[] = {"", " (invokes)", " (finish)", " (completes)"};
      out << kinds[static_cast<int>(f.kind)] << "\n";
    });
  std::uint64_t fired = 0;
  try {
    fired = p->step(steps);
  } catch (const vsd::Error& e) {
    out.flush();
    err << printable_lines(e.what()) << "\n";
    return exit_failure;
  }
  out << fired << (fired == 1 ? " firing" : " firings") << (p->enabled_any() ? "" : ", quiet") << "\n";
  for (const vsd::soml::Place* pl : p->places()) {
    out << "  " << node_label(pl) << " = ";
    if (pl->object_tokens()) {
      out << "[";
      for (std::size_t i = 0; i < pl->objects().size(); ++i)
        out << (i != 0 ? ", " : "")
            << (pl->objects()[i]->name().empty() ? "#" + std::to_string(pl->objects()[i]->id())
                                                 : printable(pl->objects()[i]->name()));
      out << "]\n";
    } else {
      out << pl->tokens() << "\n";
    }
  }
  for (const std::string& e : p->condition_errors()) err << "warning: a condition failed: " << printable_lines(e) << "\n";
  return exit_ok;
}

int analyze(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {flag("--json"), with_value("--threads"), with_value("--limit-mem"), flag("--progress"),
                           flag("--no-progress")});
  a.expect_positional(1, 1, "one FILE");
  an::ExploreOptions options;
  options.threads = static_cast<unsigned>(a.unsigned_integer("--threads", options.threads, 1024));
  if (const auto m = a.value("--limit-mem")) {
    try {
      options.memory_limit = an::parse_size(std::string(*m));
    } catch (const vsd::Error& e) {
      throw UsageError(std::string("--limit-mem: ") + e.what());
    }
  }
  if (a.has("--progress") && a.has("--no-progress")) throw UsageError("--progress and --no-progress contradict");
  if (a.has("--progress")) options.progress = an::ExploreOptions::Progress::always;
  if (a.has("--no-progress")) options.progress = an::ExploreOptions::Progress::never;
  const bool json = a.has("--json");
  const Net imported = read_net(a.positional()[0], err);
  const an::ExploreResult r = an::explore(imported.net, options);
  if (json)
    an::write_json(out, imported.net, r);
  else
    an::write_summary(out, imported.net, r);
  if (r.status == an::ExploreResult::Status::memory_limit) {
    if (json) err << "vsd-soml: " << r.message << "\n";  // the summary already says it
    return exit_failure;
  }
  return exit_ok;
}

// vsd-soml disasm FILE: the bytecode of a loaded script (Program::disassemble).
int disasm(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {});
  a.expect_positional(1, 1, "one FILE");
  const std::string_view path = a.positional()[0];
  const std::string file = path == "-" ? "<stdin>" : std::string(path);
  const std::string text = as_text(read_input(path, vsd::soml::max_source_bytes));
  Workspace ws;
  auto& soml = ws.env().use<vsd::soml::Module>();
  try {
    out << soml.load(ws.state(), file, text).disassemble();
  } catch (const vsd::Error& e) {
    out.flush();
    const std::string m = printable_lines(e.what());
    err << m << (m.ends_with("\n") ? "" : "\n");
    return exit_failure;
  }
  return exit_ok;
}

// vsd-soml compile FILE... -o DIR: the C++ of a native library of the scripts (native_library_source).
int compile(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {with_value("-o")});
  a.expect_positional(1, 1000, "one or more FILEs");
  const auto dir = a.value("-o");
  if (!dir) throw UsageError("compile needs -o DIR");
  // Said before any script is compiled, and in the user's words (the atomic write would only say that
  // it cannot make its temporary file there).
  std::error_code ec;
  if (!std::filesystem::is_directory(std::filesystem::path(std::string(*dir)), ec)) {
    err << "vsd-soml: " << printable(*dir) << ": no such directory (compile writes DIR/soml_native.cpp into an "
        << "existing DIR)\n";
    return exit_failure;
  }
  std::vector<std::unique_ptr<Workspace>> spaces;
  std::vector<const vsd::soml::Program*> programs;
  for (const std::string_view path : a.positional()) {
    const std::string file = path == "-" ? "<stdin>" : std::string(path);
    try {
      // Each script in a Registry of its own: their objects and classes do not meet (two scripts may
      // declare classes of the same name, as when each is loaded alone).
      Workspace& ws = *spaces.emplace_back(std::make_unique<Workspace>());
      const vsd::soml::Program& p = ws.env().use<vsd::soml::Module>().load(ws.state(), file, as_text(read_input(path, vsd::soml::max_source_bytes)));
      programs.push_back(&p);
    } catch (const vsd::Error& e) {
      const std::string m = printable_lines(e.what());
      err << m << (m.ends_with("\n") ? "" : "\n");
      return exit_failure;
    }
  }
  const std::string target = std::string(*dir) + "/soml_native.cpp";
  write_output(target, vsd::soml::native_library_source(programs), out);
  out << "wrote " << printable(target) << "\n";
  return exit_ok;
}

}  // namespace

int run(std::span<const std::string_view> args, std::istream& in, std::ostream& out, std::ostream& err) {
  return tool::run(tool, args, out, err, [&in](std::span<const std::string_view> a, std::ostream& o, std::ostream& e) {
    if (a.empty()) throw UsageError("no command (run, debug, analyze, convert, disasm or compile)");
    const auto rest = a.subspan(1);
    if (a[0] == "analyze") return analyze(rest, o, e);
    if (a[0] == "run") return run_script(rest, o, e);
    if (a[0] == "debug") return debug_command(rest, in, o, e);
    if (a[0] == "convert") return convert(rest, o, e);
    if (a[0] == "disasm") return disasm(rest, o, e);
    if (a[0] == "compile") return compile(rest, o, e);
    throw UsageError("unknown command '" + printable(a[0]) + "'");
  });
}

int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  return run(args, std::cin, out, err);
}

}  // namespace vsd::tool::vsd_soml
