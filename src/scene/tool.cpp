// The vsd-scene command-line tool (see vsd/scene/tool.hpp).
#include "vsd/scene/tool.hpp"

#include <cctype>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "vsd/core/environment.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/io/snapshot.hpp"
#include "vsd/scene/hull.hpp"
#include "vsd/scene/module.hpp"
#include "vsd/scene/scene.hpp"
#include "vsd/scene/urdf_loader.hpp"

namespace vsd::scene {

namespace {

constexpr std::string_view usage = R"(vsd-scene: load a robot description or a saved scene and print its tree

Usage:
  vsd-scene <file> [--package-path DIR]... [--no-meshes] [--json]
      <file> is a URDF (.urdf, .xml) or a scene saved by vsd::io (.json vsd-text, .vsds binary).
      Prints the links (with masses), the joints (type, axis, limits) between them and each link's
      visual and collision hulls with their geometry, then the warnings of the load.
      --package-path DIR  where package://pkg/... mesh URIs are looked up (DIR/pkg/...); repeatable
      --no-meshes         do not read mesh files
      --json              print the loaded scene as a vsd-text file instead of the tree
  vsd-scene --help

Exit status: 0 loaded (warnings or not), 1 the file could not be loaded, 2 a usage error.
)";

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

const Joint* joint_to(const Scene& scene, const Link& child) {
  for (const Joint* j : scene.joints())
    if (j->child_link().get() == &child) return j;
  return nullptr;
}

void print_link(const Scene& scene, const Link& link, int depth, std::ostream& out) {
  const std::string pad(static_cast<std::size_t>(depth) * 2, ' ');
  if (const Joint* j = joint_to(scene, link)) {
    out << pad << "joint " << j->name() << " ("
        << enum_text(meta_type<JointType>(), static_cast<int>(j->type())) << ")";
    if (j->type() != JointType::Fixed) out << " axis " << vec(j->axis());
    if (j->has_limits())
      out << " limits [" << fmt(j->lower()) << ", " << fmt(j->upper()) << "] effort " << fmt(j->effort())
          << " velocity " << fmt(j->velocity());
    if (j->mimic().get() != nullptr) out << " mimics " << j->mimic()->name();
    out << frame_text(j->origin()) << '\n';
  }
  out << pad << "link " << link.name();
  if (link.mass() > 0) out << " mass " << fmt(link.mass()) << " kg";
  out << '\n';
  for (const vsd::Node* c : link.children()) {
    if (const auto* h = c->as<Hull>()) {
      out << pad << "  " << (h->role() == HullRole::Visual ? "visual " : "collision ") << h->name() << ": "
          << (h->geometry().get() != nullptr ? h->geometry()->describe() : std::string("no geometry"));
      if (h->material().get() != nullptr && !h->material()->name().empty())
        out << ", material " << h->material()->name();
      out << frame_text(h->frame()) << '\n';
    }
  }
  for (const vsd::Node* c : link.children())
    if (const auto* l = c->as<Link>()) print_link(scene, *l, depth + 1, out);
}

}  // namespace

void print_tree(const Scene& scene, std::ostream& out) {
  const auto links = scene.links();
  double mass = 0;
  for (const Link* l : links) mass += l->mass();
  out << "scene " << scene.name() << ": " << links.size() << " links, " << scene.joints().size()
      << " joints, " << scene.geometries().size() << " geometries, total mass " << fmt(mass) << " kg\n";
  for (const vsd::Node* c : scene.children())
    if (const auto* l = c->as<Link>()) print_link(scene, *l, 1, out);
}

int run_tool(std::span<const std::string_view> args, std::ostream& out, std::ostream& err) {
  std::string file;
  UrdfOptions options;
  bool json = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    if (a == "--help" || a == "-h") {
      out << usage;
      return 0;
    }
    if (a == "--package-path") {
      if (i + 1 >= args.size()) {
        err << "vsd-scene: --package-path needs a directory\n" << usage;
        return 2;
      }
      options.package_paths.emplace_back(std::string(args[++i]));
    } else if (a == "--json") {
      json = true;
    } else if (a == "--no-meshes") {
      options.load_meshes = false;
    } else if (a.starts_with("-")) {
      err << "vsd-scene: unknown option '" << a << "'\n" << usage;
      return 2;
    } else if (file.empty()) {
      file = std::string(a);
    } else {
      err << "vsd-scene: more than one file given\n" << usage;
      return 2;
    }
  }
  if (file.empty()) {
    err << "vsd-scene: no file given\n" << usage;
    return 2;
  }
  try {
    Environment env;
    env.use<Module>();
    SimState& state = env.main_state();
    std::vector<std::string> warnings;
    std::vector<const Scene*> scenes;
    const std::filesystem::path path(file);
    std::string ext = path.extension().string();
    for (auto& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (ext == ".urdf" || ext == ".xml") {
      SceneReport r = load_urdf(state.database(), path, options);
      warnings = std::move(r.warnings);
      scenes.push_back(r.scene);
    } else {
      io::LoadReport r = io::load(state, path);
      warnings = std::move(r.warnings);
      state.database().visit([&](vsd::Node& n) {
        if (auto* s = n.as<Scene>()) scenes.push_back(s);
      });
    }
    if (json) {
      const auto bytes = io::save_bytes(state, io::Format::Text);
      out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    } else {
      if (scenes.empty()) out << "no scene in " << file << '\n';
      for (const Scene* s : scenes) print_tree(*s, out);
    }
    (json ? err : out) << warnings.size() << " warning" << (warnings.size() == 1 ? "" : "s") << '\n';
    for (const auto& w : warnings) (json ? err : out) << "warning: " << w << '\n';
    return 0;
  } catch (const std::exception& e) {
    err << "vsd-scene: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace vsd::scene
