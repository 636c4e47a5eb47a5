// vsd::collision against FCL used directly, and Node3D world frames against a hand-written tree
// (benchmarks/README.md, "Collision and world frames").
//
// Collision: 1,000 hulls (spheres, boxes, capsules; 4 geometries, so shapes are shared) scattered in a
// 24 m cube, so that a few dozen pairs touch. Each iteration moves some of them (all, or 10) between two
// precomputed pose sets, then updates the world and computes all contacts. The FCL peer does the same
// with the same shapes, the same broadphase (DynamicAABBTreeCollisionManager), the same request (4
// contacts per pair) and a callback that collects the contacts the same way; it is told exactly which
// objects moved (the best a hand-written program can do). vsd learns what moved from the setters'
// signals, finds the hulls below each moved node, computes their world frames, and on top sorts the
// contacts and diffs the pairs for the begin/end signals.
//
// World frames: a tree of 10,000 Node3Ds (fan-out 10, depth 5). After moving the root, or one leaf,
// every node's world frame is read. The peer is a plain array with parent indices that recomputes
// exactly the moved node's subtree, eagerly (it knows which nodes are below the moved one).
//
// Filling a world with coincident hulls: N unit boxes at one spot (objects spawned at the origin), the
// world built over them (no contacts computed). FCL's one-by-one insertion walks its tree to the most
// similar box, which among equal boxes is a walk as long as the tree: quadratic (20,000 boxes took 20 s
// in vsd-collide). vsd registers a large batch in one balanced build instead; the figures should grow as
// N log N.
//
// Ray against a mesh: one hull with a closed bumpy sphere mesh of 99,224 triangles; each iteration casts
// one of 256 precomputed rays (from 6 m out towards a point within 2.4 m of the centre; about 4 in 5
// hit). vsd::collision descends the broadphase and then FCL's own OBBRSS tree of the mesh. The peer is
// the brute force the collision module used before: the ray taken into the mesh frame once, then
// Moeller-Trumbore against every triangle of the same vertex and index arrays.
#include <benchmark/benchmark.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "vsd/collision.hpp"
#include "vsd/core.hpp"

