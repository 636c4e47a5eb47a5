// vsd::physics against plain ODE, side by side: one physics step of 200 bodies (100 boxes, 100 spheres)
// resting on a plane. Both use the same ODE parameters (hash space, QuickStep with 20 iterations, the same
// ERP/CFM, surface layer and correcting velocity) and the same contact rule (Approx1 friction, mu the
// geometric mean, the first friction direction along the sliding velocity), so the difference is what
// the database adds: sync (nothing dirty in the steady state), material lookup through the hulls, and the
// write-back of every pose and velocity through the setters (with the scene's world-frame listeners on).
// The plain ODE loop reads the poses back into an array, as any application would.
#include <benchmark/benchmark.h>
#include <ode/ode.h>

#include <cmath>
#include <memory>
#include <vector>

#include "vsd/physics.hpp"

namespace {

constexpr int body_count = 200;
constexpr double step = 0.002;
constexpr double half = 0.1;  // half size of the boxes, radius of the spheres
constexpr double mu = 0.5;
constexpr double density = 500.0;
constexpr int settle_steps = 500;

// Grid position of body i, resting on the plane (sunk into the surface layer as a settled body is).
Eigen::Vector3d place(int i) { return {0.5 * (i % 20), 0.5 * (i / 20), half - 0.0004}; }

// ---- vsd::physics ---------------------------------------------------------------------------------------
struct VsdScene {
  vsd::Environment env;
  vsd::physics::Simulation* sim = nullptr;
  std::vector<vsd::scene::Hull*> hulls;

  VsdScene() {
    env.use<vsd::physics::Module>();
    env.scheduler().set_base_step(step);
    sim = &env.module<vsd::physics::Module>()->simulation();
    auto& s = env.main_state();
    auto& root = s.create<vsd::scene::Scene>();
    s.database().add_child(root);
    auto& w = s.create<vsd::physics::World>();
    w.set_step(step);
    root.add_extension(w);
    auto& mat = s.create<vsd::scene::Material>();
    mat.set_friction(mu);
    mat.set_density(density);
    root.edit_materials().push_back(mat);
    auto geometry = [&](vsd::scene::GeometryKind k) -> vsd::scene::Geometry& {
      auto& g = s.create<vsd::scene::Geometry>();
      g.set_kind(k);
      g.set_size(Eigen::Vector3d::Constant(2 * half));
      g.set_radius(half);
      root.edit_geometries().push_back(g);
      return g;
    };
    auto& plane = geometry(vsd::scene::GeometryKind::Plane);
    auto& box = geometry(vsd::scene::GeometryKind::Box);
    auto& ball = geometry(vsd::scene::GeometryKind::Sphere);
    auto hull = [&](vsd::scene::Geometry& g, const Eigen::Vector3d& p) -> vsd::scene::Hull& {
      auto& h = s.create<vsd::scene::Hull>();
      h.set_role(vsd::scene::HullRole::Collision);
      h.set_geometry(&g);
      h.set_material(&mat);
      Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
      f.translation() = p;
      h.set_frame(f);
      root.add_child(h);
      return h;
    };
    hull(plane, Eigen::Vector3d::Zero());
    for (int i = 0; i < body_count; ++i) {
      auto& h = hull(i % 2 == 0 ? box : ball, place(i));
      h.add_extension(s.create<vsd::physics::RigidBody>());
      hulls.push_back(&h);
    }
    for (int i = 0; i < settle_steps; ++i) env.step();
  }
};

void BM_PhysicsStep_Vsd(benchmark::State& state) {
  VsdScene scene;
  for (auto _ : state) {
    scene.env.step();
    benchmark::DoNotOptimize(scene.hulls.back()->frame());
  }
  if (scene.sim->stats().bodies != body_count) state.SkipWithError("not all bodies simulated");
  state.counters["contacts"] = static_cast<double>(scene.sim->stats().contacts);
  state.SetItemsProcessed(state.iterations() * body_count);
}
BENCHMARK(BM_PhysicsStep_Vsd)->Unit(benchmark::kMicrosecond);

// ---- plain ODE, the same bodies -------------------------------------------------------------------------
struct PlainOde {
  struct Pose {
    double p[3];
    double r[12];
    double v[3];
    double w[3];
  };
  struct Surface {
    double mu;
  };
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  std::vector<dBodyID> bodies;
  std::vector<Pose> poses;
  Surface surface{mu};
  std::vector<dContact> buffer = std::vector<dContact>(8);
  std::size_t contact_count = 0;

