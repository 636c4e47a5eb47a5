// The compiled model against Orocos KDL (FK and Jacobians, to 1e-9), against finite differences, and
// against the database's own link frames; DH chains against their equivalent URDF chains.
#include "vsd/robotics/model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <initializer_list>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <limits>
#include <numbers>
#include <random>
#include <span>

#include "kdl_chain.hpp"
#include "test_util.hpp"
#include "vsd/robotics.hpp"
#include "vsd/robotics/detail/sincos.hpp"

namespace vsd::robotics {
namespace {

using vsd_test::kdl_chain;
using vsd_test::random_q;
using vsd_test::read_text;
using vsd_test::robot_file;

struct Loaded {
  Environment env;
  scene::Scene* scene = nullptr;
  KinematicTree* tree = nullptr;
  explicit Loaded(const std::string& xml) {
    env.use<Module>();
    scene::UrdfOptions o;
    o.load_meshes = false;
    scene = scene::load_urdf_text(env.main_state().database(), xml, "test.urdf", ".", o).scene;
    tree = &build_kinematics(*scene);
  }
  Model chain(const std::string& base, const std::string& tip) const {
    auto node = [&](const std::string& n) -> scene::Node3D* {
      if (n == scene->name()) return scene;
      return scene->find_link(n);
    };
    return Model::compile(*node(base), node(tip));
  }
};

// FK and Jacobian of the chain base -> tip against KDL for @p count random configurations.
void compare_with_kdl(const std::string& xml, const std::string& base, const std::string& tip, int count) {
  Loaded robot(xml);
  const Model model = robot.chain(base, tip);
  const KDL::Chain chain = kdl_chain(xml, base, tip);
  ASSERT_EQ(static_cast<int>(chain.getNrOfJoints()), model.dof());
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainJntToJacSolver jac(chain);
  KDL::JntArray q_kdl(chain.getNrOfJoints());
  KDL::Jacobian j_kdl(chain.getNrOfJoints());
  Model::Data data = model.make_data();
  Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, model.dof());
  std::mt19937_64 rng(42);
  double worst_fk = 0, worst_jac = 0;
  for (int n = 0; n < count; ++n) {
    const std::vector<double> q = random_q(model, rng);
    for (int i = 0; i < model.dof(); ++i) q_kdl(i) = q[static_cast<std::size_t>(i)];
    KDL::Frame f;
    ASSERT_GE(fk.JntToCart(q_kdl, f), 0);
    ASSERT_GE(jac.JntToJac(q_kdl, j_kdl), 0);
    model.forward(q, data);
    model.jacobian(data, model.tip(), j);
    const Frame& mine = model.pose(data, model.tip());
    for (int r = 0; r < 3; ++r) {
      worst_fk = std::max(worst_fk, std::abs(mine.translation[r] - f.p(r)));
      for (int c = 0; c < 3; ++c) worst_fk = std::max(worst_fk, std::abs(mine.rotation(r, c) - f.M(r, c)));
    }
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < model.dof(); ++c) worst_jac = std::max(worst_jac, std::abs(j(r, c) - j_kdl(r, c)));
  }
  EXPECT_LT(worst_fk, 1e-9) << base << " -> " << tip;
  EXPECT_LT(worst_jac, 1e-9) << base << " -> " << tip;
}

TEST(ModelVsKdl, Iiwa14ForwardKinematicsAndJacobian) {
  compare_with_kdl(read_text(robot_file("iiwa14.urdf")), "iiwa_link_0", "iiwa_link_ee", 1000);
  compare_with_kdl(read_text(robot_file("iiwa14.urdf")), "world", "iiwa_link_4", 200);
}

TEST(ModelVsKdl, Ur5ForwardKinematicsAndJacobian) {
  compare_with_kdl(read_text(robot_file("ur5_robot.urdf")), "base_link", "tool0", 1000);
  compare_with_kdl(read_text(robot_file("ur5_robot.urdf")), "world", "ee_link", 200);
}

// The paper's work cell: a 7-axis arm on a linear axis (the first joint prismatic).
std::string iiwa_on_linear_axis() {
  std::string xml = read_text(robot_file("iiwa14.urdf"));
  const std::string fixed = R"(<joint name="world_iiwa_joint" type="fixed">)";
  const auto at = xml.find(fixed);
  EXPECT_NE(at, std::string::npos);
  xml.replace(at, fixed.size(), R"(<joint name="world_iiwa_joint" type="prismatic">
    <axis xyz="0.6 0.8 0"/><limit lower="-2" upper="3" effort="1000" velocity="1"/>)");
  return xml;
}

