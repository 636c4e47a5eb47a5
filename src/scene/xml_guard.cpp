#include "xml_guard.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "vsd/core/error.hpp"

namespace vsd::scene::detail {

namespace {

// The index just past @p end found from @p from, or the end of the text (unterminated: the parser reports it).
std::size_t skip_past(std::string_view text, std::size_t from, std::string_view end) {
  const std::size_t at = text.find(end, from);
  return at == std::string_view::npos ? text.size() : at + end.size();
}

// The index of the '>' that ends a tag or declaration starting at @p from (text.size() when there is
// none): quoted values are skipped, and in a declaration (<!DOCTYPE ...>) so is a bracketed internal
// subset with its own declarations and comments.
std::size_t tag_end(std::string_view text, std::size_t from, bool declaration) {
  int brackets = 0;
  for (std::size_t i = from; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"' || c == '\'') {
      const std::size_t close = text.find(c, i + 1);
      if (close == std::string_view::npos) return text.size();
      i = close;
    } else if (declaration && text.compare(i, 4, "<!--") == 0) {
      i = skip_past(text, i + 4, "-->") - 1;
    } else if (declaration && c == '[') {
      ++brackets;
    } else if (declaration && c == ']') {
      brackets = std::max(0, brackets - 1);
    } else if (c == '>' && brackets == 0) {
      return i;
    }
  }
  return text.size();
}

bool space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

}  // namespace

std::string line_col(std::string_view text, std::size_t pos) {
  const std::string_view before = text.substr(0, pos);
  const auto line = std::count(before.begin(), before.end(), '\n') + 1;
  const std::size_t last_newline = before.rfind('\n');
  const std::size_t col = last_newline == std::string_view::npos ? pos + 1 : pos - last_newline;
  return std::to_string(line) + ":" + std::to_string(col);
}

void for_each_tag(std::string_view text, const std::function<void(const XmlTag&)>& fn) {
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t lt = text.find('<', i);
    if (lt == std::string_view::npos) return;
    const std::string_view rest = text.substr(lt);
    if (rest.starts_with("<!--")) {
      i = skip_past(text, lt + 4, "-->");
    } else if (rest.starts_with("<![CDATA[")) {
      i = skip_past(text, lt + 9, "]]>");
    } else if (rest.starts_with("<?")) {
      i = skip_past(text, lt + 2, "?>");
    } else if (rest.starts_with("<!")) {
      i = tag_end(text, lt + 2, true) + 1;
    } else {
      XmlTag tag;
      tag.position = lt;
      tag.end = rest.starts_with("</");
      const std::size_t name_start = lt + (tag.end ? 2 : 1);
      const std::size_t close = tag_end(text, name_start, false);
      std::size_t name_end = name_start;
      while (name_end < close && !space(text[name_end]) && text[name_end] != '/') ++name_end;
      tag.name = text.substr(name_start, name_end - name_start);
      std::size_t attributes_end = close;
      if (!tag.end && close < text.size() && close > name_start && text[close - 1] == '/') {
        tag.empty = true;
        --attributes_end;
      }
      tag.attributes = text.substr(name_end, attributes_end > name_end ? attributes_end - name_end : 0);
      fn(tag);
      i = close + 1;
    }
  }
}

std::string_view attribute(std::string_view attributes, std::string_view name) {
  std::size_t i = 0;
  while (i < attributes.size()) {
    while (i < attributes.size() && space(attributes[i])) ++i;
    const std::size_t key_start = i;
    while (i < attributes.size() && attributes[i] != '=' && !space(attributes[i])) ++i;
    const std::string_view key = attributes.substr(key_start, i - key_start);
    while (i < attributes.size() && (space(attributes[i]) || attributes[i] == '=')) ++i;
    if (i >= attributes.size()) return {};
    const char quote = attributes[i];
    if (quote != '"' && quote != '\'') return {};  // malformed: the parser will say so
    const std::size_t value_end = attributes.find(quote, i + 1);
    if (value_end == std::string_view::npos) return {};
    if (key == name) return attributes.substr(i + 1, value_end - i - 1);
    i = value_end + 1;
  }
  return {};
}

