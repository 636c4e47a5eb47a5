#include "inspector.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <exception>
#include <string>

#include "json.hpp"
#include "views.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/extension.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/meta_instance.hpp"
#include "vsd/core/meta_method.hpp"
#include "vsd/core/meta_property.hpp"
#include "vsd/core/node.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/core/text.hpp"
#include "vsd/core/value.hpp"

namespace vsd::web::detail {
namespace {

/// Values longer than this travel as `null` with `"truncated": true` (a mesh's vertices, a long log):
/// the page asks for what it draws (/api/mesh), not for megabytes in a table cell.
constexpr std::size_t max_value_text = 64 * 1024;
/// Rows of one /api/table or /api/children page; entries of /api/timeline.
constexpr std::size_t max_rows = 1000;
constexpr std::size_t max_timeline = 10000;
constexpr std::size_t max_trace = 1000;  // token-trace entries per answer or event

class StateResolver final : public RefResolver {
 public:
  explicit StateResolver(const SimState& s) : s_(s) {}
  SimStateInstance* resolve(Id id) const override { return s_.find(id); }

 private:
  const SimState& s_;
};

std::string describe(const SimStateInstance& i) {
  std::string s = "#" + std::to_string(i.id()) + " (" + i.meta().name();
  if (const auto* n = i.as<NamedModelInstance>(); n != nullptr && !n->name().empty()) s += " '" + n->name() + "'";
  return s + ")";
}

const char* kind_of(const MetaType& t) {
  switch (t.kind()) {
    case TypeKind::Ref:
    case TypeKind::SharedRef:
      return "ref";
    case TypeKind::RefList:
    case TypeKind::SharedRefList:
      return "list";
    default:
      return "value";
  }
}

bool numeric(const MetaType& t) {
  switch (t.kind()) {
    case TypeKind::Bool:
    case TypeKind::Int:
    case TypeKind::UInt:
    case TypeKind::Float:
    case TypeKind::Double:
      return true;
    default:
      return false;
  }
}

bool editable(const MetaProperty& p) { return p.has(Editable) && !p.has(ReadOnly); }

void write_flags(JsonWriter& out, const MetaProperty& p) {
  out.begin_array();
  if (p.has(Editable)) out.string("Editable");
  if (p.has(Savable)) out.string("Savable");
  if (p.has(Distributed)) out.string("Distributed");
  if (p.has(ReadOnly)) out.string("ReadOnly");
  if (p.has(Transient)) out.string("Transient");
  out.end_array();
}

/// The value of @p p as JSON; a too long one as null (and says so through @p truncated).
void write_value(JsonWriter& out, const SimStateInstance& i, const MetaProperty& p, bool* truncated = nullptr) {
  std::string text;
  p.type().write_text(p.address(i), text);
  if (text.size() > max_value_text) {
    out.null();
    if (truncated != nullptr) *truncated = true;
    return;
  }
  out.raw(text);
}

/// `"parent": id` of a node's parent, `null` for a node without one and for what is not a node.
void write_parent(JsonWriter& out, const SimStateInstance& i) {
  out.key("parent");
  const Node* parent = i.as<Node>() != nullptr ? static_cast<const Node&>(i).parent() : nullptr;
  if (parent != nullptr)
    out.number(parent->id());
  else
    out.null();
}

void write_method(JsonWriter& out, const MetaMethod& m) {
  out.begin_object().member("name", m.name()).key("params").begin_array();
  for (std::size_t k = 0; k < m.arguments().size(); ++k)
    out.begin_object().member("name", "arg" + std::to_string(k)).member("type", m.arguments()[k]->name()).end_object();
  out.end_array();
  if (m.result() != nullptr)
    out.member("result", m.result()->name());
  else
    out.key("result").null();
  out.end_object();
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::optional<double> to_number(std::string_view s) {
  s = trim(s);
  if (s == "true") return 1.0;
  if (s == "false") return 0.0;
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
  return v;
}

/// A `where` filter of /api/table: terms `property op value` joined by `&&`.
class Filter {
 public:
  Filter(const MetaInstance& cls, std::string_view text) {
    while (!trim(text).empty()) {
      const std::size_t amp = text.find("&&");
      parse(cls, trim(text.substr(0, amp)));
      if (amp == std::string_view::npos) break;
      text.remove_prefix(amp + 2);
    }
  }
  [[nodiscard]] bool matches(const SimStateInstance& i) const {
    for (const Term& t : terms_) {
      // A subclass instance answers for the class's property; one of another class lacks it.
      std::string text;
      t.property->type().write_text(t.property->address(i), text);
      if (t.property->type().kind() == TypeKind::String && text.size() >= 2) {
        TextReader r(text);
        text = r.string();  // compare the string, not its JSON quoting
      }
      if (t.op == "~") {
        if (text.find(t.value) == std::string::npos) return false;
        continue;
      }
      if (t.number) {
        const std::optional<double> v = to_number(text);
        if (!v) return false;
        const double a = *v, b = *t.number;
        const bool ok = t.op == "==" ? a == b : t.op == "!=" ? a != b : t.op == "<" ? a < b
                      : t.op == "<=" ? a <= b : t.op == ">" ? a > b : a >= b;
        if (!ok) return false;
        continue;
      }
      const bool eq = text == t.value;
      if ((t.op == "==" && !eq) || (t.op == "!=" && eq)) return false;
    }
    return true;
  }

 private:
  struct Term {
    const MetaProperty* property;
    std::string op;
    std::string value;
    std::optional<double> number;
  };
  void parse(const MetaInstance& cls, std::string_view term) {
    static constexpr std::string_view ops[] = {">=", "<=", "==", "!=", "~", "<", ">"};
    std::size_t at = std::string_view::npos;
    std::string_view op;
    for (std::string_view o : ops) {
      const std::size_t k = term.find(o);
      if (k != std::string_view::npos && (at == std::string_view::npos || k < at)) {
        at = k;
        op = o;
      }
    }
    if (at == std::string_view::npos)
      throw Error("filter: '" + std::string(term) + "' is not 'property op value' (op: == != < <= > >= ~)");
    const std::string_view name = trim(term.substr(0, at));
    const MetaProperty* p = cls.find_property(name);
    if (p == nullptr) throw Error("filter: class " + cls.name() + " has no property '" + std::string(name) + "'");
    std::string_view value = trim(term.substr(at + op.size()));
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"') value = value.substr(1, value.size() - 2);
    Term t{p, std::string(op), std::string(value), std::nullopt};
    if (op != "~" && numeric(p->type())) {
      t.number = to_number(value);
      if (!t.number)
        throw Error("filter: property '" + std::string(name) + "' is a number (" + p->type().name() +
                    "), '" + std::string(value) + "' is not");
    } else if (op != "~" && op != "==" && op != "!=") {
      throw Error("filter: '" + std::string(op) + "' compares numbers; property '" + std::string(name) +
                  "' is " + p->type().name());
    }
    terms_.push_back(std::move(t));
  }
  std::vector<Term> terms_;
};

}  // namespace

const std::string* Request::param(std::string_view name) const noexcept {
  for (const auto& [k, v] : query)
    if (k == name) return &v;
  return nullptr;
}

Reply Reply::error(int status, std::string_view message) {
  JsonWriter out;
  out.begin_object().member("error", message).end_object();
  return Reply{status, out.take()};
}

Inspector::Inspector(Environment& env, SimState& state, const Options& options, Feed& feed)
    : env_(env),
      state_(state),
      options_(options),
      feed_(feed),
      timeline_(state, options.timeline_bytes),
      watch_(state, Watch::Granularity::per_property) {
  const MetaInstance& all = SimStateInstance::static_meta();
  watch_.all_properties(all).created(all).deleted(all);
  watch_.reparented(Node::static_meta()).reparented(Extension::static_meta());
  // The nets view reads the enabled transitions from the state: make them current for a program that
  // was loaded but not stepped yet.
  refresh_programs(env, state);
  if (options.debug) {
    debug_ = std::make_unique<Debugging>(env, state, options.trace_entries);
    debug_->announce = [this](const std::string& json) {
      publish(true);  // the changes up to the stop first: the page shows the state the program stopped in
      (void)feed_.broadcast(make_event("debug", json));
    };
  }
  last_stats_ = std::chrono::steady_clock::now();
  stats_steps_ = env.scheduler().steps();
  stats_firings_ = firings(env, state);
}

Inspector::~Inspector() = default;

Event Inspector::hello() const {
  JsonWriter out;
  out.begin_object()
      .member("step", env_.scheduler().steps())
      .member("time", env_.time())
      .member("seq", seq_)
      .member("state", state_.name())
      .end_object();
  return make_event("hello", out.str());
}

SimStateInstance& Inspector::find(Id id) const {
  SimStateInstance* i = state_.find(id);
  if (i == nullptr) throw Error("no instance #" + std::to_string(id) + " in state '" + state_.name() + "'");
  return *i;
}

Reply Inspector::handle(const Request& r) {
  try {
    if (r.method == "GET") return get(r);
    if (r.method == "POST") {
      if (!r.writable) return Reply::error(403, "writing needs the token (header X-VSD-Token)");
      // Stopped in the middle of a firing: nothing may run or change the state but the debugger.
      if (debug_ && debug_->stopped() && r.path.rfind("/api/debug/", 0) != 0 && r.path != "/api/pause")
        return Reply::error(409, "a SOML++ program is stopped at a breakpoint: resume it first (POST /api/debug/resume)");
      return post(r);
    }
    return Reply::error(405, "method " + r.method + " is not allowed");
  } catch (const Error& e) {
    return Reply::error(400, e.what());
  } catch (const std::bad_alloc&) {
    return Reply::error(413, "the request needs more memory than the server has");
  } catch (const std::exception& e) {
    return Reply::error(400, e.what());
  }
}

Reply Inspector::get(const Request& r) {
  JsonWriter out;
  if (r.path == "/api/info") {
    info(out, r);
  } else if (r.path == "/api/classes") {
    classes(out);
  } else if (r.path == "/api/children") {
    children(out, r);
  } else if (r.path == "/api/table") {
    table(out, r);
  } else if (r.path == "/api/instance") {
    instance(out, r);
  } else if (r.path == "/api/scene") {
    write_scene(out, state_);
  } else if (r.path == "/api/mesh") {
    const std::string* id = r.param("id");
    if (id == nullptr) throw Error("request: parameter 'id' is missing");
    write_mesh(out, state_, parse_id(*id, "id"));
  } else if (r.path == "/api/nets") {
    write_nets(out, state_);
  } else if (r.path == "/api/timeline") {
    timeline_.write(out, max_timeline);
  } else if (r.path == "/api/trace" || r.path.rfind("/api/debug", 0) == 0) {
    if (!debug_) return Reply::error(404, "debugging is off in this server (Options::debug)");
    const auto count = [&](std::string_view name, std::size_t dflt, std::size_t max) {
      const std::string* v = r.param(name);
      return v != nullptr ? parse_count(*v, name, max) : dflt;
    };
    if (r.path == "/api/debug") {
      debug_->write(out);
    } else if (r.path == "/api/debug/source") {
      const std::string* p = r.param("program");
      if (p == nullptr) throw Error("request: parameter 'program' is missing");
      debug_->write_source(out, parse_id(*p, "program"));
    } else if (r.path == "/api/debug/locals") {
      debug_->write_locals(out, count("frame", 0, SIZE_MAX));
    } else if (r.path == "/api/debug/print") {
      const std::string* path = r.param("path");
      if (path == nullptr) throw Error("request: parameter 'path' is missing");
      debug_->write_print(out, *path, count("frame", 0, SIZE_MAX));
    } else if (r.path == "/api/trace") {
      debug_->write_trace(out, count("after", 0, SIZE_MAX), count("limit", 500, max_trace));
    } else {
      return Reply::error(404, "no such path: " + r.path);
    }
  } else {
    return Reply::error(404, "no such path: " + r.path);
  }
  return Reply{200, out.take()};
}

Reply Inspector::post(const Request& r) {
  JsonWriter out;
  if (r.path == "/api/set") {
    set(out, r);
  } else if (r.path == "/api/call") {
    call(out, r);
  } else if (r.path == "/api/fire") {
    fire(out, r);
  } else if (r.path == "/api/pause") {
    const JsonObject body = JsonObject::parse(r.body);
    paused_ = body.boolean("paused");
    out.begin_object().member("ok", true).member("paused", paused_).end_object();
  } else if (r.path == "/api/timeline/seek") {
    seek(out, r);
  } else if (r.path.rfind("/api/debug/", 0) == 0) {
    if (!debug_) return Reply::error(404, "debugging is off in this server (Options::debug)");
    if (r.path != "/api/debug/resume" && r.path != "/api/debug/break" && r.path != "/api/debug/remove" &&
        r.path != "/api/debug/pause")
      return Reply::error(404, "no such path: " + r.path);
    debug_->post(out, r.path, JsonObject::parse(r.body));
  } else if (r.path == "/api/timeline/live") {
    (void)JsonObject::parse(r.body.empty() ? std::string_view("{}") : std::string_view(r.body));
    timeline_.seek(timeline_.end(), env_.scheduler().steps(), env_.time());
    paused_ = false;
    out.begin_object().member("ok", true).member("position", timeline_.position()).end_object();
  } else {
    return Reply::error(404, "no such path: " + r.path);
  }
  publish(true);  // the edit reaches every page now, and becomes a timeline entry of its own
  return Reply{200, out.take()};
}

void Inspector::info(JsonWriter& out, const Request& r) const {
  out.begin_object()
      .member("name", "vsd")
      .member("state", state_.name())
      .member("step", env_.scheduler().steps())
      .member("time", env_.time())
      .member("writable", r.writable)
      .member("paused", paused_)
      .member("instances", static_cast<std::uint64_t>(state_.size()))
      .member("version", 1)
      .end_object();
}

void Inspector::classes(JsonWriter& out) const {
  std::vector<const MetaInstance*> all = env_.registry().classes();
  std::sort(all.begin(), all.end(), [](const auto* a, const auto* b) { return a->name() < b->name(); });
  out.begin_array();
  for (const MetaInstance* c : all) {
    out.begin_object().member("name", c->name());
    if (c->base() != nullptr)
      out.member("base", c->base()->name());
    else
      out.key("base").null();
    out.member("abstract", c->is_abstract());
    out.member("count", static_cast<std::uint64_t>(state_.index().count(*c, true)));
    out.key("properties").begin_array();
    for (const MetaProperty* p : c->properties()) {
      out.begin_object().member("name", p->name()).member("type", p->type().name()).member("kind", kind_of(p->type()));
      out.key("flags");
      write_flags(out, *p);
      if (p->type().kind() == TypeKind::Enum) {
        out.key("enum").begin_array();
        for (const auto& e : p->type().enum_values()) out.string(e.name);
        out.end_array();
      }
      out.end_object();
    }
    out.end_array();
    out.key("methods").begin_array();
    for (const MetaMethod* m : c->methods()) write_method(out, *m);
    out.end_array();
    out.end_object();
  }
  out.end_array();
}

void Inspector::children(JsonWriter& out, const Request& r) const {
  const std::string* id_text = r.param("id");
  const Id id = id_text != nullptr ? parse_id(*id_text, "id") : state_.database().id();
  const SimStateInstance& i = find(id);
  const Node* node = i.as<Node>();
  if (node == nullptr) throw Error("instance " + describe(i) + " is not a Node: it has no children");
  const std::size_t offset = r.param("offset") ? parse_count(*r.param("offset"), "offset", SIZE_MAX) : 0;
  const std::size_t limit = r.param("limit") ? parse_count(*r.param("limit"), "limit", max_rows) : 200;
  const auto& list = node->children();
  out.begin_object().member("id", id).member("total", static_cast<std::uint64_t>(list.size()));
  out.member("offset", static_cast<std::uint64_t>(offset)).key("children").begin_array();
  for (std::size_t k = offset; k < list.size() && k - offset < limit; ++k) {
    const Node* c = list[k];
    if (c == nullptr) continue;
    out.begin_object().member("id", c->id()).member("name", c->name()).member("class", c->meta().name());
    out.member("children", static_cast<std::uint64_t>(c->children().size())).end_object();
  }
  out.end_array().end_object();
}

void Inspector::table(JsonWriter& out, const Request& r) const {
  const std::string* cls_name = r.param("class");
  if (cls_name == nullptr) throw Error("request: parameter 'class' is missing");
  const MetaInstance* cls = env_.registry().find_class(*cls_name);
  if (cls == nullptr) throw Error("no class named '" + *cls_name + "'");
  const std::size_t offset = r.param("offset") ? parse_count(*r.param("offset"), "offset", SIZE_MAX) : 0;
  const std::size_t limit = r.param("limit") ? parse_count(*r.param("limit"), "limit", max_rows) : 100;
  const Filter filter(*cls, r.param("where") ? std::string_view(*r.param("where")) : std::string_view());
  // Columns: those asked for, else the class's plain values (no lists, no references), at most twelve.
  std::vector<const MetaProperty*> columns;
  if (const std::string* asked = r.param("columns"); asked != nullptr && !asked->empty()) {
    std::string_view rest = *asked;
    while (!rest.empty()) {
      const std::size_t comma = rest.find(',');
      const std::string_view name = trim(rest.substr(0, comma));
      const MetaProperty* p = cls->find_property(name);
      if (p == nullptr) throw Error("class " + cls->name() + " has no property '" + std::string(name) + "'");
      columns.push_back(p);
      rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
    }
  } else {
    for (const MetaProperty* p : cls->properties())
      if (std::string_view(kind_of(p->type())) == "value" && p->type().kind() != TypeKind::Vector &&
          columns.size() < 12)
        columns.push_back(p);
  }
  std::vector<const SimStateInstance*> rows;
  state_.index().for_each(*cls, true, [&](SimStateInstance& i) {
    if (filter.matches(i)) rows.push_back(&i);
  });
  // Pages by id: stable while the page scrolls, whatever order the index keeps.
  std::sort(rows.begin(), rows.end(), [](const auto* a, const auto* b) { return a->id() < b->id(); });
  out.begin_object().member("class", cls->name()).member("total", static_cast<std::uint64_t>(rows.size()));
  out.member("offset", static_cast<std::uint64_t>(offset)).key("columns").begin_array();
  for (const MetaProperty* p : columns) out.string(p->name());
  out.end_array().key("rows").begin_array();
  for (std::size_t k = offset; k < rows.size() && k - offset < limit; ++k) {
    const SimStateInstance& i = *rows[k];
    out.begin_object().member("id", i.id()).member("class", i.meta().name());
    const auto* named = i.as<NamedModelInstance>();
    out.member("name", named != nullptr ? named->name() : std::string());
    out.key("values").begin_object();
    for (const MetaProperty* p : columns) {
      out.key(p->name());
      write_value(out, i, *p);
    }
    out.end_object().end_object();
  }
  out.end_array().end_object();
}

void Inspector::instance(JsonWriter& out, const Request& r) const {
  const std::string* id_text = r.param("id");
  if (id_text == nullptr) throw Error("request: parameter 'id' is missing");
  const SimStateInstance& i = find(parse_id(*id_text, "id"));
  out.begin_object().member("id", i.id()).member("class", i.meta().name());
  const auto* named = i.as<NamedModelInstance>();
  out.member("name", named != nullptr ? named->name() : std::string());
  write_parent(out, i);
  out.key("properties").begin_array();
  for (const MetaProperty* p : i.meta().properties()) {
    out.begin_object().member("name", p->name()).member("type", p->type().name()).member("kind", kind_of(p->type()));
    out.key("flags");
    write_flags(out, *p);
    out.member("editable", editable(*p) && std::string_view(kind_of(p->type())) != "list");
    bool truncated = false;
    out.key("value");
    write_value(out, i, *p, &truncated);
    if (truncated) out.member("truncated", true);
    if (p->type().kind() == TypeKind::Enum) {
      out.key("enum").begin_array();
      for (const auto& e : p->type().enum_values()) out.string(e.name);
      out.end_array();
    }
    out.end_object();
  }
  out.end_array().key("methods").begin_array();
  for (const MetaMethod* m : i.meta().methods()) write_method(out, *m);
  out.end_array().end_object();
}

void Inspector::set(JsonWriter& out, const Request& r) {
  const JsonObject body = JsonObject::parse(r.body);
  SimStateInstance& i = find(body.id("id"));
  const std::string name = body.string("property");
  const MetaProperty* p = i.meta().find_property(name);
  if (p == nullptr) throw Error("instance " + describe(i) + " has no property '" + name + "'");
  if (!editable(*p) || std::string_view(kind_of(p->type())) == "list")
    throw Error("property '" + name + "' of " + describe(i) + " is not editable");
  const StateResolver refs(state_);
  Value v;
  try {
    v = Value::from_text(p->type(), body.require("value"), &refs, "value");
  } catch (const Error& e) {
    throw Error("property '" + name + "' of " + describe(i) + " expects " + p->type().name() + ": " + e.what());
  }
  // Set under a savepoint: what listeners do in reaction is undone too when one of them throws.
  const SimState::Savepoint sp = state_.savepoint();
  try {
    p->set_value(i, v);
    refresh_programs(env_, state_);
  } catch (...) {
    state_.roll_back(sp);
    throw;
  }
  state_.release(sp);
  out.begin_object().member("ok", true).key("value");
  write_value(out, i, *p);
  out.end_object();
}

void Inspector::call(JsonWriter& out, const Request& r) {
  const JsonObject body = JsonObject::parse(r.body);
  SimStateInstance& i = find(body.id("id"));
  const std::string name = body.string("method");
  const MetaMethod* m = i.meta().find_method(name);
  if (m == nullptr) throw Error("instance " + describe(i) + " has no method '" + name + "'");
  const std::vector<std::string_view> texts = body.find("args") != nullptr ? body.array("args") : std::vector<std::string_view>{};
  if (texts.size() != m->arguments().size())
    throw Error("method " + m->signature() + " takes " + std::to_string(m->arguments().size()) +
                " argument(s), not " + std::to_string(texts.size()));
  const StateResolver refs(state_);
  std::vector<Value> args;
  for (std::size_t k = 0; k < texts.size(); ++k) {
    const MetaType& t = *m->arguments()[k];
    try {
      args.push_back(Value::from_text(t, texts[k], &refs, "argument " + std::to_string(k + 1)));
    } catch (const Error& e) {
      throw Error("argument " + std::to_string(k + 1) + " of " + m->signature() + " expects " + t.name() + ": " + e.what());
    }
  }
  const SimState::Savepoint sp = state_.savepoint();
  Value result;
  try {
    result = m->invoke(i, args);
    refresh_programs(env_, state_);
  } catch (...) {
    state_.roll_back(sp);
    throw;
  }
  state_.release(sp);
  out.begin_object().member("ok", true).key("result");
  if (m->result() == nullptr || result.empty())
    out.null();
  else
    out.raw(result.to_text());
  out.end_object();
}

void Inspector::fire(JsonWriter& out, const Request& r) {
  const JsonObject body = JsonObject::parse(r.body);
  const Id id = body.id("transition");
  if (!fire_transition(env_, state_, id))
    throw Error("transition " + describe(find(id)) + " is not enabled");
  out.begin_object().member("ok", true).end_object();
}

void Inspector::seek(JsonWriter& out, const Request& r) {
  const JsonObject body = JsonObject::parse(r.body);
  const std::string_view index = body.require("index");
  const std::size_t k = parse_count(index, "index", SIZE_MAX);
  paused_ = true;  // looking at the past: the simulation waits (an edit or a step forks from here)
  timeline_.seek(k, env_.scheduler().steps(), env_.time());
  out.begin_object().member("ok", true).member("position", timeline_.position()).member("paused", true).end_object();
}

void Inspector::publish(bool force) {
  const bool stopped = debug_ && debug_->stopped();
  // At a stop the program is in the middle of a firing: no timeline entry ends there.
  if (!stopped) timeline_.cut(env_.scheduler().steps(), env_.time());
  if (debug_ && !stopped) debug_->sync();
  const auto now = std::chrono::steady_clock::now();
  const auto interval = std::chrono::duration<double>(options_.push_rate > 0 ? 1.0 / options_.push_rate : 0.0);
  const bool due = force || now - last_push_ >= interval;
  if (due && debug_) {
    const std::string trace = debug_->take_trace_event(max_trace);
    if (!trace.empty()) dropped_ += feed_.broadcast(make_event("trace", trace));
  }
  if (!watch_.empty() && due) {
    std::vector<Watch::Report> reports = watch_.take();
    JsonWriter out;
    write_batch(out, reports);
    dropped_ += feed_.broadcast(make_event("changes", out.str()));
    ++batches_;
    last_push_ = now;
    stats_changes_ += reports.size();
  }
  const double seconds = std::chrono::duration<double>(now - last_stats_).count();
  if (seconds >= 1.0) write_stats(seconds);
}

void Inspector::write_batch(JsonWriter& out, std::vector<Watch::Report>& reports) {
  out.begin_object()
      .member("seq", ++seq_)
      .member("step", env_.scheduler().steps())
      .member("time", env_.time());
  out.key("set").begin_array();
  for (const Watch::Report& r : reports) {
    if (r.property == nullptr) continue;
    const SimStateInstance* i = state_.find(r.id);
    if (i == nullptr) continue;  // deleted since: the deletion is reported
    bool truncated = false;
    out.begin_object().member("id", r.id).member("property", r.property->name()).key("value");
    write_value(out, *i, *r.property, &truncated);
    if (truncated) out.member("truncated", true);
    out.end_object();
  }
  out.end_array().key("created").begin_array();
  for (const Watch::Report& r : reports) {
    if (!r.changes.has(Changes::created)) continue;
    const SimStateInstance* i = state_.find(r.id);
    if (i == nullptr) continue;
    const auto* named = i->as<NamedModelInstance>();
    out.begin_object().member("id", r.id).member("class", i->meta().name());
    out.member("name", named != nullptr ? named->name() : std::string());
    write_parent(out, *i);
    out.end_object();
  }
  out.end_array().key("deleted").begin_array();
  for (const Watch::Report& r : reports)
    if (r.changes.has(Changes::deleted) && state_.find(r.id) == nullptr) out.number(r.id);
  out.end_array().key("moved").begin_array();
  for (const Watch::Report& r : reports) {
    if (!r.changes.has(Changes::parent)) continue;
    const SimStateInstance* i = state_.find(r.id);
    if (i == nullptr || i->as<Node>() == nullptr) continue;
    out.begin_object().member("id", r.id);
    write_parent(out, *i);
    out.end_object();
  }
  out.end_array();
  write_frames(out, state_, reports);
  out.end_object();
}

void Inspector::write_stats(double seconds) {
  const std::uint64_t steps = env_.scheduler().steps();
  const std::uint64_t fired = firings(env_, state_);
  JsonWriter out;
  out.begin_object()
      .member("steps_per_s", static_cast<double>(steps - stats_steps_) / seconds)
      .member("changes_per_s", static_cast<double>(stats_changes_) / seconds)
      .member("firings_per_s", static_cast<double>(fired - std::min(fired, stats_firings_)) / seconds)
      .member("clients", static_cast<std::uint64_t>(feed_.clients()))
      .member("step", steps)
      .member("time", env_.time())
      .end_object();
  (void)feed_.broadcast(make_event("stats", out.str()));
  last_stats_ = std::chrono::steady_clock::now();
  stats_steps_ = steps;
  stats_firings_ = fired;
  stats_changes_ = 0;
}

}  // namespace vsd::web::detail
