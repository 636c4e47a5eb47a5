// The SOML++ debugger (docs/soml.md, section 9). It costs nothing while it needs no stop: breakpoints
// and stepping patch OP_BREAK over the first instruction of the lines concerned in the code the VM runs
// (ProgramImpl::run_, a run-time copy; the program image's code stays the original), and the VM meets no
// extra test on any other instruction. The stop handler runs inside the VM's OP_BREAK (or before a firing),
// reads the frames and registers through the compiler's tables (line per instruction, locals with their slots
// and visible ranges), and says how to go on; the debugger then re-patches what the next stop needs.
#include "vsd/soml/debugger.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <unordered_set>

#include "program_impl.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/instance.hpp"
#include "vsd/core/node.hpp"
#include "vsd/core/reference.hpp"
#include "vsd/soml/source.hpp"

namespace vsd::soml {

namespace {

std::string quoted(const std::string& s) {
  std::string q = "\"";
  for (const char c : s) {
    switch (c) {
      case '"':
        q += "\\\"";
        break;
      case '\\':
        q += "\\\\";
        break;
      case '\n':
        q += "\\n";
        break;
      case '\t':
        q += "\\t";
        break;
      default:
        q += c;
    }
  }
  return q + "\"";
}

// A value as the debugger shows it: a vector of enums as its enums are shown ("[Mode::Idle, Mode::Run]",
// without the "soml::" of script enums), structs and vectors of them as print shows them
// ("Vector3d(1, 2, 3)"), anything else as the type writes it.
std::string shown_text(const MetaType& t, const void* addr) {
  const MetaType* et = t.kind() == TypeKind::Vector ? t.element() : nullptr;
  if (t.kind() == TypeKind::Struct || (et != nullptr && et->kind() == TypeKind::Struct))
    return value_text(Value(t, addr));
  if (et == nullptr || et->kind() != TypeKind::Enum) return t.to_text(addr);
  std::string name = et->name();
  if (name.rfind("soml::", 0) == 0) name = name.substr(6);
  std::string s = "[";
  Value e(*et);
  for (std::size_t i = 0, n = t.vector_size(addr); i < n; ++i) {
    t.vector_get(addr, i, e.data());
    const std::int64_t v = et->load_integer(e.data());
    const std::string_view label = et->enum_name(v);
    s += (i != 0 ? ", " : "") + (label.empty() ? std::to_string(v) : name + "::" + std::string(label));
  }
  return s + "]";
}

bool is_ident(std::string_view s) {
  if (s.empty() || (std::isdigit(static_cast<unsigned char>(s[0])) != 0)) return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; });
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())) != 0) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())) != 0) s.remove_suffix(1);
  return s;
}

bool is_jump(std::uint8_t op) {
  return op != OP_RESUME && op_jumps(op);  // OP_RESUME only ever runs from a trampoline
}

}  // namespace

std::string net_node_label(const vsd::Node* n) {
  if (n == nullptr) return "-";
  const vsd::Node* owner = n->parent();
  const bool script_level =
      owner != nullptr && owner->parent() != nullptr && owner->parent()->parent() == nullptr;
  return (owner != nullptr && !script_level ? owner->name() + "." : std::string()) + n->name();
}

