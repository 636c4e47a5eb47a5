// The ODE mirror of a SimState's bodies, joints and collision hulls, kept current through signals.
#include "vsd/physics/simulation.hpp"

#include <ode/ode.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <new>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "ode_runtime.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/core/watch.hpp"
#include "vsd/scene/hull.hpp"
#include "vsd/scene/link.hpp"
#include "vsd/scene/node3d.hpp"

namespace vsd::physics {

namespace {

using scene::GeometryKind;
using scene::Hull;
using scene::Node3D;

// ---- small helpers ---------------------------------------------------------------------------------------

std::string describe(const vsd::NamedModelInstance& i) {
  std::string s = "'";
  if (const auto* n = i.as<vsd::Node>()) {
    s += n->path();
  } else {
    s += i.name();
  }
  return s + "' (#" + std::to_string(i.id()) + ")";
}

std::string describe_ext(const vsd::Extension& e) {
  std::string s = std::string(e.meta().name());
  if (!e.name().empty()) s += " '" + e.name() + "'";
  s += " #" + std::to_string(e.id());
  if (const auto* o = e.owner()) s += " on " + describe(*o);
  return s;
}

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

// Speeds (m/s, rad/s) beyond this are input errors, not physics (faster than light), and they are where
// ODE's integrator would overflow into an internal assertion — which no handler can turn into a clean
// error from the middle of a step — so they are refused before and after every step.
constexpr double speed_limit = 1e8;
bool sane(const Eigen::Vector3d& v) { return v.allFinite() && v.norm() <= speed_limit; }
bool finite(const Eigen::Isometry3d& f) { return f.matrix().allFinite(); }

void to_ode(const Eigen::Matrix3d& r, dMatrix3 out) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out[i * 4 + j] = r(i, j);
    out[i * 4 + 3] = 0.0;
  }
}

Eigen::Matrix3d from_ode(const dReal* r) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = r[i * 4 + j];
  return m;
}

// The ODE triangle data of one scene::Geometry (scaled vertices, indices, and their mass properties per
// unit density), shared by every trimesh geom of a hull with that geometry. ODE keeps pointers into the
// arrays, so they live as long as the last geom built from them (each GeomRec holds a reference); a
// changed geometry gets a new MeshData, and the geoms built from the old one are rebuilt.
struct MeshData {
  std::vector<dReal> vertices;  // x, y, z per vertex, scaled
  std::vector<dTriIndex> indices;
  dTriMeshDataID data = nullptr;
  double volume = 0.0;                                      // signed (> 0 for a closed, outward mesh)
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();       // of the enclosed volume
  Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero();  // integral of x x^T over the volume
  MeshData() = default;
  MeshData(const MeshData&) = delete;
  MeshData& operator=(const MeshData&) = delete;
  ~MeshData() {
    if (data != nullptr) dGeomTriMeshDataDestroy(data);
  }
};

// What a geom is; a change of any of it means a new ODE geom.
struct Shape {
  GeometryKind kind = GeometryKind::Mesh;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  double radius = 0.0;
  double length = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  std::shared_ptr<const MeshData> mesh;  // meshes only
  bool operator==(const Shape&) const = default;
};

// ---- records: what exists in ODE ----------------------------------------------------------------------

struct WorldRec;
struct BodyRec;

struct GeomRec {
  Hull* hull = nullptr;
  BodyRec* body = nullptr;  // null: static
  WorldRec* world = nullptr;
  dGeomID geom = nullptr;
  Shape shape;
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();  // hull frame in the body node's frame
  bool seen = false;
};

struct BodyRec {
  RigidBody* ext = nullptr;
  Node3D* node = nullptr;
  WorldRec* world = nullptr;
  dBodyID body = nullptr;
  MassProperties mass;
  std::vector<GeomRec*> geoms;
  int depth = 0;
  bool seen = false;
};

struct JointSignature {
  JointKind kind = JointKind::Hinge;
  BodyRec* owner = nullptr;
  BodyRec* other = nullptr;
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis2 = Eigen::Vector3d::Zero();
  bool operator==(const JointSignature&) const = default;
};

struct JointRec {
  Joint* ext = nullptr;
  WorldRec* world = nullptr;
  dJointID joint = nullptr;
  JointSignature sig;
  bool seen = false;
};

struct WorldRec {
  World* ext = nullptr;
  vsd::Node* node = nullptr;
  dWorldID world = nullptr;
  dSpaceID space = nullptr;
  dJointGroupID contacts = nullptr;
  double pending = 0.0;   // simulated time not yet stepped
  double advanced = 0.0;  // stepped in the current advance()
  bool poisoned = false;  // ODE failed inside a step: its objects are abandoned, never touched again
  bool seen = false;
};

// ---- plans: what the database asks for (phase 1 of a rebuild; validated, nothing changed yet) -----------

struct GeomPlan {
  Hull* hull;
  std::size_t body;  // index into bodies, or npos
  std::size_t world;
  Shape shape;
};
struct BodyPlan {
  RigidBody* ext;
  Node3D* node;
  std::size_t world;
  int depth;
  MassProperties mass;
  std::vector<std::size_t> geoms;
};
struct JointPlan {
  Joint* ext;
  std::size_t owner;
  std::size_t other;  // npos: the static world
  std::size_t world;
};
struct WorldPlan {
  World* ext;
  vsd::Node* node;
};
constexpr std::size_t npos = static_cast<std::size_t>(-1);

// Two ODE bodies, in address order.
struct BodyPair {
  dBodyID a;
  dBodyID b;
  BodyPair(dBodyID x, dBodyID y) : a(std::less<>{}(x, y) ? x : y), b(std::less<>{}(x, y) ? y : x) {}
  bool operator==(const BodyPair&) const = default;
};
struct BodyPairHash {
  std::size_t operator()(const BodyPair& p) const noexcept {
    const std::size_t h = std::hash<const void*>{}(p.a);
    return h ^ (std::hash<const void*>{}(p.b) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
  }
};

}  // namespace

// =====================================================================================================

struct Simulation::Impl {
  detail::OdeRuntime runtime;  // first member: ODE stays initialised until everything below is gone
  vsd::SimState* state;

  std::unordered_map<const World*, std::unique_ptr<WorldRec>> worlds;
  std::unordered_map<const RigidBody*, std::unique_ptr<BodyRec>> bodies;
  std::unordered_map<const Node3D*, BodyRec*> body_by_node;
  std::unordered_map<const Hull*, std::unique_ptr<GeomRec>> geoms;
  std::unordered_map<const Joint*, std::unique_ptr<JointRec>> joints;
  // Trimesh data by geometry: built on first use, dropped when the geometry changes or goes.
  std::unordered_map<const scene::Geometry*, std::shared_ptr<const MeshData>> meshes;
  std::vector<BodyRec*> order;  // bodies, parents before children (write-back order)

  bool dirty = true;                     // layout must be rebuilt
  std::vector<vsd::Id> moved;            // nodes whose frame someone else set
  std::unordered_set<BodyRec*> touched;  // bodies whose mass, velocity or gravity someone else set
  bool writing = false;                  // our own write-back: our listeners ignore it
  std::vector<std::string> warnings;
  std::set<std::string> warned;
  std::vector<dContact> contact_buffer;
  // Pairs of bodies joined by one of our joints (how many joints), so that near_callback skips them in
  // O(1): ODE's dAreConnectedExcluding walks a body's joints, contact joints of the step included, which
  // made a heap of touching bodies quadratic.
  std::unordered_map<BodyPair, int, BodyPairHash> joined;
  SimulationStats stats;

  // What the mirror depends on. An at-once Watch whose callback only takes notes (layout dirty; node
  // moved by someone else; body property touched) and applies deletions at once, so no record dangles.
  // No subscription on plain Nodes: a World on a plain node is seen through its own attachment
  // (reparented), and structure through children added and removed, so plain nodes and script objects
  // keep their fast setters.
  Watch watch;

  explicit Impl(vsd::SimState& s)
      : state(&s), watch(s, [this](SimStateInstance& i, const MetaProperty* p, Changes what) { heard(i, p, what); }) {
    subscribe();
  }
  ~Impl() { clear_all(); }

