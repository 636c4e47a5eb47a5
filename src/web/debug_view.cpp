#include "debug_view.hpp"

#include <algorithm>

#include "json.hpp"
#include "views.hpp"
#include "vsd/core/element_index.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/soml/net_classes.hpp"
#include "vsd/soml/runtime.hpp"

namespace vsd::web::detail {
namespace {

const char* reason_name(soml::StopReason r) {
  switch (r) {
    case soml::StopReason::Breakpoint:
      return "breakpoint";
    case soml::StopReason::Transition:
      return "transition";
    case soml::StopReason::Step:
      break;
  }
  return "step";
}

const char* kind_name(soml::FiringKind k) {
  switch (k) {
    case soml::FiringKind::Invoke:
      return "invoke";
    case soml::FiringKind::Finish:
      return "finish";
    case soml::FiringKind::Complete:
      return "complete";
    case soml::FiringKind::Plain:
      break;
  }
  return "plain";
}

soml::Resume parse_resume(const std::string& how) {
  if (how == "continue") return soml::Resume::Continue;
  if (how == "step") return soml::Resume::Step;
  if (how == "next") return soml::Resume::Next;
  if (how == "finish") return soml::Resume::Finish;
  throw Error("request: 'how' is '" + how.substr(0, 40) + "'; expected continue, step, next or finish");
}

Id id_of(const Node* n) { return n != nullptr ? n->id() : Id{0}; }

}  // namespace

/// One program of the state and the debugger attached to it (none when another debugger was first).
struct Debugging::Entry {
  std::uint64_t key = 0;  // the program's number in the API: 1, 2, ... in the order they were seen
  soml::Program* program = nullptr;
  std::unique_ptr<soml::Debugger> debugger;
  std::string error;  // why there is no debugger
};

Debugging::Debugging(Environment& env, SimState& state, std::size_t trace_capacity)
    : env_(env), state_(state), trace_capacity_(std::max<std::size_t>(trace_capacity, 1)) {
  sync();
}

Debugging::~Debugging() = default;

void Debugging::sync() {
  const std::vector<soml::Program*> now = programs_of(env_, state_);
  std::erase_if(entries_, [&](const std::unique_ptr<Entry>& e) {
    if (stop_ && stop_->entry == e.get()) return false;  // running: it cannot be gone
    const bool detached = e->debugger != nullptr && !e->debugger->attached();
    // A program made at the address of one that went is a new one: the detached entry goes first.
    return detached || std::find(now.begin(), now.end(), e->program) == now.end();
  });
  for (soml::Program* p : now) {
    const bool known = std::any_of(entries_.begin(), entries_.end(), [&](const auto& e) { return e->program == p; });
    if (known) continue;
    auto e = std::make_unique<Entry>();
    e->key = next_key_++;
    e->program = p;
    try {
      e->debugger = std::make_unique<soml::Debugger>(*p);
      Entry* raw = e.get();
      e->debugger->on_stop([this, raw](soml::Debugger&, const soml::Stop& s) { return stopped_at(*raw, s); });
      e->debugger->on_firing([this, raw](const soml::Firing& f) {
        Traced t{++trace_seq_, raw->key, f.step, id_of(f.transition), f.mark, id_of(f.from), id_of(f.to),
                 f.invocation, f.kind, {}, {}};
        for (const auto& m : f.taken) t.taken.emplace_back(id_of(m.place), m.count);
        for (const auto& m : f.given) t.given.emplace_back(id_of(m.place), m.count);
        trace_.push_back(std::move(t));
        if (trace_.size() > trace_capacity_) trace_.pop_front();
      });
    } catch (const Error& x) {  // another debugger is attached (the application's own)
      e->debugger.reset();
      e->error = x.what();
    }
    entries_.push_back(std::move(e));
  }
}

Debugging::Entry& Debugging::entry(std::uint64_t key) {
  for (auto& e : entries_)
    if (e->key == key) {
      if (e->debugger == nullptr) throw Error("program " + std::to_string(key) + " cannot be debugged here: " + e->error);
      return *e;
    }
  throw Error("no program " + std::to_string(key) + " (GET /api/debug lists them)");
}

Debugging::Entry& Debugging::only_or(const JsonObject& body) {
  if (body.find("program") != nullptr) return entry(body.id("program"));
  if (stop_) return *stop_->entry;
  if (entries_.size() == 1) return entry(entries_.front()->key);
  throw Error(entries_.empty() ? std::string("this state has no SOML++ program")
                               : "request: member 'program' is missing (the state has " +
                                     std::to_string(entries_.size()) + " programs)");
}

soml::Resume Debugging::stopped_at(Entry& e, const soml::Stop& s) {
  if (!wait || stop_) return soml::Resume::Continue;  // nobody could resume it
  stop_ = Stopped{&e, s, stop_json(e, s)};
  resume_.reset();
  // Whatever happens in wait(), the stop ends here.
  struct Clear {
    Debugging& d;
    ~Clear() {
      d.stop_.reset();
      d.resume_.reset();
    }
  } clear{*this};
  if (announce) announce("{\"stopped\":" + stop_->json + "}");
  wait();
  const soml::Resume how = resume_.value_or(soml::Resume::Continue);
  if (announce) announce("{\"stopped\":null}");
  return how;
}

std::string Debugging::stop_json(const Entry& e, const soml::Stop& s) const {
  const soml::Debugger& d = *e.debugger;
  JsonWriter out;
  out.begin_object()
      .member("program", e.key)
      .member("file", d.file())
      .member("reason", reason_name(s.reason))
      .member("breakpoint", s.breakpoint)
      .member("function", s.function)
      .member("line", static_cast<std::uint64_t>(s.line));
  out.key("transition");
  if (s.transition != nullptr)
    out.begin_object().member("id", s.transition->id()).member("label", soml::net_node_label(s.transition)).end_object();
  else
    out.null();
  out.member("mark", s.mark);
  out.key("stack").begin_array();
  const std::vector<soml::StackFrame> stack = d.call_stack();
  for (const auto& f : stack)
    out.begin_object()
        .member("function", f.function)
        .member("file", f.file)
        .member("line", static_cast<std::uint64_t>(f.line))
        .member("self", f.self)
        .member("mark", f.mark)
        .end_object();
  out.end_array().key("locals").begin_array();
  if (!stack.empty())
    for (const auto& v : d.locals(0))
      out.begin_object().member("name", v.name).member("type", v.type).member("value", v.value).end_object();
  out.end_array().end_object();
  return out.take();
}

void Debugging::write(JsonWriter& out) {
  // A program whose debugger could not attach is tried again: the other debugger may be gone.
  std::erase_if(entries_, [&](const auto& e) { return e->debugger == nullptr; });
  sync();
  out.begin_object().key("programs").begin_array();
  for (const auto& e : entries_) {
    out.begin_object().member("program", e->key).member("debuggable", e->debugger != nullptr);
    if (e->debugger == nullptr) {
      out.member("error", e->error).end_object();
      continue;
    }
    out.member("file", e->debugger->file()).key("breakpoints").begin_array();
    for (const auto& b : e->debugger->breakpoints()) {
      out.begin_object().member("id", b.id).member("hits", b.hits);
      if (b.transition.empty()) {
        out.member("line", static_cast<std::uint64_t>(b.line));
      } else {
        // The transitions it stops before (a bare name can stop several), for the page's nets view.
        out.member("transition", b.transition).key("transitions").begin_array();
        state_.index().for_each(soml::Transition::static_meta(), true, [&](SimStateInstance& i) {
          const auto& t = static_cast<const soml::Transition&>(i);
          if (t.name() == b.transition || soml::net_node_label(&t) == b.transition) out.number(t.id());
        });
        out.end_array();
      }
      out.end_object();
    }
    out.end_array().end_object();
  }
  out.end_array().key("stopped");
  if (stop_)
    out.raw(stop_->json);
  else
    out.null();
  out.member("trace", trace_seq_).end_object();
}

void Debugging::write_source(JsonWriter& out, std::uint64_t program) {
  sync();
  const soml::Debugger& d = *entry(program).debugger;
  out.begin_object().member("program", program).member("file", d.file()).member("text", d.source());
  out.key("lines").begin_array();
  for (std::uint32_t l : d.lines()) out.number(static_cast<std::uint64_t>(l));
  out.end_array().end_object();
}

void Debugging::write_locals(JsonWriter& out, std::size_t frame) const {
  if (!stop_) throw Error("no program is stopped: locals exist only at a stop");
  const soml::Debugger& d = *stop_->entry->debugger;
  const std::size_t depth = d.call_stack().size();
  if (frame >= depth)
    throw Error("frame " + std::to_string(frame) + " does not exist (the stack has " + std::to_string(depth) + ")");
  out.begin_object().member("frame", static_cast<std::uint64_t>(frame)).key("locals").begin_array();
  for (const auto& v : d.locals(frame))
    out.begin_object().member("name", v.name).member("type", v.type).member("value", v.value).end_object();
  out.end_array().end_object();
}

void Debugging::write_print(JsonWriter& out, const std::string& path, std::size_t frame) const {
  const soml::Debugger* d = nullptr;
  if (stop_)
    d = stop_->entry->debugger.get();
  else if (entries_.size() == 1 && entries_.front()->debugger != nullptr)
    d = entries_.front()->debugger.get();
  if (d == nullptr) throw Error("print needs a stopped program, or a state with exactly one program");
  out.begin_object().member("text", d->print(path, frame)).end_object();
}

void Debugging::write_entry(JsonWriter& out, const Traced& t) const {
  const auto label = [&](Id id) {
    const auto* n = id != 0 ? state_.find<Node>(id) : nullptr;
    return n != nullptr ? soml::net_node_label(n) : "#" + std::to_string(id);
  };
  out.begin_object()
      .member("seq", t.seq)
      .member("program", t.program)
      .member("firing", t.firing)
      .member("kind", kind_name(t.kind))
      .member("transition", t.transition)
      .member("label", label(t.transition))
      .member("mark", t.mark);
  const auto place = [&](const char* name, Id id) {
    out.key(name);
    if (id == 0)
      out.null();
    else
      out.begin_object().member("id", id).member("label", label(id)).end_object();
  };
  place("from", t.from);
  place("to", t.to);
  if (t.invocation != 0) out.member("invocation", t.invocation);
  const auto moves = [&](const char* name, const auto& list) {
    out.key(name).begin_array();
    for (const auto& [id, n] : list)
      out.begin_object().member("place", id).member("label", label(id)).member("tokens", n).end_object();
    out.end_array();
  };
  moves("taken", t.taken);
  moves("given", t.given);
  out.end_object();
}

void Debugging::write_trace(JsonWriter& out, std::uint64_t after, std::size_t limit) const {
  out.begin_object().member("newest", trace_seq_).member("oldest", trace_.empty() ? trace_seq_ : trace_.front().seq);
  out.key("entries").begin_array();
  std::size_t n = 0;
  for (const Traced& t : trace_) {
    if (t.seq <= after) continue;
    if (n++ == limit) break;
    write_entry(out, t);
  }
  out.end_array().end_object();
}

std::string Debugging::take_trace_event(std::size_t limit) {
  if (trace_seq_ == trace_pushed_) return {};
  std::size_t fresh = 0;
  for (auto it = trace_.rbegin(); it != trace_.rend() && it->seq > trace_pushed_; ++it) ++fresh;
  const std::uint64_t missed = trace_seq_ - trace_pushed_ - std::min<std::uint64_t>(fresh, limit);
  JsonWriter out;
  out.begin_object().member("skipped", missed).key("entries").begin_array();
  for (std::size_t k = trace_.size() - std::min(fresh, limit); k < trace_.size(); ++k) write_entry(out, trace_[k]);
  out.end_array().end_object();
  trace_pushed_ = trace_seq_;
  return out.take();
}

void Debugging::post(JsonWriter& out, const std::string& path, const JsonObject& body) {
  sync();
  if (path == "/api/debug/resume") {
    if (!stop_) throw Error("no program is stopped");
    resume_ = parse_resume(body.string("how"));
    out.begin_object().member("ok", true).end_object();
  } else if (path == "/api/debug/break") {
    if (body.find("line") != nullptr) {
      Entry& e = only_or(body);
      const Id line = body.id("line");
      if (line == 0 || line > 0xffffffffu) throw Error("request: 'line' must be a line number of the script");
      const int id = e.debugger->break_at_line(static_cast<std::uint32_t>(line));
      out.begin_object().member("ok", true).member("program", e.key).member("id", id).end_object();
      return;
    }
    const Id tid = body.id("transition");
    const auto* t = state_.find<soml::Transition>(tid);
    if (t == nullptr) throw Error("instance #" + std::to_string(tid) + " is not a transition of this state");
    const std::string label = soml::net_node_label(t);
    // The program whose nets have it (a bare request tries each).
    std::vector<Entry*> candidates;
    if (body.find("program") != nullptr)
      candidates.push_back(&entry(body.id("program")));
    else
      for (auto& e : entries_)
        if (e->debugger != nullptr) candidates.push_back(e.get());
    for (Entry* e : candidates) {
      try {
        const int id = e->debugger->break_on_transition(label);
        out.begin_object().member("ok", true).member("program", e->key).member("id", id).member("transition", label).end_object();
        return;
      } catch (const Error&) {
        if (candidates.size() == 1) throw;
      }
    }
    throw Error("no debugged program has transition '" + label + "'");
  } else if (path == "/api/debug/remove") {
    Entry& e = only_or(body);
    const Id id = body.id("id");
    if (id > 0x7fffffff || !e.debugger->remove(static_cast<int>(id)))
      throw Error("program " + std::to_string(e.key) + " has no breakpoint " + std::to_string(id));
    out.begin_object().member("ok", true).end_object();
  } else if (path == "/api/debug/pause") {
    if (stop_) throw Error("the program is stopped already");
    Entry& e = only_or(body);
    e.debugger->step_into_next(true);
    out.begin_object().member("ok", true).member("program", e.key).end_object();
  } else {
    throw Error("no such path: " + path);
  }
}

}  // namespace vsd::web::detail
