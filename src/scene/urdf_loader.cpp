// URDF through urdfdom; the element scan for warnings through TinyXML (urdfdom's own XML library).
#include "vsd/scene/urdf_loader.hpp"

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/scene/hull.hpp"
#include "vsd/scene/mesh_loader.hpp"
#include "vsd/scene/scene.hpp"

namespace vsd::scene {

namespace fs = std::filesystem;

namespace {

// urdfdom reports through console_bridge's process-wide output handler; while it parses, ours collects
// the messages (the mutex keeps two parses from swapping handlers under each other).
std::mutex console_mutex;

class CollectingHandler : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char* /*filename*/,
           int /*line*/) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
      messages.push_back(text);
    } else if (level == console_bridge::CONSOLE_BRIDGE_LOG_WARN) {
      warnings.push_back(text);
    }
  }
  std::vector<std::string> messages;
  std::vector<std::string> warnings;
};

// urdfdom logs some errors and still returns a model (a mass of "heavy" becomes an inertial of 0 kg): any
// error it logs makes the file malformed; its warnings become the report's.
urdf::ModelInterfaceSharedPtr parse(const std::string& xml, std::string_view origin,
                                    std::vector<std::string>& warnings) {
  CollectingHandler handler;
  urdf::ModelInterfaceSharedPtr model;
  {
    std::lock_guard lock(console_mutex);
    console_bridge::useOutputHandler(&handler);
    try {
      model = urdf::parseURDF(xml);
    } catch (const std::exception& e) {  // urdfdom throws on some malformed numbers
      handler.messages.emplace_back(e.what());
    }
    console_bridge::restorePreviousOutputHandler();
  }
  for (const auto& w : handler.warnings) warnings.push_back("urdfdom: " + w);
  if (!model || !handler.messages.empty()) {
    std::string msg = std::string(origin) + ": not a valid URDF";
    for (const auto& m : handler.messages) msg += "\n  " + m;
    detail::throw_error(msg);
  }
  return model;
}

Eigen::Isometry3d to_frame(const urdf::Pose& p) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translate(Eigen::Vector3d(p.position.x, p.position.y, p.position.z));
  f.rotate(Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).normalized());
  return f;
}

std::string attr(const TiXmlElement& e, const char* name) {
  const char* v = e.Attribute(name);
  return v != nullptr ? v : "";
}

// What urdfdom does not read, as warnings naming the element: its model has no place for them, so a
// silent parse would drop them without a word.
void scan_unsupported(const std::string& xml, std::vector<std::string>& warnings) {
  TiXmlDocument doc;
  doc.Parse(xml.c_str());
  const TiXmlElement* robot = doc.RootElement();
  if (robot == nullptr) return;
  static const std::set<std::string> top{"link", "joint", "material"};
  static const std::set<std::string> link_children{"inertial", "visual", "collision"};
  static const std::set<std::string> joint_children{"origin", "parent",   "child", "axis",
                                                    "limit",  "dynamics", "mimic"};
  std::map<std::string, int> skipped_top;
  for (const TiXmlElement* e = robot->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    const std::string tag = e->Value();
    if (tag == "link") {
      for (const TiXmlElement* c = e->FirstChildElement(); c != nullptr; c = c->NextSiblingElement())
        if (link_children.count(c->Value()) == 0)
          warnings.push_back("link '" + attr(*e, "name") + "': <" + c->Value() +
                             "> is not supported, ignored");
    } else if (tag == "joint") {
      for (const TiXmlElement* c = e->FirstChildElement(); c != nullptr; c = c->NextSiblingElement())
        if (joint_children.count(c->Value()) == 0)
          warnings.push_back("joint '" + attr(*e, "name") + "': <" + c->Value() +
                             "> is not supported, ignored");
    } else if (top.count(tag) == 0) {
      ++skipped_top[tag];
    }
  }
  for (const auto& [tag, n] : skipped_top)
    warnings.push_back("robot: " + std::to_string(n) + " <" + tag + "> element" + (n > 1 ? "s are" : " is") +
                       " not supported, ignored");
}

