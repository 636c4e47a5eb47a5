// vsd::robotics against Orocos KDL on the 7-DOF KUKA iiwa14 (tests/scene/data/iiwa14.urdf, chain
// iiwa_link_0 -> iiwa_link_ee), in the same binary:
//
//   BM_Robotics_Fk_{Vsd,Kdl}         forward kinematics of the chain (vsd: every body; KDL: the tip)
//   BM_Robotics_Jacobian_{Vsd,Kdl}   FK + geometric Jacobian of the tip (KDL's JntToJac does its own FK)
//   BM_Robotics_ControlCycle8        one control cycle of the 8-axis robot (the iiwa on a linear axis) in the
//                                    database: read the joints, FK, Jacobian, a differential-IK command
//                                    written back to the joints (frames move, signals fire); p50/p99 in µs
//   BM_Robotics_Ik_{Vsd,Kdl}         IK from a nearby seed (goal + N(0, 0.1 rad) per joint, clamped):
//                                    vsd's IkSolver (LM-damped least squares, limits respected, 5 ms budget)
//                                    vs KDL's ChainIkSolverPos_LMA (default settings, no limits)
//
//   BM_Robotics_{Fk,Jacobian}_{Mujoco,Dart}, BM_Robotics_Ik_Dart: the same with MuJoCo 2.2 and DART 6, when
//                                    found at configure time, loading the same URDF (see MujocoArm, DartArm
//                                    and each benchmark for what its call covers); max_diff_vs_vsd is the
//                                    largest difference of tip pose and Jacobian from vsd's (checked < 1e-9)
//
// Joint vectors cycle through 1024 random configurations within the limits (fixed seed), so nothing is
// constant-folded and both libraries see the same inputs. The IK benchmarks time every solve on its own
// and report median_us, p99_us and success (the fraction solved); items/s is solves per second.
#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <random>
#include <vector>

#include "kdl_chain.hpp"
#if defined(VSD_BENCH_HAVE_MUJOCO) || defined(VSD_BENCH_HAVE_DART)
#include <cstring>
#include <memory>
#include <regex>
#include <stdexcept>
#endif
#ifdef VSD_BENCH_HAVE_MUJOCO
#include "mujoco_peer.hpp"
#endif
#ifdef VSD_BENCH_HAVE_DART
#include <dart/dynamics/BodyNode.hpp>
#include <dart/dynamics/InverseKinematics.hpp>
#include <dart/dynamics/SimpleFrame.hpp>
#include <dart/dynamics/Skeleton.hpp>
#include <dart/utils/urdf/DartLoader.hpp>
#endif
#include "test_util.hpp"
#include "vsd/robotics.hpp"

