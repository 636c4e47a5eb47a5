#include "net_picture.hpp"

#include <map>
#include <sstream>

#include "cell.hpp"
#include "scene_kit.hpp"
#include "vsd/soml.hpp"
#include "vsd/soml/ast.hpp"
#include "vsd/soml/checker.hpp"

namespace vsd_workcell {

namespace {

using namespace vsd::soml;

struct Writer {
  std::ostringstream out;
  std::map<const Decl*, std::string> ids;  // places and transitions -> DOT node ids
  std::vector<const TransitionDecl*> transitions;
  std::vector<std::pair<const ClassDecl*, const StartDecl*>> starts;

  static std::string quoted(const std::string& s) {
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\\\"") : std::string(1, c);
    return q + '"';
  }

  void object(const ClassDecl& c, const std::string& prefix, int depth) {
    const std::string indent(static_cast<std::size_t>(2 * depth), ' ');
    for (const DeclPtr& m : c.members) {
      const std::string id = prefix + m->name;
      switch (m->kind) {
        case DeclKind::Place: {
          const auto& p = m->as<PlaceDecl>();
          std::string label = m->name;
          if (!p.token_class.empty()) label += "\\nplace<" + p.token_class.back() + ">";
          if (p.initial_tokens > 0) label += "\\n" + std::string(static_cast<std::size_t>(std::min<std::int64_t>(p.initial_tokens, 5)), '*');
          ids[&p] = quoted(id);
          out << indent << quoted(id) << " [shape=circle, fixedsize=false, label=" << quoted(label) << "];\n";
          break;
        }
        case DeclKind::Transition: {
          const auto& t = m->as<TransitionDecl>();
          std::string label = m->name;
          const bool when = t.when_expr || t.when_block;
          if (when || t.action) label += std::string("\\n") + (when ? "σ" : "") + (when && t.action ? " " : "") + (t.action ? "γ" : "");
          ids[&t] = quoted(id);
          transitions.push_back(&t);
          out << indent << quoted(id) << " [shape=box, style=filled, fillcolor=\"#eeeeee\", label=" << quoted(label)
              << "];\n";
          break;
        }
        case DeclKind::Object:
          out << indent << "subgraph " << quoted("cluster_" + id) << " {\n"
              << indent << "  label=" << quoted(m->name) << "; style=rounded; color=\"#888888\";\n";
          object(m->as<ClassDecl>(), id + ".", depth + 1);
          out << indent << "}\n";
          break;
        case DeclKind::Class:
          for (const DeclPtr& cm : m->as<ClassDecl>().members)
            if (cm->kind == DeclKind::Start) starts.emplace_back(&m->as<ClassDecl>(), &cm->as<StartDecl>());
          break;
        default:
          break;
      }
    }
  }

  void arcs() {
    for (const TransitionDecl* t : transitions) {
      auto arc = [&](const ArrowDecl* a, const Decl* from, const Decl* to) {
        const auto f = ids.find(from), g = ids.find(to);
        if (f == ids.end() || g == ids.end()) return;  // not a static object's (cannot be drawn here)
        out << "  " << f->second << " -> " << g->second << " [";
        if (a->arrow == ArrowKind::Communication) out << "style=dashed, ";
        if (a->arrow == ArrowKind::Inhibitor) out << "arrowhead=odot, ";
        if (a->weight != 1) out << "label=" << a->weight << ", ";
        out << "];\n";
      };
      for (const ArrowDecl* a : t->inputs) arc(a, a->from_decl, t);
      for (const ArrowDecl* a : t->outputs) arc(a, t, a->to_decl);
    }
    for (const auto& [c, s] : starts) {
      const auto g = ids.find(s->place_decl);
      if (g == ids.end()) continue;
      out << "  " << quoted("new " + c->name) << " [shape=note, label=" << quoted("new " + c->name) << "];\n"
          << "  " << quoted("new " + c->name) << " -> " << g->second << " [style=dotted];\n";
    }
  }
};

}  // namespace

std::string net_dot(const std::string& path) {
  const std::string text = vsd_example::read_text(path);
  vsd::Environment env;
  add_cell_modules(env);
  const auto checked = check_source(path, text, env.registry());
  if (!checked->ok()) throw vsd::Error(checked->diagnostics.format());
  Writer w;
  std::string name = path.substr(path.find_last_of('/') + 1);
  w.out << "digraph " << Writer::quoted(name) << " {\n"
        << "  rankdir=TB; fontname=\"Helvetica\"; node [fontname=\"Helvetica\", fontsize=10];\n"
        << "  edge [arrowsize=0.6];\n  label=" << Writer::quoted(name + " (generated from the script)") << ";\n";
  w.object(*checked->script.root, "", 1);
  w.arcs();
  w.out << "}\n";
  return w.out.str();
}

}  // namespace vsd_workcell