class Builder {
 public:
  Builder(vsd::Node& parent, const urdf::ModelInterface& model, fs::path base_dir, const UrdfOptions& options,
          SceneReport& report)
      : state_(parent.state()),
        parent_(parent),
        model_(model),
        base_(std::move(base_dir)),
        options_(options),
        report_(report) {}

  void build(std::string_view origin) {
    scene_ = &state_.create<Scene>();
    scene_->set_name(model_.getName());
    scene_->set_source(std::string(origin));
    report_.scene = scene_;
    // Build the whole tree before attaching it: listeners of the target see one finished robot.
    for (const auto& [name, m] : model_.materials_) material(*m);
    const urdf::LinkConstSharedPtr root = model_.getRoot();
    Link& root_link = make_link(*root);
    scene_->add_child(root_link);
    add_subtree(*root, root_link);
    for (const auto& [name, j] : model_.joints_) {
      if (!j->mimic) continue;
      Joint* self = scene_->find_joint(name);
      Joint* target = scene_->find_joint(j->mimic->joint_name);
      if (target == nullptr) {
        report_.warnings.push_back("joint '" + name + "': mimics unknown joint '" + j->mimic->joint_name +
                                   "'");
      } else {
        self->set_mimic(target);
      }
    }
    parent_.add_child(*scene_);
  }

 private:
  void add_subtree(const urdf::Link& link, Link& node) {
    for (const auto& j : link.child_joints) {
      const urdf::LinkConstSharedPtr child = model_.getLink(j->child_link_name);
      if (!child) continue;  // urdfdom rejects this already
      Link& child_node = make_link(*child);
      child_node.set_frame(to_frame(j->parent_to_joint_origin_transform));
      node.add_child(child_node);
      make_joint(*j, node, child_node);
      add_subtree(*child, child_node);
    }
  }

  Link& make_link(const urdf::Link& l) {
    Link& n = state_.create<Link>();
    n.set_name(l.name);
    ++report_.links;
    if (l.inertial) {
      n.set_mass(l.inertial->mass);
      n.set_inertial_frame(to_frame(l.inertial->origin));
      n.set_inertia_diagonal({l.inertial->ixx, l.inertial->iyy, l.inertial->izz});
      n.set_inertia_products({l.inertial->ixy, l.inertial->ixz, l.inertial->iyz});
    }
    int i = 0;
    for (const auto& v : l.visual_array) {
      Hull* h = make_hull(l.name, "visual", i++, v->name, v->origin, v->geometry, HullRole::Visual);
      if (h == nullptr) continue;
      if (v->material) h->set_material(&material(*v->material));
      n.add_child(*h);
    }
    i = 0;
    for (const auto& c : l.collision_array) {
      Hull* h = make_hull(l.name, "collision", i++, c->name, c->origin, c->geometry, HullRole::Collision);
      if (h != nullptr) n.add_child(*h);
    }
    return n;
  }

  Hull* make_hull(const std::string& link, const char* what, int index, const std::string& name,
                  const urdf::Pose& origin, const urdf::GeometrySharedPtr& g, HullRole role) {
    const std::string where = "link '" + link + "' " + what + (index > 0 ? " " + std::to_string(index) : "");
    if (!g) {
      report_.warnings.push_back(where + ": no geometry, skipped");
      return nullptr;
    }
    Hull& h = state_.create<Hull>();
    h.set_name(name.empty() ? std::string(what) + (index > 0 ? "_" + std::to_string(index) : "") : name);
    h.set_role(role);
    h.set_frame(to_frame(origin));
    h.set_geometry(&geometry(*g, where));
    ++report_.hulls;
    return &h;
  }

  Geometry& new_geometry(std::string name) {
    Geometry& g = state_.create<Geometry>();
    g.set_name(std::move(name));
    scene_->edit_geometries().push_back(g);
    return g;
  }

