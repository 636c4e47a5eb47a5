// vsd::physics against physics, not against itself: free fall, pendulum periods (of bodies, and of a URDF
// link with and without a collision hull), Coulomb friction, restitution, energy and momentum, each
// compared with its closed form. Every tolerance is derived from the integrator (ODE's semi-implicit
// Euler: v += h a, then x += h v) and the step h, as explained where it is used.
#include <gmock/gmock.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "fixture.hpp"

namespace vsd::physics::test {
namespace {

using scene::GeometryKind;
constexpr double g = 9.81;
constexpr double h = 0.001;  // ODE step; the scheduler steps once per ODE step below

class ClosedFormTest : public PhysicsTest {
 public:
  ClosedFormTest() {
    env.scheduler().set_base_step(h);
    world->set_step(h);
  }
  void run(int steps) {
    for (int i = 0; i < steps; ++i) env.step();
  }
};

// Complete elliptic integral of the first kind K(k) by the arithmetic-geometric mean.
double elliptic_k(double k) {
  double a = 1.0;
  double b = std::sqrt(1.0 - k * k);
  for (int i = 0; i < 30; ++i) {
    const double an = (a + b) / 2;
    b = std::sqrt(a * b);
    a = an;
  }
  return M_PI / (2 * a);
}

TEST_F(ClosedFormTest, FreeFallFollowsTheExactDiscreteFormAndTheParabolaWithinGHT2) {
  auto& ball = hull(geometry(GeometryKind::Sphere, Eigen::Vector3d::Zero(), 0.1), at(0, 0, 100));
  auto& rb = body(ball);
  const double z0 = 100.0;
  for (int n = 1; n <= 2000; ++n) {
    env.step();
    if (n % 250 != 0) continue;
    const double t = n * h;
    const double z = ball.frame().translation().z();
    // Semi-implicit Euler from rest: v_n = -g n h, z_n = z0 - g h^2 n (n + 1) / 2 — exactly, up to rounding.
    const double discrete = z0 - g * h * h * n * (n + 1) / 2.0;
    EXPECT_NEAR(z, discrete, 1e-9) << "step " << n;
    EXPECT_NEAR(rb.linear_velocity().z(), -g * n * h, 1e-9) << "step " << n;
    // Against the continuous h0 - g t^2/2 the scheme is ahead by exactly g h t / 2 (first order in h).
    const double continuous = z0 - g * t * t / 2.0;
    EXPECT_NEAR(continuous - z, g * h * t / 2.0, 1e-9) << "step " << n;
  }
}

struct Pendulum {
  double length = 1.0;  // pivot to the bob's centre
  double radius = 0.05;
  double period = 0.0;    // measured
  double expected = 0.0;  // closed form
  double energy_drift = 0.0;
};

// A sphere on a massless rod (a hinge about y at distance L from its centre), released from theta0.
Pendulum swing(ClosedFormTest& t, PhysicsTest& p, double theta0, int periods) {
  Pendulum r;
  p.world->set_solver(Solver::Exact);
  auto& geo = p.geometry(GeometryKind::Sphere, Eigen::Vector3d::Zero(), r.radius);
  // The pivot is at the origin; the bob hangs at angle theta0 from the downward vertical in the x-z plane.
  Eigen::Isometry3d f = at(r.length * std::sin(theta0), 0, -r.length * std::cos(theta0));
  auto& bob = p.hull(geo, f, nullptr, nullptr, "bob");
  auto& rb = p.body(bob);
  auto& hinge = p.s.create<Joint>();
  hinge.set_kind(JointKind::Hinge);
  hinge.set_axis(Eigen::Vector3d::UnitY());
  hinge.set_anchor(-f.translation());  // the origin, in the bob's frame (no rotation)
  bob.add_extension(hinge);
  p.sim().sync();
  const double m = p.sim().mass_of(rb).mass;
  const double ic = p.sim().mass_of(rb).inertia(1, 1);  // 2/5 m r^2
  // Physical pendulum: I about the pivot = m L^2 + I_c; equivalent simple length L_eq = I / (m L);
  // period 4 sqrt(L_eq / g) K(sin(theta0 / 2)) at any amplitude (2 pi sqrt(L_eq / g) in the limit).
  const double l_eq = (m * r.length * r.length + ic) / (m * r.length);
  r.expected = 4.0 * std::sqrt(l_eq / g) * elliptic_k(std::sin(theta0 / 2));
  auto energy = [&] {
    const Eigen::Vector3d x = bob.world_frame().translation();
    return 0.5 * m * rb.linear_velocity().squaredNorm() + 0.5 * ic * rb.angular_velocity().squaredNorm() +
           m * g * x.z();
  };
  const double e0 = energy();
  // Upward crossings of x = 0 (the bottom), linearly interpolated between steps.
  std::vector<double> crossings;
  double prev = bob.world_frame().translation().x();
  const double t_end = periods * r.expected + 1.0;
  for (int n = 1; n * h < t_end; ++n) {
    t.run(1);
    const double x = bob.world_frame().translation().x();
    if (prev < 0.0 && x >= 0.0) crossings.push_back((n - 1 + (-prev) / (x - prev)) * h);
    prev = x;
    r.energy_drift =
        std::max(r.energy_drift, std::abs(energy() - e0) / (m * g * r.length * (1 - std::cos(theta0))));
  }
  if (crossings.size() >= 2)
    r.period = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  return r;
}

TEST_F(ClosedFormTest, PendulumPeriodAtSmallAmplitude) {
  const double theta0 = 0.05;  // 2.9 degrees
  const Pendulum p = swing(*this, *this, theta0, 5);
  ASSERT_GT(p.period, 0.0);
  // Tolerance: symplectic Euler's frequency error for an oscillator is (omega h)^2 / 24 ~ 4e-7 relative;
  // crossings are interpolated where the motion is nearly linear (error O(h^2 omega^2 theta0) of one
  // crossing, divided by the periods averaged); ODE's constraint correction (ERP, CFM 1e-9) keeps the rod
  // length to ~1e-9 m. 1e-4 relative leaves a wide margin over all three.
  EXPECT_NEAR(p.period / p.expected, 1.0, 1e-4);
  // The small-angle form 2 pi sqrt(L_eq / g) is within theta0^2 / 16 = 1.6e-4 of the exact one.
  EXPECT_GT(p.expected, 2 * M_PI * std::sqrt((1.0 + 2 * 0.05 * 0.05 / 5) / g));
  EXPECT_LT(p.expected / (2 * M_PI * std::sqrt((1.0 + 2 * 0.05 * 0.05 / 5) / g)) - 1.0,
            theta0 * theta0 / 16 * 1.01);
  // Energy: symplectic Euler keeps it bounded (oscillating by O(omega h) of the swing energy).
  EXPECT_LT(p.energy_drift, 0.01);
}

TEST_F(ClosedFormTest, PendulumPeriodAtLargeAmplitudeFollowsTheEllipticIntegral) {
  const double theta0 = 2.0;  // 115 degrees: 1.36 times the small-angle period
  const Pendulum p = swing(*this, *this, theta0, 3);
  ASSERT_GT(p.period, 0.0);
  EXPECT_GT(p.expected / (2 * M_PI * std::sqrt(1.001 / g)), 1.3);
  // Same error sources as at small amplitude; the speed at the bottom (and so the interpolation and
  // constraint errors per step) is ~40 times larger: 1e-3 relative.
  EXPECT_NEAR(p.period / p.expected, 1.0, 1e-3);
  EXPECT_LT(p.energy_drift, 0.01);
}

// A URDF pendulum: a massless base fixed in space, a link whose <inertial> is a small sphere of mass m at
// distance L below the pivot (a continuous joint about y), started theta0 off its rest. A collision hull
// of a quite different body (a rod from the pivot to the bob, of its own density) must not change the
// swing: the URDF's inertial is what the link is, the hull only collides.
std::string urdf_pendulum(double theta0, bool hull) {
  const double m = 2.0, r = 0.05, L = 1.0;
  const double ic = 0.4 * m * r * r;
  std::ostringstream x;
  x << "<robot name=\"pendulum\"><link name=\"base\"/><link name=\"bob\"><inertial><origin xyz=\""
    << L * std::sin(theta0) << " 0 " << -L * std::cos(theta0) << "\"/><mass value=\"" << m
    << "\"/><inertia ixx=\"" << ic << "\" iyy=\"" << ic << "\" izz=\"" << ic
    << "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
  if (hull)
    x << "<collision><origin xyz=\"" << 0.5 * L * std::sin(theta0) << " 0 " << -0.5 * L * std::cos(theta0)
      << "\" rpy=\"0 " << theta0 << " 0\"/><geometry><box size=\"0.1 0.1 " << L << "\"/></geometry></collision>";
  x << "</link><joint name=\"pivot\" type=\"continuous\"><parent link=\"base\"/><child link=\"bob\"/>"
       "<axis xyz=\"0 1 0\"/></joint></robot>";
  return x.str();
}

TEST_F(ClosedFormTest, UrdfPendulumSwingsWithItsInertialWithOrWithoutAHull) {
  const double theta0 = 0.05, m = 2.0, L = 1.0, ic = 0.4 * m * 0.05 * 0.05;
  const double expected = 4.0 * std::sqrt((m * L * L + ic) / (m * L) / g) * elliptic_k(std::sin(theta0 / 2));
  for (bool with_hull : {false, true}) {
    SCOPED_TRACE(with_hull ? "with a hull" : "without a hull");
    vsd::Environment e;
    e.use<Module>();
    e.scheduler().set_base_step(h);
    auto r = scene::load_urdf_text(e.main_state().database(), urdf_pendulum(theta0, with_hull), "p.urdf", ".");
    ASSERT_TRUE(r.warnings.empty()) << r.warnings[0];
    ASSERT_EQ(make_dynamic(*r.scene), 1u);
    r.scene->find_extension<World>()->set_solver(Solver::Exact);  // as the pendulums above
    Joint* pivot = r.scene->find_link("bob")->find_extension<Joint>();
    RigidBody* rb = r.scene->find_link("bob")->find_extension<RigidBody>();
    ASSERT_TRUE(pivot != nullptr && rb != nullptr);
    Simulation& sim = e.module<Module>()->simulation();
    sim.sync();
    EXPECT_EQ(sim.stats().geoms, with_hull ? 1u : 0u);
    EXPECT_DOUBLE_EQ(sim.mass_of(*rb).mass, m);
    EXPECT_NEAR(sim.mass_of(*rb).inertia(1, 1), ic, 1e-15);
    // Turning points (the rate changes sign from + to -): one per period, linearly interpolated.
    std::vector<double> turns;
    double prev = 0.0;
    for (int n = 1; n * h < 4 * expected + 0.5; ++n) {
      e.step();
      const double rate = pivot->rate();
      if (prev > 0.0 && rate <= 0.0) turns.push_back((n - 1 + prev / (prev - rate)) * h);
      prev = rate;
    }
    ASSERT_GE(turns.size(), 3u);
    const double period = (turns.back() - turns.front()) / static_cast<double>(turns.size() - 1);
    // The tolerance of PendulumPeriodAtSmallAmplitude (1e-4 relative covers the integrator's frequency
    // error and the interpolation); the rod of the hull alone would give sqrt(2/3) of the period.
    EXPECT_NEAR(period / expected, 1.0, 1e-4);
  }
}

TEST_F(ClosedFormTest, SlidingBoxStopsAfterVSquaredOverTwoMuG) {
  world->set_solver(Solver::Exact);
  const double mu = 0.5;
  auto& mat = material(mu, 0.0);
  ground(&mat);
  auto& box = hull(geometry(GeometryKind::Box, Eigen::Vector3d(0.2, 0.2, 0.2)), at(0, 0, 0.1), &mat);
  auto& rb = body(box);
  run(200);  // settle on the ground
  ASSERT_NEAR(box.frame().translation().z(), 0.1, 0.001);
  const double v0 = 2.0;
  rb.set_linear_velocity(Eigen::Vector3d(v0, 0, 0));
  const double x0 = box.frame().translation().x();
  run(1000);  // 1 s, the stop comes after v0 / (mu g) = 0.41 s
  EXPECT_NEAR(rb.linear_velocity().norm(), 0.0, 1e-3);
  const double d = box.frame().translation().x() - x0;
  const double expected = v0 * v0 / (2 * mu * g);  // 0.408 m
  // Discretely the box moves h v_{k+1} per step with v losing mu g h per step: it stops within one step
  // of the continuous stop, so the distance differs by at most v0 h (2 mm) plus the contact's settling.
  EXPECT_NEAR(d, expected, v0 * h + 1e-3);
  EXPECT_NEAR(box.frame().translation().y(), 0.0, 1e-6);  // friction acts against the motion only
}

// A box on a plane tilted by alpha about y; returns the distance slid down the slope in @p seconds.
double slide_on_incline(ClosedFormTest& t, PhysicsTest& p, double alpha, double mu, double seconds) {
  auto& mat = p.material(mu, 0.0);
  Eigen::Isometry3d tilt = Eigen::Isometry3d::Identity();
  tilt.rotate(Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitY()));
  auto& plane = p.geometry(GeometryKind::Plane);
  p.hull(plane, tilt, &mat, nullptr, "incline");
  Eigen::Isometry3d f = tilt;
  f.translate(Eigen::Vector3d(0, 0, 0.1 - 0.0004));  // resting, sunk into the surface layer
  auto& box = p.hull(p.geometry(GeometryKind::Box, Eigen::Vector3d(0.2, 0.2, 0.2)), f, &mat, nullptr, "box");
  p.body(box);
  const Eigen::Vector3d start = box.world_frame().translation();
  t.run(static_cast<int>(seconds / h));
  // Downhill along the plane: the x axis of the tilted frame, pointing down for alpha > 0.
  const Eigen::Vector3d downhill = tilt.rotation() * Eigen::Vector3d::UnitX();
  return (box.world_frame().translation() - start).dot(downhill);
}

TEST_F(ClosedFormTest, BoxRestsOnAnInclineBelowTheFrictionAngle) {
  world->set_solver(Solver::Exact);
  const double mu = 0.5;  // friction angle atan(0.5) = 26.6 degrees
  const double s = slide_on_incline(*this, *this, 20.0 * M_PI / 180, mu, 2.0);
  // Static friction holds: no creep beyond the settling of the contact (sub-millimetre).
  EXPECT_LT(std::abs(s), 1e-3);
}

TEST_F(ClosedFormTest, BoxSlidesAboveTheFrictionAngleWithGTimesSinMinusMuCos) {
  world->set_solver(Solver::Exact);
  const double mu = 0.5;
  const double alpha = 35.0 * M_PI / 180;
  const double seconds = 1.0;
  const double s = slide_on_incline(*this, *this, alpha, mu, seconds);
  const double a = g * (std::sin(alpha) - mu * std::cos(alpha));  // 1.61 m/s^2
  // Constant acceleration from rest: a t^2 / 2, and the discrete scheme is ahead by a h t / 2 (as in free
  // fall); allow that plus 1% for the first steps, when the contact settles.
  EXPECT_NEAR(s, a * seconds * seconds / 2, a * h * seconds / 2 + 0.01 * a * seconds * seconds / 2);
}

TEST_F(ClosedFormTest, BounceReachesESquaredTimesTheDropHeight) {
  world->set_solver(Solver::Exact);
  const double e = 0.8;
  const double r = 0.1;
  const double drop = 1.0;  // from the ball's bottom to the ground
  ground();                 // no material: restitution 0, the ball's e decides (larger of the two)
  auto& ball =
      hull(geometry(GeometryKind::Sphere, Eigen::Vector3d::Zero(), r), at(0, 0, drop + r), &material(0.5, e));
  auto& rb = body(ball);
  bool fell = false;
  double peak = 0.0;
  for (int n = 0; n < 2000; ++n) {
    env.step();
    const double z = ball.frame().translation().z() - r;
    if (rb.linear_velocity().z() > 0.0) fell = true;
    if (fell) peak = std::max(peak, z);
  }
  ASSERT_TRUE(fell);
  const double v_in = std::sqrt(2 * g * drop);  // 4.43 m/s
  // ODE's bounce makes the outgoing normal velocity exactly e times the incoming one. The ball is found
  // in contact up to one step late (it has sunk by up to v_in h) and its incoming velocity is off by up to
  // g h: the peak is off by at most v_in h + 2 e^2 drop (g h / v_in), about 7 mm.
  const double tol = v_in * h + 2 * e * e * drop * g * h / v_in;
  EXPECT_NEAR(peak, e * e * drop, tol);
}

TEST_F(ClosedFormTest, ElasticCollisionConservesMomentumAndEnergy) {
  world->set_solver(Solver::Exact);
  world->set_gravity(Eigen::Vector3d::Zero());
  auto& bouncy = material(0.0, 1.0);
  auto& a = hull(geometry(GeometryKind::Sphere, Eigen::Vector3d::Zero(), 0.1), at(-0.5, 0, 0), &bouncy,
                 nullptr, "a");
  auto& b = hull(geometry(GeometryKind::Sphere, Eigen::Vector3d::Zero(), 0.15), at(0.5, 0, 0), &bouncy,
                 nullptr, "b");
  auto& ra = body(a);
  auto& rbb = body(b);
  ra.set_linear_velocity(Eigen::Vector3d(1, 0, 0));
  rbb.set_linear_velocity(Eigen::Vector3d(-1, 0, 0));
  sim().sync();
  const double ma = sim().mass_of(ra).mass;
  const double mb = sim().mass_of(rbb).mass;
  const Eigen::Vector3d p0 = ma * ra.linear_velocity() + mb * rbb.linear_velocity();
  const double e0 =
      0.5 * ma * ra.linear_velocity().squaredNorm() + 0.5 * mb * rbb.linear_velocity().squaredNorm();
  run(1000);
  const Eigen::Vector3d p1 = ma * ra.linear_velocity() + mb * rbb.linear_velocity();
  const double e1 =
      0.5 * ma * ra.linear_velocity().squaredNorm() + 0.5 * mb * rbb.linear_velocity().squaredNorm();
  // Contact impulses are equal and opposite: momentum is kept to the solver's rounding.
  EXPECT_LT((p1 - p0).norm(), 1e-9 * (ma + mb));
  // Head-on, e = 1: the closed form of the elastic collision, and the kinetic energy kept. The bounce
  // reverses the relative velocity exactly; the penetration correction may add up to the contact's
  // max correcting velocity times the depth-to-velocity ratio of one step — 1% covers it.
  const double va = ((ma - mb) * 1.0 + 2 * mb * -1.0) / (ma + mb);
  const double vb = ((mb - ma) * -1.0 + 2 * ma * 1.0) / (ma + mb);
  EXPECT_NEAR(ra.linear_velocity().x(), va, 0.01 * std::abs(va) + 1e-3);
  EXPECT_NEAR(rbb.linear_velocity().x(), vb, 0.01 * std::abs(vb) + 1e-3);
  EXPECT_NEAR(e1 / e0, 1.0, 0.02);
}

}  // namespace
}  // namespace vsd::physics::test
