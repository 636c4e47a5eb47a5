// CollisionWorld (see vsd/collision/collision_world.hpp): the FCL side, the listeners that note what
// changed, and the sync that applies only that.
#include "vsd/collision/collision_world.hpp"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/halfspace.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <new>
#include <iterator>
#include <set>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "ray.hpp"
#include "shape_text.hpp"
#include "vsd/core/element_index.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/core/watch.hpp"
#include "vsd/scene/geometry.hpp"
#include "vsd/scene/hull.hpp"

namespace vsd::collision {

using scene::Geometry;
using scene::GeometryKind;
using scene::Hull;
using scene::Node3D;

namespace {

using Shape = std::shared_ptr<fcl::CollisionGeometryd>;

// A shape built from a Geometry, or why it could not be built.
struct ShapeEntry {
  Shape shape;
  std::string problem;  // non-empty: degenerate, shape is null
  bool plane = false;
  // A mesh without vertices (e.g. a URDF loaded without its mesh files): nothing to collide, not an error.
  bool empty = false;
};

bool finite(double v) { return std::isfinite(v); }
bool positive(double v) { return std::isfinite(v) && v > 0; }

ShapeEntry build_shape(const Geometry& g) {
  ShapeEntry e;
  const auto fail = [&](const std::string& why) {
    e.problem = describe_geometry(g) + ": " + why;
    return e;
  };
  switch (g.kind()) {
    case GeometryKind::Box:
      if (!positive(g.size().x()) || !positive(g.size().y()) || !positive(g.size().z()))
        return fail("every side of a box must be positive and finite");
      e.shape = std::make_shared<fcl::Boxd>(g.size());
      return e;
    case GeometryKind::Sphere:
      if (!positive(g.radius())) return fail("the radius of a sphere must be positive and finite");
      e.shape = std::make_shared<fcl::Sphered>(g.radius());
      return e;
    case GeometryKind::Cylinder:
      if (!positive(g.radius()) || !positive(g.length()))
        return fail("radius and length of a cylinder must be positive and finite");
      e.shape = std::make_shared<fcl::Cylinderd>(g.radius(), g.length());
      return e;
    case GeometryKind::Capsule:
      if (!positive(g.radius()) || !finite(g.length()) || g.length() < 0)
        return fail("the radius of a capsule must be positive, its length non-negative, both finite");
      e.shape = std::make_shared<fcl::Capsuled>(g.radius(), g.length());
      return e;
    case GeometryKind::Plane: {
      const Eigen::Vector3d n = g.normal();
      if (!n.allFinite() || n.norm() < 1e-12)
        return fail("the normal of a plane must be finite and non-zero");
      e.shape = std::make_shared<fcl::Halfspaced>(n.normalized(), 0.0);
      e.plane = true;
      return e;
    }
    case GeometryKind::Mesh: {
      const auto& v = g.vertices();
      const auto& f = g.facets();
      if (v.empty()) {
        e.empty = true;
        return e;
      }
      if (f.empty()) return fail("a mesh needs triangles (its facet list is empty)");
      if (f.size() % 3 != 0) return fail("the facet list is not a multiple of 3 indices");
      if (!g.scale().allFinite() || g.scale().cwiseAbs().minCoeff() <= 0)
        return fail("the mesh scale must be finite and non-zero");
      std::vector<fcl::Vector3d> points;
      points.reserve(v.size());
      for (const auto& p : v) {
        if (!p.allFinite()) return fail("a vertex is not finite");
        points.push_back(p.cwiseProduct(g.scale()));
      }
      std::vector<fcl::Triangle> triangles;
      triangles.reserve(f.size() / 3);
      for (std::size_t i = 0; i < f.size(); i += 3) {
        for (std::size_t k = 0; k < 3; ++k)
          if (f[i + k] < 0 || static_cast<std::size_t>(f[i + k]) >= v.size())
            return fail("facet " + std::to_string(i / 3) + " has vertex index " + std::to_string(f[i + k]) +
                        " out of range (" + std::to_string(v.size()) + " vertices)");
        triangles.emplace_back(static_cast<std::size_t>(f[i]), static_cast<std::size_t>(f[i + 1]),
                               static_cast<std::size_t>(f[i + 2]));
      }
      auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
      if (model->beginModel(static_cast<int>(triangles.size()), static_cast<int>(points.size())) !=
              fcl::BVH_OK ||
          model->addSubModel(points, triangles) != fcl::BVH_OK || model->endModel() != fcl::BVH_OK)
        return fail("FCL could not build the bounding volume hierarchy");
      e.shape = std::move(model);
      return e;
    }
  }
  return fail("unknown geometry kind");
}

}  // namespace

// ---- the tracked hulls ---------------------------------------------------------------------------------

struct Entry {
  Hull* hull = nullptr;
  Id id = 0;        // the hull's id, kept here so the narrow phase need not touch the hull
  Id geometry = 0;  // the Geometry whose shape the object uses (0: none)
  std::unique_ptr<fcl::CollisionObjectd> object;
  bool in_manager = false;
  bool pending = false;  // waiting in Impl::to_register for the broadphase
  bool plane = false;
  std::uint64_t stamp = 0;  // last sync that updated this entry's pose
  std::string problem;      // non-empty: left out of the broadphase
  bool empty = false;       // its geometry is a mesh without vertices: skipped, with a warning
};

struct PairKey {
  Id a, b;
  bool operator<(const PairKey& o) const noexcept { return a != o.a ? a < o.a : b < o.b; }
  bool operator==(const PairKey& o) const noexcept { return a == o.a && b == o.b; }
};

struct CollisionWorld::Impl {
  SimState& state;
  Options options;
  Id root_id = 0;
  bool root_gone = false;

