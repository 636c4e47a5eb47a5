// PNML reader and writer on pugixml. The reader walks the DOM once to collect places, transitions,
// reference nodes and arcs (in that order of need), then resolves arcs; positions for messages come from
// pugixml's node offsets, turned into line:col by a table of line starts.
#include "vsd/analysis/pnml.hpp"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <map>
#include <pugixml.hpp>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "text_file.hpp"
#include "vsd/core/error.hpp"

namespace vsd::analysis {

namespace {

constexpr const char* kPtNetType = "http://www.pnml.org/version-2009/grammar/ptnet";
constexpr const char* kPnmlNamespace = "http://www.pnml.org/version-2009/grammar/pnml";

// Element name without a namespace prefix ("pnml:place" -> "place").
std::string_view local_name(const pugi::xml_node& n) {
  std::string_view s = n.name();
  const auto colon = s.find(':');
  return colon == std::string_view::npos ? s : s.substr(colon + 1);
}

pugi::xml_node child(const pugi::xml_node& n, std::string_view name) {
  for (pugi::xml_node c = n.first_child(); c; c = c.next_sibling())
    if (c.type() == pugi::node_element && local_name(c) == name) return c;
  return {};
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

class Reader {
 public:
  Reader(std::string_view text, std::string_view source) : text_(text), source_(source) {
    line_starts_.push_back(0);
    for (std::size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') line_starts_.push_back(i + 1);
  }

  PnmlImport run() {
    pugi::xml_document doc;
    const pugi::xml_parse_result parsed =
        doc.load_buffer(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_auto);
    if (!parsed)
      fail_at(static_cast<std::size_t>(parsed.offset), std::string("malformed XML: ") + parsed.description());

    pugi::xml_node root = doc.document_element();
    if (!root || local_name(root) != "pnml")
      fail(root ? root : doc, std::string("not a PNML document: the root element is <") +
                                  (root ? root.name() : "") + ">, expected <pnml>");
    std::vector<pugi::xml_node> nets;
    for (pugi::xml_node c = root.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      if (local_name(c) == "net")
        nets.push_back(c);
      else
        skipped(c);
    }
    if (nets.empty()) fail(root, "the PNML document holds no <net>");
    if (nets.size() > 1)
      fail(nets[1], "the PNML document holds " + std::to_string(nets.size()) +
                        " nets; one net per file is supported (split the file)");
    read_net(nets.front());
    if (graphics_count_ > 0)
      out_.notes.push_back(where(first_graphics_) + ": skipped <graphics> (layout) of " +
                           std::to_string(graphics_count_) + " element(s); layout is not kept");
    return std::move(out_);
  }

 private:
  std::pair<std::size_t, std::size_t> line_col(std::size_t offset) const {
    const auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), offset);
    const auto line = static_cast<std::size_t>(it - line_starts_.begin());
    return {line, offset - line_starts_[line - 1] + 1};
  }
  std::string where_offset(std::size_t offset) const {
    const auto [line, col] = line_col(std::min(offset, text_.size()));
    return std::string(source_) + ":" + std::to_string(line) + ":" + std::to_string(col);
  }
  // pugixml's offset_debug() points just past '<' for elements; report the '<' itself.
  std::string where(const pugi::xml_node& n) const {
    const std::ptrdiff_t off = n.offset_debug();
    if (off < 0) return std::string(source_);
    const auto o = static_cast<std::size_t>(off);
    return where_offset(n.type() == pugi::node_element && o > 0 ? o - 1 : o);
  }
  [[noreturn]] void fail_at(std::size_t offset, const std::string& msg) const {
    vsd::detail::throw_error(where_offset(offset) + ": " + msg);
  }
  [[noreturn]] void fail(const pugi::xml_node& n, const std::string& msg) const {
    vsd::detail::throw_error(where(n) + ": " + msg);
  }
  void note(const pugi::xml_node& n, const std::string& msg) { out_.notes.push_back(where(n) + ": " + msg); }

  // An element the reader does not keep: reported, never silently dropped.
  void skipped(const pugi::xml_node& n) {
    const std::string_view name = local_name(n);
    if (name == "graphics") {
      if (graphics_count_++ == 0) first_graphics_ = n;
      return;
    }
    if (name == "toolspecific") {
      note(n, std::string("skipped <toolspecific tool=\"") + n.attribute("tool").value() + "\" version=\"" +
                  n.attribute("version").value() + "\"> (tool-specific information is not kept)");
      return;
    }
    note(n, "skipped unknown element <" + std::string(n.name()) + ">");
  }

  std::string required_id(const pugi::xml_node& n) const {
    std::string id = n.attribute("id").value();
    if (id.empty()) fail(n, "<" + std::string(n.name()) + "> without an id attribute");
    return id;
  }

  // Text of <name><text>...</text></name> (empty when absent).
  std::string name_of(const pugi::xml_node& n) {
    const pugi::xml_node name = child(n, "name");
    if (!name) return {};
    check_children(name, {"text"});  // a label's own <graphics> (its offset) is counted as layout
    return std::string(trim(child(name, "text").text().get()));
  }

  // A non-negative integer in <label><text>N</text></label>.
  std::uint32_t number(const pugi::xml_node& label, const char* what, bool positive) const {
    const pugi::xml_node text = child(label, "text");
    if (!text) fail(label, std::string("<") + label.name() + "> without <text>");
    const std::string_view s = trim(text.text().get());
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size() || v > UINT32_MAX)
      fail(text, std::string(what) + " '" + std::string(s) + "' is not an integer in [0, 2^32-1]");
    if (positive && v == 0) fail(text, std::string(what) + " is 0; it must be positive");
    return static_cast<std::uint32_t>(v);
  }