class Debugger::Impl final : public DebugHooks {
 public:
  Impl(Debugger& d, Program& p) : self_(d), program_(p), P_(p.impl()) {
    if (P_.debug_ != nullptr) throw Error("SOML++ debugger: another debugger is attached to this program");
    P_.debug_ = this;
    previous_trace_ = P_.trace_;
    P_.trace_ = [this](const Firing& f) {
      if (previous_trace_) previous_trace_(f);
      if (trace_) trace_(f);
    };
  }
  ~Impl() override { detach(); }
  void on_program_gone() noexcept override { detach(); }
  // Restores the program's code and trace, once; afterwards P_ and program_ are never used again.
  void detach() noexcept {
    if (gone_) return;
    gone_ = true;
    for (RunCode& rc : P_.run_) {
      if (!rc.patched) continue;
      rc.code = rc.fn->code;  // (the same size: frames that point into it stay valid)
      rc.patched = false;
    }
    P_.trace_ = previous_trace_;
    P_.debug_ = nullptr;
  }
  // Every call that reads or changes the program goes through here.
  ProgramImpl& live() const {
    if (gone_) throw Error("SOML++ debugger: the program it was attached to is gone");
    return P_;
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  enum class Mode : std::uint8_t { Run, Step, Next, Finish };

  Debugger& self_;
  Program& program_;
  ProgramImpl& P_;
  std::vector<Breakpoint> bps_;
  int next_id_ = 1;
  std::function<Resume(Debugger&, const Stop&)> handler_;
  std::function<void(const Firing&)> trace_, previous_trace_;
  Mode mode_ = Mode::Run;
  // Where the last stop was (a step ends at a line start that differs from it).
  const Function* stop_fn_ = nullptr;
  std::size_t stop_at_ = 0, stop_depth_ = 0;
  std::uint32_t stop_line_ = 0;
  bool in_stop_ = false;
  vsd::Id stop_mark_ = 0;        // at a transition breakpoint: its mark
  vsd::Id stop_transition_ = 0;  // and the transition
  bool stepping_patched_ = false;
  bool gone_ = false;  // the program was destroyed: detached for good
  // Per function: 1 where a line's run of instructions starts, 2 where a jump lands inside a line.
  std::vector<std::vector<std::uint8_t>> starts_;

  const std::vector<std::uint8_t>& starts(std::size_t fi) {
    if (starts_.size() < P_.image().functions.size()) starts_.resize(P_.image().functions.size());
    auto& s = starts_[fi];
    const Function& f = *P_.image().functions[fi];
    if (s.size() == f.code.size()) return s;
    const std::vector<Ins>& code = f.code;  // the image's: never patched
    s.assign(code.size(), 0);
    for (std::size_t i = 0; i < code.size(); ++i) {
      if (is_jump(code[i].op)) {
        const std::size_t t = (static_cast<std::size_t>(code[i].x) << 16) | code[i].c;
        if (t < s.size()) s[t] = 2;
      }
    }
    for (std::size_t i = 0; i < code.size(); ++i) {
      if (i < f.lines.size() && f.lines[i] == 0) {
        s[i] = 0;  // code without a line (a function's frame set-up) is never a stop
      } else if (i == 0 || f.lines[i] != f.lines[i - 1]) {
        s[i] = 1;
      }
    }
    return s;
  }

  // Patches OP_BREAK over every line start when stepping, else over the starts of breakpoint lines
  // only; restores everything else.
  void repatch() {
    std::unordered_set<std::uint32_t> lines;
    for (const Breakpoint& b : bps_)
      if (b.line != 0) lines.insert(b.line);
    const bool stepping = mode_ != Mode::Run;
    for (std::size_t fi = 0; fi < P_.image().functions.size(); ++fi) {
      const Function& f = *P_.image().functions[fi];
      RunCode& rc = P_.run_[fi];
      if (f.code.empty()) continue;
      const auto& s = starts(fi);
      bool any = false;
      for (std::size_t i = 0; i < s.size() && !any; ++i)
        any = s[i] != 0 && (stepping || (s[i] == 1 && lines.count(f.lines[i]) != 0));
      if (!any && !rc.patched) continue;
      if (!rc.patched) {
        rc.patched = true;
        rc.tramp.resize(2 * f.code.size());
        for (std::size_t i = 0; i < f.code.size(); ++i) {
          rc.tramp[2 * i] = f.code[i];
          rc.tramp[2 * i + 1] = Ins{OP_RESUME, static_cast<std::uint8_t>((i + 1) >> 16), 0, 0,
                                    static_cast<std::uint16_t>((i + 1) & 0xFFFF)};
        }
      }
      for (std::size_t i = 0; i < s.size(); ++i) {
        const bool want =
            s[i] != 0 && f.code[i].op != OP_JMP && (stepping || (s[i] == 1 && lines.count(f.lines[i]) != 0));
        rc.code[i] = f.code[i];
        if (want) rc.code[i].op = OP_BREAK;
      }
    }
    stepping_patched_ = stepping;
  }

  void set_mode(Mode m) {
    const bool was = mode_ != Mode::Run;
    mode_ = m;
    if (was != (m != Mode::Run) || was != stepping_patched_) repatch();
  }

  bool moved(const Function& f, std::size_t at, std::size_t depth, std::uint32_t line) const {
    return &f != stop_fn_ || depth != stop_depth_ || line != stop_line_ || at <= stop_at_;
  }

  void on_break(const Function& f, std::size_t at) override {
    if (in_stop_) return;  // the handler must not run code; if it does, it is not debugged
    const std::size_t depth = P_.frames_.size();
    const std::uint32_t line = at < f.lines.size() ? f.lines[at] : 0;
    const std::size_t fi = index_of(f);
    const bool run_start = fi < P_.image().functions.size() && starts(fi)[at] == 1;
    int hit = 0;
    if (run_start)
      for (Breakpoint& b : bps_)
        if (b.line == line && b.line != 0) {
          hit = b.id;
          ++b.hits;
          break;
        }
    bool stop = hit != 0;
    if (!stop) {
      switch (mode_) {
        case Mode::Run:
          break;
        case Mode::Step:
          stop = moved(f, at, depth, line);
          break;
        case Mode::Next:
          stop = depth <= stop_depth_ && moved(f, at, depth, line);
          break;
        case Mode::Finish:
          // Out of the frame, or (the frame was outermost) the next run of code after it.
          stop = depth < stop_depth_ || (stop_depth_ <= 1 && (&f != stop_fn_ || at <= stop_at_));
          break;
      }
    }
    if (!stop) return;
    Stop s;
    s.reason = hit != 0 ? StopReason::Breakpoint : StopReason::Step;
    s.breakpoint = hit;
    s.function = f.name;
    s.line = line;
    const Resume r = deliver(s);
    stop_fn_ = &f;
    stop_at_ = at;
    stop_depth_ = depth;
    stop_line_ = line;
    resume(r);
  }

  void on_fire(const Transition& t, std::uint64_t mark) override {
    if (in_stop_) return;
    int hit = 0;
    const std::string label = net_node_label(&t);
    for (Breakpoint& b : bps_)
      if (!b.transition.empty() && (b.transition == label || b.transition == t.name())) {
        hit = b.id;
        ++b.hits;
        break;
      }
    if (hit == 0) return;
    Stop s;
    s.reason = StopReason::Transition;
    s.breakpoint = hit;
    s.transition = &t;
    s.mark = mark;
    stop_mark_ = mark;
    stop_transition_ = t.id();
    const Resume r = deliver(s);
    stop_mark_ = 0;
    stop_transition_ = 0;
    // From a firing, any line is a new one: step and next stop in its action (next: not in calls).
    stop_fn_ = nullptr;
    stop_at_ = 0;
    stop_depth_ = 1;
    stop_line_ = 0;
    resume(r == Resume::Finish ? Resume::Continue : r);
  }

  Resume deliver(const Stop& s) {
    if (!handler_) return Resume::Continue;
    in_stop_ = true;
    try {
      const Resume r = handler_(self_, s);
      in_stop_ = false;
      return r;
    } catch (...) {
      in_stop_ = false;
      throw;
    }
  }

  void resume(Resume r) {
    switch (r) {
      case Resume::Continue:
        set_mode(Mode::Run);
        break;
      case Resume::Step:
        set_mode(Mode::Step);
        break;
      case Resume::Next:
        set_mode(Mode::Next);
        break;
      case Resume::Finish:
        set_mode(Mode::Finish);
        break;
    }
  }

  std::size_t index_of(const Function& f) const {
    for (std::size_t i = 0; i < P_.image().functions.size(); ++i)
      if (P_.image().functions[i].get() == &f) return i;
    return P_.image().functions.size();
  }

  // ---- reading the stopped program ----

  const Frame& frame(std::size_t k) const {
    if (!in_stop_) throw Error("SOML++ debugger: the program is not stopped");
    if (k >= P_.frames_.size())
      throw Error("SOML++ debugger: no frame " + std::to_string(k) + " (the stack has " +
                  std::to_string(P_.frames_.size()) + ")");
    return P_.frames_[P_.frames_.size() - 1 - k];
  }
  static std::size_t pc_of(const Frame& f) { return pc_index(f); }

  std::string instance_label(std::uint64_t id) const {
    if (id == 0) return "null";
    const SimStateInstance* o = P_.state_.find(id);
    if (o == nullptr) return "<deleted #" + std::to_string(id) + ">";
    const auto* n = o->as<NamedModelInstance>();
    if (n != nullptr && !n->name().empty()) return n->name();
    return o->meta().name() + "#" + std::to_string(id);
  }

  std::string register_text(const Type& t, const Val& v, const std::string& s, const VecReg& vr,
                            const Value& x) const {
    using K = Type::Kind;
    if (reg_kind(t) == RK::X) return x.empty() ? "<" + t.name() + ">" : shown_text(*x.type(), x.data());
    switch (t.kind) {
      case K::Vector:
        if (t.meta != nullptr && vector_elem_kind(*t.meta) != RK::None) return vector_text(*t.meta, vr);
        return "<" + t.name() + ">";
      case K::Bool:
        return v.i != 0 ? "true" : "false";
      case K::Int:
        return std::to_string(v.i);
      case K::Double:
        return fmt_double(v.d);
      case K::String:
        return quoted(s);
      case K::Enum:
        if (t.enum_decl != nullptr && v.i >= 0 && static_cast<std::size_t>(v.i) < t.enum_decl->values.size())
          return t.enum_decl->name + "::" + t.enum_decl->values[static_cast<std::size_t>(v.i)];
        if (t.meta != nullptr && !t.meta->enum_name(v.i).empty())
          return t.meta->name() + "::" + std::string(t.meta->enum_name(v.i));
        return std::to_string(v.i);
      case K::Ref:
      case K::Null:
        return instance_label(v.id);
      default:
        return "<" + t.name() + ">";
    }
  }

  std::string property_text(const SimStateInstance& o, const MetaProperty& p) const {
    const MetaType& t = p.type();
    const void* addr = p.address(o);
    switch (t.kind()) {
      case TypeKind::String:
        return quoted(*static_cast<const std::string*>(addr));
      case TypeKind::Double:
        return fmt_double(*static_cast<const double*>(addr));
      case TypeKind::Float:
        return fmt_double(*static_cast<const float*>(addr));
      case TypeKind::Bool:
        return *static_cast<const bool*>(addr) ? "true" : "false";
      case TypeKind::Enum: {
        const std::int64_t v = t.load_integer(addr);
        const std::string_view n = t.enum_name(v);
        std::string name = t.name();
        if (name.rfind("soml::", 0) == 0) name = name.substr(6);
        return n.empty() ? std::to_string(v) : name + "::" + std::string(n);
      }
      case TypeKind::Ref: {
        const SimStateInstance* r = static_cast<const RefBase*>(addr)->get();
        return instance_label(r != nullptr ? r->id() : 0);
      }
      default:
        if (t.is_reference()) {
          const SimStateInstance* r = static_cast<const RefBase*>(addr)->get();
          return instance_label(r != nullptr ? r->id() : 0);
        }
        if (t.kind() == TypeKind::RefList) {
          const auto& l = *static_cast<const RefListBase*>(addr);
          std::string s = "[";
          for (std::size_t i = 0; i < l.size(); ++i) {
            const SimStateInstance* e = l.at(i);
            s += (i != 0 ? ", " : "") + instance_label(e != nullptr ? e->id() : 0);
          }
          return s + "]";
        }
        return shown_text(t, addr);
    }
  }

  static std::string place_text(const Place& p) {
    if (!p.object_tokens()) return std::to_string(p.tokens());
    std::string s = "[";
    for (std::size_t i = 0; i < p.objects().size(); ++i) {
      const Node* n = p.objects()[i];
      s += (i != 0 ? ", " : "") + (n == nullptr        ? std::string("null")
                                   : n->name().empty() ? "#" + std::to_string(n->id())
                                                       : n->name());
    }
    return s + "]";
  }

  // An instance, as print shows it: a place's marking, or the instance's label and its properties.
  std::string instance_text(std::uint64_t id) const {
    if (id == 0) return "null";
    const SimStateInstance* o = P_.state_.find(id);
    if (o == nullptr) return "<deleted #" + std::to_string(id) + ">";
    if (const Place* p = o->as<Place>()) return net_node_label(p) + " = " + place_text(*p);
    std::string s = instance_label(id) + " (" + o->meta().name() + ") {";
    bool first = true;
    for (const MetaProperty* p : o->meta().properties()) {
      if (p->name() == "name" || p->name() == "children" || p->name() == "extensions") continue;
      s += (first ? "" : ", ") + p->name() + " = " + property_text(*o, *p);
      first = false;
    }
    return s + "}";
  }
};

Debugger::Debugger(Program& program) : impl_(std::make_unique<Impl>(*this, program)) {}
Debugger::~Debugger() = default;

int Debugger::break_at_line(std::uint32_t line) {
  ProgramImpl& P = impl_->live();
  bool found = false;
  std::uint32_t before = 0, after = 0;
  for (std::size_t fi = 0; fi < P.image().functions.size(); ++fi) {
    const Function& f = *P.image().functions[fi];
    const auto& s = impl_->starts(fi);
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s[i] != 1) continue;
      const std::uint32_t l = f.lines[i];
      if (l == line) found = true;
      if (l < line && l > before) before = l;
      if (l > line && (after == 0 || l < after)) after = l;
    }
  }
  const std::string& file = P.image().checked->source->name();
  if (!found) {
    std::string near;
    if (before != 0) near += " " + std::to_string(before);
    if (after != 0) near += (near.empty() ? " " : " and ") + std::to_string(after);
    throw Error("SOML++ debugger: no code on " + file + ":" + std::to_string(line) +
                (near.empty() ? std::string(" (the script runs no code)")
                              : " (the nearest lines with code:" + near + ")"));
  }
  Breakpoint b;
  b.id = impl_->next_id_++;
  b.line = line;
  impl_->bps_.push_back(b);
  impl_->repatch();
  return b.id;
}

