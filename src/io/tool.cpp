// The vsd-io command-line tool (see vsd/io/tool.hpp).
#include "vsd/io/tool.hpp"

#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

#include "vsd/io/file.hpp"
#include "vsd/io/snapshot.hpp"

namespace vsd::io {

namespace {

constexpr std::string_view usage =
    R"(vsd-io: convert, inspect and check vsd files (binary snapshots and vsd-text JSON)

Usage:
  vsd-io convert <in> <out> [--to text|binary]
      Convert a file. The output format follows <out>'s name (".json" is text, anything else binary)
      unless --to says otherwise. Converting back gives the same file.
  vsd-io tree <file> [--values]
      Print the nodes of a file as a tree: id, class and name of each, with its extensions; --values adds
      every saved property. Instances held only through references are listed after the tree.
  vsd-io info <file>
      Print the format, the kind (state or subtree), the number of instances per class, the run-time
      classes the file defines, and schema warnings.
  vsd-io check <file>
      Load the file as a program would, and say what is wrong with it (exit status 1) or that it is fine.
  vsd-io --help

A file is loaded all or nothing; errors name the position (line:col for text, byte offset for binary).
The tool knows vsd's own classes and the run-time classes a file defines; for files of your own C++
classes, build a tool that links them (see vsd/io/tool.hpp).

Exit status: 0 success, 1 a bad or unreadable file, 2 a usage error.
)";

struct Loaded {
  Environment env;
  LoadReport report;
};

std::unique_ptr<Loaded> load_file(std::string_view path) {
  auto l = std::make_unique<Loaded>();
  l->report = load(l->env.main_state(), std::filesystem::path(path));
  return l;
}

void print_warnings(const LoadReport& r, std::ostream& err) {
  for (const std::string& w : r.warnings) err << "warning: " << w << '\n';
}

std::string describe(const SimStateInstance& x) {
  std::string s = "#" + std::to_string(x.id()) + " " + x.meta().name();
  if (const auto* n = x.as<NamedModelInstance>(); n != nullptr && !n->name().empty()) {
    s += ' ';
    write_quoted(s, n->name());
  }
  return s;
}

class TreePrinter {
 public:
  TreePrinter(std::ostream& out, bool values) : out_(out), values_(values) {}

  void print(const SimState& state, const std::vector<Node*>& roots, bool subtree) {
    if (subtree) {
      for (const Node* r : roots) node(*r, "", "");
    } else {
      node(state.database(), "", "");
    }
    std::vector<const SimStateInstance*> rest;
    for (const SimStateInstance* x : state.instances())
      if (shown_.count(x) == 0 && x != &state.database()) rest.push_back(x);
    if (rest.empty()) return;
    out_ << "held by references only:\n";
    for (const SimStateInstance* x : rest) {
      out_ << "  " << describe(*x) << '\n';
      properties(*x, "    ");
    }
  }

 private:
  void node(const SimStateInstance& x, const std::string& lead, const std::string& indent) {
    shown_.insert(&x);
    out_ << lead << describe(x) << '\n';
    const auto* n = x.as<Node>();
    const std::size_t nchildren = n != nullptr ? n->children().size() : 0;
    const auto* named = x.as<NamedModelInstance>();
    const std::size_t next = named != nullptr ? named->extensions().size() : 0;
    const std::string inner = indent + (nchildren != 0 ? "│  " : "   ");
    properties(x, inner);
    for (std::size_t i = 0; i < next; ++i) {
      const Extension& e = *named->extensions()[i];
      shown_.insert(&e);
      out_ << inner << "+ extension " << describe(e) << '\n';
      properties(e, inner + "    ");
    }
    for (std::size_t i = 0; i < nchildren; ++i) {
      const bool last = i + 1 == nchildren;
      node(*n->children()[i], indent + (last ? "└─ " : "├─ "), indent + (last ? "   " : "│  "));
    }
  }

  void properties(const SimStateInstance& x, const std::string& indent) {
    if (!values_) return;
    for (const MetaProperty* p : x.meta().properties()) {
      if (!p->has(Savable) || p->has(Transient) || p == &Node::vsd_prop_children() ||
          p == &NamedModelInstance::vsd_prop_extensions() || p == &NamedModelInstance::vsd_prop_name())
        continue;
      std::string v;
      p->type().write_text(p->address(x), v);
      out_ << indent << p->name() << ": " << v << '\n';
    }
  }

