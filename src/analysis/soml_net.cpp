// SOML++ scripts <-> P/T nets: see include/vsd/analysis/soml_net.hpp for the rules.
#include "vsd/analysis/soml_net.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "text_file.hpp"
#include "vsd/core/error.hpp"
#include "vsd/soml/checker.hpp"
#include "vsd/soml/module.hpp"

namespace vsd::analysis {

namespace {

// The SOML++ front end's syntax tree and checker (vsd::soml); this module's own Place and Transition
// (vsd::analysis) still win over vsd::soml's net classes of the same names.
using namespace vsd::soml;

// ---- does an action change a marking? --------------------------------------------------------------

// Walks statements and expressions looking for `put`/`clear` on a place, and for calls of script
// functions that (transitively) do. Which functions do is worked out once for the whole script, over its
// call graph and without recursion (following each call into its callee recursed once per function of a
// call chain: a chain of 100,000 functions overflowed the stack); the walks themselves are bounded by the
// parser's nesting limit.
class MarkingEffects {
 public:
  explicit MarkingEffects(const ClassDecl& root) {
    std::vector<const FunctionDecl*> functions;
    std::vector<const ScopeDecl*> scopes{&root};
    while (!scopes.empty()) {
      const ScopeDecl* sc = scopes.back();
      scopes.pop_back();
      for (const DeclPtr& m : sc->members) {
        if (m->kind == DeclKind::Function) functions.push_back(&m->as<FunctionDecl>());
        if (m->has_members()) scopes.push_back(&m->as<ScopeDecl>());
      }
    }
    // Each function's own put/clear and the functions it calls; then, from those that change a marking
    // themselves, their callers, and theirs, ...
    std::unordered_map<const FunctionDecl*, std::vector<const FunctionDecl*>> callers;
    std::vector<const FunctionDecl*> work;
    for (const FunctionDecl* f : functions) {
      std::vector<const FunctionDecl*> callees;
      callees_ = &callees;
      if (in(f->body.get()) != nullptr && changing_.insert(f).second) work.push_back(f);
      callees_ = nullptr;
      for (const FunctionDecl* g : callees) callers[g].push_back(f);
    }
    while (!work.empty()) {
      const FunctionDecl* g = work.back();
      work.pop_back();
      for (const FunctionDecl* f : callers[g])
        if (changing_.insert(f).second) work.push_back(f);
    }
  }

  /// The first place operation reached from @p stmt (its position), or null.
  const Expr* in(const Stmt* stmt) {
    if (stmt == nullptr) return nullptr;
    switch (stmt->kind) {
      case StmtKind::Block:
        for (const auto& s : stmt->as<BlockStmt>().body)
          if (const Expr* e = in(s.get())) return e;
        return nullptr;
      case StmtKind::Local:
        return in(stmt->as<LocalStmt>().init.get());
      case StmtKind::If: {
        const auto& s = stmt->as<IfStmt>();
        return first(in(s.cond.get()), in(s.then_stmt.get()), in(s.else_stmt.get()));
      }
      case StmtKind::While: {
        const auto& s = stmt->as<WhileStmt>();
        return first(in(s.cond.get()), in(s.body.get()));
      }
      case StmtKind::For: {
        const auto& s = stmt->as<ForStmt>();
        return first(in(s.init.get()), in(s.cond.get()), in(s.step.get()), in(s.body.get()));
      }
      case StmtKind::ForEach: {
        const auto& s = stmt->as<ForEachStmt>();
        return first(in(s.range.get()), in(s.body.get()));
      }
      case StmtKind::Return:
      case StmtKind::Finish:
        return in(stmt->as<ReturnStmt>().value.get());
      case StmtKind::Expr:
        return in(stmt->as<ExprStmt>().expr.get());
      case StmtKind::Break:
      case StmtKind::Continue:
        return nullptr;
    }
    return nullptr;
  }