int Debugger::break_at(std::string_view location) {
  location = trim(location);
  const auto colon = location.rfind(':');
  const std::string_view file =
      colon == std::string_view::npos ? std::string_view() : location.substr(0, colon);
  const std::string_view num = colon == std::string_view::npos ? location : location.substr(colon + 1);
  std::uint32_t line = 0;
  const auto r = std::from_chars(num.data(), num.data() + num.size(), line);
  if (num.empty() || r.ec != std::errc() || r.ptr != num.data() + num.size() || line == 0)
    throw Error("SOML++ debugger: '" + std::string(location) + "' is not FILE:LINE or LINE");
  if (!file.empty()) {
    const std::string& name = impl_->live().image().checked->source->name();
    const auto slash = name.find_last_of('/');
    const std::string base = slash == std::string::npos ? name : name.substr(slash + 1);
    if (file != name && file != base)
      throw Error("SOML++ debugger: '" + std::string(file) + "' is not the script debugged (" + name + ")");
  }
  return break_at_line(line);
}

int Debugger::break_on_transition(std::string_view name) {
  name = trim(name);
  bool found = false;
  for (const auto& [owner, net] : impl_->live().nets_) {
    (void)owner;
    for (const Transition* t : net->transitions)
      if (net_node_label(t) == name || t->name() == name) found = true;
  }
  if (!found) throw Error("SOML++ debugger: no transition '" + std::string(name) + "'");
  Breakpoint b;
  b.id = impl_->next_id_++;
  b.transition = std::string(name);
  impl_->bps_.push_back(b);
  return b.id;
}