  fcl::DynamicAABBTreeCollisionManagerd manager;
  std::unordered_map<const Hull*, std::unique_ptr<Entry>> entries;
  std::vector<Entry*> planes;                 // half-spaces: queried against the tree, not in it
  // Hulls whose objects join the broadphase at the end of the current sync (see register_pending()).
  std::vector<const Hull*> to_register;
  std::unordered_map<Id, ShapeEntry> shapes;  // by Geometry id, shared by the hulls using it
  std::unordered_set<const Entry*> troubled;  // entries with a problem (left out)
  std::vector<std::string> warnings;          // each once
  std::unordered_set<std::string> warned;

  std::uint64_t sync_count = 0;
  std::size_t last_moved = 0;

  std::vector<Contact> contacts;
  std::set<PairKey> pairs;  // pairs in contact after the last update
  PairSignal begin, end;

  // Pending work: queued watches, drained by sync() (de-duplicated ids; an instance may be gone by then).
  Watch moved;               // Node3Ds whose frame changed: hulls at or below move
  Watch restructured;        // nodes re-parented: hulls at or below may enter or leave
  Watch hulls_to_refresh;    // created hulls, changed role or geometry
  Watch geometries_changed;  // rebuild the shape
  // Deletions at once: a deleted hull ends its pairs now, while it can still be named.
  Watch deletions;

  Impl(SimState& s, Options o)
      : state(s),
        options(std::move(o)),
        moved(s),
        restructured(s),
        hulls_to_refresh(s),
        geometries_changed(s),
        deletions(s, [this](SimStateInstance& i, const MetaProperty*, Changes) { deleted(i); }) {
    if (options.max_contacts_per_pair == 0) options.max_contacts_per_pair = 1;
  }

  // -- scope ------------------------------------------------------------------------------------------
  bool wanted(Hull& h) const {
    if (!options.include_visual && h.role() != scene::HullRole::Collision) return false;
    if (root_id == 0) return true;
    if (root_gone) return false;
    for (const vsd::Node* n = &h; n != nullptr; n = n->parent())
      if (n->id() == root_id) return true;
    return false;
  }