  Geometry& geometry(const urdf::Geometry& g, const std::string& where) {
    switch (g.type) {
      case urdf::Geometry::BOX: {
        const auto& b = static_cast<const urdf::Box&>(g);
        Geometry& out = new_geometry("box");
        out.set_kind(GeometryKind::Box);
        out.set_size({b.dim.x, b.dim.y, b.dim.z});
        return out;
      }
      case urdf::Geometry::SPHERE: {
        Geometry& out = new_geometry("sphere");
        out.set_kind(GeometryKind::Sphere);
        out.set_radius(static_cast<const urdf::Sphere&>(g).radius);
        return out;
      }
      case urdf::Geometry::CYLINDER: {
        const auto& c = static_cast<const urdf::Cylinder&>(g);
        Geometry& out = new_geometry("cylinder");
        out.set_kind(GeometryKind::Cylinder);
        out.set_radius(c.radius);
        out.set_length(c.length);
        return out;
      }
      case urdf::Geometry::MESH:
        break;
    }
    const auto& m = static_cast<const urdf::Mesh&>(g);
    const Eigen::Vector3d scale(m.scale.x, m.scale.y, m.scale.z);
    // One Geometry per file and scale: hulls share it.
    std::ostringstream key;
    key << m.filename << '|' << scale.x() << ',' << scale.y() << ',' << scale.z();
    if (auto it = meshes_.find(key.str()); it != meshes_.end()) return *it->second;
    Geometry& out = new_geometry(fs::path(m.filename).filename().string());
    out.set_kind(GeometryKind::Mesh);
    out.set_source(m.filename);
    out.set_scale(scale);
    meshes_[key.str()] = &out;
    if (!options_.load_meshes) return out;
    std::vector<fs::path> searched;
    const fs::path file = resolve_mesh_uri(m.filename, base_, options_.package_paths, &searched);
    if (file.empty()) {
      std::string msg = where + ": mesh '" + m.filename + "' not found";
      if (!searched.empty()) {
        msg += " (searched";
        for (const auto& s : searched) msg += " " + s.string();
        msg += ")";
      }
      report_.warnings.push_back(msg);
      return out;
    }
    try {
      load_mesh(out, file);
      ++report_.meshes_loaded;
    } catch (const vsd::Error& e) {
      report_.warnings.push_back(where + ": " + e.what());
    }
    return out;
  }

  Material& material(const urdf::Material& m) {
    // Named materials are shared; an anonymous inline one is its own.
    if (!m.name.empty())
      if (auto it = materials_.find(m.name); it != materials_.end()) return *it->second;
    Material& out = state_.create<Material>();
    out.set_name(m.name);
    out.set_color({m.color.r, m.color.g, m.color.b, m.color.a});
    scene_->edit_materials().push_back(out);
    if (!m.texture_filename.empty()) {
      TextureMap& t = state_.create<TextureMap>();
      t.set_name(m.name.empty() ? std::string("texture") : m.name + " texture");
      t.set_url(m.texture_filename);
      t.set_function(MapFunction::Color);
      scene_->edit_maps().push_back(t);
      textures_[&out] = &t;
    }
    if (!m.name.empty()) materials_[m.name] = &out;
    return out;
  }