  void read_net(const pugi::xml_node& net) {
    const std::string type = net.attribute("type").value();
    if (type != kPtNetType) {
      std::string what = "net type '" + type + "' is not supported";
      if (type.find("symmetricnet") != std::string::npos)
        what += " (a symmetric net: colours are out of scope)";
      else if (type.find("highlevelnet") != std::string::npos)
        what += " (a high-level net: colours and terms are out of scope)";
      fail(net, what + "; vsd reads place/transition nets, type '" + std::string(kPtNetType) + "'");
    }
    out_.net.set_id(required_id(net));
    out_.net.set_name(name_of(net));
    std::vector<pugi::xml_node> arcs;
    collect(net, arcs);
    resolve_references();
    for (const auto& a : arcs) read_arc(a);
  }

  // Walks a net and its pages, nested to any depth, in document order: nodes now, arcs later (their
  // ends may come after them). An explicit stack of the next sibling to visit on each open level, not
  // recursion: 50,000 nested pages overflowed the call stack.
  void collect(const pugi::xml_node& net, std::vector<pugi::xml_node>& arcs) {
    std::vector<pugi::xml_node> open{net.first_child()};
    while (!open.empty()) {
      const pugi::xml_node c = open.back();
      if (!c) {
        open.pop_back();
        continue;
      }
      open.back() = c.next_sibling();
      if (c.type() != pugi::node_element) continue;
      const std::string_view n = local_name(c);
      if (n == "name") continue;
      if (n == "page") {
        check_unique(c);
        open.push_back(c.first_child());
      } else if (n == "place") {
        read_place(c);
      } else if (n == "transition") {
        read_transition(c);
      } else if (n == "referencePlace" || n == "referenceTransition") {
        check_unique(c);
        references_.push_back(c);
      } else if (n == "arc") {
        arcs.push_back(c);
      } else {
        skipped(c);
      }
    }
  }

  void check_unique(const pugi::xml_node& n) {
    const std::string id = required_id(n);
    if (!other_ids_.emplace(id, n).second || out_.net.find_place(id) || out_.net.find_transition(id))
      fail(n, "duplicate id '" + id + "'");
  }

  void check_children(const pugi::xml_node& n, std::initializer_list<std::string_view> kept) {
    for (pugi::xml_node c = n.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      if (std::find(kept.begin(), kept.end(), local_name(c)) == kept.end()) skipped(c);
    }
  }

  void read_place(const pugi::xml_node& p) {
    const std::string id = required_id(p);
    if (other_ids_.count(id) || out_.net.find_place(id) || out_.net.find_transition(id))
      fail(p, "duplicate id '" + id + "'");
    std::uint32_t initial = 0;
    if (const pugi::xml_node m = child(p, "initialMarking")) {
      initial = number(m, "initial marking", false);
      check_children(m, {"text"});
    }
    check_children(p, {"name", "initialMarking"});
    out_.net.add_place(id, name_of(p), initial);
  }

  void read_transition(const pugi::xml_node& t) {
    const std::string id = required_id(t);
    if (other_ids_.count(id) || out_.net.find_place(id) || out_.net.find_transition(id))
      fail(t, "duplicate id '" + id + "'");
    check_children(t, {"name"});
    out_.net.add_transition(id, name_of(t));
  }