namespace {

using namespace vsd::robotics;

struct Fixture {
  vsd::Environment env;
  Model model;
  KDL::Chain chain;
  std::vector<std::vector<double>> qs;
  std::vector<KDL::JntArray> kqs;
  Fixture() {
    env.use<Module>();
    const std::string file = std::string(VSD_BENCH_ROBOT_DIR) + "/iiwa14.urdf";
    vsd::scene::UrdfOptions o;
    o.load_meshes = false;
    auto rep = vsd::scene::load_urdf(env.main_state().database(), file, o);
    (void)build_kinematics(*rep.scene);
    model = Model::compile(*rep.scene->find_link("iiwa_link_0"), rep.scene->find_link("iiwa_link_ee"));
    chain = vsd_test::kdl_chain(vsd_test::read_text(file), "iiwa_link_0", "iiwa_link_ee");
    std::mt19937_64 rng(1234);
    for (int i = 0; i < 1024; ++i) {
      qs.push_back(vsd_test::random_q(model, rng));
      KDL::JntArray k(7);
      for (int j = 0; j < 7; ++j) k(j) = qs.back()[static_cast<std::size_t>(j)];
      kqs.push_back(k);
    }
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

void BM_Robotics_Fk_Vsd(benchmark::State& state) {
  Fixture& f = fixture();
  Model::Data d = f.model.make_data();
  std::size_t i = 0;
  for (auto _ : state) {
    f.model.forward(f.qs[i++ & 1023].data(), d);
    benchmark::DoNotOptimize(d.segment.back().translation.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Robotics_Fk_Vsd);

void BM_Robotics_Fk_Kdl(benchmark::State& state) {
  Fixture& f = fixture();
  KDL::ChainFkSolverPos_recursive fk(f.chain);
  KDL::Frame out;
  std::size_t i = 0;
  for (auto _ : state) {
    fk.JntToCart(f.kqs[i++ & 1023], out);
    benchmark::DoNotOptimize(out.p.data);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Robotics_Fk_Kdl);

void BM_Robotics_Jacobian_Vsd(benchmark::State& state) {
  Fixture& f = fixture();
  Model::Data d = f.model.make_data();
  Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, 7);
  std::size_t i = 0;
  for (auto _ : state) {
    f.model.forward(f.qs[i++ & 1023].data(), d);
    f.model.jacobian(d, f.model.tip(), j);
    benchmark::DoNotOptimize(j.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Robotics_Jacobian_Vsd);

void BM_Robotics_Jacobian_Kdl(benchmark::State& state) {
  Fixture& f = fixture();
  KDL::ChainJntToJacSolver solver(f.chain);
  KDL::Jacobian j(7);
  std::size_t i = 0;
  for (auto _ : state) {
    solver.JntToJac(f.kqs[i++ & 1023], j);
    benchmark::DoNotOptimize(j.data.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Robotics_Jacobian_Kdl);

// ---- MuJoCo and DART: the same chain, loaded from the same URDF -----------------------------------------
#if defined(VSD_BENCH_HAVE_MUJOCO) || defined(VSD_BENCH_HAVE_DART)
// The iiwa14 URDF without its <visual> and <collision> elements: their meshes are not in the test data, and
// no benchmark here needs them (vsd loads the file with load_meshes = false).
std::string bare_urdf() {
  const std::string xml = vsd_test::read_text(std::string(VSD_BENCH_ROBOT_DIR) + "/iiwa14.urdf");
  static const std::regex element(R"(<(visual|collision)\b[\s\S]*?</\1>)");
  return std::regex_replace(xml, element, "");
}

// The largest difference between a peer's tip pose and Jacobian (linear rows first) and vsd's, over the
// 1024 configurations: the benchmarks below compare like with like only while this is at rounding level.
template <class Peer>
double max_difference_from_vsd(Peer&& peer) {
  Fixture& f = fixture();
  Model::Data d = f.model.make_data();
  Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, 7), pj(6, 7);
  Eigen::Isometry3d pose;
  double most = 0;
  for (const auto& q : f.qs) {
    f.model.forward(q.data(), d);
    f.model.jacobian(d, f.model.tip(), j);
    peer(q, pose, pj);
    const Frame tip = f.model.pose(d, f.model.tip());
    most = std::max({most, (pose.translation() - tip.translation).cwiseAbs().maxCoeff(),
                     (pose.linear() - tip.rotation).cwiseAbs().maxCoeff(), (pj - j).cwiseAbs().maxCoeff()});
  }
  return most;
}
constexpr double kAgree = 1e-9;
#endif

#ifdef VSD_BENCH_HAVE_MUJOCO
// MuJoCo 2.2 reads URDF itself; told to keep the links hanging from fixed joints as bodies (fusestatic),
// iiwa_link_ee among them.
struct MujocoArm {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  int tip = -1;
  MujocoArm() {
    std::string xml = bare_urdf();
    xml.insert(xml.find('>', xml.find("<robot")) + 1,
               R"(<mujoco><compiler fusestatic="false" discardvisual="true"/></mujoco>)");
    m = vsd_bench::load_mujoco("iiwa14.urdf", xml);
    d = mj_makeData(m);
    tip = mj_name2id(m, mjOBJ_BODY, "iiwa_link_ee");
  }
  MujocoArm(const MujocoArm&) = delete;
  MujocoArm& operator=(const MujocoArm&) = delete;
  ~MujocoArm() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }
  void set(const std::vector<double>& q) const {
    for (int i = 0; i < 7; ++i) d->qpos[i] = q[static_cast<std::size_t>(i)];
  }
  // FK + tip Jacobian: mj_jacBody needs the motion subspaces (cdof) that mj_comPos computes.
  void jacobian(double* jacp, double* jacr) const {
    mj_kinematics(m, d);
    mj_comPos(m, d);
    mj_jacBody(m, d, jacp, jacr, tip);
  }
};

bool mujoco_ok(benchmark::State& state, const MujocoArm& arm) {
  if (arm.m->nq != 7 || arm.m->nv != 7 || arm.tip < 0) {
    state.SkipWithError("MuJoCo's model of the iiwa14 is not the 7-joint chain with iiwa_link_ee");
    return false;
  }
  static const double diff =
      max_difference_from_vsd([&arm](const std::vector<double>& q, Eigen::Isometry3d& pose,
                                     Eigen::Matrix<double, 6, Eigen::Dynamic>& j) {
        double jp[21], jr[21];
        arm.set(q);
        arm.jacobian(jp, jr);
        pose.setIdentity();
        for (int r = 0; r < 3; ++r) {
          pose.translation()[r] = arm.d->xpos[3 * arm.tip + r];
          for (int c = 0; c < 3; ++c) pose.linear()(r, c) = arm.d->xmat[9 * arm.tip + 3 * r + c];
          for (int c = 0; c < 7; ++c) {
            j(r, c) = jp[7 * r + c];
            j(3 + r, c) = jr[7 * r + c];
          }
        }
      });
  state.counters["max_diff_vs_vsd"] = diff;
  if (diff > kAgree) state.SkipWithError("MuJoCo's tip pose or Jacobian differs from vsd's");
  return diff <= kAgree;
}

// Every body of the model (world, the 8 links, iiwa_link_ee and iiwa_link_ee_kuka): frames and inertial
// frames.
void BM_Robotics_Fk_Mujoco(benchmark::State& state) {
  Fixture& f = fixture();
  MujocoArm arm;
  if (!mujoco_ok(state, arm)) return;
  std::size_t i = 0;
  for (auto _ : state) {
    arm.set(f.qs[i++ & 1023]);
    mj_kinematics(arm.m, arm.d);
    benchmark::DoNotOptimize(arm.d->xpos[3 * arm.tip]);
    benchmark::ClobberMemory();
  }
  state.counters["bodies"] = arm.m->nbody;
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Robotics_Fk_Mujoco);

void BM_Robotics_Jacobian_Mujoco(benchmark::State& state) {
  Fixture& f = fixture();
  MujocoArm arm;
  if (!mujoco_ok(state, arm)) return;
  double jp[21], jr[21];
  std::size_t i = 0;
  for (auto _ : state) {
    arm.set(f.qs[i++ & 1023]);
    arm.jacobian(jp, jr);
    benchmark::DoNotOptimize(jp);
    benchmark::DoNotOptimize(jr);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Robotics_Jacobian_Mujoco);
#endif

#ifdef VSD_BENCH_HAVE_DART
// DART 6 through its URDF loader: the world link and its fixed joint become a welded root, 7 DOF.
struct DartArm {
  dart::dynamics::SkeletonPtr skel;
  dart::dynamics::BodyNode* tip = nullptr;
  std::vector<Eigen::VectorXd> qs;
  DartArm() {
    dart::utils::DartLoader loader;
    skel = loader.parseSkeletonString(bare_urdf(), dart::common::Uri("file:///iiwa14.urdf"));
    if (skel == nullptr) throw std::runtime_error("DART could not load the iiwa14");
    tip = skel->getBodyNode("iiwa_link_ee");
    for (const auto& q : fixture().qs) qs.push_back(Eigen::Map<const Eigen::VectorXd>(q.data(), 7));
  }
};

bool dart_ok(benchmark::State& state, DartArm& arm) {
  if (arm.skel->getNumDofs() != 7 || arm.tip == nullptr) {
    state.SkipWithError("DART's model of the iiwa14 is not the 7-joint chain with iiwa_link_ee");
    return false;
  }
  static const double diff =
      max_difference_from_vsd([&arm](const std::vector<double>& q, Eigen::Isometry3d& pose,
                                     Eigen::Matrix<double, 6, Eigen::Dynamic>& j) {
        arm.skel->setPositions(Eigen::Map<const Eigen::VectorXd>(q.data(), 7));
        pose = arm.tip->getWorldTransform();
        const dart::math::Jacobian dj = arm.tip->getWorldJacobian();  // angular rows first
        j.topRows<3>() = dj.bottomRows<3>();
        j.bottomRows<3>() = dj.topRows<3>();
      });
  state.counters["max_diff_vs_vsd"] = diff;
  if (diff > kAgree) state.SkipWithError("DART's tip pose or Jacobian differs from vsd's");
  return diff <= kAgree;
}

// setPositions, then the world transform of every body node (DART computes them lazily, on request).
void BM_Robotics_Fk_Dart(benchmark::State& state) {
  DartArm arm;
  if (!dart_ok(state, arm)) return;
  const std::size_t bodies = arm.skel->getNumBodyNodes();
  std::size_t i = 0;
  for (auto _ : state) {
    arm.skel->setPositions(arm.qs[i++ & 1023]);
    for (std::size_t b = 0; b < bodies; ++b)
      benchmark::DoNotOptimize(arm.skel->getBodyNode(b)->getWorldTransform().translation().data());
    benchmark::ClobberMemory();
  }
  state.counters["bodies"] = static_cast<double>(bodies);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Robotics_Fk_Dart);

// setPositions, then the tip's world Jacobian (which brings the transforms of the bodies above it up to
// date).
void BM_Robotics_Jacobian_Dart(benchmark::State& state) {
  DartArm arm;
  if (!dart_ok(state, arm)) return;
  std::size_t i = 0;
  for (auto _ : state) {
    arm.skel->setPositions(arm.qs[i++ & 1023]);
    benchmark::DoNotOptimize(arm.tip->getWorldJacobian().data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Robotics_Jacobian_Dart);
#endif

// Targets (FK of the random configurations) and nearby seeds, the same for both solvers.
struct IkCase {
  Eigen::Isometry3d target;
  std::vector<double> seed;
};
const std::vector<IkCase>& ik_cases() {
  static const std::vector<IkCase> cases = [] {
    Fixture& f = fixture();
    std::vector<IkCase> out;
    Model::Data d = f.model.make_data();
    std::mt19937_64 rng(99);
    std::normal_distribution<double> noise(0.0, 0.1);
    for (const auto& q : f.qs) {
      f.model.forward(q, d);
      IkCase c{f.model.pose(d, f.model.tip()).isometry(), q};
      for (double& v : c.seed) v += noise(rng);
      f.model.clamp(c.seed.data());
      out.push_back(std::move(c));
    }
    return out;
  }();
  return cases;
}

void report(benchmark::State& state, std::vector<double>& us, std::size_t ok) {
  std::sort(us.begin(), us.end());
  if (!us.empty()) {
    state.counters["median_us"] = us[us.size() / 2];
    state.counters["p99_us"] = us[std::min(us.size() - 1, us.size() * 99 / 100)];
    state.counters["success"] = static_cast<double>(ok) / static_cast<double>(us.size());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(us.size()));
}

void BM_Robotics_Ik_Vsd(benchmark::State& state) {
  Fixture& f = fixture();
  const auto& cases = ik_cases();
  IkSolver ik(f.model, f.model.tip());
  std::vector<double> us;
  std::size_t ok = 0, i = 0;
  for (auto _ : state) {
    const IkCase& c = cases[i++ & 1023];
    const auto t0 = std::chrono::steady_clock::now();
    const IkResult r = ik.solve(c.target, c.seed);
    us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    ok += r.success ? 1 : 0;
    benchmark::DoNotOptimize(r.q.data());
  }
  report(state, us, ok);
}
BENCHMARK(BM_Robotics_Ik_Vsd);

void BM_Robotics_Ik_Kdl(benchmark::State& state) {
  Fixture& f = fixture();
  const auto& cases = ik_cases();
  KDL::ChainIkSolverPos_LMA ik(f.chain);
  KDL::JntArray seed(7), out(7);
  std::vector<double> us;
  std::size_t ok = 0, i = 0;
  for (auto _ : state) {
    const IkCase& c = cases[i++ & 1023];
    for (int j = 0; j < 7; ++j) seed(j) = c.seed[static_cast<std::size_t>(j)];
    KDL::Frame target;
    for (int r = 0; r < 3; ++r) {
      target.p(r) = c.target.translation()[r];
      for (int k = 0; k < 3; ++k) target.M(r, k) = c.target.linear()(r, k);
    }
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = ik.CartToJnt(seed, target, out);
    us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    ok += rc >= 0 ? 1 : 0;
    benchmark::DoNotOptimize(out.data.data());
  }
  report(state, us, ok);
}
BENCHMARK(BM_Robotics_Ik_Kdl);

#ifdef VSD_BENCH_HAVE_DART
// DART's InverseKinematics on the tip, with its defaults but for the DOF (the skeleton's 7), gradient descent
// within the joint limits, solved when every component of the 6D error is within 1e-6 (vsd's tolerances are
// 1e-6 m and 1e-6 rad). Seeded by setting the skeleton's positions; findSolution does not apply the result.
// (MuJoCo has no IK; DART's ikfast plugin needs solver code generated for the robot, which the iiwa14
// does not come with.)
void BM_Robotics_Ik_Dart(benchmark::State& state) {
  DartArm arm;
  if (!dart_ok(state, arm)) return;
  const auto& cases = ik_cases();
  const auto& ik = arm.tip->getIK(true);
  auto target = std::make_shared<dart::dynamics::SimpleFrame>(dart::dynamics::Frame::World(), "target");
  ik->setTarget(target);
  ik->setDofs(std::vector<std::size_t>{0, 1, 2, 3, 4, 5, 6});  // useChain(), the default, finds none here
  Eigen::VectorXd out(7);
  std::vector<double> us;
  std::size_t ok = 0, i = 0;
  for (auto _ : state) {
    const IkCase& c = cases[i++ & 1023];
    arm.skel->setPositions(Eigen::Map<const Eigen::VectorXd>(c.seed.data(), 7));
    target->setTransform(c.target);
    const auto t0 = std::chrono::steady_clock::now();
    const bool solved = ik->findSolution(out);
    us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    // Solved means: its answer puts the tip on the target (checked here, not timed).
    arm.skel->setPositions(out);
    const Eigen::Isometry3d reached = arm.tip->getWorldTransform();
    const bool on_target = (reached.translation() - c.target.translation()).norm() < 1e-5 &&
                           Eigen::AngleAxisd(reached.linear().transpose() * c.target.linear()).angle() < 1e-5;
    ok += solved && on_target ? 1 : 0;
    benchmark::DoNotOptimize(out.data());
  }
  report(state, us, ok);
}
BENCHMARK(BM_Robotics_Ik_Dart);
#endif

}  // namespace

namespace {

// The 8-axis control cycle, each cycle timed on its own (wall time, steady_clock).
void BM_Robotics_ControlCycle8(benchmark::State& state) {
  vsd::Environment env;
  env.use<Module>();
  std::string xml = vsd_test::read_text(std::string(VSD_BENCH_ROBOT_DIR) + "/iiwa14.urdf");
  const std::string fixed = R"(<joint name="world_iiwa_joint" type="fixed">)";
  xml.replace(xml.find(fixed), fixed.size(), R"(<joint name="world_iiwa_joint" type="prismatic">
    <axis xyz="0.6 0.8 0"/><limit lower="-2" upper="3" effort="1000" velocity="1"/>)");
  vsd::scene::UrdfOptions o;
  o.load_meshes = false;
  auto rep = vsd::scene::load_urdf_text(env.main_state().database(), xml, "rail", ".", o);
  KinematicTree& tree = build_kinematics(*rep.scene);
  tree.set_positions(std::vector<double>{0.0, 0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0});
  const Model& model = tree.model();
  const int tip = model.find_body("iiwa_link_ee");
  Model::Data d = model.make_data();
  Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, 8);
  model.forward(tree.positions(), d);
  const Eigen::Vector3d start = model.pose(d, tip).translation;
  std::vector<double> us;
  us.reserve(1 << 20);
  std::size_t k = 0;
  for (auto _ : state) {
    // A target circling the start point, so every cycle commands a real motion.
    const double a = 0.01 * static_cast<double>(k++);
    const Eigen::Vector3d target = start + 0.05 * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0);
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<double> q = tree.positions();  // read
    model.forward(q.data(), d);                // FK
    model.jacobian(d, tip, j);                 // Jacobian
    Eigen::Matrix<double, 6, 1> e = Eigen::Matrix<double, 6, 1>::Zero();
    e.head<3>() = target - model.pose(d, tip).translation;
    Eigen::Matrix<double, 6, 6> jj = j * j.transpose();
    jj.diagonal().array() += 1e-4;
    const Eigen::Matrix<double, 8, 1> dq = j.transpose() * jj.llt().solve(0.1 * e);
    for (std::size_t i = 0; i < 8; ++i) q[i] += dq[static_cast<Eigen::Index>(i)];
    model.clamp(q.data());
    tree.set_positions(q);  // command
    us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(us.begin(), us.end());
  if (!us.empty()) {
    state.counters["p50_us"] = us[us.size() / 2];
    state.counters["p99_us"] = us[std::min(us.size() - 1, us.size() * 99 / 100)];
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Robotics_ControlCycle8);

}  // namespace