TEST(ModelVsKdl, ArmOnALinearAxis) {
  const std::string xml = iiwa_on_linear_axis();
  compare_with_kdl(xml, "world", "iiwa_link_ee", 1000);
  Loaded robot(xml);
  const Model m = robot.chain("world", "iiwa_link_ee");
  ASSERT_EQ(m.dof(), 8);
  EXPECT_EQ(m.layout()[0].name, "world_iiwa_joint");
  EXPECT_EQ(m.layout()[0].type, KinematicJointType::Prismatic);
  EXPECT_EQ(m.layout()[0].lower, -2.0);
}

// The database's link frames (moved by joint values) agree with the compiled model.
TEST(Model, AgreesWithTheDatabaseFrames) {
  Loaded robot(read_text(robot_file("ur5_robot.urdf")));
  const Model& m = robot.tree->model();
  std::mt19937_64 rng(7);
  Model::Data data = m.make_data();
  int checked = 0;
  for (int n = 0; n < 20; ++n) {
    const std::vector<double> q = random_q(m, rng);
    robot.tree->set_positions(q);
    m.forward(q, data);
    for (int b = 0; b < m.body_count(); ++b) {
      const scene::Link* l = robot.scene->find_link(m.body_name(b));
      if (l == nullptr) continue;  // hulls are bodies too (fixed at their frames); links are checked here
      ++checked;
      const Eigen::Isometry3d rel = robot.scene->world_frame().inverse() * l->world_frame();
      EXPECT_TRUE(rel.matrix().isApprox(m.pose(data, b).isometry().matrix(), 1e-12)) << m.body_name(b);
    }
  }
  EXPECT_EQ(checked, 20 * static_cast<int>(robot.scene->links().size()));  // every link
}

// A tree with a universal joint and a mimic joint, against finite differences of its own FK.
std::vector<JointSpec> tree_specs() {
  std::vector<JointSpec> s(5);
  s[0].name = "slide";
  s[0].body = "carriage";
  s[0].type = KinematicJointType::Prismatic;
  s[0].placement.axis = Eigen::Vector3d(1, 1, 0);
  s[1].name = "wrist";
  s[1].body = "hand";
  s[1].parent = 0;
  s[1].type = KinematicJointType::Universal;
  s[1].placement.pre = Eigen::Translation3d(0, 0, 0.4) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX());
  s[1].placement.axis = Eigen::Vector3d::UnitX();
  s[1].axis2 = Eigen::Vector3d(0, 1, 1);
  s[1].placement.post = Eigen::Isometry3d(Eigen::Translation3d(0.1, 0, 0.05));
  s[2].name = "finger_a";
  s[2].body = "finger_a";
  s[2].parent = 1;
  s[2].placement.pre = Eigen::Isometry3d(Eigen::Translation3d(0, 0.05, 0.1));
  s[2].placement.axis = Eigen::Vector3d::UnitY();
  s[3].name = "finger_b";
  s[3].body = "finger_b";
  s[3].parent = 1;
  s[3].placement.pre = Eigen::Isometry3d(Eigen::Translation3d(0, -0.05, 0.1));
  s[3].placement.axis = Eigen::Vector3d(0.2, -1, 0.1);
  s[3].mimic = 2;
  s[3].mimic_multiplier = -0.5;
  s[3].mimic_offset = 0.1;
  s[4].name = "tip_b";
  s[4].body = "tip_b";
  s[4].parent = 3;
  s[4].type = KinematicJointType::Fixed;
  s[4].placement.pre = Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.08));
  return s;
}

TEST(Model, LayoutOfUniversalAndMimicJoints) {
  const Model m = Model::build(tree_specs());
  ASSERT_EQ(m.dof(), 4);  // slide, wrist, wrist#2, finger_a; finger_b follows finger_a
  EXPECT_EQ(m.layout()[0].name, "slide");
  EXPECT_EQ(m.layout()[1].name, "wrist");
  EXPECT_EQ(m.layout()[2].name, "wrist#2");
  EXPECT_EQ(m.layout()[3].name, "finger_a");
  EXPECT_EQ(m.body_count(), 5);
  EXPECT_EQ(m.find_body("tip_b"), 4);
  EXPECT_EQ(m.find_body("nothing"), -1);
}