  // A reference node stands for the node named by its `ref`, possibly another reference. Each chain is
  // followed once: a reference whose target is known gives it to every reference met on the way there,
  // so resolving n references costs O(n) however they chain (following each chain to its end was
  // quadratic: 20,000 chained references took 10 s). A chain that comes back to a reference on it is a
  // cycle, reported with its ids.
  void resolve_references() {
    std::unordered_map<std::string, std::size_t> by_id;  // reference id -> index in references_
    for (std::size_t i = 0; i < references_.size(); ++i) by_id.emplace(references_[i].attribute("id").value(), i);
    enum : std::uint8_t { kTodo, kOnPath, kDone };
    std::vector<std::uint8_t> state(references_.size(), kTodo);
    std::vector<std::string> target(references_.size());
    std::vector<std::size_t> path;
    for (std::size_t start = 0; start < references_.size(); ++start) {
      if (state[start] == kDone) continue;
      std::string end;
      for (std::size_t i = start;;) {
        const pugi::xml_node& r = references_[i];
        const std::string ref = r.attribute("ref").value();
        if (ref.empty()) fail(r, "<" + std::string(r.name()) + "> without a ref attribute");
        state[i] = kOnPath;
        path.push_back(i);
        const auto next = by_id.find(ref);
        if (next == by_id.end()) {  // a place or transition (or nothing: checked below)
          end = ref;
          break;
        }
        if (state[next->second] == kDone) {
          end = target[next->second];
          break;
        }
        if (state[next->second] == kOnPath) fail(references_[next->second], cycle_text(path, next->second));
        i = next->second;
      }
      for (const std::size_t i : path) {
        state[i] = kDone;
        target[i] = end;
      }
      path.clear();
    }
    for (std::size_t i = 0; i < references_.size(); ++i) {
      const pugi::xml_node& r = references_[i];
      const bool want_place = local_name(r) == "referencePlace";
      if (want_place ? !out_.net.find_place(target[i]) : !out_.net.find_transition(target[i]))
        fail(r, "reference to unknown " + std::string(want_place ? "place" : "transition") + " '" + target[i] +
                    "'");
      alias_.emplace(r.attribute("id").value(), target[i]);
      check_children(r, {"name"});
    }
  }

  // "reference cycle: 'a' -> 'b' -> 'a'": the references of @p path from @p from on, and back (at most
  // 10 of them named).
  std::string cycle_text(const std::vector<std::size_t>& path, std::size_t from) const {
    const auto begin = std::find(path.begin(), path.end(), from);
    const auto length = static_cast<std::size_t>(path.end() - begin);
    std::string s = "reference cycle of " + std::to_string(length) + " reference(s): ";
    std::size_t shown = 0;
    for (auto it = begin; it != path.end() && shown < 10; ++it, ++shown)
      s += "'" + std::string(references_[*it].attribute("id").value()) + "' -> ";
    if (length > shown) s += "... -> ";
    return s + "'" + references_[from].attribute("id").value() + "'";
  }

  const std::string& resolve(const std::string& id) const {
    const auto it = alias_.find(id);
    return it == alias_.end() ? id : it->second;
  }

  void read_arc(const pugi::xml_node& a) {
    const std::string id = required_id(a);
    if (!arc_ids_.emplace(id).second || other_ids_.count(id) || out_.net.find_place(id) ||
        out_.net.find_transition(id))
      fail(a, "duplicate id '" + id + "'");
    const std::string source = a.attribute("source").value();
    const std::string target = a.attribute("target").value();
    if (source.empty() || target.empty()) fail(a, "arc '" + id + "' needs source and target attributes");
    const std::string& from = resolve(source);
    const std::string& to = resolve(target);
    const auto sp = out_.net.find_place(from);
    const auto st = out_.net.find_transition(from);
    const auto tp = out_.net.find_place(to);
    const auto tt = out_.net.find_transition(to);
    if (!sp && !st) fail(a, "arc '" + id + "' has unknown source '" + source + "'");
    if (!tp && !tt) fail(a, "arc '" + id + "' has unknown target '" + target + "'");
    if ((sp && tp) || (st && tt))
      fail(a, "arc '" + id + "' joins two " + (sp ? "places" : "transitions") + " ('" + source + "', '" +
                  target + "')");
    std::uint32_t weight = 1;
    if (const pugi::xml_node ins = child(a, "inscription")) {
      weight = number(ins, "arc weight", true);
      check_children(ins, {"text"});
    }
    bool inhibitor = false;
    if (const pugi::xml_node type = child(a, "type")) {
      const std::string_view v = type.attribute("value").value();
      if (v == "inhibitor")
        inhibitor = true;
      else if (v != "normal")
        fail(type, "arc type '" + std::string(v) + "' is not supported (normal and inhibitor are)");
    }
    check_children(a, {"inscription", "type"});
    if (inhibitor) {
      if (!sp) fail(a, "inhibitor arc '" + id + "' must go from a place to a transition");
      out_.net.add_inhibitor(*tt, *sp, weight, id);
      return;
    }
    // A parallel arc is merged into the earlier one: the transition's arc count stays the same.
    const Transition& t = out_.net.transitions()[sp ? *tt : *st];
    const std::size_t before = sp ? t.inputs.size() : t.outputs.size();
    if (sp)
      out_.net.add_input(*tt, *sp, weight, id);
    else
      out_.net.add_output(*st, *tp, weight, id);
    if ((sp ? t.inputs.size() : t.outputs.size()) == before)
      note(a, "arc '" + id + "' is parallel to an earlier arc from '" + source + "' to '" + target +
                  "'; their weights are added and the net keeps the earlier id");
  }