  void subscribe() {
    const auto& link = scene::Link::static_meta();
    std::vector<const MetaProperty*> link_props;  // what a Link adds to a Node3D: mass and inertia
    for (const MetaProperty* p : link.properties())
      if (&p->owner() == &link) link_props.push_back(p);
    std::vector<const MetaProperty*> joint_props;  // all but the measured values the step writes
    for (const MetaProperty* p : Joint::static_meta().properties())
      if (p != &Joint::vsd_prop_position() && p != &Joint::vsd_prop_rate() && p != &Joint::vsd_prop_position2() &&
          p != &Joint::vsd_prop_rate2())
        joint_props.push_back(p);
    for (const MetaInstance* cls : {&Node3D::static_meta(), &RigidBody::static_meta(), &World::static_meta(),
                                    &Joint::static_meta()})
      watch.created(*cls).deleted(*cls);
    watch.deleted(scene::Geometry::static_meta())
        .reparented(vsd::Node::static_meta())
        .reparented(RigidBody::static_meta())
        .reparented(World::static_meta())
        .reparented(Joint::static_meta())
        .properties(Node3D::static_meta(), {&Node3D::vsd_prop_frame()})
        .properties(Hull::static_meta(), {&Hull::vsd_prop_role(), &Hull::vsd_prop_geometry(), &Hull::vsd_prop_material()})
        .properties(link, link_props)
        .all_properties(RigidBody::static_meta())
        .all_properties(World::static_meta())
        .properties(Joint::static_meta(), joint_props)
        .all_properties(scene::Geometry::static_meta())
        // Density decides derived masses; friction and restitution are read at contact time, but checked
        // by the plan.
        .properties(scene::Material::static_meta(), {&scene::Material::vsd_prop_density(),
                                                     &scene::Material::vsd_prop_friction(),
                                                     &scene::Material::vsd_prop_restitution()});
  }

  void heard(SimStateInstance& inst, const MetaProperty* p, Changes what) {
    if (what.has(Changes::deleted)) {
      if (inst.as<scene::Geometry>() != nullptr) {
        meshes.erase(inst.as<scene::Geometry>());
        dirty = true;
      } else {
        deleted(inst);
      }
    } else if (what.has(Changes::created) || what.has(Changes::parent)) {
      dirty = true;
    } else if (inst.as<RigidBody>() != nullptr) {
      body_changed(inst, *p);
    } else if (inst.as<World>() != nullptr) {
      if (!writing || p != &World::vsd_prop_time()) dirty = true;
    } else if (inst.as<scene::Geometry>() != nullptr) {
      meshes.erase(inst.as<scene::Geometry>());
      dirty = true;
    } else if (inst.as<Joint>() != nullptr || inst.as<scene::Material>() != nullptr) {
      dirty = true;
    } else {
      node_changed(inst, *p);
    }
  }

  void node_changed(SimStateInstance& inst, const MetaProperty& p) {
    if (writing) return;
    if (&p == &Node3D::vsd_prop_frame()) {
      moved.push_back(inst.id());
    } else {
      dirty = true;  // a Hull's role, geometry or material, a Link's mass or inertia
    }
  }

  void body_changed(SimStateInstance& inst, const MetaProperty& p) {
    if (writing) return;
    if (&p == &RigidBody::vsd_prop_force() || &p == &RigidBody::vsd_prop_torque()) return;  // read per step
    auto it = bodies.find(static_cast<RigidBody*>(&inst));
    if (it == bodies.end()) {
      dirty = true;
      return;
    }
    touched.insert(it->second.get());
  }

  // Deletions are applied at once (not noted): records must never point at a freed instance.
  void deleted(SimStateInstance& inst) {
    if (auto* w = inst.as<World>()) {
      if (auto it = worlds.find(w); it != worlds.end()) drop_world(*it->second);
    } else if (auto* b = inst.as<RigidBody>()) {
      if (auto it = bodies.find(b); it != bodies.end()) drop_body(*it->second);
    } else if (auto* j = inst.as<Joint>()) {
      if (auto it = joints.find(j); it != joints.end()) drop_joint(*it->second);
    } else if (auto* n = inst.as<Node3D>()) {
      if (auto it = body_by_node.find(n); it != body_by_node.end()) drop_body(*it->second);
      if (auto* h = inst.as<Hull>())
        if (auto it = geoms.find(h); it != geoms.end()) drop_geom(*it->second);
    }
    // World nodes that are plain Nodes: a deleted node takes its extensions with it (deleted above).
    dirty = true;
  }

  // ---- destroying ODE objects ----
  void drop_joint(JointRec& j) {
    if (j.sig.other != nullptr)
      if (auto it = joined.find({j.sig.owner->body, j.sig.other->body}); it != joined.end() && --it->second == 0)
        joined.erase(it);
    if (!j.world->poisoned) dJointDestroy(j.joint);
    joints.erase(j.ext);
  }
  void drop_geom(GeomRec& g) {
    if (g.body != nullptr) std::erase(g.body->geoms, &g);
    if (!g.world->poisoned) dGeomDestroy(g.geom);
    geoms.erase(g.hull);
  }
  void drop_body(BodyRec& b) {
    std::vector<JointRec*> js;
    for (auto& [k, j] : joints)
      if (j->sig.owner == &b || j->sig.other == &b) js.push_back(j.get());
    for (JointRec* j : js) drop_joint(*j);
    while (!b.geoms.empty()) drop_geom(*b.geoms.back());
    touched.erase(&b);
    std::erase(order, &b);
    if (!b.world->poisoned) dBodyDestroy(b.body);
    body_by_node.erase(b.node);
    bodies.erase(b.ext);
  }
  void drop_world(WorldRec& w) {
    std::vector<JointRec*> js;
    for (auto& [k, j] : joints)
      if (j->world == &w) js.push_back(j.get());
    for (JointRec* j : js) drop_joint(*j);
    std::vector<BodyRec*> bs;
    for (auto& [k, b] : bodies)
      if (b->world == &w) bs.push_back(b.get());
    for (BodyRec* b : bs) drop_body(*b);
    std::vector<GeomRec*> gs;
    for (auto& [k, g] : geoms)
      if (g->world == &w) gs.push_back(g.get());
    for (GeomRec* g : gs) drop_geom(*g);
    // A world ODE failed in is abandoned (leaked), not destroyed: its internal state is inconsistent after
    // the failure, and destroying it would run into ODE's own assertions (an abort).
    if (!w.poisoned) {
      dJointGroupDestroy(w.contacts);
      dSpaceDestroy(w.space);
      dWorldDestroy(w.world);
    }
    worlds.erase(w.ext);
  }
  void clear_all() {
    std::vector<WorldRec*> ws;
    for (auto& [k, w] : worlds) ws.push_back(w.get());
    for (WorldRec* w : ws) drop_world(*w);
  }

  // ---- phase 1: the plan ----
  struct Plan {
    std::vector<WorldPlan> worlds;
    std::vector<BodyPlan> bodies;
    std::vector<GeomPlan> geoms;
    std::vector<JointPlan> joints;
    std::unordered_map<const Node3D*, std::size_t> body_of_node;
  };

  void warn(std::string text) {
    if (warned.insert(text).second) warnings.push_back(std::move(text));
  }

  static void check_world(const World& w) {
    auto bad = [&](const std::string& what) { detail_throw(describe_ext(w) + ": " + what); };
    if (!finite(w.gravity())) bad("gravity is not finite");
    if (!(w.step() > 0.0) || !std::isfinite(w.step()))
      bad("step must be > 0, got " + std::to_string(w.step()));
    if (w.iterations() < 1) bad("iterations must be >= 1");
    if (!(w.erp() >= 0.0 && w.erp() <= 1.0)) bad("erp must be in [0, 1]");
    if (!(w.cfm() >= 0.0) || !std::isfinite(w.cfm())) bad("cfm must be >= 0");
    if (w.max_contacts() < 1 || w.max_contacts() > 256) bad("max_contacts must be in 1..256");
    if (!(w.contact_surface_layer() >= 0.0) || !std::isfinite(w.contact_surface_layer()))
      bad("contact_surface_layer must be >= 0");
    if (!(w.max_correcting_velocity() >= 0.0)) bad("max_correcting_velocity must be >= 0");
    if (!(w.bounce_threshold() >= 0.0) || !std::isfinite(w.bounce_threshold()))
      bad("bounce_threshold must be >= 0");
    if (!(w.default_friction() >= 0.0) || !(w.default_restitution() >= 0.0 && w.default_restitution() <= 1.0))
      bad("default friction must be >= 0 and default restitution in [0, 1]");
  }

