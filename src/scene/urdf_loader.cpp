// URDF through urdfdom, behind the shape check of xml_guard.hpp; the element scan for warnings through
// TinyXML (urdfdom's own XML library); the values validated before anything is built.
#include "vsd/scene/urdf_loader.hpp"

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <mutex>
#include <new>
#include <set>
#include <sstream>
#include <unordered_map>

#include "input_file.hpp"
#include "path_confinement.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/scene/hull.hpp"
#include "vsd/scene/mesh_loader.hpp"
#include "vsd/scene/scene.hpp"
#include "xml_guard.hpp"

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
    try {
      if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
        messages.push_back(text);
      } else if (level == console_bridge::CONSOLE_BRIDGE_LOG_WARN) {
        warnings.push_back(text);
      }
    } catch (...) {  // nothing may leave a logging call inside urdfdom; an error is still an error
      failed = true;
    }
  }
  std::vector<std::string> messages;
  std::vector<std::string> warnings;
  bool failed = false;  // a message could not be kept (out of memory)
};

// urdfdom logs some errors and still returns a model (a mass of "heavy" becomes an inertial of 0 kg): any
// error it logs makes the file malformed; its warnings become the report's.
urdf::ModelInterfaceSharedPtr parse(const std::string& xml, std::string_view origin,
                                    std::vector<std::string>& warnings) {
  CollectingHandler handler;
  urdf::ModelInterfaceSharedPtr model;
  {
    std::lock_guard lock(console_mutex);
    // Restored however parseURDF ends: the handler lives on this stack frame.
    struct Install {
      explicit Install(console_bridge::OutputHandler* h) { console_bridge::useOutputHandler(h); }
      ~Install() { console_bridge::restorePreviousOutputHandler(); }
      Install(const Install&) = delete;
      Install& operator=(const Install&) = delete;
    } install(&handler);
    try {
      model = urdf::parseURDF(xml);
    } catch (const std::bad_alloc&) {
      vsd::detail::throw_error(std::string(origin) + ": out of memory parsing the URDF");
    } catch (const std::exception& e) {  // urdfdom throws on some malformed numbers
      handler.messages.emplace_back(e.what());
    }
  }
  for (const auto& w : handler.warnings) warnings.push_back("urdfdom: " + w);
  if (!model || !handler.messages.empty() || handler.failed) {
    std::string msg = std::string(origin) + ": not a valid URDF";
    for (const auto& m : handler.messages) msg += "\n  " + m;
    vsd::detail::throw_error(msg);
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


// ---- validation: what urdfdom accepts but no body, joint or shape can be ---------------------------------

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

class Validator {
 public:
  explicit Validator(const urdf::ModelInterface& model) : model_(model) {}

  void run() {
    for (const auto& [name, link] : model_.links_) {
      if (link->inertial) inertial(name, *link->inertial);
      int i = 0;
      for (const auto& v : link->visual_array) geometry(where(name, "visual", i++), v->geometry);
      i = 0;
      for (const auto& c : link->collision_array) geometry(where(name, "collision", i++), c->geometry);
    }
    for (const auto& [name, joint] : model_.joints_) this->joint(name, *joint);
    mimic_cycles();
  }

  std::vector<std::string> errors;
  std::vector<std::string> warnings;

 private:
  static std::string where(const std::string& link, const char* what, int index) {
    return "link '" + link + "' " + what + (index > 0 ? " " + std::to_string(index) : "");
  }

  void inertial(const std::string& link, const urdf::Inertial& in) {
    const std::string at = "link '" + link + "' <inertial>";
    if (in.mass < 0) errors.push_back(at + " <mass>: " + num(in.mass) + " kg is negative");
    const std::pair<const char*, double> diagonal[] = {{"ixx", in.ixx}, {"iyy", in.iyy}, {"izz", in.izz}};
    bool negative = false;
    for (const auto& [field, v] : diagonal)
      if (v < 0) {
        errors.push_back(at + " <inertia> " + field + ": " + num(v) + " kg m^2 is negative");
        negative = true;
      }
    if (negative || !(in.mass > 0)) return;
    Eigen::Matrix3d inertia;
    inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    const Eigen::Vector3d m = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia).eigenvalues();
    const double slack = 1e-9 * m.cwiseAbs().maxCoeff();
    if (!(m.minCoeff() > 0)) {
      warnings.push_back(at + " <inertia>: not positive definite (principal moments " + num(m(0)) + ", " +
                         num(m(1)) + ", " + num(m(2)) + " kg m^2) for a mass of " + num(in.mass) +
                         " kg; vsd::physics refuses this link as a body");
    } else if (m(0) + m(1) + slack < m(2)) {
      warnings.push_back(at + " <inertia>: principal moment " + num(m(2)) + " exceeds the sum of the others (" +
                         num(m(0)) + " + " + num(m(1)) + " kg m^2), which no rigid body has; vsd::physics "
                         "refuses this link as a body");
    }
  }

  // A negative dimension is an error; zero a warning (collision and physics leave such a hull out).
  void dimension(const std::string& at, const char* field, double v) {
    if (v < 0) {
      errors.push_back(at + ": " + field + " " + num(v) + " is negative");
    } else if (v == 0) {
      warnings.push_back(at + ": " + field + " is 0; the shape is degenerate (collision and physics leave it out)");
    }
  }

  void geometry(const std::string& at, const urdf::GeometrySharedPtr& g) {
    if (!g) return;  // the builder warns
    switch (g->type) {
      case urdf::Geometry::BOX: {
        const auto& d = static_cast<const urdf::Box&>(*g).dim;
        const std::pair<const char*, double> sides[] = {{"x", d.x}, {"y", d.y}, {"z", d.z}};
        for (const auto& [axis, v] : sides) dimension(at + " <box>", (std::string("size ") + axis).c_str(), v);
        break;
      }
      case urdf::Geometry::SPHERE:
        dimension(at + " <sphere>", "radius", static_cast<const urdf::Sphere&>(*g).radius);
        break;
      case urdf::Geometry::CYLINDER: {
        const auto& c = static_cast<const urdf::Cylinder&>(*g);
        dimension(at + " <cylinder>", "radius", c.radius);
        dimension(at + " <cylinder>", "length", c.length);
        break;
      }
      case urdf::Geometry::MESH: {
        const auto& sc = static_cast<const urdf::Mesh&>(*g).scale;
        if (sc.x == 0 || sc.y == 0 || sc.z == 0)
          warnings.push_back(at + " <mesh>: a scale of 0 flattens the mesh (collision and physics leave it out)");
        break;
      }
    }
  }

  void joint(const std::string& name, const urdf::Joint& j) {
    const std::string at = "joint '" + name + "'";
    const bool moves = j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS ||
                       j.type == urdf::Joint::PRISMATIC || j.type == urdf::Joint::PLANAR;
    if (moves && j.axis.x == 0 && j.axis.y == 0 && j.axis.z == 0)
      errors.push_back(at + " <axis>: the axis is zero");
    if (j.limits) {
      const urdf::JointLimits& l = *j.limits;
      const bool bounded = j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::PRISMATIC;
      if (bounded && l.lower > l.upper)
        errors.push_back(at + " <limit>: lower " + num(l.lower) + " is above upper " + num(l.upper));
      if (l.effort < 0) warnings.push_back(at + " <limit> effort: " + num(l.effort) + " is negative");
      if (l.velocity < 0) warnings.push_back(at + " <limit> velocity: " + num(l.velocity) + " is negative");
    }
    if (j.dynamics) {
      if (j.dynamics->damping < 0)
        warnings.push_back(at + " <dynamics> damping: " + num(j.dynamics->damping) + " is negative");
      if (j.dynamics->friction < 0)
        warnings.push_back(at + " <dynamics> friction: " + num(j.dynamics->friction) + " is negative");
    }
  }

  // A joint that mimics itself, or a ring of mimics: no value could satisfy it. Each joint mimics at most
  // one other, so every walk along the mimics ends at a joint that mimics nobody (or an unknown one) or
  // runs into a ring; joints already walked are not walked again (linear in the number of joints).
  void mimic_cycles() {
    enum class Mark { Unseen, OnPath, Done };
    std::map<std::string, Mark> mark;
    for (const auto& [start, ignored] : model_.joints_) {
      std::vector<std::string> path;
      std::string at = start;
      for (;;) {
        auto it = model_.joints_.find(at);
        if (it == model_.joints_.end()) break;  // an unknown target: the builder warns
        Mark& m = mark[at];
        if (m == Mark::Done) break;
        if (m == Mark::OnPath) {
          std::string ring;
          for (auto p = std::find(path.begin(), path.end(), at); p != path.end(); ++p)
            ring += "'" + *p + "' -> ";
          errors.push_back("joint '" + at + "' <mimic>: a mimic cycle " + ring + "'" + at + "'");
          break;
        }
        m = Mark::OnPath;
        path.push_back(at);
        if (!it->second->mimic) break;
        at = it->second->mimic->joint_name;
      }
      for (const auto& p : path) mark[p] = Mark::Done;
    }
  }

  const urdf::ModelInterface& model_;
};

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
      auto self = joints_.find(name);
      auto target = joints_.find(j->mimic->joint_name);
      if (self == joints_.end()) continue;  // not in the tree (urdfdom rejects this already)
      if (target == joints_.end()) {
        report_.warnings.push_back("joint '" + name + "': mimics unknown joint '" + j->mimic->joint_name +
                                   "'");
      } else {
        self->second->set_mimic(target->second);
      }
    }
    parent_.add_child(*scene_);
  }

 private:
  // Depth first with an explicit stack: a chain of links may be deeper than the call stack.
  void add_subtree(const urdf::Link& root, Link& root_node) {
    std::vector<std::pair<const urdf::Link*, Link*>> todo{{&root, &root_node}};
    while (!todo.empty()) {
      const auto [link, node] = todo.back();
      todo.pop_back();
      std::vector<std::pair<const urdf::Link*, Link*>> children;
      for (const auto& j : link->child_joints) {
        const urdf::LinkConstSharedPtr child = model_.getLink(j->child_link_name);
        if (!child) continue;  // urdfdom rejects this already
        Link& child_node = make_link(*child);
        child_node.set_frame(to_frame(j->parent_to_joint_origin_transform));
        node->add_child(child_node);
        make_joint(*j, *node, child_node);
        children.emplace_back(child.get(), &child_node);
      }
      // Reversed onto the stack: links are still made in the file's order, depth first.
      todo.insert(todo.end(), children.rbegin(), children.rend());
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
    const MeshUriResolution found = resolve_mesh_uri(m.filename, base_, options_);
    if (!found.refused.empty()) {
      report_.warnings.push_back(where + ": mesh '" + m.filename + "' not read: " + found.refused);
      return out;
    }
    if (found.file.empty()) {
      std::string msg = where + ": mesh '" + m.filename + "' not found";
      if (!found.searched.empty()) {
        msg += " (searched";
        for (const auto& s : found.searched) msg += " " + s.string();
        msg += ")";
      }
      report_.warnings.push_back(msg);
      return out;
    }
    try {
      const MeshReport mr = load_mesh(out, found.file, mesh_options());
      for (const auto& w : mr.warnings) report_.warnings.push_back(where + ": mesh '" + m.filename + "': " + w);
      ++report_.meshes_loaded;
    } catch (const vsd::Error& e) {
      report_.warnings.push_back(where + ": " + e.what());
    }
    return out;
  }

  // Files a mesh pulls in obey the rule its own reference does: the URDF's folder and the package paths.
  MeshOptions mesh_options() const {
    MeshOptions o;
    o.allowed_roots = options_.package_paths;
    o.allowed_roots.insert(o.allowed_roots.begin(), base_.empty() ? fs::path(".") : base_);
    o.allow_paths_outside = options_.allow_paths_outside;
    o.max_file_bytes = options_.max_mesh_bytes;
    return o;
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
    joints_[j.name] = &out;
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
  std::unordered_map<std::string, Joint*> joints_;
};

}  // namespace