  std::string_view text_;
  std::string_view source_;
  std::vector<std::size_t> line_starts_;
  PnmlImport out_;
  std::size_t graphics_count_ = 0;
  pugi::xml_node first_graphics_;
  std::vector<pugi::xml_node> references_;
  std::unordered_map<std::string, pugi::xml_node> other_ids_;  // pages and reference nodes
  std::unordered_map<std::string, std::string> alias_;         // reference node -> place/transition id
  std::unordered_set<std::string> arc_ids_;
};

void add_text(pugi::xml_node parent, const char* label, const std::string& text) {
  parent.append_child(label).append_child("text").text().set(text.c_str());
}

}  // namespace

PnmlImport read_pnml(std::string_view text, std::string_view source) { return Reader(text, source).run(); }

PnmlImport read_pnml(std::istream& in, std::string_view source) {
  return read_pnml(detail::read_text(in, source), source);
}

PnmlImport read_pnml_file(const std::filesystem::path& path) {
  return read_pnml(detail::read_text_file(path), path.string());
}

std::string write_pnml(const PtNet& net) {
  pugi::xml_document doc;
  pugi::xml_node decl = doc.append_child(pugi::node_declaration);
  decl.append_attribute("version") = "1.0";
  decl.append_attribute("encoding") = "UTF-8";
  pugi::xml_node root = doc.append_child("pnml");
  root.append_attribute("xmlns") = kPnmlNamespace;
  pugi::xml_node n = root.append_child("net");
  n.append_attribute("id") = net.id().empty() ? "net" : net.id().c_str();
  n.append_attribute("type") = kPtNetType;
  if (!net.name().empty()) add_text(n, "name", net.name());
  pugi::xml_node page = n.append_child("page");
  // The page id must not collide with a node id.
  std::string page_id = "page";
  while (net.find_place(page_id) || net.find_transition(page_id)) page_id += "_";
  page.append_attribute("id") = page_id.c_str();
  for (const Place& p : net.places()) {
    pugi::xml_node e = page.append_child("place");
    e.append_attribute("id") = p.id.c_str();
    add_text(e, "name", p.name);
    if (p.initial != 0) add_text(e, "initialMarking", std::to_string(p.initial));
  }
  for (const Transition& t : net.transitions()) {
    pugi::xml_node e = page.append_child("transition");
    e.append_attribute("id") = t.id.c_str();
    add_text(e, "name", t.name);
  }
  // Arc ids must be unique across the whole net: keep the given ones, make up the missing ones.
  std::unordered_set<std::string> used;
  for (const Place& p : net.places()) used.insert(p.id);
  for (const Transition& t : net.transitions()) used.insert(t.id);
  used.insert(page_id);
  std::size_t next = 0;
  auto arc = [&](const ArcRef& a, const std::string& source, const std::string& target, bool inhibitor) {
    std::string id = a.id;
    if (id.empty() || !used.insert(id).second) {
      do id = "a" + std::to_string(next++);
      while (!used.insert(id).second);
    }
    pugi::xml_node e = page.append_child("arc");
    e.append_attribute("id") = id.c_str();
    e.append_attribute("source") = source.c_str();
    e.append_attribute("target") = target.c_str();
    if (a.weight != 1) add_text(e, "inscription", std::to_string(a.weight));
    if (inhibitor) e.append_child("type").append_attribute("value") = "inhibitor";
  };
  for (const Transition& t : net.transitions()) {
    for (const ArcRef& a : t.inputs) arc(a, net.places()[a.place].id, t.id, false);
    for (const ArcRef& a : t.outputs) arc(a, t.id, net.places()[a.place].id, false);
    for (const ArcRef& a : t.inhibitors) arc(a, net.places()[a.place].id, t.id, true);
  }
  std::ostringstream out;
  doc.save(out, "  ", pugi::format_default, pugi::encoding_utf8);
  return std::move(out).str();
}

void write_pnml_file(const PtNet& net, const std::filesystem::path& path) {
  detail::write_text_file(path, write_pnml(net));
}

}  // namespace vsd::analysis