TEST(Model, JacobianMatchesFiniteDifferences) {
  const Model m = Model::build(tree_specs());
  Model::Data d = m.make_data(), d2 = m.make_data();
  Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, m.dof());
  std::mt19937_64 rng(3);
  for (int n = 0; n < 50; ++n) {
    std::vector<double> q = random_q(m, rng);
    m.forward(q, d);
    for (int body = 0; body < m.body_count(); ++body) {
      m.jacobian(d, body, j);
      const Frame f0 = m.pose(d, body);
      for (int c = 0; c < m.dof(); ++c) {
        const double h = 1e-6;
        std::vector<double> qh = q;
        qh[static_cast<std::size_t>(c)] += h;
        m.forward(qh, d2);
        const Frame& f1 = m.pose(d2, body);
        const Eigen::Vector3d v = (f1.translation - f0.translation) / h;
        const Eigen::AngleAxisd w(f1.rotation * f0.rotation.transpose());
        const Eigen::Vector3d omega = w.angle() * w.axis() / h;
        EXPECT_LT((j.col(c).head<3>() - v).norm(), 1e-5) << "body " << body << " column " << c;
        EXPECT_LT((j.col(c).tail<3>() - omega).norm(), 1e-5) << "body " << body << " column " << c;
      }
    }
  }
}

TEST(Model, MimicJointFollowsItsMaster) {
  const Model m = Model::build(tree_specs());
  Model::Data d = m.make_data();
  m.forward(std::vector<double>{0.2, 0.1, -0.3, 0.8}, d);
  EXPECT_DOUBLE_EQ(d.value[4],
                   -0.5 * 0.8 + 0.1);  // segments: slide, wrist, wrist#2, finger_a, finger_b, tip_b
}

TEST(Model, BadSpecificationsAreErrors) {
  auto specs = tree_specs();
  specs[2].placement.axis = Eigen::Vector3d::Zero();
  EXPECT_THROW((void)Model::build(specs), vsd::Error);
  specs = tree_specs();
  specs[0].has_limits = true;
  specs[0].lower = 1;
  specs[0].upper = -1;
  EXPECT_THROW((void)Model::build(specs), vsd::Error);
  specs = tree_specs();
  specs[2].parent = 7;
  EXPECT_THROW((void)Model::build(specs), vsd::Error);
  specs = tree_specs();
  specs[2].mimic = 3;  // 2 -> 3 -> 2
  EXPECT_THROW((void)Model::build(specs), vsd::Error);
  specs = tree_specs();
  specs[3].mimic = 4;  // a fixed master
  EXPECT_THROW((void)Model::build(specs), vsd::Error);
  const Model m = Model::build(tree_specs());
  Model::Data d = m.make_data();
  EXPECT_THROW(m.forward(std::vector<double>{1, 2}, d), vsd::Error);
}

// A chain from a link to itself has no joints and no bodies: its FK is the base (tip() is -1). Before,
// pose(tip()) read before the start of the model's arrays.
TEST(Model, AChainOfNoJointsHasTheBaseAsItsPose) {
  Loaded robot(read_text(robot_file("iiwa14.urdf")));
  const Model same = robot.chain("iiwa_link_3", "iiwa_link_3");
  EXPECT_EQ(same.dof(), 0);
  EXPECT_EQ(same.body_count(), 0);
  EXPECT_EQ(same.tip(), -1);
  Model::Data d = same.make_data();
  same.forward(std::vector<double>{}, d);
  EXPECT_TRUE(same.pose(d, same.tip()).rotation.isIdentity(0.0));
  EXPECT_TRUE(same.pose(d, same.tip()).translation.isZero(0.0));
  Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, 0);
  same.jacobian(d, same.tip(), j);
  // Through fixed joints only: no values, one body at the fixed joint's origin (0.045 m along z).
  const Model fixed = robot.chain("iiwa_link_7", "iiwa_link_ee");
  EXPECT_EQ(fixed.dof(), 0);
  Model::Data df = fixed.make_data();
  fixed.forward(std::vector<double>{}, df);
  EXPECT_TRUE(fixed.pose(df, fixed.tip()).translation.isApprox(Eigen::Vector3d(0, 0, 0.045)));
}