  [[noreturn]] static void detail_throw(const std::string& s) { throw vsd::Error("vsd::physics: " + s); }

  // The shape of a collision hull; nullopt-like: returns false when the hull is skipped (with a warning).
  bool shape_of(const Hull& h, bool on_body, Shape& out) {
    const scene::Geometry* g = h.geometry().get();
    if (g == nullptr) {
      warn("collision hull " + describe(h) + " has no geometry: it does not collide");
      return false;
    }
    out = Shape{};
    out.kind = g->kind();
    auto bad = [&](const std::string& what) {
      detail_throw("collision hull " + describe(h) + ", geometry " + g->describe() + ": " + what);
    };
    switch (g->kind()) {
      case GeometryKind::Box:
        if (!(g->size().minCoeff() > 0.0) || !finite(g->size())) bad("box sizes must be > 0");
        out.size = g->size();
        break;
      case GeometryKind::Sphere:
        if (!(g->radius() > 0.0) || !std::isfinite(g->radius())) bad("radius must be > 0");
        out.radius = g->radius();
        break;
      case GeometryKind::Cylinder:
      case GeometryKind::Capsule:
        if (!(g->radius() > 0.0) || !std::isfinite(g->radius())) bad("radius must be > 0");
        if (!(g->length() > 0.0) || !std::isfinite(g->length())) bad("length must be > 0");
        out.radius = g->radius();
        out.length = g->length();
        break;
      case GeometryKind::Plane:
        if (on_body) bad("a plane is unbounded and cannot belong to a rigid body (only to static scenery)");
        if (!finite(g->normal()) || !(g->normal().norm() > 0.0))
          bad("plane normal must be a finite non-zero vector");
        out.normal = g->normal().normalized();
        break;
      case GeometryKind::Mesh:
        if (!g->has_mesh_data()) {  // e.g. a URDF mesh whose file was missing: the loader warned already
          warn("collision hull " + describe(h) + ": its mesh has no vertices (" + g->describe() +
               "); it does not collide");
          return false;
        }
        out.mesh = mesh_data(h, *g);
        break;
    }
    return true;
  }

