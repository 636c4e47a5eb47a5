// vsd-scene (see tool.hpp).
#include "tool.hpp"

#include <iomanip>
#include <ostream>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "vsd/core/environment.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/io/snapshot.hpp"
#include "vsd/scene/hull.hpp"
#include "vsd/scene/module.hpp"
#include "vsd/scene/scene.hpp"
#include "vsd_tool/arguments.hpp"
#include "vsd_tool/input.hpp"
#include "vsd_tool/models.hpp"
#include "vsd_tool/runner.hpp"
#include "vsd_tool/scene_input.hpp"
#include "vsd_tool/text.hpp"

namespace vsd::tool::vsd_scene {

namespace {

constexpr std::string_view usage = R"(vsd-scene: load a robot description or a saved scene and print its tree

Usage:
  vsd-scene <file> [--package-path DIR]... [--no-meshes] [--json]
      <file> is a URDF (.urdf, .xml) or a scene saved by vsd::io (.json vsd-text, .vsds binary); "-" reads
      standard input (XML is taken as a URDF).
      Prints the links (with masses), the joints (type, axis, limits) between them and each link's
      visual and collision hulls with their geometry, then the warnings of the load.
      --package-path DIR  where package://pkg/... mesh URIs are looked up (DIR/pkg/...); repeatable
      --no-meshes         do not read mesh files
      --json              print the loaded scene as a vsd-text file instead of the tree
  vsd-scene --help

Exit status: 0 loaded (warnings or not), 1 the file could not be loaded, 2 a usage error.
)";

const Tool tool{"vsd-scene", usage};

std::string fmt(double v) {
  std::ostringstream s;
  s << std::setprecision(6) << v;
  return s.str();
}

std::string vec(const Eigen::Vector3d& v) {
  return "[" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + "]";
}

std::string frame_text(const Eigen::Isometry3d& f) {
  if (f.isApprox(Eigen::Isometry3d::Identity())) return "";
  const Eigen::Vector3d rpy = f.rotation().eulerAngles(2, 1, 0).reverse();
  return " at " + vec(f.translation()) + (rpy.isZero(1e-12) ? "" : " rpy(zyx) " + vec(rpy));
}

std::string enum_text(const MetaType& t, std::int64_t v) {
  for (const auto& e : t.enum_values())
    if (e.value == v) return e.name;
  return std::to_string(v);
}

// Levels of the tree that are indented; deeper ones (a URDF chain of 10 000 links) say their level, so
// the output stays linear in the number of links.
constexpr std::size_t indented_levels = 48;

void print_link(const scene::Link& link, const scene::Joint* j, std::size_t depth, std::ostream& out) {
  const std::string pad = depth <= indented_levels
                              ? std::string(depth * 2, ' ')
                              : std::string(indented_levels * 2, ' ') + "(level " + std::to_string(depth) + ") ";
  if (j != nullptr) {
    out << pad << "joint " << printable(j->name()) << " ("
        << enum_text(meta_type<scene::JointType>(), static_cast<int>(j->type())) << ")";
    if (j->type() != scene::JointType::Fixed) out << " axis " << vec(j->axis());
    if (j->has_limits())
      out << " limits [" << fmt(j->lower()) << ", " << fmt(j->upper()) << "] effort " << fmt(j->effort())
          << " velocity " << fmt(j->velocity());
    if (j->mimic().get() != nullptr) out << " mimics " << printable(j->mimic()->name());
    out << frame_text(j->origin()) << '\n';
  }
  out << pad << "link " << printable(link.name());
  if (link.mass() > 0) out << " mass " << fmt(link.mass()) << " kg";
  out << '\n';
  for (const vsd::Node* c : link.children()) {
    if (const auto* h = c->as<scene::Hull>()) {
      out << pad << "  " << (h->role() == scene::HullRole::Visual ? "visual " : "collision ") << printable(h->name())
          << ": " << (h->geometry().get() != nullptr ? printable(h->geometry()->describe()) : std::string("no geometry"));
      if (h->material().get() != nullptr && !h->material()->name().empty())
        out << ", material " << printable(h->material()->name());
      out << frame_text(h->frame()) << '\n';
    }
  }
}

// The tree of @p scene: links depth first, each after the joint that leads to it (iterative).
void print_tree(const scene::Scene& scene, std::ostream& out) {
  const auto links = scene.links();
  double mass = 0;
  for (const scene::Link* l : links) mass += l->mass();
  const auto joints = scene.joints();
  out << "scene " << printable(scene.name()) << ": " << links.size() << " links, " << joints.size()
      << " joints, " << scene.geometries().size() << " geometries, total mass " << fmt(mass) << " kg\n";
  std::unordered_map<const scene::Link*, const scene::Joint*> joint_to;
  for (const scene::Joint* j : joints)
    if (const scene::Link* child = j->child_link().get()) joint_to.emplace(child, j);
  std::vector<std::pair<const vsd::Node*, std::size_t>> stack;  // a link (or the scene) and its depth
  stack.emplace_back(&scene, 0);
  while (!stack.empty()) {
    const auto [n, depth] = stack.back();
    stack.pop_back();
    if (depth > 0) {
      const auto* link = static_cast<const scene::Link*>(n);
      const auto it = joint_to.find(link);
      print_link(*link, it == joint_to.end() ? nullptr : it->second, depth, out);
    }
    const auto& children = n->children();
    for (std::size_t i = children.size(); i-- > 0;)  // reversed: the first child is printed first
      if (children[i]->is_a<scene::Link>()) stack.emplace_back(children[i], depth + 1);
  }
}

int body(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {repeated("--package-path"), flag("--json"), flag("--no-meshes")});
  a.expect_positional(1, 1, "one file");
  scene::UrdfOptions options;
  for (const std::string_view p : a.values("--package-path")) options.package_paths.emplace_back(std::string(p));
  options.load_meshes = !a.has("--no-meshes");
  const bool json = a.has("--json");
  Workspace ws;
  ws.env().use<scene::Module>();
  SimState& state = ws.state();
  const SceneInput in = load_scene_input(state, a.positional()[0], options);
  if (json) {
    const auto bytes = io::save_bytes(state, io::Format::Text);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  } else {
    std::vector<const scene::Scene*> scenes;  // depth first, without recursion (deep trees are fine)
    std::vector<const vsd::Node*> todo{&state.database()};
    while (!todo.empty()) {
      const vsd::Node* n = todo.back();
      todo.pop_back();
      if (const auto* s = n->as<scene::Scene>()) scenes.push_back(s);
      for (std::size_t i = n->children().size(); i-- > 0;) todo.push_back(n->children()[i]);
    }
    if (scenes.empty()) out << "no scene in " << input_name(a.positional()[0]) << '\n';
    for (const scene::Scene* s : scenes) print_tree(*s, out);
  }
  std::ostream& report = json ? err : out;
  report << in.warnings.size() << " warning" << (in.warnings.size() == 1 ? "" : "s") << '\n';
  print_warnings(in.warnings, report);
  return exit_ok;
}

}  // namespace

int run(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  return tool::run(tool, args, out, err, body);
}

}  // namespace vsd::tool::vsd_scene