// `vsd-robot fk` printed [inf, inf, inf]: finite origins and values can overflow (two origins of 1e308 m).
// The checked forward() says so, naming the body; values that are not finite are refused before, and so
// are non-finite origins, axes, limits and mimic factors when a model is built.
TEST(Model, NonFiniteInputsAndOverflowingPosesAreErrors) {
  const std::string far = R"(<robot name="far"><link name="a"/><link name="b"/><link name="c"/>
  <joint name="j1" type="revolute"><parent link="a"/><child link="b"/><origin xyz="1e308 1e308 1e308"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="prismatic"><parent link="b"/><child link="c"/><origin xyz="1e308 1e308 1e308"/>
    <axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>)";
  Loaded robot(far);
  const Model m = robot.chain("a", "c");
  Model::Data d = m.make_data();
  try {
    m.forward(std::vector<double>{0, 0}, d);
    FAIL();
  } catch (const vsd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("the pose of body 'c' is not finite"), std::string::npos) << e.what();
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  try {
    m.forward(std::vector<double>{0, nan}, d);
    FAIL();
  } catch (const vsd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("the value of 'j2' is not finite"), std::string::npos) << e.what();
  }
  const double inf = std::numeric_limits<double>::infinity();
  auto specs = tree_specs();
  specs[1].placement.pre.translation().x() = inf;
  EXPECT_THROW((void)Model::build(specs), vsd::Error);
  specs = tree_specs();
  specs[0].has_limits = true;
  specs[0].lower = -inf;
  specs[0].upper = 1;
  EXPECT_THROW((void)Model::build(specs), vsd::Error);
  specs = tree_specs();
  specs[3].mimic_multiplier = nan;
  EXPECT_THROW((void)Model::build(specs), vsd::Error);
}

TEST(Model, TipNotBelowBaseIsAnError) {
  Loaded robot(read_text(robot_file("ur5_robot.urdf")));
  try {
    (void)robot.chain("tool0", "base_link");
    FAIL() << "no error";
  } catch (const vsd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("'base_link' is not below 'tool0'"), std::string::npos) << e.what();
  }
}

// A tree of joints j0, j1, ... below @p parents (-1: a root), each after a random origin (on the x-z plane
// for even i), rotating about axes[i % axes.size()], but j6 fixed and j8 prismatic.
std::vector<JointSpec> random_tree(std::initializer_list<int> parents, std::span<const Eigen::Vector3d> axes,
                                   std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::vector<JointSpec> specs;
  int i = 0;
  for (const int parent : parents) {
    JointSpec s;
    s.name = s.body = "j" + std::to_string(i);
    s.parent = parent;
    s.type = i == 6   ? KinematicJointType::Fixed
             : i == 8 ? KinematicJointType::Prismatic
                      : KinematicJointType::Rotary;
    s.placement.pre = Eigen::Translation3d(u(rng), i % 2 == 0 ? 0.0 : u(rng), u(rng)) *
                      Eigen::AngleAxisd(u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized());
    s.placement.axis = axes[static_cast<std::size_t>(i) % axes.size()];
    specs.push_back(s);
    ++i;
  }
  return specs;
}

// Joint values in (-6, 6), beyond the limits random_q() keeps to.
std::vector<double> random_angles(const Model& m, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::vector<double> q(static_cast<std::size_t>(m.dof()));
  for (double& v : q) v = 3.0 * u(rng);
  return q;
}

// The fast form (a rotation about x, y or z after a general origin; the parent's product kept in
// registers when it is the previous segment) against the plain composition parent * pre * R(axis, v),
// on a tree: chained segments, a branch back to an earlier body, fixed and prismatic segments between.
TEST(Model, CoordinateAxisJointsMatchThePlainComposition) {
  const Eigen::Vector3d axes[3] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                   Eigen::Vector3d::UnitZ()};
  std::mt19937_64 rng(99);
  const std::vector<JointSpec> specs = random_tree({-1, 0, 1, 2, 1, 4, 5, 3, 7, 0}, axes, rng);
  const Model m = Model::build(specs);
  Model::Data d = m.make_data();
  for (int trial = 0; trial < 20; ++trial) {
    const std::vector<double> q = random_angles(m, rng);
    m.forward(q, d);
    std::vector<Eigen::Isometry3d> want;
    int k = 0;
    for (int i = 0; i < 10; ++i) {
      const JointSpec& s = specs[static_cast<std::size_t>(i)];
      Eigen::Isometry3d local = s.placement.pre;
      if (s.type == KinematicJointType::Rotary)
        local = local * Eigen::AngleAxisd(q[static_cast<std::size_t>(k++)], s.placement.axis);
      else if (s.type == KinematicJointType::Prismatic)
        local = local * Eigen::Translation3d(q[static_cast<std::size_t>(k++)] * s.placement.axis);
      want.push_back(s.parent < 0 ? local : want[static_cast<std::size_t>(s.parent)] * local);
      const Frame& got = m.pose(d, i);
      EXPECT_TRUE(got.rotation.isApprox(want.back().linear(), 1e-12)) << "body " << i;
      EXPECT_LT((got.translation - want.back().translation()).norm(), 1e-12) << "body " << i;
    }
  }
}

