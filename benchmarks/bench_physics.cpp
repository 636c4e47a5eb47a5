// vsd::physics against plain ODE, side by side: one physics step of 200 bodies (100 boxes, 100 spheres)
// resting on a plane. Both use the same ODE parameters (hash space, QuickStep with 20 iterations, the same
// ERP/CFM, surface layer and correcting velocity) and the same contact rule (Approx1 friction, mu the
// geometric mean, the first friction direction along the sliding velocity), so the difference is what
// the database adds: sync (nothing dirty in the steady state), material lookup through the hulls, and the
// write-back of every pose and velocity through the setters (with the scene's world-frame listeners on).
// The plain ODE loop reads the poses back into an array, as any application would.
//
// MuJoCo 2.2 and DART 6 step the same bodies too when they are found at configure time (see MujocoScene
// and DartScene for what each step covers); every peer's benchmark fails unless all bodies still rest on
// the plane after it, and reports its contact count.
#include <benchmark/benchmark.h>
#include <ode/ode.h>

#include <cmath>
#include <memory>
#include <vector>
#ifdef VSD_BENCH_HAVE_MUJOCO
#include "mujoco_peer.hpp"

#include <cstring>
#include <sstream>
#include <stdexcept>
#endif
#ifdef VSD_BENCH_HAVE_DART
#include <dart/collision/fcl/FCLCollisionDetector.hpp>
#include <dart/collision/ode/OdeCollisionDetector.hpp>
#include <dart/constraint/ConstraintSolver.hpp>
#include <dart/dynamics/BodyNode.hpp>
#include <dart/dynamics/BoxShape.hpp>
#include <dart/dynamics/FreeJoint.hpp>
#include <dart/dynamics/PlaneShape.hpp>
#include <dart/dynamics/Skeleton.hpp>
#include <dart/dynamics/SphereShape.hpp>
#include <dart/dynamics/WeldJoint.hpp>
#include <dart/simulation/World.hpp>
#endif
#include <string>

#include "physics_scene.hpp"
#include "vsd/physics.hpp"

namespace {

using namespace vsd_bench_physics;  // body_count, step, half, mu, density, settle_steps, place(), VsdScene

// ---- vsd::physics ---------------------------------------------------------------------------------------
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

// After the steps: every body still rests on the plane (a peer whose contact buffer is too small lets
// some fall through, which makes its steps cheaper and its figure meaningless).
template <class Height>
bool all_resting(benchmark::State& state, Height&& height) {
  for (int i = 0; i < body_count; ++i) {
    const double z = height(i);
    if (!(z > 0.5 * half && z < 1.5 * half)) {
      state.SkipWithError(("body " + std::to_string(i) + " no longer rests on the plane").c_str());
      return false;
    }
  }
  return true;
}

#ifdef VSD_BENCH_HAVE_MUJOCO
// ---- MuJoCo 2.2, the same bodies ------------------------------------------------------------------------
// Free bodies of the same size and density on an infinite plane, friction 0.5 (MuJoCo takes the larger of
// two geoms' coefficients: 0.5), the same step. mj_step is MuJoCo's whole step: collision, constraint
// solver (Newton, MuJoCo's default, or PGS: argument 0 or 1), integration. The contact buffers are raised
// from 2.2.2's defaults, which hold 100 contacts and drop the rest (bodies then sink through the plane).
// Poses and velocities are copied out of mjData after each step, as the plain ODE loop does.
struct MujocoScene {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  std::vector<double> poses;
  explicit MujocoScene(int solver) {
    std::ostringstream x;
    x << "<mujoco><option timestep=\"" << step << "\" gravity=\"0 0 -9.81\"/>"
      << "<size nconmax=\"2000\" njmax=\"8000\"/>"
      << "<default><geom friction=\"" << mu << " 0.005 0.0001\" density=\"" << density << "\"/></default>"
      << "<worldbody><geom type=\"plane\" size=\"0 0 1\"/>";
    for (int i = 0; i < body_count; ++i) {
      const Eigen::Vector3d p = place(i);
      x << "<body pos=\"" << p.x() << ' ' << p.y() << ' ' << p.z() << "\"><freejoint/><geom type=\""
        << (i % 2 == 0 ? "box" : "sphere") << "\" size=\"" << half;
      if (i % 2 == 0) x << ' ' << half << ' ' << half;
      x << "\"/></body>";
    }
    x << "</worldbody></mujoco>";
    const std::string xml = x.str();
    m = vsd_bench::load_mujoco("bodies.xml", xml);
    m->opt.solver = solver == 0 ? mjSOL_NEWTON : mjSOL_PGS;
    d = mj_makeData(m);
    poses.resize(static_cast<std::size_t>(m->nq + m->nv));
    for (int i = 0; i < settle_steps; ++i) do_step();
  }
  MujocoScene(const MujocoScene&) = delete;
  MujocoScene& operator=(const MujocoScene&) = delete;
  ~MujocoScene() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }
  void do_step() {
    mj_step(m, d);
    std::memcpy(poses.data(), d->qpos, sizeof(double) * static_cast<std::size_t>(m->nq));
    std::memcpy(poses.data() + m->nq, d->qvel, sizeof(double) * static_cast<std::size_t>(m->nv));
  }
};