void check_xml_shape(std::string_view text, std::string_view origin, std::string_view what,
                     const XmlLimits& limits) {
  const std::string name(origin);
  if (text.size() > limits.max_bytes)
    vsd::detail::throw_error(name + ": " + std::string(what) + " of " + std::to_string(text.size()) +
                             " bytes is larger than the limit of " + std::to_string(limits.max_bytes) +
                             " bytes; refused before parsing");
  std::size_t depth = 0;
  std::size_t elements = 0;
  for_each_tag(text, [&](const XmlTag& tag) {
    if (tag.end) {
      if (depth > 0) --depth;  // a mismatched end tag is the parser's to report
      return;
    }
    ++elements;
    // An empty element occupies a level too, without staying open.
    if (depth + 1 > limits.max_depth)
      vsd::detail::throw_error(name + ":" + line_col(text, tag.position) + ": " + std::string(what) +
                               " nests elements deeper than " + std::to_string(limits.max_depth) +
                               " levels; refused before parsing");
    if (elements > limits.max_elements)
      vsd::detail::throw_error(name + ":" + line_col(text, tag.position) + ": " + std::string(what) +
                               " has more than " + std::to_string(limits.max_elements) +
                               " elements; refused before parsing");
    if (!tag.empty) ++depth;
  });
}

namespace {

// The node graph of a COLLADA document: a vertex per <node>, edges to its nested nodes and to the nodes
// it instances; geometry instances weigh by the values of their geometry.
struct ColladaGraph {
  struct Vertex {
    std::size_t position = 0;
    std::string_view id;
    std::vector<std::size_t> nested;
    std::vector<std::pair<std::string_view, std::size_t>> instances;  // node id, position of the reference
    std::vector<std::pair<std::string_view, bool>> geometries;        // id, through a controller
    bool root = false;                                                 // in a <visual_scene>, not nested
  };
  std::vector<Vertex> vertices;
  std::unordered_map<std::string_view, std::size_t> node_by_id;
  std::unordered_map<std::string_view, std::uint64_t> geometry_values;
  std::unordered_map<std::string_view, std::string_view> controller_geometry;
};

std::string_view local_reference(std::string_view url) {
  return url.starts_with('#') ? url.substr(1) : std::string_view{};  // other files are not followed
}

ColladaGraph read_graph(std::string_view text) {
  ColladaGraph g;
  std::vector<std::size_t> open;  // nodes open at this point
  int visual_scenes = 0;
  std::string_view geometry, controller;
  for_each_tag(text, [&](const XmlTag& tag) {
    const std::string_view name = tag.name;
    if (name == "node") {
      if (tag.end) {
        if (!open.empty()) open.pop_back();
        return;
      }
      const std::size_t v = g.vertices.size();
      g.vertices.emplace_back();
      auto& vertex = g.vertices.back();
      vertex.position = tag.position;
      vertex.id = attribute(tag.attributes, "id");
      if (!vertex.id.empty()) g.node_by_id.emplace(vertex.id, v);
      if (!open.empty()) {
        g.vertices[open.back()].nested.push_back(v);
      } else {
        vertex.root = visual_scenes > 0;
      }
      if (!tag.empty) open.push_back(v);
    } else if (name == "visual_scene") {
      if (tag.end) {
        visual_scenes = std::max(0, visual_scenes - 1);
      } else if (!tag.empty) {
        ++visual_scenes;
      }
    } else if (tag.end) {
      if (name == "geometry") geometry = {};
      if (name == "controller") controller = {};
    } else if (name == "instance_node" && !open.empty()) {
      const std::string_view target = local_reference(attribute(tag.attributes, "url"));
      if (!target.empty()) g.vertices[open.back()].instances.emplace_back(target, tag.position);
    } else if ((name == "instance_geometry" || name == "instance_controller") && !open.empty()) {
      const std::string_view target = local_reference(attribute(tag.attributes, "url"));
      if (!target.empty()) g.vertices[open.back()].geometries.emplace_back(target, name == "instance_controller");
    } else if (name == "geometry") {
      geometry = tag.empty ? std::string_view{} : attribute(tag.attributes, "id");
    } else if (name == "float_array" && !geometry.empty()) {
      std::uint64_t count = 0;
      for (char c : attribute(tag.attributes, "count")) {
        if (c < '0' || c > '9') break;
        count = std::min<std::uint64_t>(count * 10 + static_cast<std::uint64_t>(c - '0'), 1ULL << 60);
      }
      auto& total = g.geometry_values[geometry];
      total = std::min<std::uint64_t>(total + count, 1ULL << 60);
    } else if (name == "controller") {
      controller = tag.empty ? std::string_view{} : attribute(tag.attributes, "id");
    } else if ((name == "skin" || name == "morph") && !controller.empty()) {
      const std::string_view source = local_reference(attribute(tag.attributes, "source"));
      if (!source.empty()) g.controller_geometry.emplace(controller, source);
    }
  });
  return g;
}

}  // namespace

