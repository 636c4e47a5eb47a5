// vsd-soml: the command-line tool for nets (`vsd-soml --help`): runs SOML++ scripts, analyses the state
// spaces of PNML and SOML++ nets, and converts between the two.
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <string_view>
#include <vector>

#include "debug.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/soml.hpp"
#include "vsd/analysis.hpp"

namespace {

namespace an = vsd::analysis;

constexpr const char* kUsage =
    "Usage: vsd-soml analyze FILE [--json] [--threads N] [--limit-mem SIZE] [--progress | --no-progress]\n"
    "       vsd-soml run FILE [--steps N] [--trace] [--seed S]\n"
    "       vsd-soml debug FILE [--break FILE:LINE]... [--break-transition NAME]... [--seed S] [--steps N]\n"
    "       vsd-soml convert IN OUT\n"
    "       vsd-soml --help\n"
    "\n"
    "run      Loads the SOML++ script FILE into a database and fires its transitions: N firings, or until\n"
    "         none is enabled (at most 1000000). print() writes to stdout; at the end the marking of\n"
    "         every place is printed. Errors in the script are printed with file:line:col. A PNML file\n"
    "         (.pnml) is imported as the SOML++ net `convert` writes for it.\n"
    "  --steps N         fire at most N transitions\n"
    "  --trace           print every firing: step, transition, the token it moved, from where to where\n"
    "  --seed S          the seed of the choice among enabled transitions (default 1)\n"
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
    "         stderr; the original id stays in a comment).\n"
    "\n"
    "Exit status: 0 analysed (bounded or unbounded), 1 the file is bad or the memory limit was reached,\n"
    "2 usage error.\n";

int usage_error(const std::string& msg) {
  std::cerr << "vsd-soml: " << msg << "\n"
            << "Try 'vsd-soml --help'.\n";
  return 2;
}

bool has_pnml_extension(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  return ext == ".pnml" || ext == ".xml" || ext == ".PNML" || ext == ".XML";
}

bool looks_like_pnml(const std::filesystem::path& path) {
  if (has_pnml_extension(path)) return true;
  std::ifstream in(path, std::ios::binary);
  char ch = 0;
  while (in.get(ch))
    if (!std::isspace(static_cast<unsigned char>(ch))) return ch == '<';
  return false;
}

struct Net {
  an::PtNet net;
  std::vector<std::string> notes;
};

// A PNML or SOML++ file as a net; its notes go to stderr.
Net read_net(const std::filesystem::path& file) {
  Net n;
  if (looks_like_pnml(file)) {
    an::PnmlImport i = an::read_pnml_file(file);
    n = {std::move(i.net), std::move(i.notes)};
  } else {
    an::SomlNetImport i = an::read_soml_net_file(file);
    n = {std::move(i.net), std::move(i.notes)};
  }
  for (const auto& note : n.notes) std::cerr << "note: " << note << "\n";
  return n;
}

int convert(const std::vector<std::string_view>& args) {
  std::vector<std::string> files;
  for (const std::string_view a : args) {
    if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option '" + std::string(a) + "'");
    files.emplace_back(a);
  }
  if (files.size() != 2) throw std::invalid_argument("convert takes IN and OUT");
  if (!std::filesystem::exists(files[0])) {
    std::cerr << "vsd-soml: " << files[0] << ": no such file\n";
    return 1;
  }
  const Net in = read_net(files[0]);
  if (has_pnml_extension(files[1])) {
    an::write_pnml_file(in.net, files[1]);
  } else {
    std::vector<std::string> renamed;
    an::write_soml_file(in.net, files[1], &renamed);
    for (const auto& r : renamed) std::cerr << "note: " << r << "\n";
  }
  return 0;
}

std::string node_label(const vsd::Node* n) { return vsd::soml::net_node_label(n); }

int run(const std::vector<std::string_view>& args) {
  std::string file;
  std::uint64_t steps = 1'000'000;
  bool trace = false;
  vsd::soml::RunOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    auto value = [&]() {
      if (i + 1 >= args.size()) throw std::invalid_argument(std::string(args[i]) + " needs a value");
      return std::string(args[++i]);
    };
    auto number = [&](const std::string& v, const char* what) {
      std::size_t used = 0;
      unsigned long long n = 0;
      try {
        n = std::stoull(v, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != v.size() || v.empty() || v[0] == '-')
        throw std::invalid_argument(std::string(what) + " needs a number, not '" + v + "'");
      return static_cast<std::uint64_t>(n);
    };
    if (args[i] == "--steps") {
      steps = number(value(), "--steps");
    } else if (args[i] == "--seed") {
      options.seed = number(value(), "--seed");
    } else if (args[i] == "--trace") {
      trace = true;
    } else if (!args[i].empty() && args[i][0] == '-') {
      throw std::invalid_argument("unknown option '" + std::string(args[i]) + "'");
    } else if (file.empty()) {
      file = std::string(args[i]);
    } else {
      throw std::invalid_argument("run takes one FILE");
    }
  }
  if (file.empty()) throw std::invalid_argument("run needs a FILE");
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    std::cerr << "vsd-soml: cannot read '" << file << "'\n";
    return 1;
  }
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (looks_like_pnml(file)) {  // a P/T net: imported as the SOML++ net write_soml() makes of it
    const an::PnmlImport imported = an::read_pnml(text, file);
    for (const auto& note : imported.notes) std::cerr << "note: " << note << "\n";
    std::vector<std::string> renamed;
    text = an::write_soml(imported.net, &renamed);
    for (const auto& r : renamed) std::cerr << "note: " << r << "\n";
  }
  vsd::Registry registry;
  vsd::Environment env(0, registry);
  auto& soml = env.use<vsd::soml::Module>();
  vsd::soml::Program* p = nullptr;
  try {
    p = &soml.load(env.main_state(), file, text, options);
  } catch (const vsd::Error& e) {
    std::cerr << e.what() << (std::string(e.what()).ends_with("\n") ? "" : "\n");
    return 1;
  }
  if (trace)
    p->on_firing([](const vsd::soml::Firing& f) {
      std::cout << "step " << f.step << ": " << node_label(f.transition);
      if (f.mark != 0) {
        const vsd::SimStateInstance* m = f.transition->state().find(f.mark);
        const auto* mn = m != nullptr ? m->as<vsd::Node>() : nullptr;
        std::cout << " mark "
                  << (mn != nullptr && !mn->name().empty() ? mn->name() : "#" + std::to_string(f.mark)) << " "
                  << node_label(f.from) << " -> " << node_label(f.to);
      }
      // Net invocation: the first half, the finish and the invoking transition's completion.
      static constexpr const char* kinds[] = {"", " (invokes)", " (finish)", " (completes)"};
      std::cout << kinds[static_cast<int>(f.kind)] << "\n";
    });
  std::uint64_t fired = 0;
  try {
    fired = p->step(steps);
  } catch (const vsd::Error& e) {
    std::cout.flush();
    std::cerr << e.what() << "\n";
    return 1;
  }
  std::cout << fired << (fired == 1 ? " firing" : " firings") << (p->enabled_any() ? "" : ", quiet") << "\n";
  for (const vsd::soml::Place* pl : p->places()) {
    std::cout << "  " << node_label(pl) << " = ";
    if (pl->object_tokens()) {
      std::cout << "[";
      for (std::size_t i = 0; i < pl->objects().size(); ++i)
        std::cout << (i != 0 ? ", " : "")
                  << (pl->objects()[i]->name().empty() ? "#" + std::to_string(pl->objects()[i]->id())
                                                       : pl->objects()[i]->name());
      std::cout << "]\n";
    } else {
      std::cout << pl->tokens() << "\n";
    }
  }
  for (const std::string& e : p->condition_errors())
    std::cerr << "warning: a condition failed: " << e << "\n";
  return 0;
}