  PlainOde() {
    dInitODE2(0);
    world = dWorldCreate();
    space = dHashSpaceCreate(nullptr);
    contacts = dJointGroupCreate(0);
    dWorldSetGravity(world, 0, 0, -9.81);
    dWorldSetERP(world, 0.2);
    dWorldSetCFM(world, 1e-9);
    dWorldSetQuickStepNumIterations(world, 20);
    dWorldSetContactSurfaceLayer(world, 0.0005);
    dWorldSetContactMaxCorrectingVel(world, 1.0);
    dGeomSetData(dCreatePlane(space, 0, 0, 1, 0), &surface);
    for (int i = 0; i < body_count; ++i) {
      dBodyID b = dBodyCreate(world);
      dMass m;
      dGeomID g;
      if (i % 2 == 0) {
        dMassSetBox(&m, density, 2 * half, 2 * half, 2 * half);
        g = dCreateBox(space, 2 * half, 2 * half, 2 * half);
      } else {
        dMassSetSphere(&m, density, half);
        g = dCreateSphere(space, half);
      }
      dBodySetMass(b, &m);
      const Eigen::Vector3d p = place(i);
      dBodySetPosition(b, p.x(), p.y(), p.z());
      dGeomSetBody(g, b);
      dGeomSetData(g, &surface);
      bodies.push_back(b);
    }
    poses.resize(bodies.size());
    for (int i = 0; i < settle_steps; ++i) do_step();
  }
  ~PlainOde() {
    dJointGroupDestroy(contacts);
    dSpaceDestroy(space);
    dWorldDestroy(world);
    dCloseODE();
  }

  static void near(void* data, dGeomID a, dGeomID b) {
    auto& self = *static_cast<PlainOde*>(data);
    dBodyID ba = dGeomGetBody(a);
    dBodyID bb = dGeomGetBody(b);
    if (ba == bb) return;
    if (ba != nullptr && bb != nullptr && dAreConnectedExcluding(ba, bb, dJointTypeContact) != 0) return;
    const int n = dCollide(a, b, 8, &self.buffer[0].geom, sizeof(dContact));
    if (n <= 0) return;
    const double m =
        std::sqrt(static_cast<Surface*>(dGeomGetData(a))->mu * static_cast<Surface*>(dGeomGetData(b))->mu);
    for (int i = 0; i < n; ++i) {
      dContact& c = self.buffer[static_cast<std::size_t>(i)];
      c.surface.mode = dContactApprox1;
      c.surface.mu = m;
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
      }
      dJointAttach(dJointCreateContact(self.world, self.contacts, &c), ba, bb);
    }
    self.contact_count += static_cast<std::size_t>(n);
  }

  void do_step() {
    contact_count = 0;
    dSpaceCollide(space, this, &near);
    dWorldQuickStep(world, step);
    dJointGroupEmpty(contacts);
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      Pose& q = poses[i];
      const dReal* p = dBodyGetPosition(bodies[i]);
      const dReal* r = dBodyGetRotation(bodies[i]);
      const dReal* v = dBodyGetLinearVel(bodies[i]);
      const dReal* w = dBodyGetAngularVel(bodies[i]);
      for (int k = 0; k < 3; ++k) {
        q.p[k] = p[k];
        q.v[k] = v[k];
        q.w[k] = w[k];
      }
      for (int k = 0; k < 12; ++k) q.r[k] = r[k];
    }
  }
};

void BM_PhysicsStep_PlainOde(benchmark::State& state) {
  PlainOde ode;
  for (auto _ : state) {
    ode.do_step();
    benchmark::DoNotOptimize(ode.poses.back());
  }
  state.counters["contacts"] = static_cast<double>(ode.contact_count);
  state.SetItemsProcessed(state.iterations() * body_count);
}
BENCHMARK(BM_PhysicsStep_PlainOde)->Unit(benchmark::kMicrosecond);

}  // namespace
