// vsd-io (see tool.hpp).
#include "tool.hpp"

#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <unordered_set>
#include <vector>

#include "vsd/io/snapshot.hpp"
#include "vsd_tool/arguments.hpp"
#include "vsd_tool/input.hpp"
#include "vsd_tool/models.hpp"
#include "vsd_tool/runner.hpp"
#include "vsd_tool/text.hpp"

namespace vsd::tool::vsd_io {

namespace {

constexpr std::string_view usage =
    R"(vsd-io: convert, inspect and check vsd files (binary snapshots and vsd-text JSON)

Usage:
  vsd-io convert <in> <out> [--to text|binary]
      Convert a file. The output format follows <out>'s name (".json" is text, anything else binary)
      unless --to says otherwise. Converting back gives the same file. The output is written atomically
      (a failed write leaves the old file whole); "-" writes to standard output.
  vsd-io tree <file> [--values]
      Print the nodes of a file as a tree: id, class and name of each, with its extensions; --values adds
      every saved property. Instances held only through references are listed after the tree.
  vsd-io info <file>
      Print the format, the kind (state or subtree), the number of instances per class, the run-time
      classes the file defines, and schema warnings.
  vsd-io check <file>
      Load the file as a program would, and say what is wrong with it (exit status 1) or that it is fine.
  vsd-io --help

<file> and <in> may be "-" (standard input) or a pipe. A file is loaded all or nothing; errors name the
position (line:col for text, byte offset for binary). The tool knows the classes of every vsd module and
the run-time classes a file defines; classes it does not know (your own C++ classes) are shown through
stand-ins with their saved values and a warning, and such a file is not converted (the output would
carry the stand-ins, not your classes).

Exit status: 0 success, 1 a bad or unreadable file, 2 a usage error.
)";

const Tool tool{"vsd-io", usage, true};

struct Loaded {
  Workspace ws;
  io::LoadReport report;
};

std::unique_ptr<Loaded> load_file(std::string_view path) {
  auto l = std::make_unique<Loaded>();
  l->report = load_vsd(l->ws.state(), path);
  return l;
}

void print_warnings(const io::LoadReport& r, std::ostream& err) { tool::print_warnings(r.warnings, err); }

std::string describe(const SimStateInstance& x) {
  std::string s = "#" + std::to_string(x.id()) + " " + printable(x.meta().name());
  if (const auto* n = x.as<NamedModelInstance>(); n != nullptr && !n->name().empty()) {
    s += ' ';
    write_quoted(s, n->name());
  }
  return s;
}

// The tree, drawn with box characters. Iterative, and only the first levels are drawn: a chain of 100 000
// nodes prints in linear time and memory (each deeper line says its level instead of 300 000 columns).
class TreePrinter {
 public:
  TreePrinter(std::ostream& out, bool values) : out_(out), values_(values) {}