  // -- shapes -----------------------------------------------------------------------------------------
  const ShapeEntry& shape_of(Geometry& g) {
    auto it = shapes.find(g.id());
    if (it == shapes.end()) it = shapes.emplace(g.id(), build_shape(g)).first;
    return it->second;
  }

  // -- entries ----------------------------------------------------------------------------------------
  void leave_manager(Entry& e) {
    if (e.in_manager) manager.unregisterObject(e.object.get());
    e.in_manager = false;
    e.pending = false;
    if (e.plane) std::erase(planes, &e);
    e.plane = false;
  }

  // Places e's object at the hull's world pose, or records why it cannot be placed.
  bool place(Entry& e) {
    const Eigen::Isometry3d& w = e.hull->world_frame();
    if (!w.matrix().allFinite()) {
      troubled.insert(&e);
      e.problem = describe_hull(*e.hull) + ": " + describe_geometry_of(*e.hull) +
                  ": the world pose is not finite (" + describe_pose(w) + ")";
      return false;
    }
    e.object->setTransform(w);
    e.object->computeAABB();
    return true;
  }

  // (Re)builds the entry of a hull from scratch: membership, shape, pose, broadphase.
  void refresh(Hull& h) {
    auto it = entries.find(&h);
    if (!wanted(h)) {
      if (it != entries.end()) remove(h);
      return;
    }
    Entry* e;
    if (it == entries.end()) {
      auto owned = std::make_unique<Entry>();
      owned->hull = &h;
      owned->id = h.id();
      e = owned.get();
      entries.emplace(&h, std::move(owned));
    } else {
      e = it->second.get();
    }
    leave_manager(*e);
    e->problem.clear();
    troubled.erase(e);
    e->object.reset();
    e->geometry = 0;
    e->empty = false;
    Geometry* g = h.geometry().get();
    if (g == nullptr) return;  // no geometry: tracked, but nothing to collide
    const ShapeEntry& s = shape_of(*g);
    if (s.empty) {
      // As vsd::physics does: skipped with one warning (the URDF loader warned about the files already).
      e->empty = true;
      warn(describe_hull(h) + ": its mesh has no vertices (" + describe_geometry(*g) +
           "); it does not collide");
      return;
    }
    if (s.shape == nullptr) {
      troubled.insert(e);
      e->problem = describe_hull(h) + ": " + s.problem + " (at " + describe_pose(h.world_frame()) + ")";
      return;
    }
    e->geometry = g->id();
    e->object = std::make_unique<fcl::CollisionObjectd>(s.shape);
    e->object->setUserData(e);
    e->stamp = sync_count;
    if (!place(*e)) return;
    if (s.plane) {
      e->plane = true;
      planes.push_back(e);
    } else {
      e->pending = true;
      to_register.push_back(&h);
    }
  }

  // Brings the objects refreshed in this sync into the broadphase. FCL inserts one object by descending
  // its tree towards the most similar box; among many equal boxes (hulls spawned at one spot) that walk
  // is as long as the tree, and 20,000 of them took 20 s. So a batch at least half the size of the tree
  // rebuilds it in one go, top down by medians (balanced whatever the boxes, n log n); a small batch is
  // inserted.
  void register_pending() {
    if (to_register.empty()) return;
    std::vector<fcl::CollisionObjectd*> batch;
    for (const Hull* h : to_register) {
      auto it = entries.find(h);
      if (it == entries.end() || !it->second->pending) continue;  // removed or refreshed away since
      Entry& e = *it->second;
      e.pending = false;
      e.in_manager = true;
      batch.push_back(e.object.get());
    }
    to_register.clear();
    if (batch.size() * 2 >= manager.size()) {
      std::vector<fcl::CollisionObjectd*> all;
      manager.getObjects(all);
      all.insert(all.end(), batch.begin(), batch.end());
      manager.clear();
      manager.registerObjects(all);
    } else {
      for (fcl::CollisionObjectd* o : batch) manager.registerObject(o);
    }
  }