  // The shared trimesh data of @p g, built (and validated) on first use.
  std::shared_ptr<const MeshData> mesh_data(const Hull& h, const scene::Geometry& g) {
    if (auto it = meshes.find(&g); it != meshes.end()) return it->second;
    auto bad = [&](const std::string& what) {
      detail_throw("collision hull " + describe(h) + ", geometry " + g.describe() + ": " + what);
    };
    const auto& v = g.vertices();
    const auto& f = g.facets();
    if (f.empty()) bad("a mesh needs triangles (its facet list is empty)");
    if (f.size() % 3 != 0)
      bad("the facet list holds " + std::to_string(f.size()) + " indices, not a multiple of 3");
    if (!finite(g.scale()) || g.scale().cwiseAbs().minCoeff() == 0.0)
      bad("the mesh scale must be finite and non-zero");
    if (v.size() > static_cast<std::size_t>(std::numeric_limits<int>::max() / 3))
      bad("too many vertices for ODE");
    auto m = std::make_shared<MeshData>();
    m->vertices.reserve(v.size() * 3);
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!finite(v[i])) bad("vertex " + std::to_string(i) + " is not finite");
      const Eigen::Vector3d p = v[i].cwiseProduct(g.scale());
      m->vertices.insert(m->vertices.end(), {p.x(), p.y(), p.z()});
    }
    m->indices.reserve(f.size());
    for (std::size_t i = 0; i < f.size(); ++i) {
      if (f[i] < 0 || static_cast<std::size_t>(f[i]) >= v.size())
        bad("facet " + std::to_string(i / 3) + " refers to vertex " + std::to_string(f[i]) +
            ", but there are " + std::to_string(v.size()) + " vertices");
      m->indices.push_back(static_cast<dTriIndex>(f[i]));
    }
    // A negative scale mirrors the mesh and turns its facets inside out: reverse them back.
    if (g.scale().prod() < 0.0)
      for (std::size_t i = 0; i < m->indices.size(); i += 3) std::swap(m->indices[i + 1], m->indices[i + 2]);
    // Volume, centroid and second moment by the divergence theorem: the signed tetrahedra from the origin
    // to each facet (for a tetrahedron 0, a, b, c of volume V: integral of x x^T = V/20 (sum of x_i x_i^T
    // + s s^T), s = a + b + c).
    Eigen::Vector3d first = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < m->indices.size(); i += 3) {
      const auto at = [&](std::size_t k) {
        const dReal* p = &m->vertices[3 * static_cast<std::size_t>(m->indices[i + k])];
        return Eigen::Vector3d(p[0], p[1], p[2]);
      };
      const Eigen::Vector3d a = at(0), b = at(1), c = at(2), sum = a + b + c;
      const double vol = a.dot(b.cross(c)) / 6.0;
      m->volume += vol;
      first += vol * sum / 4.0;
      m->second_moment +=
          vol / 20.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose());
    }
    if (m->volume != 0.0) m->centroid = first / m->volume;
    m->data = dGeomTriMeshDataCreate();
    dGeomTriMeshDataBuildDouble(m->data, m->vertices.data(), 3 * sizeof(dReal), static_cast<int>(v.size()),
                                m->indices.data(), static_cast<int>(m->indices.size()),
                                3 * sizeof(dTriIndex));
    std::shared_ptr<const MeshData> shared = std::move(m);
    meshes.emplace(&g, shared);
    return shared;
  }

  static Eigen::Isometry3d relative(const Node3D& body, const Node3D& hull) {
    Eigen::Isometry3d r = body.world_frame().inverse() * hull.world_frame();
    r.makeAffine();
    return r;
  }

  // Friction and restitution are read inside near_callback, where nothing can be refused: they are
  // checked here, when the hull enters the plan (they used to be clamped silently).
  static void check_material(const Hull& h) {
    const scene::Material* m = h.material().get();
    if (m == nullptr) return;
    if (!(m->friction() >= 0.0) || !std::isfinite(m->friction()))
      detail_throw("collision hull " + describe(h) + ": material friction must be finite and >= 0, got " +
                   std::to_string(m->friction()));
    if (!(m->restitution() >= 0.0 && m->restitution() <= 1.0))
      detail_throw("collision hull " + describe(h) + ": material restitution must lie in [0, 1], got " +
                   std::to_string(m->restitution()));
  }

  static double density_of(const Hull& h) {
    const scene::Material* m = h.material().get();
    const double d = m != nullptr ? m->density() : 1000.0;
    if (!(d > 0.0) || !std::isfinite(d))
      detail_throw("collision hull " + describe(h) + ": material density must be > 0, got " +
                   std::to_string(d));
    return d;
  }

  MassProperties compute_mass(const BodyPlan& b, const Plan& plan) const {
    const RigidBody& rb = *b.ext;
    auto bad = [&](const std::string& what) {
      detail_throw("rigid body on " + describe(*b.node) + ": " + what);
    };
    if (!std::isfinite(rb.mass()) || rb.mass() < 0.0)
      bad("mass must be >= 0 (0: derived), got " + std::to_string(rb.mass()));
    if (!finite(rb.center_of_mass()) || !finite(rb.inertia_diagonal()) || !finite(rb.inertia_products()))
      bad("centre of mass and inertia must be finite");
    MassProperties mp;
    const auto* link = b.node->as<scene::Link>();
    if (!rb.inertia_diagonal().isZero(0.0)) {
      if (!(rb.mass() > 0.0)) bad("an explicit inertia needs an explicit mass > 0");
      mp.mass = rb.mass();
      mp.center = rb.center_of_mass();
      const auto& d = rb.inertia_diagonal();
      const auto& o = rb.inertia_products();
      mp.inertia << d.x(), o.x(), o.y(), o.x(), d.y(), o.z(), o.y(), o.z(), d.z();
    } else if (link != nullptr && link->mass() != 0.0) {
      // The link's inertial data is what the description says the body is: it wins over the volume of
      // its collision hulls, which are an approximation of its surface for contacts.
      if (!(link->mass() > 0.0) || !std::isfinite(link->mass()))
        bad("link " + describe(*link) + " has a mass of " + std::to_string(link->mass()) +
            " kg; a body needs a positive, finite mass");
      const double scale = rb.mass() > 0.0 ? rb.mass() / link->mass() : 1.0;
      const Eigen::Matrix3d rot = link->inertial_frame().rotation();
      mp.mass = link->mass() * scale;
      mp.center = link->inertial_frame().translation();
      mp.inertia = rot * link->inertia() * rot.transpose() * scale;
      if (!mp.inertia.allFinite() || mp.inertia.isZero(0.0))
        bad("link " + describe(*link) + " has a mass but no inertia");
    } else {
      dMass total;
      dMassSetZero(&total);
      bool any = false;
      for (std::size_t gi : b.geoms) {
        const GeomPlan& g = plan.geoms[gi];
        dMass m;
        const double rho = density_of(*g.hull);
        switch (g.shape.kind) {
          case GeometryKind::Box:
            dMassSetBox(&m, rho, g.shape.size.x(), g.shape.size.y(), g.shape.size.z());
            break;
          case GeometryKind::Sphere:
            dMassSetSphere(&m, rho, g.shape.radius);
            break;
          case GeometryKind::Cylinder:
            dMassSetCylinder(&m, rho, 3, g.shape.radius, g.shape.length);
            break;
          case GeometryKind::Capsule:
            dMassSetCapsule(&m, rho, 3, g.shape.radius, g.shape.length);
            break;
          case GeometryKind::Mesh: {
            const MeshData& md = *g.shape.mesh;
            // An open or inside-out mesh has no (or a negative) volume: its mass would be nonsense.
            if (!(md.volume > 0.0))
              detail_throw("collision hull " + describe(*g.hull) + ", geometry " +
                           g.hull->geometry()->describe() + ": the mesh encloses no positive volume (" +
                           std::to_string(md.volume) +
                           " m^3): it must be closed with its facets wound counter-clockwise seen from "
                           "outside, or the body needs an explicit mass and inertia_diagonal");
            // dMass holds the inertia about the body origin (here the mesh origin) with the centre c.
            const Eigen::Matrix3d c2 = rho * md.second_moment;
            const Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity() * c2.trace() - c2;
            dMassSetParameters(&m, rho * md.volume, md.centroid.x(), md.centroid.y(), md.centroid.z(),
                               inertia(0, 0), inertia(1, 1), inertia(2, 2), inertia(0, 1), inertia(0, 2),
                               inertia(1, 2));
            break;
          }
          default:
            continue;
        }
        const Eigen::Isometry3d rel = relative(*b.node, *g.hull);
        dMatrix3 r;
        to_ode(rel.rotation(), r);
        dMassRotate(&m, r);
        dMassTranslate(&m, rel.translation().x(), rel.translation().y(), rel.translation().z());
        dMassAdd(&total, &m);
        any = true;
      }
      if (!any)
        bad("no mass: set RigidBody.mass and inertia_diagonal, or give the body collision hulls (role "
            "Collision) with primitive or closed mesh geometry");
      if (rb.mass() > 0.0) dMassAdjust(&total, rb.mass());
      const Eigen::Vector3d c(total.c[0], total.c[1], total.c[2]);
      dMassTranslate(&total, -c.x(), -c.y(), -c.z());  // inertia about the centre of mass
      mp.mass = total.mass;
      mp.center = c;
      mp.inertia = from_ode(total.I);
    }
    // ODE's own check (positive definite inertia, triangle inequalities of the principal moments).
    dMass check;
    dMassSetParameters(&check, mp.mass, 0, 0, 0, mp.inertia(0, 0), mp.inertia(1, 1), mp.inertia(2, 2),
                       mp.inertia(0, 1), mp.inertia(0, 2), mp.inertia(1, 2));
    if (!(mp.mass > 0.0) || !mp.inertia.allFinite() || !mp.center.allFinite())
      bad("mass must be > 0 and finite");
    std::vector<std::string> ignored;
    {
      detail::MessageSink sink(ignored);  // dMassCheck explains itself through dMessage; we say it ourselves
      const Eigen::Vector3d pm = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(mp.inertia).eigenvalues();
      const double slack = 1e-9 * pm.cwiseAbs().maxCoeff();
      const bool triangle =
          pm(0) + pm(1) + slack >= pm(2) && pm(0) + pm(2) + slack >= pm(1) && pm(1) + pm(2) + slack >= pm(0);
      if (dMassCheck(&check) == 0 || !(pm.minCoeff() > 0.0) || !triangle) {
        std::ostringstream s;
        s << "inertia is not physical (not positive definite, or a principal moment exceeds the sum of the "
             "other two): mass "
          << mp.mass << ", inertia [" << mp.inertia.row(0) << "; " << mp.inertia.row(1) << "; "
          << mp.inertia.row(2) << "]";
        bad(s.str());
      }
    }
    return mp;
  }

  Plan make_plan() {
    Plan plan;
    std::unordered_map<const vsd::Node*, std::size_t> world_of_node;
    for (World* w : state->index().all<World>()) {
      vsd::NamedModelInstance* owner = w->owner();
      if (owner == nullptr) continue;  // floating: not in use
      auto* node = owner->as<vsd::Node>();
      if (node == nullptr) detail_throw(describe_ext(*w) + " must be attached to a node");
      if (world_of_node.contains(node))
        detail_throw("node " + describe(*node) + " carries two physics::World extensions");
      check_world(*w);
      world_of_node[node] = plan.worlds.size();
      plan.worlds.push_back({w, node});
    }
    std::unordered_set<const RigidBody*> planned_bodies;
    std::unordered_set<const Joint*> planned_joints;
    std::vector<std::pair<Joint*, std::size_t>> pending_joints;  // joint, owner node's world
    struct Item {
      vsd::Node* node;
      std::size_t body;
      int depth;
    };
    for (std::size_t wi = 0; wi < plan.worlds.size(); ++wi) {
      std::vector<Item> todo{{plan.worlds[wi].node, npos, 0}};
      while (!todo.empty()) {
        Item it = todo.back();
        todo.pop_back();
        if (it.node != plan.worlds[wi].node && world_of_node.contains(it.node))
          continue;  // a world of its own
        std::size_t body = it.body;
        int depth = it.depth;
        auto* n3 = it.node->as<Node3D>();
        for (vsd::Extension* e : it.node->extensions()) {
          if (auto* rb = e->as<RigidBody>()) {
            if (n3 == nullptr) detail_throw(describe_ext(*rb) + " must be attached to a scene::Node3D");
            if (body != npos && plan.bodies[body].node == n3)
              detail_throw("node " + describe(*n3) + " carries two RigidBody extensions");
            body = plan.bodies.size();
            depth = it.depth + 1;
            plan.bodies.push_back({rb, n3, wi, depth, {}, {}});
            plan.body_of_node[n3] = body;
            planned_bodies.insert(rb);
          }
        }
        for (vsd::Extension* e : it.node->extensions())
          if (auto* j = e->as<Joint>()) {
            pending_joints.emplace_back(j, wi);
            planned_joints.insert(j);
          }
        if (auto* h = it.node->as<Hull>(); h != nullptr && h->role() == scene::HullRole::Collision) {
          check_material(*h);
          Shape shape;
          if (shape_of(*h, body != npos, shape)) {
            if (body != npos) plan.bodies[body].geoms.push_back(plan.geoms.size());
            plan.geoms.push_back({h, body, wi, shape});
          }
        }
        const auto& children = it.node->children();
        for (auto c = children.size(); c-- > 0;) todo.push_back({children[c], body, depth});
      }
    }
    // Bodies and joints outside every world are mistakes, not scenery.
    for (RigidBody* rb : state->index().all<RigidBody>())
      if (rb->owner() != nullptr && !planned_bodies.contains(rb))
        detail_throw(describe_ext(*rb) +
                     " is in no physics world: attach a physics::World to one of its ancestors");
    for (Joint* j : state->index().all<Joint>())
      if (j->owner() != nullptr && !planned_joints.contains(j))
        detail_throw(describe_ext(*j) +
                     " is in no physics world: attach a physics::World to one of its ancestors");
    for (auto& b : plan.bodies) {
      if (!finite(b.node->world_frame()))
        detail_throw("rigid body node " + describe(*b.node) + " has a non-finite frame");
      if (!sane(b.ext->linear_velocity()) || !sane(b.ext->angular_velocity()))
        detail_throw("rigid body on " + describe(*b.node) + ": velocities must be finite and below 1e8");
      b.mass = compute_mass(b, plan);
    }
    for (auto& g : plan.geoms)
      if (g.body == npos && !finite(g.hull->world_frame()))
        detail_throw("collision hull " + describe(*g.hull) + " has a non-finite frame");
    for (auto& [j, wi] : pending_joints) plan.joints.push_back(plan_joint(*j, wi, plan));
    return plan;
  }

  JointPlan plan_joint(Joint& j, std::size_t wi, const Plan& plan) {
    auto bad = [&](const std::string& what) { detail_throw(describe_ext(j) + ": " + what); };
    auto* owner_node = j.owner()->as<Node3D>();
    auto oit = owner_node != nullptr ? plan.body_of_node.find(owner_node) : plan.body_of_node.end();
    if (oit == plan.body_of_node.end()) bad("its node has no RigidBody");
    std::size_t other = npos;
    if (Node3D* o = j.other().get()) {
      auto it = plan.body_of_node.find(o);
      if (it == plan.body_of_node.end())
        bad("the other node " + describe(*o) + " has no RigidBody (null means the static world)");
      other = it->second;
      if (other == oit->second) bad("a joint needs two different bodies");
      if (plan.bodies[other].world != wi)
        bad("joins bodies of different worlds (" + describe_ext(*plan.worlds[wi].ext) + " and " +
            describe_ext(*plan.worlds[plan.bodies[other].world].ext) + ")");
    }
    if (!finite(j.anchor()) || !finite(j.axis()) || !finite(j.axis2())) bad("anchor and axes must be finite");
    const bool axial =
        j.kind() == JointKind::Hinge || j.kind() == JointKind::Slider || j.kind() == JointKind::Universal;
    if (axial && !(j.axis().norm() > 1e-12)) bad("axis must not be zero");
    if (j.kind() == JointKind::Universal) {
      if (!(j.axis2().norm() > 1e-12)) bad("axis2 must not be zero");
      if (std::abs(j.axis().normalized().dot(j.axis2().normalized())) > 1e-6)
        bad("axis and axis2 must be perpendicular");
    }
    if (!std::isfinite(j.lower()) || !std::isfinite(j.upper()) || !std::isfinite(j.motor_velocity()) ||
        !std::isfinite(j.motor_max_force()) || j.motor_max_force() < 0.0)
      bad("limits and motor values must be finite, motor_max_force >= 0");
    if (!axial && (j.has_limits() || j.motor_max_force() > 0.0))
      bad("limits and motors apply to hinge, slider and universal joints only");
    if (j.has_limits()) {
      if (j.lower() > j.upper()) bad("lower limit above upper limit");
      if (j.kind() != JointKind::Slider && (j.lower() < -M_PI || j.upper() > M_PI))
        bad("angle limits must lie in [-pi, pi]");
    }
    if (!std::isfinite(j.lower2()) || !std::isfinite(j.upper2()) || !std::isfinite(j.motor_velocity2()) ||
        !std::isfinite(j.motor_max_force2()) || j.motor_max_force2() < 0.0)
      bad("second-axis limits and motor values must be finite, motor_max_force2 >= 0");
    if (j.kind() != JointKind::Universal && (j.has_limits2() || j.motor_max_force2() > 0.0))
      bad("second-axis limits and motors (has_limits2, motor_max_force2) apply to universal joints only");
    if (j.has_limits2()) {
      if (j.lower2() > j.upper2()) bad("lower2 limit above upper2 limit");
      // ODE's second universal angle is an elevation out of the plane normal to axis 1: it never leaves
      // [-pi/2, pi/2], so a stop beyond that would never be reached.
      if (j.lower2() < -M_PI / 2 || j.upper2() > M_PI / 2)
        bad("second-axis angle limits must lie in [-pi/2, pi/2]");
    }
    return {&j, oit->second, other, wi};
  }

  // ---- phase 2: apply the plan (does not throw) ----
  void set_world_params(WorldRec& w) {
    const World& e = *w.ext;
    dWorldSetGravity(w.world, e.gravity().x(), e.gravity().y(), e.gravity().z());
    dWorldSetERP(w.world, e.erp());
    dWorldSetCFM(w.world, e.cfm());
    dWorldSetQuickStepNumIterations(w.world, e.iterations());
    dWorldSetContactSurfaceLayer(w.world, e.contact_surface_layer());
    dWorldSetContactMaxCorrectingVel(
        w.world, e.max_correcting_velocity() > 0.0 ? e.max_correcting_velocity() : dInfinity);
  }

  void place_body(BodyRec& b) {
    const Eigen::Isometry3d& w = b.node->world_frame();
    const Eigen::Vector3d p = w * b.mass.center;
    dBodySetPosition(b.body, p.x(), p.y(), p.z());
    dMatrix3 r;
    to_ode(w.rotation(), r);
    dBodySetRotation(b.body, r);
    dBodyEnable(b.body);
  }

  void set_body_state(BodyRec& b) {
    dMass m;
    const auto& mp = b.mass;
    dMassSetParameters(&m, mp.mass, 0, 0, 0, mp.inertia(0, 0), mp.inertia(1, 1), mp.inertia(2, 2),
                       mp.inertia(0, 1), mp.inertia(0, 2), mp.inertia(1, 2));
    dBodySetMass(b.body, &m);
    place_body(b);
    const auto& v = b.ext->linear_velocity();
    const auto& av = b.ext->angular_velocity();
    dBodySetLinearVel(b.body, v.x(), v.y(), v.z());
    dBodySetAngularVel(b.body, av.x(), av.y(), av.z());
    dBodySetGravityMode(b.body, b.ext->gravity() ? 1 : 0);
    for (GeomRec* g : b.geoms) place_geom(*g);
  }

  void place_geom(GeomRec& g) {
    if (g.body != nullptr) {
      const Eigen::Vector3d t = g.offset.translation() - g.body->mass.center;
      dGeomSetOffsetPosition(g.geom, t.x(), t.y(), t.z());
      dMatrix3 r;
      to_ode(g.offset.rotation(), r);
      dGeomSetOffsetRotation(g.geom, r);
      return;
    }
    const Eigen::Isometry3d& w = g.hull->world_frame();
    if (g.shape.kind == GeometryKind::Plane) {
      const Eigen::Vector3d n = (w.rotation() * g.shape.normal).normalized();
      dGeomPlaneSetParams(g.geom, n.x(), n.y(), n.z(), n.dot(w.translation()));
      return;
    }
    dGeomSetPosition(g.geom, w.translation().x(), w.translation().y(), w.translation().z());
    dMatrix3 r;
    to_ode(w.rotation(), r);
    dGeomSetRotation(g.geom, r);
  }

  static dGeomID make_geom(dSpaceID space, const Shape& s) {
    if (s.kind == GeometryKind::Mesh) return dCreateTriMesh(space, s.mesh->data, nullptr, nullptr, nullptr);
    switch (s.kind) {
      case GeometryKind::Box:
        return dCreateBox(space, s.size.x(), s.size.y(), s.size.z());
      case GeometryKind::Sphere:
        return dCreateSphere(space, s.radius);
      case GeometryKind::Cylinder:
        return dCreateCylinder(space, s.radius, s.length);
      case GeometryKind::Capsule:
        return dCreateCapsule(space, s.radius, s.length);
      case GeometryKind::Plane:
        return dCreatePlane(space, s.normal.x(), s.normal.y(), s.normal.z(), 0.0);
      case GeometryKind::Mesh:
        break;
    }
    return nullptr;  // not reached: meshes are made above
  }

  void set_joint_params(JointRec& j) {
    const Joint& e = *j.ext;
    const double lo = e.has_limits() ? e.lower() : -dInfinity;
    const double hi = e.has_limits() ? e.upper() : dInfinity;
    auto params = [&](auto set) {
      // Widen first, so that the new pair is never rejected for crossing the old one.
      set(j.joint, dParamLoStop, -dInfinity);
      set(j.joint, dParamHiStop, dInfinity);
      set(j.joint, dParamLoStop, lo);
      set(j.joint, dParamHiStop, hi);
      set(j.joint, dParamVel, e.motor_velocity());
      set(j.joint, dParamFMax, e.motor_max_force());
    };
    switch (e.kind()) {
      case JointKind::Hinge:
        params(&dJointSetHingeParam);
        break;
      case JointKind::Slider:
        params(&dJointSetSliderParam);
        break;
      case JointKind::Universal: {
        params(&dJointSetUniversalParam);
        const double lo2 = e.has_limits2() ? e.lower2() : -dInfinity;
        const double hi2 = e.has_limits2() ? e.upper2() : dInfinity;
        dJointSetUniversalParam(j.joint, dParamLoStop2, -dInfinity);
        dJointSetUniversalParam(j.joint, dParamHiStop2, dInfinity);
        dJointSetUniversalParam(j.joint, dParamLoStop2, lo2);
        dJointSetUniversalParam(j.joint, dParamHiStop2, hi2);
        dJointSetUniversalParam(j.joint, dParamVel2, e.motor_velocity2());
        dJointSetUniversalParam(j.joint, dParamFMax2, e.motor_max_force2());
        break;
      }
      default:
        break;
    }
  }

  void build_joint(JointRec& j) {
    const Joint& e = *j.ext;
    dWorldID w = j.world->world;
    const Eigen::Isometry3d& f = j.sig.owner->node->world_frame();
    const Eigen::Vector3d a = f * e.anchor();
    const Eigen::Vector3d x1 = (f.rotation() * e.axis()).normalized();
    const Eigen::Vector3d x2 = (f.rotation() * e.axis2()).normalized();
    switch (e.kind()) {
      case JointKind::Hinge:
        j.joint = dJointCreateHinge(w, nullptr);
        break;
      case JointKind::Slider:
        j.joint = dJointCreateSlider(w, nullptr);
        break;
      case JointKind::Universal:
        j.joint = dJointCreateUniversal(w, nullptr);
        break;
      case JointKind::Ball:
        j.joint = dJointCreateBall(w, nullptr);
        break;
      case JointKind::Fixed:
        j.joint = dJointCreateFixed(w, nullptr);
        break;
    }
    dJointAttach(j.joint, j.sig.owner->body, j.sig.other != nullptr ? j.sig.other->body : nullptr);
    switch (e.kind()) {
      case JointKind::Hinge:
        dJointSetHingeAnchor(j.joint, a.x(), a.y(), a.z());
        dJointSetHingeAxis(j.joint, x1.x(), x1.y(), x1.z());
        break;
      case JointKind::Slider:
        dJointSetSliderAxis(j.joint, x1.x(), x1.y(), x1.z());
        break;
      case JointKind::Universal:
        dJointSetUniversalAnchor(j.joint, a.x(), a.y(), a.z());
        dJointSetUniversalAxis1(j.joint, x1.x(), x1.y(), x1.z());
        dJointSetUniversalAxis2(j.joint, x2.x(), x2.y(), x2.z());
        break;
      case JointKind::Ball:
        dJointSetBallAnchor(j.joint, a.x(), a.y(), a.z());
        break;
      case JointKind::Fixed:
        dJointSetFixed(j.joint);
        break;
    }
    set_joint_params(j);
  }

  void rebuild() {
    Plan plan = make_plan();  // throws; nothing has changed yet
    // Worlds.
    for (auto& [k, w] : worlds) w->seen = false;
    std::vector<WorldRec*> wrec(plan.worlds.size());
    for (std::size_t i = 0; i < plan.worlds.size(); ++i) {
      auto& slot = worlds[plan.worlds[i].ext];
      if (slot && (slot->node != plan.worlds[i].node || slot->poisoned)) {
        WorldRec* old = slot.get();
        drop_world(*old);  // moved to another node: start afresh
      }
      auto& rec = worlds[plan.worlds[i].ext];
      if (!rec) {
        rec = std::make_unique<WorldRec>();
        rec->ext = plan.worlds[i].ext;
        rec->node = plan.worlds[i].node;
        rec->world = dWorldCreate();
        rec->space = dHashSpaceCreate(nullptr);
        dSpaceSetCleanup(rec->space, 0);  // geoms are destroyed one by one, by their records
        rec->contacts = dJointGroupCreate(0);
      }
      rec->seen = true;
      set_world_params(*rec);
      wrec[i] = rec.get();
    }
    {
      std::vector<WorldRec*> stale;
      for (auto& [k, w] : worlds)
        if (!w->seen) stale.push_back(w.get());
      for (WorldRec* w : stale) drop_world(*w);
    }
    // Bodies.
    for (auto& [k, b] : bodies) b->seen = false;
    std::vector<BodyRec*> brec(plan.bodies.size());
    for (std::size_t i = 0; i < plan.bodies.size(); ++i) {
      const BodyPlan& p = plan.bodies[i];
      auto it = bodies.find(p.ext);
      if (it != bodies.end() && (it->second->node != p.node || it->second->world != wrec[p.world])) {
        drop_body(*it->second);
        it = bodies.end();
      }
      if (it == bodies.end()) {
        auto rec = std::make_unique<BodyRec>();
        rec->ext = p.ext;
        rec->node = p.node;
        rec->world = wrec[p.world];
        rec->body = dBodyCreate(rec->world->world);
        body_by_node[p.node] = rec.get();
        it = bodies.emplace(p.ext, std::move(rec)).first;
      }
      BodyRec& b = *it->second;
      b.seen = true;
      b.depth = p.depth;
      b.mass = p.mass;
      brec[i] = &b;
    }
    {
      std::vector<BodyRec*> stale;
      for (auto& [k, b] : bodies)
        if (!b->seen) stale.push_back(b.get());
      for (BodyRec* b : stale) drop_body(*b);
    }
    // Geoms.
    for (auto& [k, g] : geoms) g->seen = false;
    for (const GeomPlan& p : plan.geoms) {
      BodyRec* body = p.body != npos ? brec[p.body] : nullptr;
      auto it = geoms.find(p.hull);
      if (it != geoms.end() && (it->second->body != body || it->second->world != wrec[p.world] ||
                                !(it->second->shape == p.shape))) {
        drop_geom(*it->second);
        it = geoms.end();
      }
      if (it == geoms.end()) {
        auto rec = std::make_unique<GeomRec>();
        rec->hull = p.hull;
        rec->body = body;
        rec->world = wrec[p.world];
        rec->shape = p.shape;
        rec->geom = make_geom(rec->world->space, p.shape);
        dGeomSetData(rec->geom, rec.get());
        if (body != nullptr) {
          dGeomSetBody(rec->geom, body->body);
          body->geoms.push_back(rec.get());
        }
        it = geoms.emplace(p.hull, std::move(rec)).first;
      }
      GeomRec& g = *it->second;
      g.seen = true;
      if (body != nullptr) g.offset = relative(*body->node, *g.hull);
      if (body == nullptr) place_geom(g);
    }
    {
      std::vector<GeomRec*> stale;
      for (auto& [k, g] : geoms)
        if (!g->seen) stale.push_back(g.get());
      for (GeomRec* g : stale) drop_geom(*g);
    }
    // Body state (mass, pose, velocities, geom offsets): the database is the truth.
    for (BodyRec* b : brec) set_body_state(*b);
    // Joints, after the bodies are placed (ODE measures joint positions from the pose at creation).
    for (auto& [k, j] : joints) j->seen = false;
    for (const JointPlan& p : plan.joints) {
      JointSignature sig{p.ext->kind(),   brec[p.owner], p.other != npos ? brec[p.other] : nullptr,
                         p.ext->anchor(), p.ext->axis(), p.ext->axis2()};
      auto it = joints.find(p.ext);
      if (it != joints.end() && !(it->second->sig == sig && it->second->world == wrec[p.world])) {
        drop_joint(*it->second);
        it = joints.end();
      }
      if (it == joints.end()) {
        auto rec = std::make_unique<JointRec>();
        rec->ext = p.ext;
        rec->world = wrec[p.world];
        rec->sig = sig;
        build_joint(*rec);
        if (rec->sig.other != nullptr) ++joined[{rec->sig.owner->body, rec->sig.other->body}];
        it = joints.emplace(p.ext, std::move(rec)).first;
      } else {
        set_joint_params(*it->second);
      }
      it->second->seen = true;
    }
    {
      std::vector<JointRec*> stale;
      for (auto& [k, j] : joints)
        if (!j->seen) stale.push_back(j.get());
      for (JointRec* j : stale) drop_joint(*j);
    }
    order = brec;
    std::stable_sort(order.begin(), order.end(), [](BodyRec* a, BodyRec* b) { return a->depth < b->depth; });
    dirty = false;
    moved.clear();
    touched.clear();
    ++stats.rebuilds;
  }

  // ---- sync ----
  void sync() {
    if (!dirty && !moved.empty()) apply_moves();
    if (dirty) {
      rebuild();
      return;
    }
    if (!touched.empty()) {
      // Recompute what a changed body property affects; validate everything before changing anything.
      std::vector<std::pair<BodyRec*, MassProperties>> todo;
      for (BodyRec* b : touched) {
        if (!sane(b->ext->linear_velocity()) || !sane(b->ext->angular_velocity()))
          detail_throw("rigid body on " + describe(*b->node) + ": velocities must be finite and below 1e8");
        todo.emplace_back(b, mass_for(*b));
      }
      for (auto& [b, m] : todo) {
        b->mass = m;
        set_body_state(*b);
      }
      touched.clear();
    }
  }

  // The mass of one existing body, from its current geoms (a plan of that body alone).
  MassProperties mass_for(BodyRec& b) {
    Plan plan;
    BodyPlan bp{b.ext, b.node, 0, b.depth, {}, {}};
    for (GeomRec* g : b.geoms) {
      bp.geoms.push_back(plan.geoms.size());
      plan.geoms.push_back({g->hull, 0, 0, g->shape});
    }
    return compute_mass(bp, plan);
  }

  void apply_moves() {
    std::vector<vsd::Id> ids;
    ids.swap(moved);
    std::vector<BodyRec*> teleported;
    std::vector<GeomRec*> statics;
    for (vsd::Id id : ids) {
      auto* start = state->find<vsd::Node>(id);
      if (start == nullptr) continue;
      // Walk the moved subtree: bodies and static hulls follow their nodes; a body hull that moved
      // without its body changes the body's shape and mass: a rebuild.
      struct Item {
        vsd::Node* node;
        bool body_moved;
      };
      std::vector<Item> todo{{start, false}};
      while (!todo.empty()) {
        Item it = todo.back();
        todo.pop_back();
        bool body_moved = it.body_moved;
        if (auto* n3 = it.node->as<Node3D>()) {
          if (auto b = body_by_node.find(n3); b != body_by_node.end()) {
            teleported.push_back(b->second);
            body_moved = true;
          }
          if (auto* h = n3->as<Hull>())
            if (auto g = geoms.find(h); g != geoms.end()) {
              if (g->second->body == nullptr) {
                statics.push_back(g->second.get());
              } else if (!body_moved) {
                dirty = true;
                return;
              }
            }
        }
        for (vsd::Node* c : it.node->children()) todo.push_back({c, body_moved});
      }
    }
    for (BodyRec* b : teleported)
      if (!finite(b->node->world_frame()))
        detail_throw("rigid body node " + describe(*b->node) + " has a non-finite frame");
    for (GeomRec* g : statics)
      if (!finite(g->hull->world_frame()))
        detail_throw("collision hull " + describe(*g->hull) + " has a non-finite frame");
    for (BodyRec* b : teleported) place_body(*b);
    for (GeomRec* g : statics) place_geom(*g);
  }

  // ---- stepping ----
  // What one dSpaceCollide of one world collects. ODE calls near_callback through C frames: nothing may
  // leave it by an exception, so a failure is kept here (and the remaining pairs skipped) and rethrown
  // once dSpaceCollide has returned.
  struct CollideContext {
    Impl* self;
    WorldRec* world;
    std::size_t contacts = 0;       // contact joints made in this step
    bool too_many = false;          // max_contacts_per_step reached: the rest is skipped
    std::exception_ptr failure;     // thrown inside the callback: the rest is skipped
  };

  static double friction_of(const GeomRec& g, const World& w) {
    const scene::Material* m = g.hull->material().get();
    return m != nullptr ? std::max(0.0, m->friction()) : w.default_friction();
  }
  static double restitution_of(const GeomRec& g, const World& w) {
    const scene::Material* m = g.hull->material().get();
    return m != nullptr ? std::clamp(m->restitution(), 0.0, 1.0) : w.default_restitution();
  }

  static void near_callback(void* data, dGeomID a, dGeomID b) noexcept {
    auto* ctx = static_cast<CollideContext*>(data);
    if (ctx->failure || ctx->too_many) return;
    try {
      collide_pair(*ctx, a, b);
    } catch (...) {
      ctx->failure = std::current_exception();
    }
  }

  static void collide_pair(CollideContext& context, dGeomID a, dGeomID b) {
    CollideContext* ctx = &context;
    dBodyID ba = dGeomGetBody(a);
    dBodyID bb = dGeomGetBody(b);
    if (ba == bb) return;  // static/static, or two hulls of one body
    if (ba != nullptr && bb != nullptr && ctx->self->joined.contains({ba, bb})) return;  // jointed bodies
    Impl& self = *ctx->self;
    const World& w = *ctx->world->ext;
    auto& buf = self.contact_buffer;
    buf.resize(static_cast<std::size_t>(w.max_contacts()));
    const int n = dCollide(a, b, w.max_contacts(), &buf[0].geom, sizeof(dContact));
    if (n <= 0) return;
    if (ctx->contacts + static_cast<std::size_t>(n) > max_contacts_per_step) {
      ctx->too_many = true;
      return;
    }
    ctx->contacts += static_cast<std::size_t>(n);
    const auto* ga = static_cast<const GeomRec*>(dGeomGetData(a));
    const auto* gb = static_cast<const GeomRec*>(dGeomGetData(b));
    // Combination rules: friction the geometric mean, restitution the larger of the two (a ball bounces
    // on a dead floor as it would on a perfectly hard one).
    const double mu = std::sqrt(friction_of(*ga, w) * friction_of(*gb, w));
    const double e = std::max(restitution_of(*ga, w), restitution_of(*gb, w));
    for (int i = 0; i < n; ++i) {
      dContact& c = buf[static_cast<std::size_t>(i)];
      c.surface.mode = dContactApprox1;  // Coulomb: friction bounded by mu times the normal force
      c.surface.mu = mu;
      if (e > 0.0) {
        c.surface.mode |= dContactBounce;
        c.surface.bounce = e;
        c.surface.bounce_vel = w.bounce_threshold();
      }
      // Align the first friction direction with the sliding velocity, so that the friction pyramid's
      // bound mu*N acts along the motion (not mu*N per axis of an arbitrary pair of directions).
      dVector3 va = {0, 0, 0, 0};
      dVector3 vb = {0, 0, 0, 0};
      const dReal* p = c.geom.pos;
      if (ba != nullptr) dBodyGetPointVel(ba, p[0], p[1], p[2], va);
      if (bb != nullptr) dBodyGetPointVel(bb, p[0], p[1], p[2], vb);
      Eigen::Vector3d rel(va[0] - vb[0], va[1] - vb[1], va[2] - vb[2]);
      const Eigen::Vector3d nrm(c.geom.normal[0], c.geom.normal[1], c.geom.normal[2]);
      rel -= rel.dot(nrm) * nrm;
      if (rel.norm() > 1e-9) {
        rel.normalize();
        c.surface.mode |= dContactFDir1;
        c.fdir1[0] = rel.x();
        c.fdir1[1] = rel.y();
        c.fdir1[2] = rel.z();
        c.fdir1[3] = 0;
      }
      dJointID cj = dJointCreateContact(ctx->world->world, ctx->world->contacts, &c);
      dJointAttach(cj, ba, bb);
    }
    self.stats.contacts += static_cast<std::size_t>(n);
  }

  void advance(double seconds) {
    if (!(seconds >= 0.0) || !std::isfinite(seconds))
      detail_throw("advance: seconds must be finite and >= 0, got " + std::to_string(seconds));
    sync();
    // Each world's step count, checked before anything moves: an absurd interval (1e6 s at the default
    // step would be 1e9 ODE steps, and beyond 2^64 steps the count would not even fit) is an error.
    for (auto& [k, w] : worlds) {
      const double steps = std::floor((w->pending + seconds) / w->ext->step() + 1e-9);
      if (steps > static_cast<double>(max_steps_per_advance)) {
        std::ostringstream msg;
        msg << "advance(" << seconds << " s) would take " << steps << " steps of " << w->ext->step()
            << " s in " << describe_ext(*w->ext) << "; at most " << max_steps_per_advance
            << " per call (advance in shorter intervals, or make World.step larger)";
        detail_throw(msg.str());
      }
    }
    // Force accumulators: checked before anything moves.
    std::vector<BodyRec*> forced;
    for (BodyRec* b : order) {
      const auto& f = b->ext->force();
      const auto& t = b->ext->torque();
      if (f.isZero(0.0) && t.isZero(0.0)) continue;
      if (!finite(f) || !finite(t))
        detail_throw("rigid body on " + describe(*b->node) + ": force and torque must be finite");
      // The velocity change they cause over this advance (bounded by the smallest principal moment).
      const double i_min =
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(b->mass.inertia).eigenvalues().minCoeff();
      if (!(f.norm() / b->mass.mass * seconds <= speed_limit) || !(t.norm() / i_min * seconds <= speed_limit))
        detail_throw("rigid body on " + describe(*b->node) +
                     ": force or torque would change its velocity by more than 1e8 in one step");
      forced.push_back(b);
    }
    bool stepped = false;
    {
      std::lock_guard lock(detail::ode_mutex());
      detail::MessageSink sink(warnings);
      stats.contacts = 0;
      for (auto& [k, w] : worlds) {
        const double h = w->ext->step();
        w->pending += seconds;
        const auto n = static_cast<std::uint64_t>(std::floor(w->pending / h + 1e-9));
        w->pending = std::max(0.0, w->pending - static_cast<double>(n) * h);
        w->advanced = static_cast<double>(n) * h;
        for (std::uint64_t i = 0; i < n; ++i) {
          for (BodyRec* b : forced) {
            if (b->world != w.get()) continue;
            const auto& f = b->ext->force();
            const auto& t = b->ext->torque();
            dBodyAddForce(b->body, f.x(), f.y(), f.z());
            dBodyAddTorque(b->body, t.x(), t.y(), t.z());
          }
          CollideContext ctx{this, w.get(), 0, false, nullptr};
          try {
            dSpaceCollide(w->space, &ctx, &near_callback);
            if (ctx.failure) std::rethrow_exception(ctx.failure);
            if (ctx.too_many) {
              dJointGroupEmpty(w->contacts);
              dirty = true;  // worlds and steps before this one moved ODE's bodies; the database did not
              std::ostringstream msg;
              msg << "more than " << max_contacts_per_step << " contact points in one step of "
                  << describe_ext(*w->ext)
                  << " (hulls overlapping en masse?); the database keeps the last good state";
              detail_throw(msg.str());
            }
            if (w->ext->solver() == Solver::Exact) {
              dWorldStep(w->world, h);
            } else {
              dWorldQuickStep(w->world, h);
            }
            dJointGroupEmpty(w->contacts);
          } catch (const vsd::Error& e) {  // from ODE's error or debug handler
            if (ctx.too_many) throw;
            w->poisoned = true;
            dirty = true;
            detail_throw(std::string(e.what()) + " (stepping " + describe_ext(*w->ext) +
                         "; the database keeps the last good state and ODE's world is rebuilt from it)");
          } catch (const std::bad_alloc&) {
            w->poisoned = true;
            dirty = true;
            detail_throw("out of memory stepping " + describe_ext(*w->ext) +
                         "; the database keeps the last good state and ODE's world is rebuilt from it");
          }
          ++stats.steps;
          stepped = true;
        }
      }
    }
    if (!stepped) return;  // forces wait for the first step
    // A non-finite result leaves the database as it was; the next sync rebuilds ODE from it.
    for (BodyRec* b : order) {
      const dReal* p = dBodyGetPosition(b->body);
      const dReal* r = dBodyGetRotation(b->body);
      const dReal* v = dBodyGetLinearVel(b->body);
      const dReal* av = dBodyGetAngularVel(b->body);
      bool ok = sane(Eigen::Vector3d(v[0], v[1], v[2])) && sane(Eigen::Vector3d(av[0], av[1], av[2]));
      for (int i = 0; i < 3; ++i) ok = ok && std::isfinite(p[i]);
      for (int i = 0; i < 12; ++i) ok = ok && std::isfinite(r[i]);
      if (!ok) {
        dirty = true;
        detail_throw(
            "the step made the pose or velocity of rigid body " + describe(*b->node) +
            " non-finite or faster than 1e8 (forces too large for the step?); the database keeps the "
            "last good state");
      }
    }
    write_back(forced);
  }

  void write_back(const std::vector<BodyRec*>& forced) {
    writing = true;
    struct Reset {
      bool& flag;
      ~Reset() { flag = false; }
    } reset{writing};
    for (BodyRec* b : order) {
      const dReal* p = dBodyGetPosition(b->body);
      const Eigen::Matrix3d r = from_ode(dBodyGetRotation(b->body));
      Eigen::Isometry3d w = Eigen::Isometry3d::Identity();
      w.linear() = r;
      w.translation() = Eigen::Vector3d(p[0], p[1], p[2]) - r * b->mass.center;
      b->node->set_world_frame(w);
      const dReal* v = dBodyGetLinearVel(b->body);
      const dReal* av = dBodyGetAngularVel(b->body);
      b->ext->set_linear_velocity(Eigen::Vector3d(v[0], v[1], v[2]));
      b->ext->set_angular_velocity(Eigen::Vector3d(av[0], av[1], av[2]));
    }
    for (BodyRec* b : forced) {
      b->ext->set_force(Eigen::Vector3d::Zero());
      b->ext->set_torque(Eigen::Vector3d::Zero());
    }
    for (auto& [k, j] : joints) {
      double pos = 0.0;
      double rate = 0.0;
      switch (j->ext->kind()) {
        case JointKind::Hinge:
          pos = dJointGetHingeAngle(j->joint);
          rate = dJointGetHingeAngleRate(j->joint);
          break;
        case JointKind::Slider:
          pos = dJointGetSliderPosition(j->joint);
          rate = dJointGetSliderPositionRate(j->joint);
          break;
        case JointKind::Universal:
          pos = dJointGetUniversalAngle1(j->joint);
          rate = dJointGetUniversalAngle1Rate(j->joint);
          j->ext->set_position2(dJointGetUniversalAngle2(j->joint));
          j->ext->set_rate2(dJointGetUniversalAngle2Rate(j->joint));
          break;
        default:
          continue;
      }
      j->ext->set_position(pos);
      j->ext->set_rate(rate);
    }
    for (auto& [k, w] : worlds)
      if (w->advanced > 0.0) w->ext->set_time(w->ext->time() + w->advanced);
  }
};