  const Expr* in(const Expr* e) {
    if (e == nullptr) return nullptr;
    switch (e->kind) {
      case ExprKind::Unary:
      case ExprKind::Postfix:
        return in(e->as<UnaryExpr>().operand.get());
      case ExprKind::Binary:
      case ExprKind::Assign: {
        const auto& b = e->as<BinaryExpr>();
        return first(in(b.lhs.get()), in(b.rhs.get()));
      }
      case ExprKind::Conditional: {
        const auto& c = e->as<ConditionalExpr>();
        return first(in(c.cond.get()), in(c.then_expr.get()), in(c.else_expr.get()));
      }
      case ExprKind::Call: {
        const auto& c = e->as<CallExpr>();
        // Reported at the callee (`free.put`, `fill`), where a reader looks for it.
        const Expr* at = c.callee ? leftmost(c.callee.get()) : e;
        if (c.binding.kind == Binding::Kind::Builtin &&
            (c.binding.builtin == Builtin::PlacePut || c.binding.builtin == Builtin::PlaceClear))
          return at;
        if (c.binding.kind == Binding::Kind::Function && c.binding.decl != nullptr) {
          const auto* f = &c.binding.decl->as<FunctionDecl>();
          if (callees_ != nullptr)
            callees_->push_back(f);  // (the call graph is being made: only direct effects count)
          else if (changing_.count(f) != 0)
            return at;
        }
        if (const Expr* x = in(c.callee.get())) return x;
        for (const auto& a : c.args)
          if (const Expr* x = in(a.get())) return x;
        return nullptr;
      }
      case ExprKind::Member:
        return in(e->as<MemberExpr>().object.get());
      case ExprKind::Index: {
        const auto& i = e->as<IndexExpr>();
        return first(in(i.object.get()), in(i.index.get()));
      }
      case ExprKind::New:
      case ExprKind::Is:
      case ExprKind::As: {
        const auto& n = e->as<NewExpr>();
        if (const Expr* x = in(n.operand.get())) return x;
        for (const auto& a : n.args)
          if (const Expr* x = in(a.get())) return x;
        return nullptr;
      }
      default:
        return nullptr;
    }
  }

 private:
  // The first token of a postfix expression: `free` of `free.put`.
  static const Expr* leftmost(const Expr* e) {
    for (;;) {
      if (e->kind == ExprKind::Member && e->as<MemberExpr>().object)
        e = e->as<MemberExpr>().object.get();
      else if (e->kind == ExprKind::Call && e->as<CallExpr>().callee)
        e = e->as<CallExpr>().callee.get();
      else if (e->kind == ExprKind::Index && e->as<IndexExpr>().object)
        e = e->as<IndexExpr>().object.get();
      else
        return e;
    }
  }
  template <class... E>
  static const Expr* first(E... e) {
    const Expr* found = nullptr;
    ((found = found != nullptr ? found : e), ...);
    return found;
  }
  std::unordered_set<const FunctionDecl*> changing_;  // the functions that change a marking, transitively
  std::vector<const FunctionDecl*>* callees_ = nullptr;  // while the call graph is made: the calls met
};

// ---- SOML++ -> PtNet ---------------------------------------------------------------------------------

class Converter {
 public:
  explicit Converter(const CheckResult& checked) : checked_(checked), effects_(*checked.script.root) {}

  SomlNetImport run() {
    const ClassDecl& root = *checked_.script.root;
    instance(root, "");
    note_class_nets(root);
    for (const Pending& a : arrows_) arrow(a);
    if (!refusals_.empty()) {
      std::stable_sort(refusals_.begin(), refusals_.end(),
                       [](const Refusal& a, const Refusal& b) { return a.loc.offset < b.loc.offset; });
      std::string msg = checked_.source->name() + ": the net is not a place/transition net (" +
                        std::to_string(refusals_.size()) + (refusals_.size() == 1 ? " construct" : " constructs") +
                        " outside black-token nets):";
      for (const Refusal& r : refusals_) msg += "\n" + r.text;
      vsd::detail::throw_error(msg);
    }
    // The file's stem is the net's id (an XML id when written as PNML), the file its name.
    std::string id = std::filesystem::path(checked_.source->name()).stem().string();
    result_.net.set_id(id.empty() ? "net" : id);
    result_.net.set_name(checked_.source->name());
    return std::move(result_);
  }