  void warn(std::string text) {
    if (warned.insert(text).second) warnings.push_back(std::move(text));
  }

  void remove(Hull& h) {
    auto it = entries.find(&h);
    if (it == entries.end()) return;
    leave_manager(*it->second);
    troubled.erase(it->second.get());
    entries.erase(it);
    // Its pairs end now: afterwards there is no hull to name.
    std::vector<PairKey> ended;
    for (const PairKey& k : pairs)
      if (k.a == h.id() || k.b == h.id()) ended.push_back(k);
    for (const PairKey& k : ended) pairs.erase(k);
    std::erase_if(contacts, [&](const Contact& c) { return c.a == &h || c.b == &h; });
    // The hull being deleted may already be gone from the id map: name it directly.
    const auto lookup = [&](Id id) { return id == h.id() ? &h : state.find<Hull>(id); };
    for (const PairKey& k : ended) {
      Hull* a = lookup(k.a);
      Hull* b = lookup(k.b);
      if (a != nullptr && b != nullptr) end.emit(*a, *b);
    }
  }

  // -- what the world depends on -----------------------------------------------------------------------
  void watch() {
    moved.properties(Node3D::static_meta(), {&Node3D::vsd_prop_frame()});
    restructured.reparented(vsd::Node::static_meta());
    hulls_to_refresh.properties(Hull::static_meta(), {&Hull::vsd_prop_role(), &Hull::vsd_prop_geometry()})
        .created(Hull::static_meta());
    std::vector<const MetaProperty*> shape;  // everything of a Geometry but its name
    for (const MetaProperty* p : Geometry::static_meta().properties())
      if (p != &Geometry::vsd_prop_name()) shape.push_back(p);
    geometries_changed.properties(Geometry::static_meta(), shape);
    deletions.deleted(Hull::static_meta()).deleted(Geometry::static_meta());
    if (root_id != 0) deletions.deleted(vsd::Node::static_meta());
  }

  void deleted(SimStateInstance& i) {
    if (auto* h = i.as<Hull>()) remove(*h);
    if (i.as<Geometry>() != nullptr) shapes.erase(i.id());
    if (i.id() == root_id) root_gone = true;
  }

  static std::vector<Id> ids_of(Watch& w) {
    std::vector<Id> ids;
    ids.reserve(w.size());
    w.drain([&](const Watch::Report& r) { ids.push_back(r.id); });
    return ids;
  }

  // Calls fn for every Hull at or below the node with id @p id (when it still exists).
  template <class F>
  void for_hulls_below(Id id, F&& fn) {
    auto* top = state.find<vsd::Node>(id);
    if (top == nullptr) return;
    if (top->children().empty()) {  // the common case, a moved hull: no walk
      if (auto* h = top->as<Hull>()) fn(*h);
      return;
    }
    // An explicit stack (trees may be deeper than the call stack), kept between calls.
    const std::size_t base = walk.size();
    walk.push_back(top);
    while (walk.size() > base) {
      vsd::Node* n = walk.back();
      walk.pop_back();
      if (auto* h = n->as<Hull>()) fn(*h);
      for (vsd::Node* c : n->children()) walk.push_back(c);
    }
  }
  std::vector<vsd::Node*> walk;