  void print(const SimState& state, const std::vector<Node*>& roots, bool subtree) {
    if (subtree) {
      for (const Node* r : roots) tree(*r);
    } else {
      tree(state.database());
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
  static constexpr std::size_t drawn_levels = 48;

  void tree(const SimStateInstance& root) {
    node(root, "", "");
    const auto* rn = root.as<Node>();
    if (rn == nullptr) return;
    struct Frame {
      const Node* n;
      std::size_t next;
    };
    std::vector<Frame> stack{{rn, 0}};
    std::string indent;              // the drawn indentation of the current level's children
    std::vector<std::size_t> marks;  // indent's length before each level below the root
    while (!stack.empty()) {
      Frame& f = stack.back();
      if (f.next == f.n->children().size()) {
        stack.pop_back();
        if (!marks.empty()) {
          indent.resize(marks.back());
          marks.pop_back();
        }
        continue;
      }
      const Node& c = *f.n->children()[f.next++];
      const bool last = f.next == f.n->children().size();
      const std::size_t level = stack.size();
      marks.push_back(indent.size());
      if (level <= drawn_levels) {
        node(c, indent + (last ? "└─ " : "├─ "), indent + (last ? "   " : "│  "));
        indent += last ? "   " : "│  ";
      } else {
        node(c, indent + "… level " + std::to_string(level) + ": ", indent + "    ");
      }
      stack.push_back({&c, 0});
    }
  }

  // One node: its line, its values and its extensions (@p indent: where its children's lines start).
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
  }

  void properties(const SimStateInstance& x, const std::string& indent) {
    if (!values_) return;
    for (const MetaProperty* p : x.meta().properties()) {
      if (!p->has(Savable) || p->has(Transient) || p == &Node::vsd_prop_children() ||
          p == &NamedModelInstance::vsd_prop_extensions() || p == &NamedModelInstance::vsd_prop_name())
        continue;
      std::string v;
      p->type().write_text(p->address(x), v);
      out_ << indent << printable(p->name()) << ": " << printable(v) << '\n';
    }
  }

  std::ostream& out_;
  bool values_;
  std::unordered_set<const SimStateInstance*> shown_;
};

int convert(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {with_value("--to")});
  a.expect_positional(2, 2, "an input and an output file");
  std::optional<io::Format> to;
  if (const auto f = a.value("--to")) {
    if (*f != "text" && *f != "binary") throw UsageError("--to needs 'text' or 'binary', not '" + printable(*f) + "'");
    to = *f == "text" ? io::Format::Text : io::Format::Binary;
  }
  const std::string_view in = a.positional()[0];
  const std::string_view target = a.positional()[1];
  auto l = load_file(in);
  print_warnings(l->report, err);
  if (!l->report.placeholder_classes.empty()) {
    std::string names;
    for (const std::string& c : l->report.placeholder_classes) names += (names.empty() ? "'" : ", '") + c + "'";
    throw Error("not converted: this tool does not know the class" +
                std::string(l->report.placeholder_classes.size() == 1 ? " " : "es ") + names +
                ", and the output would carry stand-ins instead (convert it in a program that links them)");
  }
  const io::Format format = to.value_or(target == "-" ? io::Format::Text : io::format_for(std::string(target)));
  const SimState& state = l->ws.state();
  const auto bytes = l->report.subtree && l->report.roots.size() == 1 ? io::save_bytes(*l->report.roots[0], format)
                                                                      : io::save_bytes(state, format);
  write_output(target, bytes, out);
  (target == "-" ? err : out) << "wrote " << l->report.instances << " instances to "
                              << (target == "-" ? "standard output" : printable(target)) << " ("
                              << (format == io::Format::Text ? "text" : "binary") << ")\n";
  return exit_ok;
}

int tree(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {flag("--values")});
  a.expect_positional(1, 1, "one file");
  auto l = load_file(a.positional()[0]);
  print_warnings(l->report, err);
  TreePrinter(out, a.has("--values")).print(l->ws.state(), l->report.roots, l->report.subtree);
  return exit_ok;
}

void print_names(std::ostream& out, std::string_view what, const std::vector<std::string>& names) {
  if (names.empty()) return;
  out << what << ':';
  for (const std::string& n : names) out << ' ' << printable(n);
  out << '\n';
}

int info(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {});
  a.expect_positional(1, 1, "one file");
  auto l = load_file(a.positional()[0]);
  const io::LoadReport& r = l->report;
  out << "file:      " << input_name(a.positional()[0]) << '\n'
      << "format:    " << (r.format == io::Format::Text ? "text (vsd-text " : "binary (VSDS ") << r.version
      << ")\n"
      << "kind:      " << (r.subtree ? "subtree" : "state") << '\n'
      << "instances: " << r.instances << '\n';
  std::map<std::string, std::size_t> per_class;
  const SimState& state = l->ws.state();
  for (const SimStateInstance* x : state.instances())
    if (r.subtree || x != &state.database()) ++per_class[x->meta().name()];
  for (const auto& [name, n] : per_class) out << "  " << n << " " << printable(name) << '\n';
  print_names(out, "run-time types defined by the file", r.defined_types);
  print_names(out, "run-time classes defined by the file", r.defined_classes);
  print_names(out, "classes this tool does not know (shown through stand-ins)", r.placeholder_classes);
  print_warnings(r, err);
  return exit_ok;
}

int check(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {});
  a.expect_positional(1, 1, "one file");
  auto l = load_file(a.positional()[0]);
  print_warnings(l->report, err);
  out << input_name(a.positional()[0]) << ": ok, " << l->report.instances << " instances"
      << (l->report.warnings.empty() ? "" : " (" + std::to_string(l->report.warnings.size()) + " warnings)")
      << '\n';
  return exit_ok;
}

int body(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  if (args.empty()) throw UsageError("no command (convert, tree, info or check)");
  const auto rest = args.subspan(1);
  if (args[0] == "convert") return convert(rest, out, err);
  if (args[0] == "tree") return tree(rest, out, err);
  if (args[0] == "info") return info(rest, out, err);
  if (args[0] == "check") return check(rest, out, err);
  throw UsageError("unknown command '" + printable(args[0]) + "'");
}

}  // namespace

int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  return tool::run(tool, args, out, err, body);
}

}  // namespace vsd::tool::vsd_io