// ---- DH ------------------------------------------------------------------------------------------------

// UR5's published DH table (standard convention).
std::vector<DhJoint> ur5_dh() {
  const double pi2 = std::numbers::pi / 2;
  const double a[6] = {0, -0.425, -0.39225, 0, 0, 0};
  const double d[6] = {0.089159, 0, 0, 0.10915, 0.09465, 0.0823};
  const double alpha[6] = {pi2, 0, 0, pi2, -pi2, 0};
  std::vector<DhJoint> rows;
  for (int i = 0; i < 6; ++i) {
    DhJoint r;
    r.name = "j" + std::to_string(i + 1);
    r.parameters = {a[i], alpha[i], d[i], i == 1 ? 0.1 : 0.0};
    if (i == 2) r.type = KinematicJointType::Prismatic;  // exercises a prismatic DH joint too
    rows.push_back(r);
  }
  return rows;
}

// The URDF chain equivalent to a DH table: joint i's origin is the previous row's post times row i's pre.
std::string urdf_of(DhConvention conv, const std::vector<DhJoint>& rows) {
  Environment env;
  SimState& s = env.main_state();
  std::string xml = "<robot name=\"dh\"><link name=\"base\"/>";
  Eigen::Isometry3d carry = Eigen::Isometry3d::Identity();
  std::string parent = "base";
  for (const DhJoint& r : rows) {
    auto& j = s.create<KinematicJoint>();
    j.set_type(r.type);
    j.set_dh_parameters(conv, r.parameters);
    const JointPlacement p = j.placement();
    const std::string child = r.name + "_link";
    xml += "<link name=\"" + child + "\"/><joint name=\"" + r.name + "\" type=\"" +
           (r.type == KinematicJointType::Prismatic ? "prismatic" : "continuous") + "\"><parent link=\"" +
           parent + "\"/><child link=\"" + child + "\"/>" + vsd_test::urdf_origin(carry * p.pre) +
           "<axis xyz=\"0 0 1\"/>" +
           (r.type == KinematicJointType::Prismatic
                ? "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>"
                : "") +
           "</joint>";
    carry = p.post;
    parent = child;
  }
  xml += "<link name=\"flange\"/><joint name=\"flange_joint\" type=\"fixed\"><parent link=\"" + parent +
         "\"/><child link=\"flange\"/>" + vsd_test::urdf_origin(carry) + "</joint></robot>";
  return xml;
}

void compare_dh_with_urdf(DhConvention conv) {
  const std::vector<DhJoint> rows = ur5_dh();
  Environment env;
  env.use<Module>();
  auto& base = env.main_state().create<scene::Node3D>();
  base.set_name("base");
  env.main_state().database().add_child(base);
  KinematicTree& tree = build_dh_chain(base, conv, rows);
  const Model dh = tree.model();
  ASSERT_EQ(dh.dof(), 6);

  Loaded urdf(urdf_of(conv, rows));
  const Model chain = urdf.chain("base", "flange");
  ASSERT_EQ(chain.dof(), 6);

  // KDL's own DH frames as a third opinion for the standard convention (KDL puts a segment's joint
  // before its frame, which is the standard convention's order: Rz(q) Rz(theta) Tz(d) Tx(a) Rx(alpha)).
  KDL::Chain kdl;
  for (const DhJoint& r : rows) {
    const auto& p = r.parameters;
    const KDL::Joint::JointType jt =
        r.type == KinematicJointType::Prismatic ? KDL::Joint::TransZ : KDL::Joint::RotZ;
    kdl.addSegment(KDL::Segment(KDL::Joint(jt), KDL::Frame::DH(p.a, p.alpha, p.d, p.theta)));
  }
  KDL::ChainFkSolverPos_recursive kfk(kdl);
  KDL::JntArray kq(6);

  Model::Data a = dh.make_data(), b = chain.make_data();
  std::mt19937_64 rng(11);
  for (int n = 0; n < 300; ++n) {
    const std::vector<double> q = random_q(dh, rng);
    dh.forward(q, a);
    chain.forward(q, b);
    const Frame& fa = dh.pose(a, dh.tip());
    const Frame& fb = chain.pose(b, chain.tip());
    EXPECT_LT((fa.translation - fb.translation).norm(), 1e-9);
    EXPECT_LT((fa.rotation - fb.rotation).norm(), 1e-9);
    for (int i = 0; i < 6; ++i) kq(i) = q[static_cast<std::size_t>(i)];
    KDL::Frame kf;
    ASSERT_GE(kfk.JntToCart(kq, kf), 0);
    if (conv == DhConvention::Standard) {
      for (int r = 0; r < 3; ++r) {
        EXPECT_NEAR(fa.translation[r], kf.p(r), 1e-9);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(fa.rotation(r, c), kf.M(r, c), 1e-9);
      }
    }
  }
}