void check_collada_instances(std::string_view text, std::string_view origin, std::size_t max_nodes,
                             std::size_t max_floats) {
  const ColladaGraph g = read_graph(text);
  const std::size_t n = g.vertices.size();
  // Edges: nested nodes first, then instanced ones (an unknown id is assimp's to report).
  std::vector<std::vector<std::size_t>> edges(n);
  std::vector<std::vector<std::size_t>> edge_position(n);
  for (std::size_t v = 0; v < n; ++v) {
    for (std::size_t c : g.vertices[v].nested) {
      edges[v].push_back(c);
      edge_position[v].push_back(g.vertices[c].position);
    }
    for (const auto& [id, pos] : g.vertices[v].instances)
      if (auto it = g.node_by_id.find(id); it != g.node_by_id.end()) {
        edges[v].push_back(it->second);
        edge_position[v].push_back(pos);
      }
  }
  auto own_values = [&](std::size_t v) {
    std::uint64_t sum = 0;
    for (const auto& [id, through_controller] : g.vertices[v].geometries) {
      std::string_view geometry = id;
      if (through_controller) {
        auto c = g.controller_geometry.find(id);
        geometry = c != g.controller_geometry.end() ? c->second : std::string_view{};
      }
      if (auto it = g.geometry_values.find(geometry); it != g.geometry_values.end())
        sum = std::min<std::uint64_t>(sum + it->second, 1ULL << 60);
    }
    return sum;
  };
  // Depth first without recursion; a vertex met again while still on the path closes a cycle. Every
  // vertex is finished once, with the nodes and values its expansion holds (saturating).
  enum class Mark : std::uint8_t { New, OnPath, Done };
  std::vector<Mark> mark(n, Mark::New);
  std::vector<std::uint64_t> nodes(n, 0), values(n, 0);
  const std::uint64_t cap = 1ULL << 60;
  const std::string where(origin);
  for (std::size_t start = 0; start < n; ++start) {
    if (mark[start] != Mark::New) continue;
    std::vector<std::pair<std::size_t, std::size_t>> stack{{start, 0}};  // vertex, next edge
    mark[start] = Mark::OnPath;
    while (!stack.empty()) {
      auto& [v, next] = stack.back();
      if (next < edges[v].size()) {
        const std::size_t c = edges[v][next];
        const std::size_t pos = edge_position[v][next];
        ++next;
        if (mark[c] == Mark::OnPath) {
          const std::string_view id = g.vertices[c].id;
          vsd::detail::throw_error(where + ":" + line_col(text, pos) + ": COLLADA mesh: node '" +
                                   std::string(id.empty() ? "(no id)" : id) +
                                   "' contains itself through <instance_node> references; refused before "
                                   "parsing");
        }
        if (mark[c] == Mark::New) {
          mark[c] = Mark::OnPath;
          stack.emplace_back(c, 0);
        }
        continue;
      }
      std::uint64_t count = 1, sum = own_values(v);
      for (std::size_t c : edges[v]) {
        count = std::min(count + nodes[c], cap);
        sum = std::min(sum + values[c], cap);
      }
      nodes[v] = count;
      values[v] = sum;
      mark[v] = Mark::Done;
      stack.pop_back();
    }
  }
  std::uint64_t total_nodes = 0, total_values = 0;
  for (std::size_t v = 0; v < n; ++v)
    if (g.vertices[v].root) {
      total_nodes = std::min(total_nodes + nodes[v], cap);
      total_values = std::min(total_values + values[v], cap);
    }
  if (total_nodes > max_nodes || total_values > max_floats)
    vsd::detail::throw_error(
        where + ": COLLADA mesh: its scene expands to " +
        (total_nodes >= cap ? std::string("more than 2^60") : std::to_string(total_nodes)) + " nodes and " +
        (total_values >= cap ? std::string("more than 2^60") : std::to_string(total_values)) +
        " geometry values once every instance is expanded (limits " + std::to_string(max_nodes) + " and " +
        std::to_string(max_floats) + "); refused before parsing");
}

}  // namespace vsd::scene::detail