  std::ostream& out_;
  bool values_;
  std::unordered_set<const SimStateInstance*> shown_;
};

int convert(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  std::vector<std::string_view> files;
  std::optional<Format> to;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--to") {
      if (i + 1 == args.size()) throw std::invalid_argument("--to needs 'text' or 'binary'");
      const std::string_view f = args[++i];
      if (f != "text" && f != "binary")
        throw std::invalid_argument("--to needs 'text' or 'binary', not '" + std::string(f) + "'");
      to = f == "text" ? Format::Text : Format::Binary;
    } else if (args[i].substr(0, 1) == "-") {
      throw std::invalid_argument("convert: unknown option '" + std::string(args[i]) + "'");
    } else {
      files.push_back(args[i]);
    }
  }
  if (files.size() != 2) throw std::invalid_argument("convert needs an input and an output file");
  auto l = load_file(files[0]);
  print_warnings(l->report, err);
  const std::filesystem::path target(files[1]);
  const Format format = to.value_or(format_for(target));
  const SimState& state = l->env.main_state();
  if (l->report.subtree && l->report.roots.size() == 1)
    save(*l->report.roots[0], target, format);
  else
    save(state, target, format);
  out << "wrote " << l->report.instances << " instances to " << files[1] << " ("
      << (format == Format::Text ? "text" : "binary") << ")\n";
  return 0;
}

int tree(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  bool values = false;
  std::vector<std::string_view> files;
  for (std::string_view a : args) {
    if (a == "--values")
      values = true;
    else if (a.substr(0, 1) == "-")
      throw std::invalid_argument("tree: unknown option '" + std::string(a) + "'");
    else
      files.push_back(a);
  }
  if (files.size() != 1) throw std::invalid_argument("tree needs one file");
  auto l = load_file(files[0]);
  print_warnings(l->report, err);
  TreePrinter(out, values).print(l->env.main_state(), l->report.roots, l->report.subtree);
  return 0;
}

int info(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  if (args.size() != 1 || args[0].substr(0, 1) == "-") throw std::invalid_argument("info needs one file");
  auto l = load_file(args[0]);
  const LoadReport& r = l->report;
  out << "file:      " << args[0] << '\n'
      << "format:    " << (r.format == Format::Text ? "text (vsd-text " : "binary (VSDS ") << r.version
      << ")\n"
      << "kind:      " << (r.subtree ? "subtree" : "state") << '\n'
      << "instances: " << r.instances << '\n';
  std::map<std::string, std::size_t> per_class;
  for (const SimStateInstance* x : l->env.main_state().instances())
    if (r.subtree || x != &l->env.main_state().database()) ++per_class[x->meta().name()];
  for (const auto& [name, n] : per_class) out << "  " << n << " " << name << '\n';
  if (!r.defined_types.empty()) {
    out << "run-time types defined by the file:";
    for (const std::string& t : r.defined_types) out << ' ' << t;
    out << '\n';
  }
  if (!r.defined_classes.empty()) {
    out << "run-time classes defined by the file:";
    for (const std::string& c : r.defined_classes) out << ' ' << c;
    out << '\n';
  }
  print_warnings(r, err);
  return 0;
}

int check(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  if (args.size() != 1 || args[0].substr(0, 1) == "-") throw std::invalid_argument("check needs one file");
  auto l = load_file(args[0]);
  print_warnings(l->report, err);
  out << args[0] << ": ok, " << l->report.instances << " instances"
      << (l->report.warnings.empty() ? "" : " (" + std::to_string(l->report.warnings.size()) + " warnings)")
      << '\n';
  return 0;
}

}  // namespace

int run_tool(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  if (args.empty()) {
    err << usage;
    return 2;
  }
  if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    out << usage;
    return 0;
  }
  const auto rest = args.subspan(1);
  try {
    if (args[0] == "convert") return convert(rest, out, err);
    if (args[0] == "tree") return tree(rest, out, err);
    if (args[0] == "info") return info(rest, out, err);
    if (args[0] == "check") return check(rest, out, err);
    throw std::invalid_argument("unknown command '" + std::string(args[0]) + "'");
  } catch (const std::invalid_argument& e) {
    err << "vsd-io: " << e.what() << " (vsd-io --help tells more)\n";
    return 2;
  } catch (const Error& e) {
    err << "vsd-io: " << e.what() << '\n';
    return 1;
  }
}

int run_tool(int argc, char** argv) {
  std::vector<std::string_view> args(argv + (argc > 0 ? 1 : 0), argv + argc);
  return run_tool(args, std::cout, std::cerr);
}

}  // namespace vsd::io