 private:
  struct Refusal {
    SourceLoc loc;
    std::string text;
  };
  struct Pending {
    const ArrowDecl* decl;
    std::string prefix;
  };

  [[nodiscard]] std::string where(SourceLoc loc, const std::string& msg) const {
    Diagnostic d;
    d.severity = Severity::Error;
    d.loc = loc;
    d.message = msg;
    return checked_.diagnostics.format(d);
  }
  void refuse(SourceLoc loc, const std::string& msg) { refusals_.push_back({loc, where(loc, msg)}); }
  void note(SourceLoc loc, const std::string& msg) {
    result_.notes.push_back(checked_.source->name() + ":" + std::to_string(loc.line) + ":" +
                            std::to_string(loc.column) + ": " + msg);
  }

  // One instance: the members of its declaration and of its script base classes (base first, so the
  // net's order follows inheritance), then its nested objects.
  void instance(const ClassDecl& decl, const std::string& prefix) {
    std::vector<const ClassDecl*> chain;
    for (const ClassDecl* c = &decl; c != nullptr; c = c->base.decl) chain.insert(chain.begin(), c);
    for (const ClassDecl* c : chain)
      for (const auto& m : c->members) member(*m, prefix);
  }

  void member(const Decl& m, const std::string& prefix) {
    const std::string id = prefix + m.name;
    switch (m.kind) {
      case DeclKind::Place: {
        const auto& p = m.as<PlaceDecl>();
        if (p.is_port) return;  // only in nets, which are not part of the static net
        if (!p.token.empty()) {
          refuse(p.loc, "place '" + id + "' holds object tokens (" + p.token.name() + ")");
          return;
        }
        if (p.initial_tokens < 0 || p.initial_tokens > std::int64_t{0xffffffff}) {
          refuse(p.loc, "place '" + id + "' starts with " + std::to_string(p.initial_tokens) + " tokens");
          return;
        }
        places_[{prefix, &p}] = result_.net.add_place(id, id, static_cast<std::uint32_t>(p.initial_tokens));
        return;
      }
      case DeclKind::Transition: {
        const auto& t = m.as<TransitionDecl>();
        if (t.when_expr || t.when_block) refuse(t.loc, "transition '" + id + "' has a condition");
        if (!t.invoke_name.empty()) refuse(t.invoke_loc, "transition '" + id + "' invokes a net");
        if (!t.subst_name.empty()) refuse(t.subst_loc, "transition '" + id + "' is substituted by a net");
        if (t.action) {
          if (const Expr* e = effects_.in(t.action.get()))
            refuse(e->loc, "the action of transition '" + id + "' changes a marking");
          else
            note(t.action->loc, "the action of transition '" + id +
                                    "' is ignored: it changes no marking, so the state space is the same");
        }
        transitions_[{prefix, &t}] = result_.net.add_transition(id, id);
        return;
      }
      case DeclKind::Arrow:
        arrows_.push_back({&m.as<ArrowDecl>(), prefix});
        return;
      case DeclKind::Start:
        refuse(m.loc, "start place: instances become object tokens");
        return;
      case DeclKind::Object:
        instance(m.as<ClassDecl>(), id + ".");
        return;
      default:  // enums, classes, nets, functions, properties: no places of the static net
        return;
    }
  }

