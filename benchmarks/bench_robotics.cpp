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