  void make_joint(const urdf::Joint& j, Link& parent, Link& child) {
    Joint& out = state_.create<Joint>();
    out.set_name(j.name);
    ++report_.joints;
    switch (j.type) {
      case urdf::Joint::REVOLUTE:
        out.set_type(JointType::Revolute);
        break;
      case urdf::Joint::CONTINUOUS:
        out.set_type(JointType::Continuous);
        break;
      case urdf::Joint::PRISMATIC:
        out.set_type(JointType::Prismatic);
        break;
      case urdf::Joint::FLOATING:
        out.set_type(JointType::Floating);
        break;
      case urdf::Joint::PLANAR:
        out.set_type(JointType::Planar);
        break;
      case urdf::Joint::FIXED:
        out.set_type(JointType::Fixed);
        break;
      default:
        out.set_type(JointType::Unknown);
        break;
    }
    out.set_origin(to_frame(j.parent_to_joint_origin_transform));
    out.set_axis({j.axis.x, j.axis.y, j.axis.z});
    out.set_parent_link(&parent);
    out.set_child_link(&child);
    if (j.limits) {
      out.set_has_limits(true);
      out.set_lower(j.limits->lower);
      out.set_upper(j.limits->upper);
      out.set_effort(j.limits->effort);
      out.set_velocity(j.limits->velocity);
    }
    if (j.dynamics) {
      out.set_damping(j.dynamics->damping);
      out.set_friction(j.dynamics->friction);
    }
    if (j.mimic) {
      out.set_mimic_multiplier(j.mimic->multiplier);
      out.set_mimic_offset(j.mimic->offset);
    }
    scene_->edit_joints().push_back(out);
  }

 public:
  /// Hulls of textured materials get the texture as a colour map.
  void attach_textures() {
    if (textures_.empty()) return;
    scene_->visit([&](vsd::Node& n) {
      if (auto* h = n.as<Hull>(); h != nullptr && h->material().get() != nullptr)
        if (auto it = textures_.find(h->material().get()); it != textures_.end())
          h->edit_maps().push_back(*it->second);
    });
  }

 private:
  SimState& state_;
  vsd::Node& parent_;
  const urdf::ModelInterface& model_;
  fs::path base_;
  const UrdfOptions& options_;
  SceneReport& report_;
  Scene* scene_ = nullptr;
  std::map<std::string, Geometry*> meshes_;
  std::map<std::string, Material*> materials_;
  std::map<const Material*, TextureMap*> textures_;
};

}  // namespace

fs::path resolve_mesh_uri(std::string_view uri, const fs::path& base_dir,
                          const std::vector<fs::path>& package_paths, std::vector<fs::path>* searched) {
  std::vector<fs::path> candidates;
  constexpr std::string_view package = "package://";
  constexpr std::string_view file = "file://";
  if (uri.starts_with(package)) {
    const std::string_view rest = uri.substr(package.size());
    const auto slash = rest.find('/');
    const std::string pkg(rest.substr(0, slash));
    const std::string inner(slash == std::string_view::npos ? std::string_view{} : rest.substr(slash + 1));
    for (const auto& dir : package_paths) {
      candidates.push_back(dir / pkg / inner);
      if (dir.filename() == pkg) candidates.push_back(dir / inner);
    }
  } else if (uri.starts_with(file)) {
    candidates.emplace_back(std::string(uri.substr(file.size())));
  } else {
    const fs::path p{std::string(uri)};
    candidates.push_back(p.is_absolute() ? p : base_dir / p);
  }
  std::error_code ec;
  for (const auto& c : candidates)
    if (fs::is_regular_file(c, ec)) return c;
  if (searched != nullptr) *searched = std::move(candidates);
  return {};
}

SceneReport load_urdf_text(vsd::Node& parent, std::string_view xml, std::string_view origin,
                           const fs::path& base_dir, const UrdfOptions& options) {
  const std::string text(xml);
  SceneReport report;
  const urdf::ModelInterfaceSharedPtr model = parse(text, origin, report.warnings);
  scan_unsupported(text, report.warnings);
  Builder b(parent, *model, base_dir, options, report);
  b.build(origin);
  b.attach_textures();
  return report;
}

SceneReport load_urdf(vsd::Node& parent, const fs::path& file, const UrdfOptions& options) {
  std::ifstream in(file, std::ios::binary);
  if (!in) detail::throw_error("'" + file.string() + "': cannot open URDF file");
  std::ostringstream text;
  text << in.rdbuf();
  return load_urdf_text(parent, text.str(), file.string(), file.parent_path(), options);
}

}  // namespace vsd::scene