  void arrow(const Pending& a) {
    const ArrowDecl& d = *a.decl;
    if (d.arrow == ArrowKind::Communication) {
      refuse(d.loc, "communication arrow (its remote place is found at run time)");
      return;
    }
    if (d.condition) refuse(d.condition->loc, "arrow condition");
    if (d.from_decl == nullptr || d.to_decl == nullptr) return;  // the checker reported it
    if (d.weight <= 0 || d.weight > std::int64_t{0xffffffff}) {
      refuse(d.weight_loc, "arrow weight " + std::to_string(d.weight) + " is out of range");
      return;
    }
    const auto w = static_cast<std::uint32_t>(d.weight);
    if (d.from_decl->kind == DeclKind::Place) {
      auto p = places_.find({a.prefix, d.from_decl});
      auto t = transitions_.find({a.prefix, d.to_decl});
      if (p == places_.end() || t == transitions_.end()) return;  // refused above
      if (d.arrow == ArrowKind::Inhibitor)
        result_.net.add_inhibitor(t->second, p->second, w);
      else
        result_.net.add_input(t->second, p->second, w);
    } else {
      auto t = transitions_.find({a.prefix, d.from_decl});
      auto p = places_.find({a.prefix, d.to_decl});
      if (p == places_.end() || t == transitions_.end()) return;
      result_.net.add_output(t->second, p->second, w);
    }
  }

  // Places and transitions of classes (and of nets) belong to instances made at run time.
  void note_class_nets(const ClassDecl& scope) {
    for (const auto& m : scope.members) {
      if (m->kind == DeclKind::Class || m->kind == DeclKind::Net) {
        const auto& c = m->as<ClassDecl>();
        const bool has_net = std::any_of(c.members.begin(), c.members.end(), [](const DeclPtr& x) {
          return x->kind == DeclKind::Place || x->kind == DeclKind::Transition;
        });
        if (has_net && m->kind == DeclKind::Class)
          note(c.loc, "the net of class '" + c.name +
                          "' belongs to its instances made at run time: only objects' nets are analysed");
      }
      if (m->is_class_like()) note_class_nets(m->as<ClassDecl>());
    }
  }