// forward() has an AVX form (chosen at run time on x86 with AVX) and the portable SSE2 form, which
// VSD_ROBOTICS_NO_AVX=1 selects when a model is built: both must give the same frames bit for bit, on the
// iiwa chain and on a tree with every kind of segment (coordinate axes other than z, a general axis, a
// post transform, fixed and prismatic joints, a second root, branches), and for angles beyond the
// table's range (the scalar library fallback).
Model build_with_env(const std::function<Model()>& make, bool portable) {
  if (portable) ::setenv("VSD_ROBOTICS_NO_AVX", "1", 1);
  Model m = make();
  if (portable) ::unsetenv("VSD_ROBOTICS_NO_AVX");
  return m;
}

void expect_same_bits(const Model& a, const Model& b, const std::vector<double>& q) {
  Model::Data da = a.make_data(), db = b.make_data();
  a.forward(q, da);
  b.forward(q, db);
  ASSERT_EQ(da.segment.size(), db.segment.size());
  for (std::size_t i = 0; i < da.segment.size(); ++i) {
    EXPECT_EQ(0,
              std::memcmp(da.segment[i].rotation.data(), db.segment[i].rotation.data(), 9 * sizeof(double)))
        << "segment " << i << "\n"
        << da.segment[i].rotation << "\n"
        << db.segment[i].rotation;
    EXPECT_EQ(0, std::memcmp(da.segment[i].translation.data(), db.segment[i].translation.data(),
                             3 * sizeof(double)))
        << "segment " << i;
  }
}

TEST(Model, AvxAndPortableFormsGiveTheSameBits) {
  Loaded robot(read_text(robot_file("iiwa14.urdf")));
  auto iiwa = [&] { return robot.chain("iiwa_link_0", "iiwa_link_ee"); };
  const Model fast = build_with_env(iiwa, false), portable = build_with_env(iiwa, true);
  std::mt19937_64 rng(7);
  for (int n = 0; n < 200; ++n) expect_same_bits(fast, portable, random_q(fast, rng));
  std::vector<double> far(7, 0.5);
  far[3] = 2.5e5;  // beyond the table's range: the library's sin and cos for all
  expect_same_bits(fast, portable, far);

  const Eigen::Vector3d axes[4] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                   Eigen::Vector3d::UnitZ(), Eigen::Vector3d(1, 2, 3).normalized()};
  std::vector<JointSpec> specs = random_tree({-1, 0, 1, 2, 1, 4, 5, 3, 7, 0, -1, 10, 11}, axes, rng);
  specs[11].placement.post =
      Eigen::Translation3d(0.1, 0.2, 0.3) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX());
  auto tree = [&] { return Model::build(specs); };
  const Model tf = build_with_env(tree, false), tp = build_with_env(tree, true);
  for (int n = 0; n < 50; ++n) expect_same_bits(tf, tp, random_angles(tf, rng));
}

TEST(DhChain, StandardAgreesWithItsUrdfChainAndKdl) { compare_dh_with_urdf(DhConvention::Standard); }
TEST(DhChain, ModifiedAgreesWithItsUrdfChain) { compare_dh_with_urdf(DhConvention::Modified); }