  void sync() {
    ++sync_count;
    last_moved = 0;
    if (root_gone && !entries.empty()) {
      std::vector<Hull*> all;
      for (auto& [h, e] : entries) all.push_back(e->hull);
      for (Hull* h : all) remove(*h);
    }
    // Geometry first: the refreshes below then see the new shapes.
    if (!geometries_changed.empty()) {
      const std::vector<Id> ids = ids_of(geometries_changed);
      std::unordered_set<Id> changed(ids.begin(), ids.end());
      for (Id g : changed) shapes.erase(g);
      std::vector<Hull*> users;
      for (auto& [h, e] : entries)
        if (changed.contains(e->geometry) || (e->geometry == 0 && e->hull->geometry().get() != nullptr &&
                                              changed.contains(e->hull->geometry()->id())))
          users.push_back(e->hull);
      for (Hull* h : users) refresh(*h);
      last_moved += users.size();
    }
    if (!hulls_to_refresh.empty()) {
      const std::vector<Id> ids = ids_of(hulls_to_refresh);
      for (Id id : ids)
        if (auto* h = state.find<Hull>(id)) refresh(*h);
      last_moved += ids.size();
    }
    if (!restructured.empty()) {
      const std::vector<Id> ids = ids_of(restructured);
      for (Id id : ids)
        for_hulls_below(id, [&](Hull& h) {
          refresh(h);
          ++last_moved;
        });
    }
    if (!moved.empty()) {
      const std::vector<Id> ids = ids_of(moved);
      std::vector<fcl::CollisionObjectd*> updated;
      for (Id id : ids) {
        for_hulls_below(id, [&](Hull& h) {
          auto it = entries.find(&h);
          if (it == entries.end()) return;
          Entry& e = *it->second;
          if (e.stamp == sync_count) return;  // already placed in this sync
          e.stamp = sync_count;
          if (e.object == nullptr) {
            // A hull left out for a non-finite pose may be fine again: rebuild it.
            if (!e.problem.empty()) refresh(h);
            return;
          }
          if (!place(e)) {
            leave_manager(e);
            return;
          }
          if (!e.problem.empty()) {  // it was out for its pose and is back
            refresh(h);
            return;
          }
          if (e.in_manager) updated.push_back(e.object.get());
          ++last_moved;
        });
      }
      if (!updated.empty()) manager.update(updated);
    }
    register_pending();
  }

  // -- narrow phase -----------------------------------------------------------------------------------
  // Contacts are collected with the hull ids from the entries, so the narrow phase touches the FCL
  // objects and the entries only, never the hulls (fewer cache misses in a large world).
  struct Found {
    Id a, b;
    Contact contact;
  };
  // What a broadphase query collects. FCL calls collide_callback from its own frames, which must not be
  // left by an exception: a failure (or too many contacts) is kept here, the callback tells FCL to stop,
  // and update() acts on it once FCL has returned.
  struct CollideData {
    Impl* self;
    std::vector<std::string>* errors;
    std::exception_ptr failure;
    bool too_many = false;
  };
  fcl::CollisionRequestd request{4, true};
  std::vector<Found> found;  // reused by update()

  void collide_pair(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, std::vector<std::string>& errors) {
    auto* e1 = static_cast<Entry*>(o1->getUserData());
    auto* e2 = static_cast<Entry*>(o2->getUserData());
    if (options.pair_filter && !options.pair_filter(*e1->hull, *e2->hull)) return;
    if (e1->id > e2->id) {
      std::swap(e1, e2);
      std::swap(o1, o2);
    }
    fcl::CollisionResultd result;
    try {
      fcl::collide(o1, o2, request, result);
    } catch (const std::exception& ex) {
      errors.push_back("FCL failed on " + describe_pair(*e1->hull, *e2->hull) + ": " + ex.what());
      return;
    }
    for (std::size_t i = 0; i < result.numContacts(); ++i) {
      const fcl::Contactd& c = result.getContact(i);
      Contact k;
      k.a = e1->hull;
      k.b = e2->hull;
      k.position = c.pos;
      // FCL's normal points from the contact's o1 to its o2.
      k.normal = c.o1 == o1->collisionGeometry().get() ? c.normal : Eigen::Vector3d(-c.normal);
      if (k.normal.allFinite() && k.normal.norm() > 0) k.normal.normalize();
      k.depth = c.penetration_depth;
      if (!k.position.allFinite() || !std::isfinite(k.depth) || !k.normal.allFinite()) {
        errors.push_back("FCL returned a non-finite contact for " + describe_pair(*e1->hull, *e2->hull));
        continue;
      }
      found.push_back({e1->id, e2->id, k});
    }
  }

  static bool collide_callback(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) noexcept {
    auto* d = static_cast<CollideData*>(data);
    if (d->failure || d->too_many) return true;
    try {
      d->self->collide_pair(o1, o2, *d->errors);
      d->too_many = d->self->found.size() > d->self->options.max_contacts;
    } catch (...) {
      d->failure = std::current_exception();
    }
    return d->failure || d->too_many;  // true: FCL stops the query
  }

  // After a query: a failure or too many contacts end update() here, before anything it keeps changes.
  void check_query(CollideData& data) {
    if (data.failure) {
      found.clear();
      try {
        std::rethrow_exception(data.failure);
      } catch (const std::bad_alloc&) {
        throw Error("collision: out of memory computing contacts; contacts and pairs are those of the "
                    "previous update");
      }
    }
    if (data.too_many) {
      found.clear();
      throw Error("collision: more than " + std::to_string(options.max_contacts) +
                  " contact points in one update (Options::max_contacts; hulls overlapping en masse?); "
                  "contacts and pairs are those of the previous update");
    }
  }

  void update() {
    sync();
    request.num_max_contacts = options.max_contacts_per_pair;
    found.clear();
    std::vector<std::string> errors;
    CollideData data{this, &errors, nullptr, false};
    manager.collide(&data, &collide_callback);
    check_query(data);
    for (std::size_t i = 0; i < planes.size(); ++i) {
      manager.collide(planes[i]->object.get(), &data, &collide_callback);
      check_query(data);
      // Half-space against half-space: FCL computes it, and two ground planes may well be meant to touch.
      for (std::size_t j = i + 1; j < planes.size(); ++j)
        if (collide_callback(planes[i]->object.get(), planes[j]->object.get(), &data)) check_query(data);
    }
    std::stable_sort(found.begin(), found.end(),
                     [](const Found& x, const Found& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
    std::set<PairKey> now;
    contacts.clear();
    contacts.reserve(found.size());
    for (const Found& f : found) {
      if (now.empty() || !(std::prev(now.end())->a == f.a && std::prev(now.end())->b == f.b))
        now.insert(now.end(), PairKey{f.a, f.b});
      contacts.push_back(f.contact);
    }
    std::vector<PairKey> ended, begun;
    std::set_difference(pairs.begin(), pairs.end(), now.begin(), now.end(), std::back_inserter(ended));
    std::set_difference(now.begin(), now.end(), pairs.begin(), pairs.end(), std::back_inserter(begun));
    pairs = std::move(now);
    // Listeners may delete hulls: look each one up again.
    for (const PairKey& k : ended) {
      auto* a = state.find<Hull>(k.a);
      auto* b = state.find<Hull>(k.b);
      if (a != nullptr && b != nullptr) end.emit(*a, *b);
    }
    for (const PairKey& k : begun) {
      auto* a = state.find<Hull>(k.a);
      auto* b = state.find<Hull>(k.b);
      if (a != nullptr && b != nullptr && pairs.contains(k)) begin.emit(*a, *b);
    }
    if (!troubled.empty() || !errors.empty()) {
      std::vector<std::string> all = problem_lines();
      all.insert(all.end(), errors.begin(), errors.end());
      std::string msg = "collision: " + std::to_string(all.size()) + " problem(s):";
      for (const auto& p : all) msg += "\n  " + p;
      throw Error(msg);
    }
  }

  std::vector<std::string> problem_lines() const {
    std::vector<std::pair<Id, std::string>> lines;
    for (const Entry* e : troubled) lines.emplace_back(e->id, e->problem);
    std::sort(lines.begin(), lines.end());
    std::vector<std::string> out;
    for (auto& l : lines) out.push_back(std::move(l.second));
    return out;
  }

  Entry& usable(const Hull& h) {
    auto it = entries.find(&h);
    if (it == entries.end())
      throw Error("collision: " + describe_hull(h) +
                  " is not in the collision world (role, scope or deleted)");
    Entry& e = *it->second;
    if (!e.problem.empty()) throw Error("collision: " + e.problem);
    if (e.empty) throw Error("collision: " + describe_hull(h) + ": its mesh has no vertices");
    if (e.object == nullptr) throw Error("collision: " + describe_hull(h) + " has no geometry");
    return e;
  }
};

// ---- CollisionWorld ------------------------------------------------------------------------------------

CollisionWorld::CollisionWorld(SimState& state, Options options)
    : impl_(std::make_unique<Impl>(state, std::move(options))) {
  Impl& m = *impl_;
  if (m.options.root != nullptr) {
    if (&m.options.root->state() != &state)
      throw Error("collision: the root node of a collision world must belong to its SimState");
    m.root_id = m.options.root->id();
  }
  m.watch();
  state.index().for_each(Hull::static_meta(), true,
                         [&](SimStateInstance& i) { m.refresh(static_cast<Hull&>(i)); });
  m.register_pending();
  m.manager.setup();
}

CollisionWorld::~CollisionWorld() = default;

void CollisionWorld::update() { impl_->update(); }
void CollisionWorld::sync() { impl_->sync(); }

const std::vector<Contact>& CollisionWorld::contacts() const noexcept { return impl_->contacts; }

std::vector<std::pair<scene::Hull*, scene::Hull*>> CollisionWorld::contact_pairs() const {
  std::vector<std::pair<Hull*, Hull*>> out;
  for (const PairKey& k : impl_->pairs) {
    auto* a = impl_->state.find<Hull>(k.a);
    auto* b = impl_->state.find<Hull>(k.b);
    if (a != nullptr && b != nullptr) out.emplace_back(a, b);
  }
  return out;
}

bool CollisionWorld::in_contact(const scene::Hull& a, const scene::Hull& b) const {
  const Id x = std::min(a.id(), b.id()), y = std::max(a.id(), b.id());
  return impl_->pairs.contains({x, y});
}

DistanceResult CollisionWorld::distance(const scene::Hull& a, const scene::Hull& b) {
  impl_->sync();
  Entry& ea = impl_->usable(a);
  Entry& eb = impl_->usable(b);
  // Unsigned distance with FCL's own GJK (exact for the primitives); overlapping pairs are measured by
  // the collision query below. Not FCL's signed distance: for a pair its distance solver sees
  // overlapping but its collision check finds no penetrating contact (touching or concentric shapes),
  // FCL 0.7 asserts (index != -1 in distance-inl.h), or without assertions reads a contact that is not
  // there. vsd-collide hit that with a sphere inside another sphere.
  fcl::DistanceRequestd request(true, false);
  request.gjk_solver_type = fcl::GST_INDEP;
  fcl::DistanceResultd result;
  DistanceResult r;
  try {
    fcl::distance(ea.object.get(), eb.object.get(), request, result);
    r.distance = result.min_distance;
    r.point_a = result.nearest_points[0];
    r.point_b = result.nearest_points[1];
    if (!(r.distance > 0)) {
      // Overlapping or touching: minus the deepest penetration, at its contact point (which need not lie
      // on either surface, as with FCL's signed distance).
      fcl::CollisionRequestd creq(8, true);
      fcl::CollisionResultd cres;
      fcl::collide(ea.object.get(), eb.object.get(), creq, cres);
      r.distance = 0;
      if (cres.numContacts() > 0) {
        std::size_t deepest = 0;
        for (std::size_t i = 1; i < cres.numContacts(); ++i)
          if (cres.getContact(i).penetration_depth > cres.getContact(deepest).penetration_depth) deepest = i;
        r.distance = -std::max(0.0, cres.getContact(deepest).penetration_depth);
        r.point_a = r.point_b = cres.getContact(deepest).pos;
      }
      if (!r.point_a.allFinite() || !r.point_b.allFinite()) {
        // touching without a usable point: the midpoint of the two origins
        r.point_a = r.point_b = (ea.object->getTranslation() + eb.object->getTranslation()) / 2;
      }
    }
  } catch (const std::exception& ex) {
    throw Error("collision: FCL failed on the distance of " + describe_pair(a, b) + ": " + ex.what());
  }
  if (!std::isfinite(r.distance) || !r.point_a.allFinite() || !r.point_b.allFinite())
    throw Error("collision: FCL returned a non-finite distance or nearest point for " + describe_pair(a, b));
  return r;
}

std::optional<RayHit> CollisionWorld::ray_cast(const Eigen::Vector3d& origin,
                                               const Eigen::Vector3d& direction, double max_distance) {
  if (!origin.allFinite() || !direction.allFinite() || direction.norm() < 1e-300)
    throw Error("collision: a ray needs a finite origin and a finite non-zero direction (origin " +
                describe_vector(origin) + ", direction " + describe_vector(direction) + ")");
  if (std::isnan(max_distance) || max_distance < 0)
    throw Error("collision: the maximum distance of a ray must be non-negative");
  impl_->sync();
  const Ray ray{origin, direction.normalized(), max_distance};
  std::optional<RayHit> best;
  const auto test = [&](Entry& e) {
    if (e.object == nullptr || !e.problem.empty()) return;
    if (auto hit = ray_hit_shape(ray, *e.object->collisionGeometry(), e.object->getTransform())) {
      if (!best || hit->distance < best->distance) {
        RayHit h;
        h.hull = e.hull;
        h.distance = hit->distance;
        h.point = hit->point;
        h.normal = hit->normal;
        best = h;
      }
    }
  };
  // The broadphase tree: descend only into boxes the ray enters before the best hit so far.
  using Node = fcl::detail::NodeBase<fcl::AABBd>;
  std::vector<const Node*> todo;
  if (const Node* root = impl_->manager.getTree().getRoot()) todo.push_back(root);
  while (!todo.empty()) {
    const Node* n = todo.back();
    todo.pop_back();
    const double limit = best ? best->distance : ray.max_distance;
    if (!ray_enters_box(ray, n->bv.min_, n->bv.max_, limit)) continue;
    if (n->isLeaf()) {
      test(*static_cast<Entry*>(static_cast<fcl::CollisionObjectd*>(n->data)->getUserData()));
    } else {
      todo.push_back(n->children[0]);
      todo.push_back(n->children[1]);
    }
  }
  for (Entry* p : impl_->planes) test(*p);
  return best;
}

CollisionWorld::PairSink CollisionWorld::on_contact_begin() noexcept { return PairSink(impl_->begin); }
CollisionWorld::PairSink CollisionWorld::on_contact_end() noexcept { return PairSink(impl_->end); }
std::size_t CollisionWorld::size() const noexcept { return impl_->entries.size(); }
bool CollisionWorld::contains(const scene::Hull& hull) const { return impl_->entries.contains(&hull); }
std::size_t CollisionWorld::shape_count() const noexcept {
  std::unordered_set<const fcl::CollisionGeometryd*> distinct;
  for (const auto& [h, e] : impl_->entries)
    if (e->object != nullptr) distinct.insert(e->object->collisionGeometry().get());
  return distinct.size();
}
std::size_t CollisionWorld::last_moved() const noexcept { return impl_->last_moved; }
std::vector<std::string> CollisionWorld::problems() const { return impl_->problem_lines(); }

const std::vector<std::string>& CollisionWorld::warnings() const noexcept { return impl_->warnings; }

}  // namespace vsd::collision