  const CheckResult& checked_;
  SomlNetImport result_;
  MarkingEffects effects_;
  std::map<std::pair<std::string, const Decl*>, std::uint32_t> places_, transitions_;
  std::vector<Pending> arrows_;
  std::vector<Refusal> refusals_;  // sorted by position before they are reported
};

// ---- PtNet -> SOML++ ---------------------------------------------------------------------------------

bool is_ident_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool is_ident_char(char c) { return is_ident_start(c) || (c >= '0' && c <= '9'); }

// Words a place or transition must not be called: the keywords, and the type names a declaration
// could be mistaken for.
bool reserved(std::string_view s) {
  static const std::set<std::string_view> words = {
      "arrow", "as",   "auto", "break",  "class",  "continue",   "do",   "else",  "enum",   "false",  "finish",
      "for",   "if",   "invoke", "is",   "mark",   "net",        "new",  "null",  "object", "place",  "return",
      "start", "this", "transition", "true", "void", "when",     "while", "int",  "int64",  "int32",  "double",
      "float", "bool", "string", "ref",  "shared", "vector",     "list"};
  return words.count(s) != 0;
}

std::string identifier_for(const std::string& id) {
  std::string s;
  s.reserve(id.size() + 1);
  for (char c : id) s += is_ident_char(c) ? c : '_';
  if (s.empty() || !is_ident_start(s[0])) s.insert(s.begin(), '_');
  if (reserved(s)) s += '_';
  return s;
}

// A string as a comment can hold it (no line breaks).
std::string comment_text(const std::string& s) {
  std::string out;
  for (char c : s) out += (c == '\n' || c == '\r') ? ' ' : c;
  return out;
}

}  // namespace

SomlNetImport net_from_soml(const CheckResult& checked) {
  if (!checked.ok()) vsd::detail::throw_error(checked.diagnostics.format());
  return Converter(checked).run();
}

SomlNetImport read_soml_net(std::string_view text, std::string_view source) {
  const auto checked = check_source(std::string(source), std::string(text));
  return net_from_soml(*checked);
}

SomlNetImport read_soml_net(std::istream& in, std::string_view source) {
  return read_soml_net(detail::read_text(in, source), source);
}

SomlNetImport read_soml_net_file(const std::filesystem::path& path) {
  return read_soml_net(detail::read_text_file(path), path.string());
}

std::string write_soml(const PtNet& net, std::vector<std::string>* notes) {
  // Identifiers: the id where it is one, else a cleaned-up id made unique with a suffix.
  // Ids that are identifiers keep their names (they are unique in a PtNet); the others take what is free.
  std::set<std::string> used;
  for (const Place& p : net.places())
    if (identifier_for(p.id) == p.id) used.insert(p.id);
  for (const Transition& t : net.transitions())
    if (identifier_for(t.id) == t.id) used.insert(t.id);
  auto name_of = [&](const std::string& id) {
    if (identifier_for(id) == id) return id;
    std::string base = identifier_for(id);
    std::string s = base;
    for (int n = 2; !used.insert(s).second; ++n) s = base + "_" + std::to_string(n);
    if (s != id && notes != nullptr) notes->push_back("renamed '" + id + "' to '" + s + "'");
    return s;
  };
  std::vector<std::string> place_names, transition_names;
  for (const Place& p : net.places()) place_names.push_back(name_of(p.id));
  for (const Transition& t : net.transitions()) transition_names.push_back(name_of(t.id));

  auto origin = [](const std::string& ident, const std::string& id, const std::string& name) {
    std::string c;
    if (ident != id) c += "id \"" + comment_text(id) + "\"";
    if (!name.empty() && name != id) c += (c.empty() ? "" : ", ") + std::string("name \"") + comment_text(name) + "\"";
    return c.empty() ? std::string() : "  // " + c;
  };

  std::string out;
  out += "// Place/transition net";
  if (!net.id().empty()) out += " \"" + comment_text(net.id()) + "\"";
  if (!net.name().empty() && net.name() != net.id()) out += " (" + comment_text(net.name()) + ")";
  auto count = [](std::size_t n, const char* what) {
    return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
  };
  out += ": " + count(net.place_count(), "place") + ", " + count(net.transition_count(), "transition") + ", " +
         count(net.arc_count(), "arc") + ".\n\n";
  for (std::size_t i = 0; i < net.place_count(); ++i) {
    const Place& p = net.places()[i];
    out += "place " + place_names[i];
    if (p.initial != 0) out += " = " + std::to_string(p.initial);
    out += ";" + origin(place_names[i], p.id, p.name) + "\n";
  }
  out += "\n";
  for (std::size_t i = 0; i < net.transition_count(); ++i) {
    const Transition& t = net.transitions()[i];
    out += "transition " + transition_names[i] + ";" + origin(transition_names[i], t.id, t.name) + "\n";
  }
  for (std::size_t i = 0; i < net.transition_count(); ++i) {
    const Transition& t = net.transitions()[i];
    if (t.inputs.empty() && t.outputs.empty() && t.inhibitors.empty()) continue;
    out += "\n";
    auto arc = [&](const ArcRef& a, std::string_view op, bool into_transition) {
      const std::string& place = place_names[a.place];
      out += "arrow " + (into_transition ? place : transition_names[i]) + " " + std::string(op) + " " +
             (into_transition ? transition_names[i] : place);
      if (a.weight != 1) out += " * " + std::to_string(a.weight);
      out += ";\n";
    };
    for (const ArcRef& a : t.inputs) arc(a, "->", true);
    for (const ArcRef& a : t.outputs) arc(a, "->", false);
    for (const ArcRef& a : t.inhibitors) arc(a, "-o", true);
  }
  return out;
}

void write_soml_file(const PtNet& net, const std::filesystem::path& path, std::vector<std::string>* notes) {
  detail::write_text_file(path, write_soml(net, notes));
}

soml::Program& import_net(soml::Module& soml, SimState& state, const PtNet& net, std::vector<std::string>* notes) {
  std::string name = net.id().empty() ? std::string("net") : net.id();
  return soml.load(state, name + ".soml", write_soml(net, notes));
}

}  // namespace vsd::analysis