TEST(DhChain, BadTablesAreErrors) {
  Environment env;
  env.use<Module>();
  auto& base = env.main_state().create<scene::Node3D>();
  env.main_state().database().add_child(base);
  EXPECT_THROW(build_dh_chain(base, DhConvention::Standard, std::vector<DhJoint>{}), vsd::Error);
  std::vector<DhJoint> rows(1);
  rows[0].type = KinematicJointType::Universal;
  EXPECT_THROW(build_dh_chain(base, DhConvention::Standard, rows), vsd::Error);
  rows[0].type = KinematicJointType::Rotary;
  EXPECT_THROW(build_dh_chain(base, DhConvention::None, rows), vsd::Error);
}

TEST(SinCos, MatchesTheLibrary) {
  std::mt19937_64 rng(5);
  auto check = [](double x) {
    double s, c;
    robotics::detail::sincos(x, s, c);
    ASSERT_NEAR(s, std::sin(x), 3e-16) << x;
    ASSERT_NEAR(c, std::cos(x), 3e-16) << x;
  };
  for (int i = 0; i < 100000; ++i) check(std::uniform_real_distribution<double>(-50, 50)(rng));
  // The table points k pi/64, the midpoints between them (where the reduction switches) and their
  // neighbours, and large arguments still below the library fallback.
  for (int k = -300; k <= 300; ++k) {
    for (const double x : {k * std::numbers::pi / 64, (k + 0.5) * std::numbers::pi / 64}) {
      check(x);
      check(std::nextafter(x, 1e9));
      check(std::nextafter(x, -1e9));
    }
  }
  for (const double x : {99999.9, -99999.9, 12345.678, 1e-300, -1e-300}) check(x);
  double s, c;
  robotics::detail::sincos(0.0, s, c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  // Exactly at the table's points of symmetry where it matters for fixed joints and zero configurations.
  robotics::detail::sincos(-0.0, s, c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  // Beyond the range, NaN and infinity: the library's results.
  robotics::detail::sincos(1e6, s, c);
  EXPECT_EQ(s, std::sin(1e6));
  EXPECT_EQ(c, std::cos(1e6));
  robotics::detail::sincos(std::numeric_limits<double>::quiet_NaN(), s, c);
  EXPECT_TRUE(std::isnan(s));
  EXPECT_TRUE(std::isnan(c));
  robotics::detail::sincos(std::numeric_limits<double>::infinity(), s, c);
  EXPECT_TRUE(std::isnan(s));
}

TEST(SinCos, BatchGivesTheScalarResults) {
  std::mt19937_64 rng(6);
  // Odd and even lengths (the batch works on pairs and finishes with the scalar form).
  for (const std::size_t n : {0U, 1U, 7U, 8U, 1000U}) {
    std::vector<double> xs, ss(n), cs(n);
    for (std::size_t i = 0; i < n; ++i) xs.push_back(std::uniform_real_distribution<double>(-20, 20)(rng));
    robotics::detail::sincos_batch(xs.data(), ss.data(), cs.data(), n);
    for (std::size_t i = 0; i < n; ++i) {
      double s1, c1;
      robotics::detail::sincos(xs[i], s1, c1);
      ASSERT_EQ(ss[i], s1) << xs[i];
      ASSERT_EQ(cs[i], c1) << xs[i];
    }
  }
  // One value out of range (or NaN) anywhere: the library for it, the same values for the others.
  std::vector<double> xs, ss(9), cs(9);
  for (int i = 0; i < 9; ++i) xs.push_back(0.3 * i - 1.0);
  for (const double bad : {2e5, -2e5, std::numeric_limits<double>::quiet_NaN()}) {
    for (const std::size_t at : {0U, 3U, 8U}) {
      std::vector<double> v = xs;
      v[at] = bad;
      robotics::detail::sincos_batch(v.data(), ss.data(), cs.data(), v.size());
      for (std::size_t i = 0; i < v.size(); ++i) {
        if (i == at) {
          if (std::isnan(bad)) {
            EXPECT_TRUE(std::isnan(ss[i]));
          } else {
            EXPECT_EQ(ss[i], std::sin(bad));
            EXPECT_EQ(cs[i], std::cos(bad));
          }
          continue;
        }
        double s1, c1;
        robotics::detail::sincos(v[i], s1, c1);
        EXPECT_EQ(ss[i], s1);
        EXPECT_EQ(cs[i], c1);
      }
    }
  }
}

}  // namespace
}  // namespace vsd::robotics