namespace {

using vsd::scene::Geometry;
using vsd::scene::GeometryKind;
using vsd::scene::Hull;
using vsd::scene::Node3D;

constexpr int kHulls = 1000;

// The same scene for both sides: kind, two poses per hull.
struct Layout {
  std::vector<int> shape;  // 0 sphere r 0.5, 1 box 0.8^3, 2 capsule r 0.3 l 0.8, 3 box 1.2 x 0.4 x 0.4
  std::vector<Eigen::Isometry3d> pose[2];
};

const Layout& layout() {
  static const Layout l = [] {
    Layout out;
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> pos(-12, 12), ang(-M_PI, M_PI), step(-0.1, 0.1);
    for (int i = 0; i < kHulls; ++i) {
      out.shape.push_back(i % 4);
      Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
      a.translation() = Eigen::Vector3d(pos(rng), pos(rng), pos(rng));
      a.rotate(Eigen::AngleAxisd(ang(rng), Eigen::Vector3d(pos(rng), pos(rng), pos(rng)).normalized()));
      Eigen::Isometry3d b = a;
      b.translation() += Eigen::Vector3d(step(rng), step(rng), step(rng));
      b.rotate(Eigen::AngleAxisd(step(rng), Eigen::Vector3d::UnitZ()));
      out.pose[0].push_back(a);
      out.pose[1].push_back(b);
    }
    return out;
  }();
  return l;
}

// ---- vsd::collision ---------------------------------------------------------------------------------

void BM_Collision_Vsd(benchmark::State& st) {
  const int moved = static_cast<int>(st.range(0));
  const Layout& l = layout();
  vsd::Environment env;
  env.use<vsd::collision::Module>();
  vsd::SimState& s = env.main_state();
  Geometry* geoms[4];
  for (int k = 0; k < 4; ++k) {
    auto& g = s.create<Geometry>();
    if (k == 0) {
      g.set_kind(GeometryKind::Sphere);
      g.set_radius(0.5);
    } else if (k == 1) {
      g.set_kind(GeometryKind::Box);
      g.set_size(Eigen::Vector3d(0.8, 0.8, 0.8));
    } else if (k == 2) {
      g.set_kind(GeometryKind::Capsule);
      g.set_radius(0.3);
      g.set_length(0.8);
    } else {
      g.set_kind(GeometryKind::Box);
      g.set_size(Eigen::Vector3d(1.2, 0.4, 0.4));
    }
    geoms[k] = &g;
  }
  std::vector<Hull*> hulls;
  for (int i = 0; i < kHulls; ++i) {
    auto& h = s.create<Hull>();
    h.set_role(vsd::scene::HullRole::Collision);
    h.set_geometry(geoms[l.shape[static_cast<std::size_t>(i)]]);
    h.set_frame(l.pose[0][static_cast<std::size_t>(i)]);
    s.database().add_child(h);
    hulls.push_back(&h);
  }
  vsd::collision::CollisionWorld world(s);
  world.update();
  std::size_t contacts = 0, iterations = 0;
  int phase = 0;
  for (auto _ : st) {
    phase ^= 1;
    for (int i = 0; i < moved; ++i) {
      const auto k = static_cast<std::size_t>(i * (kHulls / moved));
      hulls[k]->set_frame(l.pose[phase][k]);
    }
    world.update();
    contacts += world.contacts().size();
    ++iterations;
  }
  st.counters["contacts"] = static_cast<double>(contacts) / static_cast<double>(iterations);
}
BENCHMARK(BM_Collision_Vsd)->Arg(kHulls)->Arg(10)->Unit(benchmark::kMicrosecond);

// ---- FCL used directly --------------------------------------------------------------------------------

struct FclContact {
  fcl::CollisionObjectd* a;
  fcl::CollisionObjectd* b;
  Eigen::Vector3d position, normal;
  double depth;
};

struct FclData {
  fcl::CollisionRequestd request{4, true};
  std::vector<FclContact> contacts;
};

bool fcl_callback(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
  auto* d = static_cast<FclData*>(data);
  fcl::CollisionResultd result;
  fcl::collide(o1, o2, d->request, result);
  for (std::size_t i = 0; i < result.numContacts(); ++i) {
    const fcl::Contactd& c = result.getContact(i);
    d->contacts.push_back({o1, o2, c.pos, c.normal, c.penetration_depth});
  }
  return false;
}

void BM_Collision_FclDirect(benchmark::State& st) {
  const int moved = static_cast<int>(st.range(0));
  const Layout& l = layout();
  std::shared_ptr<fcl::CollisionGeometryd> shapes[4] = {
      std::make_shared<fcl::Sphered>(0.5), std::make_shared<fcl::Boxd>(0.8, 0.8, 0.8),
      std::make_shared<fcl::Capsuled>(0.3, 0.8), std::make_shared<fcl::Boxd>(1.2, 0.4, 0.4)};
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  fcl::DynamicAABBTreeCollisionManagerd manager;
  for (int i = 0; i < kHulls; ++i) {
    const auto k = static_cast<std::size_t>(i);
    objects.push_back(std::make_unique<fcl::CollisionObjectd>(shapes[l.shape[k]], l.pose[0][k]));
    objects.back()->computeAABB();
    manager.registerObject(objects.back().get());
  }
  manager.setup();
  FclData data;
  std::vector<fcl::CollisionObjectd*> updated;
  std::size_t contacts = 0, iterations = 0;
  int phase = 0;
  for (auto _ : st) {
    phase ^= 1;
    updated.clear();
    for (int i = 0; i < moved; ++i) {
      const auto k = static_cast<std::size_t>(i * (kHulls / moved));
      objects[k]->setTransform(l.pose[phase][k]);
      objects[k]->computeAABB();
      updated.push_back(objects[k].get());
    }
    manager.update(updated);
    data.contacts.clear();
    manager.collide(&data, &fcl_callback);
    contacts += data.contacts.size();
    ++iterations;
  }
  st.counters["contacts"] = static_cast<double>(contacts) / static_cast<double>(iterations);
}
BENCHMARK(BM_Collision_FclDirect)->Arg(kHulls)->Arg(10)->Unit(benchmark::kMicrosecond);

void BM_Collision_FillCoincident(benchmark::State& st) {
  const auto n = static_cast<int>(st.range(0));
  vsd::Environment env;
  vsd::SimState& s = env.main_state();
  auto& g = s.create<Geometry>();
  g.set_kind(GeometryKind::Box);
  g.set_size(Eigen::Vector3d(1, 1, 1));
  auto& holder = s.create<vsd::scene::Scene>();
  s.database().add_child(holder);
  holder.edit_geometries().push_back(g);
  for (int i = 0; i < n; ++i) {
    auto& h = s.create<Hull>();
    h.set_role(vsd::scene::HullRole::Collision);
    h.set_geometry(&g);
    holder.add_child(h);
  }
  for (auto _ : st) {
    vsd::collision::CollisionWorld world(s);
    benchmark::DoNotOptimize(world.size());
  }
  st.SetComplexityN(n);
}
BENCHMARK(BM_Collision_FillCoincident)
    ->Arg(1000)
    ->Arg(4000)
    ->Arg(16000)
    ->Complexity(benchmark::oNLogN)
    ->Unit(benchmark::kMillisecond);

// ---- world frames of a 10,000-node tree ---------------------------------------------------------------

constexpr int kFanout = 10;
constexpr int kNodes = 10000;

Eigen::Isometry3d small_pose(int i, int phase) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.translation() = Eigen::Vector3d(0.1 * (i % 7), 0.05 * phase, 0.2);
  f.rotate(Eigen::AngleAxisd(0.01 * (i % 13) + 0.001 * phase, Eigen::Vector3d::UnitZ()));
  return f;
}