void BM_PhysicsStep_Mujoco(benchmark::State& state) {
  MujocoScene scene(static_cast<int>(state.range(0)));
  state.SetLabel(state.range(0) == 0 ? "Newton" : "PGS");
  for (auto _ : state) {
    scene.do_step();
    benchmark::DoNotOptimize(scene.poses.back());
  }
  if (scene.d->warning[mjWARN_CONTACTFULL].number > 0 || scene.d->warning[mjWARN_CNSTRFULL].number > 0)
    state.SkipWithError("MuJoCo's contact or constraint buffer overflowed");
  else if (!all_resting(state, [&](int i) { return scene.d->xpos[3 * (i + 1) + 2]; }))
    return;
  state.counters["contacts"] = scene.d->ncon;
  state.SetItemsProcessed(state.iterations() * body_count);
}
BENCHMARK(BM_PhysicsStep_Mujoco)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
#endif

#ifdef VSD_BENCH_HAVE_DART
// ---- DART 6, the same bodies ----------------------------------------------------------------------------
// One skeleton per body (a free joint), the ground a welded plane, friction 0.5 on every shape, the same
// step. World::step is DART's whole step: collision, its boxed-LCP constraint solver (Dantzig, PGS as the
// fallback), integration. Collision through DART's ODE detector (argument 0: the like-for-like figure,
// ODE's own box, sphere and plane tests) or its FCL detector (argument 1: FCL with DART's default of meshed
// primitives, the ground a box). The contact cap is raised from DART's default of 1000, past which bodies
// sink. Poses and velocities are read back after each step, as the plain ODE loop does.
struct DartScene {
  dart::simulation::WorldPtr world = dart::simulation::World::create();
  std::vector<dart::dynamics::BodyNode*> bodies;
  std::vector<double> poses;
  explicit DartScene(int detector) {
    using namespace dart::dynamics;
    world->setTimeStep(step);
    world->setGravity(Eigen::Vector3d(0, 0, -9.81));
    auto* solver = world->getConstraintSolver();  // the detector first: the shapes go to it as they come
    if (detector == 0)
      solver->setCollisionDetector(dart::collision::OdeCollisionDetector::create());
    else
      solver->setCollisionDetector(dart::collision::FCLCollisionDetector::create());
    solver->getCollisionOption().maxNumContacts = 10000;
    auto ground = Skeleton::create("ground");
    auto* g = ground->createJointAndBodyNodePair<WeldJoint>().second;
    // FCL has no plane in DART 6.12 (it substitutes a box of zero thickness, and bodies fall through): a
    // box 1 m thick whose top face is the plane instead.
    ShapePtr floor = std::make_shared<PlaneShape>(Eigen::Vector3d::UnitZ(), 0.0);
    if (detector != 0) {
      floor = std::make_shared<BoxShape>(Eigen::Vector3d(1000, 1000, 1));
      Eigen::Isometry3d below = Eigen::Isometry3d::Identity();
      below.translation().z() = -0.5;
      g->getParentJoint()->setTransformFromParentBodyNode(below);
    }
    g->createShapeNodeWith<CollisionAspect, DynamicsAspect>(floor)->getDynamicsAspect()->setFrictionCoeff(mu);
    world->addSkeleton(ground);
    for (int i = 0; i < body_count; ++i) {
      auto skel = Skeleton::create("body" + std::to_string(i));
      auto [joint, body] = skel->createJointAndBodyNodePair<FreeJoint>();
      ShapePtr shape;
      if (i % 2 == 0)
        shape = std::make_shared<BoxShape>(Eigen::Vector3d::Constant(2 * half));
      else
        shape = std::make_shared<SphereShape>(half);
      body->createShapeNodeWith<CollisionAspect, DynamicsAspect>(shape)
          ->getDynamicsAspect()
          ->setFrictionCoeff(mu);
      const double mass = density * shape->getVolume();
      body->setInertia(Inertia(mass, Eigen::Vector3d::Zero(), shape->computeInertia(mass)));
      Eigen::Isometry3d tf = Eigen::Isometry3d::Identity();
      tf.translation() = place(i);
      FreeJoint::setTransformOf(joint, tf);
      world->addSkeleton(skel);
      bodies.push_back(body);
    }
    poses.resize(bodies.size() * 18);
    for (int i = 0; i < settle_steps; ++i) do_step();
  }
  void do_step() {
    world->step();
    double* out = poses.data();
    for (auto* b : bodies) {
      const Eigen::Isometry3d& tf = b->getWorldTransform();
      const Eigen::Vector6d v =
          b->getSpatialVelocity(dart::dynamics::Frame::World(), dart::dynamics::Frame::World());
      for (int k = 0; k < 3; ++k) *out++ = tf.translation()[k];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) *out++ = tf.linear()(r, c);
      for (int k = 0; k < 6; ++k) *out++ = v[k];
    }
  }
};

void BM_PhysicsStep_Dart(benchmark::State& state) {
  DartScene scene(static_cast<int>(state.range(0)));
  state.SetLabel(state.range(0) == 0 ? "ODE collision" : "FCL collision");
  for (auto _ : state) {
    scene.do_step();
    benchmark::DoNotOptimize(scene.poses.back());
  }
  if (!all_resting(state, [&](int i) {
        return scene.bodies[static_cast<std::size_t>(i)]->getWorldTransform().translation().z();
      }))
    return;
  state.counters["contacts"] = static_cast<double>(scene.world->getLastCollisionResult().getNumContacts());
  state.SetItemsProcessed(state.iterations() * body_count);
}
BENCHMARK(BM_PhysicsStep_Dart)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace
