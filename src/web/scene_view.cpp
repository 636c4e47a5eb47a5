#include <string>
#include <unordered_set>

#include "json.hpp"
#include "views.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/scene/geometry.hpp"
#include "vsd/scene/hull.hpp"
#include "vsd/scene/material.hpp"
#include "vsd/scene/node3d.hpp"

namespace vsd::web::detail {
namespace {

using scene::Geometry;
using scene::GeometryKind;
using scene::Hull;
using scene::Node3D;

void write_matrix(JsonWriter& out, const Eigen::Isometry3d& m) {
  out.begin_array();
  const double* d = m.matrix().data();  // column-major, as three.js Matrix4.fromArray reads it
  for (int i = 0; i < 16; ++i) out.number(d[i]);
  out.end_array();
}

void write_vector(JsonWriter& out, const double* v, int n) {
  out.begin_array();
  for (int i = 0; i < n; ++i) out.number(v[i]);
  out.end_array();
}

/// The id of @p n's nearest Node3D ancestor, or null.
void write_frame_parent(JsonWriter& out, const Node3D& n) {
  if (const Node3D* p = n.frame_parent())
    out.number(p->id());
  else
    out.null();
}

void write_shape(JsonWriter& out, const Geometry* g) {
  out.begin_object();
  if (g == nullptr) {
    out.member("kind", "None").end_object();
    return;
  }
  out.member("kind", std::string(g->kind() == GeometryKind::Mesh       ? "Mesh"
                                 : g->kind() == GeometryKind::Box      ? "Box"
                                 : g->kind() == GeometryKind::Sphere   ? "Sphere"
                                 : g->kind() == GeometryKind::Cylinder ? "Cylinder"
                                 : g->kind() == GeometryKind::Capsule  ? "Capsule"
                                                                       : "Plane"));
  switch (g->kind()) {
    case GeometryKind::Box:
      out.key("size");
      write_vector(out, g->size().data(), 3);
      break;
    case GeometryKind::Sphere:
      out.member("radius", g->radius());
      break;
    case GeometryKind::Cylinder:
    case GeometryKind::Capsule:
      out.member("radius", g->radius()).member("length", g->length());
      break;
    case GeometryKind::Plane:
      out.key("normal");
      write_vector(out, g->normal().data(), 3);
      break;
    case GeometryKind::Mesh:
      out.member("geometry", g->id()).member("triangles", static_cast<std::uint64_t>(g->facet_count()));
      out.key("scale");
      write_vector(out, g->scale().data(), 3);
      break;
  }
  out.end_object();
}

}  // namespace

void write_scene(JsonWriter& out, const SimState& state) {
  out.begin_object();
  out.key("nodes").begin_array();
  state.index().for_each(Node3D::static_meta(), true, [&](SimStateInstance& i) {
    if (i.as<Hull>() != nullptr) return;
    const auto& n = static_cast<const Node3D&>(i);
    out.begin_object().member("id", n.id()).member("name", n.name()).member("class", n.meta().name());
    out.key("parent");
    write_frame_parent(out, n);
    out.key("world");
    write_matrix(out, n.world_frame());
    out.end_object();
  });
  out.end_array();
  out.key("hulls").begin_array();
  state.index().for_each(Hull::static_meta(), true, [&](SimStateInstance& i) {
    const auto& h = static_cast<const Hull&>(i);
    out.begin_object().member("id", h.id()).member("name", h.name()).key("node");
    write_frame_parent(out, h);
    out.member("role", std::string(h.role() == scene::HullRole::Visual ? "Visual" : "Collision"));
    out.key("world");
    write_matrix(out, h.world_frame());
    out.key("shape");
    write_shape(out, h.geometry().get());
    const Eigen::Vector4d color =
        h.material().get() != nullptr ? h.material()->color() : Eigen::Vector4d(0.8, 0.8, 0.8, 1.0);
    out.key("color");
    write_vector(out, color.data(), 4);
    out.end_object();
  });
  out.end_array();
  out.end_object();
}

void write_mesh(JsonWriter& out, const SimState& state, Id id) {
  const Geometry* g = state.find<Geometry>(id);
  if (g == nullptr) throw Error("instance #" + std::to_string(id) + " is not a Geometry of this state");
  const auto& v = g->vertices();
  const auto& f = g->facets();
  out.begin_object().member("id", id).member("kind", std::string(g->kind() == GeometryKind::Mesh ? "Mesh" : "Primitive"));
  out.key("positions").begin_array();
  for (const auto& p : v) out.number(p.x()).number(p.y()).number(p.z());
  out.end_array();
  out.key("indices").begin_array();
  // Only whole triangles whose indices are in range travel: a damaged mesh draws what is sound.
  for (std::size_t t = 0; t + 2 < f.size(); t += 3) {
    const auto ok = [&](std::int32_t k) { return k >= 0 && static_cast<std::size_t>(k) < v.size(); };
    if (!ok(f[t]) || !ok(f[t + 1]) || !ok(f[t + 2])) continue;
    out.number(static_cast<std::int64_t>(f[t])).number(static_cast<std::int64_t>(f[t + 1]));
    out.number(static_cast<std::int64_t>(f[t + 2]));
  }
  out.end_array();
  out.end_object();
}

void write_frames(JsonWriter& out, const SimState& state, const std::vector<Watch::Report>& reports) {
  const MetaProperty* frame = &Node3D::vsd_prop_frame();
  std::unordered_set<Id> done;
  out.key("frames").begin_array();
  const auto emit = [&](const Node3D& n) {
    if (!done.insert(n.id()).second) return;
    out.begin_object().member("id", n.id()).key("world");
    write_matrix(out, n.world_frame());
    out.end_object();
  };
  for (const Watch::Report& r : reports) {
    const bool moves = r.property == frame || r.changes.has(Changes::parent) || r.changes.has(Changes::created);
    if (!moves || done.count(r.id) != 0) continue;
    SimStateInstance* i = state.find(r.id);
    if (i == nullptr || i->as<Node>() == nullptr) continue;
    // Everything below a moved node moves with it (its world frame), whatever class holds it.
    static_cast<Node*>(i)->visit([&](Node& d) {
      if (const auto* n = d.as<Node3D>()) emit(*n);
    });
  }
  out.end_array();
}

}  // namespace vsd::web::detail