// Parent of node i in breadth-first numbering with fan-out kFanout (-1 for the root).
int parent_of(int i) { return i == 0 ? -1 : (i - 1) / kFanout; }

enum class Moved { Root, Leaf };

void world_frames_vsd(benchmark::State& st, Moved which) {
  vsd::Environment env;
  env.use<vsd::scene::Module>();
  vsd::SimState& s = env.main_state();
  std::vector<Node3D*> nodes;
  for (int i = 0; i < kNodes; ++i) {
    auto& n = s.create<Node3D>();
    n.set_frame(small_pose(i, 0));
    const int p = parent_of(i);
    (p < 0 ? static_cast<vsd::Node&>(s.database()) : *nodes[static_cast<std::size_t>(p)]).add_child(n);
    nodes.push_back(&n);
  }
  Node3D* target = which == Moved::Root ? nodes.front() : nodes.back();
  const int target_index = which == Moved::Root ? 0 : kNodes - 1;
  int phase = 0;
  double sum = 0;
  for (auto _ : st) {
    phase ^= 1;
    target->set_frame(small_pose(target_index, phase));
    for (const Node3D* n : nodes) sum += n->world_frame().translation().x();
  }
  benchmark::DoNotOptimize(sum);
}

// The hand-written peer: frames and world frames in arrays; a move recomputes the moved node's subtree
// (children lists precomputed), then the same reads.
void world_frames_raw(benchmark::State& st, Moved which) {
  std::vector<Eigen::Isometry3d> frame(kNodes), world(kNodes);
  std::vector<std::vector<int>> children(kNodes);
  for (int i = 0; i < kNodes; ++i) {
    frame[static_cast<std::size_t>(i)] = small_pose(i, 0);
    if (parent_of(i) >= 0) children[static_cast<std::size_t>(parent_of(i))].push_back(i);
  }
  const auto recompute_below = [&](int top) {
    std::vector<int> todo{top};
    while (!todo.empty()) {
      const auto i = static_cast<std::size_t>(todo.back());
      todo.pop_back();
      const int p = parent_of(static_cast<int>(i));
      world[i] = p < 0 ? frame[i] : world[static_cast<std::size_t>(p)] * frame[i];
      for (int c : children[i]) todo.push_back(c);
    }
  };
  recompute_below(0);
  const int target = which == Moved::Root ? 0 : kNodes - 1;
  int phase = 0;
  double sum = 0;
  for (auto _ : st) {
    phase ^= 1;
    frame[static_cast<std::size_t>(target)] = small_pose(target, phase);
    recompute_below(target);
    for (const auto& w : world) sum += w.translation().x();
  }
  benchmark::DoNotOptimize(sum);
}

void BM_WorldFrames_Vsd_MoveRoot(benchmark::State& st) { world_frames_vsd(st, Moved::Root); }
void BM_WorldFrames_Raw_MoveRoot(benchmark::State& st) { world_frames_raw(st, Moved::Root); }
void BM_WorldFrames_Vsd_MoveLeaf(benchmark::State& st) { world_frames_vsd(st, Moved::Leaf); }
void BM_WorldFrames_Raw_MoveLeaf(benchmark::State& st) { world_frames_raw(st, Moved::Leaf); }
BENCHMARK(BM_WorldFrames_Vsd_MoveRoot)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_WorldFrames_Raw_MoveRoot)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_WorldFrames_Vsd_MoveLeaf)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_WorldFrames_Raw_MoveLeaf)->Unit(benchmark::kMicrosecond);

// ---- ray against a ~100k-triangle mesh -------------------------------------------------------------------

struct RayMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::int32_t> facets;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> rays;  // origin, unit direction (world)
};