bool Debugger::remove(int id) {
  (void)impl_->live();
  auto& v = impl_->bps_;
  auto it = std::find_if(v.begin(), v.end(), [&](const Breakpoint& b) { return b.id == id; });
  if (it == v.end()) return false;
  v.erase(it);
  impl_->repatch();
  return true;
}

const std::vector<Breakpoint>& Debugger::breakpoints() const noexcept { return impl_->bps_; }

void Debugger::on_stop(std::function<Resume(Debugger&, const Stop&)> fn) { impl_->handler_ = std::move(fn); }

void Debugger::step_into_next(bool on) {
  (void)impl_->live();
  impl_->stop_fn_ = nullptr;
  impl_->stop_depth_ = 0;
  impl_->stop_line_ = 0;
  impl_->set_mode(on ? Impl::Mode::Step : Impl::Mode::Run);
}

void Debugger::on_firing(std::function<void(const Firing&)> fn) { impl_->trace_ = std::move(fn); }

bool Debugger::stopped() const noexcept { return impl_->in_stop_; }

std::vector<StackFrame> Debugger::call_stack() const {
  std::vector<StackFrame> out;
  if (!impl_->in_stop_ || impl_->gone_) return out;
  const ProgramImpl& P = impl_->P_;
  for (std::size_t k = 0; k < P.frames_.size(); ++k) {
    const Frame& f = impl_->frame(k);
    const std::size_t at = Impl::pc_of(f);
    StackFrame s;
    s.function = f.fn->name;
    s.file = P.image().checked->source->name();
    s.line = at < f.fn->lines.size() ? f.fn->lines[at] : 0;
    s.self = f.self;
    s.mark = f.mark;
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<Variable> Debugger::locals(std::size_t k) const {
  (void)impl_->live();
  const Frame& f = impl_->frame(k);
  const ProgramImpl& P = impl_->P_;
  const std::size_t at = Impl::pc_of(f);
  std::vector<Variable> out;
  for (const Function::Local& l : f.fn->locals) {
    if (at < l.from || at >= l.to) continue;
    const std::size_t r = f.base + static_cast<std::size_t>(l.slot);
    Variable v;
    v.name = l.name;
    v.type = l.type.name();
    v.value = impl_->register_text(l.type, P.regs_[r], P.sregs_[r], P.vregs_[r], P.xregs_[r]);
    // A later local of the same name (an inner block) hides an earlier one.
    auto same = std::find_if(out.begin(), out.end(), [&](const Variable& o) { return o.name == v.name; });
    if (same != out.end())
      *same = std::move(v);
    else
      out.push_back(std::move(v));
  }
  return out;
}

std::string Debugger::print(std::string_view path, std::size_t k) const {
  const ProgramImpl& P = impl_->live();
  const std::string text(trim(path));
  std::vector<std::string> parts;
  for (std::size_t from = 0;;) {
    const auto dot = text.find('.', from);
    parts.push_back(std::string(trim(std::string_view(text).substr(from, dot - from))));
    if (dot == std::string::npos) break;
    from = dot + 1;
  }
  for (const auto& p : parts)
    if (!is_ident(p))
      throw Error("SOML++ debugger: '" + text +
                  "' is not a name or a path (print takes a local, this, mark, a property or an object, "
                  "with .member steps)");
  const bool framed = impl_->in_stop_ && !P.frames_.empty();
  const Frame* f = framed ? &impl_->frame(k) : nullptr;
  std::uint64_t self = f != nullptr                   ? f->self
                       : impl_->stop_transition_ != 0 ? impl_->stop_transition_
                                                      : impl_->program_.root().id();
  const std::uint64_t mark = f != nullptr ? f->mark : impl_->stop_mark_;

  // The first name: a local, this, mark, a member of the frame's instance or an enclosing one, an object.
  std::uint64_t cur = 0;
  std::string value;
  bool is_instance = false;
  const std::string& first = parts[0];
  if (f != nullptr) {
    const std::size_t at = Impl::pc_of(*f);
    const Function::Local* found = nullptr;
    for (const Function::Local& l : f->fn->locals)
      if (l.name == first && at >= l.from && at < l.to) found = &l;
    if (found != nullptr) {
      const std::size_t r = f->base + static_cast<std::size_t>(found->slot);
      if (found->type.kind == Type::Kind::Ref) {
        cur = P.regs_[r].id;
        is_instance = true;
      } else {
        value = impl_->register_text(found->type, P.regs_[r], P.sregs_[r], P.vregs_[r], P.xregs_[r]);
      }
      if (!is_instance && parts.size() > 1)
        throw Error("SOML++ debugger: '" + first + "' is a " + found->type.name() + ", it has no members");
    }
  }
  if (value.empty() && !is_instance) {
    if (first == "this") {
      cur = self;
      is_instance = true;
    } else if (first == "mark") {
      if (mark == 0) throw Error("SOML++ debugger: there is no mark here");
      cur = mark;
      is_instance = true;
    } else {
      // Members of the frame's instance, then of the instances around it (a transition's object, ...).
      for (const SimStateInstance* o = P.state_.find(self); o != nullptr && value.empty() && !is_instance;) {
        if (const MetaProperty* mp = o->meta().find_property(first)) {
          if (mp->type().is_reference()) {
            const SimStateInstance* r = static_cast<const RefBase*>(mp->address(*o))->get();
            cur = r != nullptr ? r->id() : 0;
            is_instance = true;
          } else {
            value = impl_->property_text(*o, *mp);
            if (parts.size() > 1)
              throw Error("SOML++ debugger: '" + first + "' is a " + mp->type().name() +
                          ", it has no members");
          }
          break;
        }
        const Node* n = o->as<Node>();
        if (n != nullptr && n->find_child(first) != nullptr) {
          cur = n->find_child(first)->id();
          is_instance = true;
          break;
        }
        o = n != nullptr ? n->parent() : nullptr;
      }
      if (value.empty() && !is_instance) {
        if (const Node* obj = impl_->program_.object(first)) {
          cur = obj->id();
          is_instance = true;
        }
      }
      if (value.empty() && !is_instance)
        throw Error("SOML++ debugger: no local, property or object '" + first + "'");
    }
  }
  // The steps.
  std::string walked = first;
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const SimStateInstance* o = cur == 0 ? nullptr : P.state_.find(cur);
    if (o == nullptr) throw Error("SOML++ debugger: '" + walked + "' is null");
    const std::string& m = parts[i];
    if (const MetaProperty* mp = o->meta().find_property(m)) {
      if (mp->type().is_reference()) {
        const SimStateInstance* r = static_cast<const RefBase*>(mp->address(*o))->get();
        cur = r != nullptr ? r->id() : 0;
      } else {
        if (i + 1 < parts.size())
          throw Error("SOML++ debugger: '" + walked + "." + m + "' is a " + mp->type().name() +
                      ", it has no members");
        return walked + "." + m + " = " + impl_->property_text(*o, *mp);
      }
    } else if (const Node* n = o->as<Node>(); n != nullptr && n->find_child(m) != nullptr) {
      cur = n->find_child(m)->id();
    } else {
      throw Error("SOML++ debugger: " + o->meta().name() + " '" + walked + "' has no member '" + m + "'");
    }
    walked += "." + m;
  }
  if (!is_instance) return text + " = " + value;
  const SimStateInstance* o = cur == 0 ? nullptr : P.state_.find(cur);
  if (o != nullptr && o->as<Place>() != nullptr) return impl_->instance_text(cur);
  return walked + " = " + impl_->instance_text(cur);
}

std::string Debugger::marking() const {
  (void)impl_->live();
  std::string s;
  for (const Place* p : impl_->program_.places())
    s += net_node_label(p) + " = " + Impl::place_text(*p) + "\n";
  return s;
}

Program& Debugger::program() const {
  (void)impl_->live();
  return impl_->program_;
}

bool Debugger::attached() const noexcept { return !impl_->gone_; }

const std::string& Debugger::source() const { return impl_->live().image().checked->source->text(); }

const std::string& Debugger::file() const { return impl_->live().image().checked->source->name(); }

std::vector<std::uint32_t> Debugger::lines() const {
  const ProgramImpl& P = impl_->live();
  std::vector<std::uint32_t> out;
  for (std::size_t fi = 0; fi < P.image().functions.size(); ++fi) {
    const auto& s = impl_->starts(fi);
    for (std::size_t i = 0; i < s.size(); ++i)
      if (s[i] == 1) out.push_back(P.image().functions[fi]->lines[i]);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace vsd::soml