namespace {

// "http", for "http://..."; empty when @p uri has no scheme (a plain path).
std::string_view scheme_of(std::string_view uri) {
  const auto colon = uri.find("://");
  if (colon == std::string_view::npos || colon == 0) return {};
  for (char c : uri.substr(0, colon))
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '+' && c != '-' && c != '.') return {};
  return uri.substr(0, colon);
}

}  // namespace

MeshUriResolution resolve_mesh_uri(std::string_view uri, const fs::path& base_dir, const UrdfOptions& options) {
  MeshUriResolution r;
  std::vector<fs::path> candidates;
  const std::string_view scheme = scheme_of(uri);
  const std::string_view rest = scheme.empty() ? uri : uri.substr(scheme.size() + 3);
  if (scheme == "package") {
    const auto slash = rest.find('/');
    const std::string pkg(rest.substr(0, slash));
    const std::string inner(slash == std::string_view::npos ? std::string_view{} : rest.substr(slash + 1));
    for (const auto& dir : options.package_paths) {
      candidates.push_back(dir / pkg / inner);
      if (dir.filename() == pkg) candidates.push_back(dir / inner);
    }
  } else if (scheme == "file") {
    candidates.emplace_back(std::string(rest));
  } else if (!scheme.empty()) {
    r.refused = "URI scheme '" + std::string(scheme) + "' is not supported (package://, file:// and paths are)";
    return r;
  } else {
    const fs::path p{std::string(uri)};
    candidates.push_back(p.is_absolute() ? p : base_dir / p);
  }
  std::vector<fs::path> roots = options.package_paths;
  roots.insert(roots.begin(), base_dir.empty() ? fs::path(".") : base_dir);
  const detail::PathConfinement confinement(roots, options.allow_paths_outside);
  for (const auto& c : candidates) {
    std::string why;
    switch (confinement.admit(c, r.file, why)) {
      case detail::PathConfinement::Verdict::Admitted:
        r.refused.clear();
        return r;
      case detail::PathConfinement::Verdict::Refused:
        if (r.refused.empty())
          r.refused = why + (confinement.allows_outside() ? std::string()
                                                            : "; UrdfOptions::allow_paths_outside permits it");
        break;
      case detail::PathConfinement::Verdict::Missing:
        break;
    }
  }
  if (r.refused.empty()) r.searched = std::move(candidates);
  return r;
}