const RayMesh& ray_mesh() {
  static const RayMesh m = [] {
    RayMesh out;
    constexpr int n = 158;  // 4 n (n - 1) = 99,224 triangles
    out.vertices.emplace_back(0, 0, 2);
    for (int i = 1; i < n; ++i)
      for (int j = 0; j < 2 * n; ++j) {
        const double th = M_PI * i / n, ph = M_PI * j / n;
        const double r = 2 + 0.3 * std::sin(5 * th) * std::cos(3 * ph);
        out.vertices.emplace_back(r * std::sin(th) * std::cos(ph), r * std::sin(th) * std::sin(ph),
                                  r * std::cos(th));
      }
    out.vertices.emplace_back(0, 0, -2);
    const auto ring = [](int i, int j) { return 1 + (i - 1) * 2 * n + (j % (2 * n)); };
    const auto last = static_cast<std::int32_t>(out.vertices.size() - 1);
    for (int j = 0; j < 2 * n; ++j) {
      out.facets.insert(out.facets.end(), {0, ring(1, j), ring(1, j + 1)});
      out.facets.insert(out.facets.end(), {last, ring(n - 1, j + 1), ring(n - 1, j)});
    }
    for (int i = 1; i + 1 < n; ++i)
      for (int j = 0; j < 2 * n; ++j) {
        out.facets.insert(out.facets.end(), {ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
        out.facets.insert(out.facets.end(), {ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
      }
    out.pose.translate(Eigen::Vector3d(1, -2, 3));
    out.pose.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int k = 0; k < 256; ++k) {
      const Eigen::Vector3d c = out.pose.translation();
      const Eigen::Vector3d o = c + 6.0 * Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      const Eigen::Vector3d t = c + 2.4 * Eigen::Vector3d(u(rng), u(rng), u(rng));
      out.rays.emplace_back(o, (t - o).normalized());
    }
    return out;
  }();
  return m;
}

void BM_RayMesh_Vsd(benchmark::State& st) {
  const RayMesh& m = ray_mesh();
  vsd::Environment env;
  env.use<vsd::collision::Module>();
  vsd::SimState& s = env.main_state();
  auto& g = s.create<Geometry>();
  g.set_kind(GeometryKind::Mesh);
  g.set_vertices(m.vertices);
  g.set_facets(m.facets);
  auto& h = s.create<Hull>();
  h.set_role(vsd::scene::HullRole::Collision);
  h.set_geometry(&g);
  h.set_frame(m.pose);
  s.database().add_child(h);
  vsd::collision::CollisionWorld world(s);
  world.update();
  std::size_t i = 0, hits = 0;
  for (auto _ : st) {
    const auto& [o, d] = m.rays[i++ % m.rays.size()];
    auto hit = world.ray_cast(o, d);
    hits += hit ? 1 : 0;
    benchmark::DoNotOptimize(hit);
  }
  st.counters["hit_share"] = static_cast<double>(hits) / static_cast<double>(std::max<std::size_t>(i, 1));
  st.counters["triangles"] = static_cast<double>(m.facets.size() / 3);
}
BENCHMARK(BM_RayMesh_Vsd)->Unit(benchmark::kMicrosecond);

void BM_RayMesh_BruteForce(benchmark::State& st) {
  const RayMesh& m = ray_mesh();
  const Eigen::Matrix3d r = m.pose.linear();
  std::size_t i = 0, hits = 0;
  for (auto _ : st) {
    const auto& [wo, wd] = m.rays[i++ % m.rays.size()];
    const Eigen::Vector3d o = r.transpose() * (wo - m.pose.translation());
    const Eigen::Vector3d d = r.transpose() * wd;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < m.facets.size(); k += 3) {
      const Eigen::Vector3d &a = m.vertices[static_cast<std::size_t>(m.facets[k])],
                            &b = m.vertices[static_cast<std::size_t>(m.facets[k + 1])],
                            &c = m.vertices[static_cast<std::size_t>(m.facets[k + 2])];
      const Eigen::Vector3d e1 = b - a, e2 = c - a, p = d.cross(e2);
      const double det = e1.dot(p);
      if (std::abs(det) < 1e-14 * e1.norm() * e2.norm()) continue;
      const Eigen::Vector3d t0 = o - a;
      const double u = t0.dot(p) / det;
      if (u < 0 || u > 1) continue;
      const Eigen::Vector3d q = t0.cross(e1);
      const double v = d.dot(q) / det;
      if (v < 0 || u + v > 1) continue;
      const double t = e2.dot(q) / det;
      if (t >= 0 && t < best) best = t;
    }
    hits += best < std::numeric_limits<double>::infinity() ? 1 : 0;
    benchmark::DoNotOptimize(best);
  }
  st.counters["hit_share"] = static_cast<double>(hits) / static_cast<double>(std::max<std::size_t>(i, 1));
  st.counters["triangles"] = static_cast<double>(m.facets.size() / 3);
}
BENCHMARK(BM_RayMesh_BruteForce)->Unit(benchmark::kMicrosecond);

}  // namespace