int analyze(const std::vector<std::string_view>& args) {
  std::string file;
  bool json = false;
  an::ExploreOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    auto value = [&](const char* what) -> std::string {
      if (i + 1 >= args.size()) throw std::invalid_argument(std::string(a) + " needs " + what);
      return std::string(args[++i]);
    };
    if (a == "--json") {
      json = true;
    } else if (a == "--threads") {
      const std::string v = value("a number");
      char* end = nullptr;
      const unsigned long n = std::strtoul(v.c_str(), &end, 10);
      if (v.empty() || *end != '\0' || n > 1024)
        throw std::invalid_argument("--threads: '" + v + "' is not 0..1024");
      options.threads = static_cast<unsigned>(n);
    } else if (a == "--limit-mem") {
      try {
        options.memory_limit = an::parse_size(value("a size"));
      } catch (const vsd::Error& e) {
        throw std::invalid_argument(std::string("--limit-mem: ") + e.what());
      }
    } else if (a == "--progress") {
      options.progress = an::ExploreOptions::Progress::always;
    } else if (a == "--no-progress") {
      options.progress = an::ExploreOptions::Progress::never;
    } else if (!a.empty() && a[0] == '-') {
      throw std::invalid_argument("unknown option '" + std::string(a) + "'");
    } else if (file.empty()) {
      file = std::string(a);
    } else {
      throw std::invalid_argument("analyze takes one FILE");
    }
  }
  if (file.empty()) throw std::invalid_argument("analyze needs a FILE");
  if (!std::filesystem::exists(file)) {
    std::cerr << "vsd-soml: " << file << ": no such file\n";
    return 1;
  }
  const Net imported = read_net(file);
  const an::ExploreResult r = an::explore(imported.net, options);
  if (json)
    an::write_json(std::cout, imported.net, r);
  else
    an::write_summary(std::cout, imported.net, r);
  if (r.status == an::ExploreResult::Status::memory_limit) {
    if (json) std::cerr << "vsd-soml: " << r.message << "\n";  // the summary already says it
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string_view> args(argv + 1, argv + argc);
  if (args.empty()) return usage_error("no command");
  if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::cout << kUsage;
    return 0;
  }
  try {
    if (args[0] == "analyze") return analyze(std::vector<std::string_view>(args.begin() + 1, args.end()));
    if (args[0] == "run") return run(std::vector<std::string_view>(args.begin() + 1, args.end()));
    if (args[0] == "debug") return debug_command(std::vector<std::string_view>(args.begin() + 1, args.end()));
    if (args[0] == "convert") return convert(std::vector<std::string_view>(args.begin() + 1, args.end()));
    return usage_error("unknown command '" + std::string(args[0]) + "'");
  } catch (const std::invalid_argument& e) {
    return usage_error(e.what());
  } catch (const std::exception& e) {
    std::cerr << "vsd-soml: " << e.what() << "\n";
    return 1;
  }
}