SceneReport load_urdf_text(vsd::Node& parent, std::string_view xml, std::string_view origin,
                           const fs::path& base_dir, const UrdfOptions& options) {
  detail::check_xml_shape(xml, origin, "URDF", {max_urdf_depth, max_urdf_elements, max_urdf_bytes});
  const std::string text(xml);
  SceneReport report;
  const urdf::ModelInterfaceSharedPtr model = parse(text, origin, report.warnings);
  Validator check(*model);
  check.run();
  if (!check.errors.empty()) {
    std::string msg = std::string(origin) + ": not a valid URDF";
    for (const auto& e : check.errors) msg += "\n  " + e;
    vsd::detail::throw_error(msg);
  }
  report.warnings.insert(report.warnings.end(), check.warnings.begin(), check.warnings.end());
  scan_unsupported(text, report.warnings);
  Builder b(parent, *model, base_dir, options, report);
  b.build(origin);
  b.attach_textures();
  return report;
}

SceneReport load_urdf(vsd::Node& parent, const fs::path& file, const UrdfOptions& options) {
  const std::string text = detail::read_input(file, max_urdf_bytes, "URDF file");
  const bool from_stdin = file == "-";
  return load_urdf_text(parent, text, from_stdin ? std::string("standard input") : file.string(),
                        from_stdin ? fs::path(".") : file.parent_path(), options);
}

}  // namespace vsd::scene