// =====================================================================================================

Simulation::Simulation(vsd::SimState& state) : impl_(std::make_unique<Impl>(state)) {}
Simulation::~Simulation() = default;

void Simulation::sync() { impl_->sync(); }
void Simulation::advance(double seconds) { impl_->advance(seconds); }

void Simulation::add_force_at(RigidBody& body, const Eigen::Vector3d& force, const Eigen::Vector3d& point) {
  auto it = impl_->bodies.find(&body);
  if (it == impl_->bodies.end())
    throw vsd::Error("vsd::physics: " + describe_ext(body) + " is not simulated");
  const Eigen::Vector3d com = it->second->node->world_frame() * it->second->mass.center;
  body.add_force(force);
  body.add_torque((point - com).cross(force));
}

MassProperties Simulation::mass_of(const RigidBody& body) const {
  auto it = impl_->bodies.find(&body);
  if (it == impl_->bodies.end())
    throw vsd::Error("vsd::physics: " + describe_ext(body) + " is not simulated");
  return it->second->mass;
}

bool Simulation::simulates(const RigidBody& body) const noexcept { return impl_->bodies.contains(&body); }

SimulationStats Simulation::stats() const noexcept {
  SimulationStats s = impl_->stats;
  s.worlds = impl_->worlds.size();
  s.bodies = impl_->bodies.size();
  s.joints = impl_->joints.size();
  s.geoms = impl_->geoms.size();
  std::unordered_set<const MeshData*> meshes;
  for (const auto& [k, g] : impl_->geoms)
    if (g->shape.mesh) meshes.insert(g->shape.mesh.get());
  s.meshes = meshes.size();
  return s;
}

const std::vector<std::string>& Simulation::warnings() const noexcept { return impl_->warnings; }
vsd::SimState& Simulation::state() const noexcept { return *impl_->state; }

}  // namespace vsd::physics
