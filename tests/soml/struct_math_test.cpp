// Arithmetic on the Eigen structs in SOML++ code (docs/soml.md 4.14): every operator and method against
// Eigen computed in C++ for random inputs; results stored into one of their operands; a net whose
// condition is a distance reacting to C++ changes of Isometry3d and Vector3d properties; run-time and
// check-time errors with their position.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "script_fixture.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace struct_math_test {

using ::testing::HasSubstr;
using vsd::Value;
using vsd::soml::Program;
using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Quat = Eigen::Quaterniond;
using Iso = Eigen::Isometry3d;

constexpr double kTol = 1e-12;

constexpr const char* kOps = R"(
Vector3d add(Vector3d a, Vector3d b) { return a + b; }
Vector3d sub(Vector3d a, Vector3d b) { return a - b; }
Vector3d neg(Vector3d a) { return -a; }
Vector3d scale(Vector3d a, double s) { return a * s; }
Vector3d rscale(double s, Vector3d a) { return s * a; }
Vector3d iscale(Vector3d a) { return 3 * a / 2; }
Vector3d div(Vector3d a, double s) { return a / s; }
double dot(Vector3d a, Vector3d b) { return a.dot(b); }
Vector3d cross(Vector3d a, Vector3d b) { return a.cross(b); }
double norm(Vector3d a) { return a.norm(); }
double squared_norm(Vector3d a) { return a.squared_norm(); }
Vector3d normalized(Vector3d a) { return a.normalized(); }
Vector3d compound(Vector3d a, Vector3d b, double s) { Vector3d c = a; c += b; c -= s * b; c *= s; c /= 2; return c; }
Vector2d add2(Vector2d a, Vector2d b) { return a + b - b * 0.5; }
double dot2(Vector2d a, Vector2d b) { return a.dot(b) + a.norm(); }
Vector4d ops4(Vector4d a, Vector4d b, double s) { return (a - b) / s + a.normalized(); }
double dot4(Vector4d a, Vector4d b) { return a.dot(b) - b.squared_norm(); }
Quaterniond qmul(Quaterniond p, Quaterniond q) { return p * q; }
Vector3d qrot(Quaterniond q, Vector3d v) { return q * v; }
Quaterniond qinv(Quaterniond q) { return q.inverse(); }
Quaterniond qconj(Quaterniond q) { return q.conjugate(); }
Quaterniond qnormalized(Quaterniond q) { return q.normalized(); }
Quaterniond axis_angle(Vector3d axis, double angle) { return Quaterniond::from_axis_angle(axis, angle); }
Isometry3d frame(Vector3d t, Quaterniond q) { return Isometry3d(t, q); }
Isometry3d tmul(Isometry3d a, Isometry3d b) { return a * b; }
Vector3d tapply(Isometry3d a, Vector3d v) { return a * v; }
Isometry3d tinv(Isometry3d a) { return a.inverse(); }
double distance(Isometry3d a, Vector3d local, Vector3d target) { return (a * local - target).norm(); }
)";

struct StructMath : soml_test::ScriptTest {
  std::mt19937_64 rng{20261123};
  double uniform(double lo = -10, double hi = 10) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  Vec3 v3() { return {uniform(), uniform(), uniform()}; }
  Quat unit_quat() { return Quat(uniform(), uniform(), uniform(), uniform()).normalized(); }
  Iso iso() {
    Iso t = Iso::Identity();
    t.translation() = v3();
    t.linear() = unit_quat().toRotationMatrix();
    return t;
  }
  Value call(Program& p, const char* fn, std::vector<Value> args) { return p.root().call(fn, args); }
};

::testing::AssertionResult near(const Eigen::MatrixXd& got, const Eigen::MatrixXd& want) {
  if ((got - want).cwiseAbs().maxCoeff() <= kTol * (1 + want.cwiseAbs().maxCoeff()))
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got\n" << got << "\nwant\n" << want;
}
::testing::AssertionResult near(const Quat& got, const Quat& want) {
  return near(got.coeffs(), want.coeffs());
}
::testing::AssertionResult near(const Iso& got, const Iso& want) { return near(got.matrix(), want.matrix()); }

TEST_F(StructMath, VectorOperatorsAndMethodsMatchEigen) {
  Program& p = load(kOps);
  for (int i = 0; i < 50; ++i) {
    SCOPED_TRACE(i);
    const Vec3 a = v3(), b = v3();
    const double s = uniform(0.5, 4);
    EXPECT_TRUE(near(call(p, "add", {a, b}).as<Vec3>(), a + b));
    EXPECT_TRUE(near(call(p, "sub", {a, b}).as<Vec3>(), a - b));
    EXPECT_TRUE(near(call(p, "neg", {a}).as<Vec3>(), -a));
    EXPECT_TRUE(near(call(p, "scale", {a, s}).as<Vec3>(), a * s));
    EXPECT_TRUE(near(call(p, "rscale", {s, a}).as<Vec3>(), s * a));
    EXPECT_TRUE(near(call(p, "iscale", {a}).as<Vec3>(), 3 * a / 2));
    EXPECT_TRUE(near(call(p, "div", {a, s}).as<Vec3>(), a / s));
    EXPECT_NEAR(call(p, "dot", {a, b}).as<double>(), a.dot(b), kTol * 100);
    EXPECT_TRUE(near(call(p, "cross", {a, b}).as<Vec3>(), a.cross(b)));
    EXPECT_NEAR(call(p, "norm", {a}).as<double>(), a.norm(), kTol * 10);
    EXPECT_NEAR(call(p, "squared_norm", {a}).as<double>(), a.squaredNorm(), kTol * 100);
    EXPECT_TRUE(near(call(p, "normalized", {a}).as<Vec3>(), a.normalized()));
    EXPECT_TRUE(near(call(p, "compound", {a, b, s}).as<Vec3>(), (a + b - s * b) * s / 2));
    const Vec2 a2(uniform(), uniform()), b2(uniform(), uniform());
    EXPECT_TRUE(near(call(p, "add2", {a2, b2}).as<Vec2>(), a2 + b2 - b2 * 0.5));
    EXPECT_NEAR(call(p, "dot2", {a2, b2}).as<double>(), a2.dot(b2) + a2.norm(), kTol * 100);
    const Vec4 a4(uniform(), uniform(), uniform(), uniform()), b4(uniform(), uniform(), uniform(), uniform());
    EXPECT_TRUE(near(call(p, "ops4", {a4, b4, s}).as<Vec4>(), (a4 - b4) / s + a4.normalized()));
    EXPECT_NEAR(call(p, "dot4", {a4, b4}).as<double>(), a4.dot(b4) - b4.squaredNorm(), kTol * 1000);
  }
  // Eigen keeps a zero vector as it is: no NaN.
  EXPECT_EQ(call(p, "normalized", {Vec3(0, 0, 0)}).as<Vec3>(), Vec3(0, 0, 0));
}

TEST_F(StructMath, QuaternionsAndFramesMatchEigen) {
  Program& p = load(kOps);
  for (int i = 0; i < 50; ++i) {
    SCOPED_TRACE(i);
    const Quat q = unit_quat(), r = unit_quat();
    const Quat raw(uniform(), uniform(), uniform(), uniform());
    const Vec3 v = v3();
    EXPECT_TRUE(near(call(p, "qmul", {q, r}).as<Quat>(), q * r));
    EXPECT_TRUE(near(call(p, "qmul", {raw, r}).as<Quat>(), raw * r));
    EXPECT_TRUE(near(call(p, "qrot", {q, v}).as<Vec3>(), q * v));
    EXPECT_TRUE(near(call(p, "qinv", {raw}).as<Quat>(), raw.inverse()));
    EXPECT_TRUE(near(call(p, "qconj", {raw}).as<Quat>(), raw.conjugate()));
    EXPECT_TRUE(near(call(p, "qnormalized", {raw}).as<Quat>(), raw.normalized()));
    const Vec3 axis = v3();
    const double angle = uniform(-3, 3);
    EXPECT_TRUE(near(call(p, "axis_angle", {axis, angle}).as<Quat>(),
                     Quat(Eigen::AngleAxisd(angle, axis.normalized()))));
    const Iso a = iso(), b = iso();
    Iso built = Iso::Identity();
    built.translation() = v;
    built.linear() = raw.normalized().toRotationMatrix();
    EXPECT_TRUE(near(call(p, "frame", {v, raw}).as<Iso>(), built)) << "the rotation is normalised";
    EXPECT_TRUE(near(call(p, "tmul", {a, b}).as<Iso>(), a * b));
    EXPECT_TRUE(near(call(p, "tapply", {a, v}).as<Vec3>(), a * v));
    EXPECT_TRUE(near(call(p, "tinv", {a}).as<Iso>(), a.inverse(Eigen::Isometry)));
    const Vec3 local = v3(), target = v3();
    EXPECT_NEAR(call(p, "distance", {a, local, target}).as<double>(), (a * local - target).norm(), 1e-10);
  }
}

TEST_F(StructMath, AResultMayReplaceAnOperandAndChangeTheRegistersType) {
  Program& p = load(R"(
Vector3d steps(Isometry3d t, Vector3d v, int n) { for (int i = 0; i < n; i++) v = t * v; return v; }
Isometry3d power(Isometry3d t, int n) { Isometry3d r = t; for (int i = 1; i < n; i++) r = r * t; return r; }
Quaterniond qpower(Quaterniond q, int n) { Quaterniond r = q; for (int i = 1; i < n; i++) r *= q; return r; }
Vector3d flip(Vector3d v) { v = -v; v = v + v; v = v.cross(Vector3d(0, 0, 1)); return v; }
// One temporary register holds a quaternion, then a vector.
Vector3d mixed(Quaterniond q, Vector3d v) { return (q * q) * v; }
)");
  const Iso t = iso();
  const Vec3 v = v3();
  Vec3 want = v;
  for (int i = 0; i < 7; ++i) want = t * want;
  EXPECT_TRUE(near(call(p, "steps", {t, v, std::int64_t{7}}).as<Vec3>(), want));
  EXPECT_TRUE(near(call(p, "power", {t, std::int64_t{3}}).as<Iso>(), t * t * t));
  const Quat q = unit_quat();
  EXPECT_TRUE(near(call(p, "qpower", {q, std::int64_t{3}}).as<Quat>(), q * q * q));
  EXPECT_TRUE(near(call(p, "flip", {v}).as<Vec3>(), (-2 * v).cross(Vec3(0, 0, 1))));
  EXPECT_TRUE(near(call(p, "mixed", {q, v}).as<Vec3>(), (q * q) * v));
}

TEST_F(StructMath, ADistanceConditionReactsToChangesFromCpp) {
  Program& p = load(R"(
class Box : Node {
  Isometry3d pose;
  Vector3d target = Vector3d(1, 0, 0);
}
shared<Box> box = new Box();
int hits = 0;
// The box's grasp point, 10 cm along its local z axis, and its distance to the target.
double gap() { return (box.pose * Vector3d(0, 0, 0.1) - box.target).norm(); }
place away = 1;
place close;
transition near {
  when (box.pose * Vector3d(0, 0, 0.1) - box.target).norm() < 0.05;
  do { hits += 1; }
}
transition far { when gap() >= 0.05; }
arrow away -> near;
arrow near -> close;
arrow close -> far;
arrow far -> away;
)");
  vsd::Node* box = p.root().get<vsd::SharedRef<vsd::Node>>("box").get();
  ASSERT_NE(box, nullptr);
  EXPECT_EQ(p.run_until_quiet(), 0u) << "the grasp point (0, 0, 0.1) is 1 m from the target";
  // A quarter turn about y takes the local z axis to +x: the grasp point is the translation + (0.1, 0, 0).
  Iso pose = Iso::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix();
  pose.translation() = Vec3(0.5, 0, 0);
  box->set("pose", Value(pose));
  EXPECT_EQ(p.run_until_quiet(), 0u) << "(0.6, 0, 0) is 0.4 m from the target";
  box->set("target", Value(Vec3(0.62, 0.03, 0)));
  EXPECT_EQ(p.run_until_quiet(), 1u) << "the Vector3d change re-tested the condition: 3.6 cm";
  EXPECT_EQ(p.root().get<std::int64_t>("hits"), 1);
  pose.translation() = Vec3(0.9, 0, 0);
  box->set("pose", Value(pose));
  EXPECT_EQ(p.run_until_quiet(), 1u) << "the Isometry3d change re-tested 'far'";
  pose.translation() = Vec3(0.55, 0, 0);
  box->set("pose", Value(pose));
  EXPECT_EQ(p.run_until_quiet(), 1u) << "4.2 cm: near again";
  EXPECT_EQ(p.root().get<std::int64_t>("hits"), 2);
}

TEST_F(StructMath, MisuseIsAnErrorWithItsPosition) {
  const std::string e = soml_test::error_of([&] {
    load(R"(void f() {
  Vector3d v;
  Isometry3d t;
  Vector3d a = v + 1;
  Vector3d b = t * Vector2d(1, 2);
  Vector3d c = v.cross();
}
)",
         "bad.soml");
  });
  EXPECT_THAT(e, HasSubstr("bad.soml:4:18: error: type mismatch: '+' takes two numbers or two vectors of one "
                           "size, not 'Vector3d' and 'int'"));
  EXPECT_THAT(e,
              HasSubstr("bad.soml:5:18: error: type mismatch: '*' takes numbers, a vector and a number, two "
                        "Quaterniond or two Isometry3d, or a Quaterniond or Isometry3d and a Vector3d, not "
                        "'Isometry3d' and 'Vector2d'"));
  EXPECT_THAT(e, HasSubstr("bad.soml:6:23: error: wrong number of arguments: method 'cross' of 'Vector3d' "
                           "takes 1, 0 given"));
  Program& p = load("Quaterniond turn(Vector3d axis) { return Quaterniond::from_axis_angle(axis, 1.0); }\n",
                    "turn.soml");
  EXPECT_THAT(
      soml_test::error_of([&] { p.root().call("turn", {Value(Vec3(0, 0, 0))}); }),
      HasSubstr("Quaterniond::from_axis_angle: the axis is the zero vector\n  at turn (turn.soml:1:70)"));
}

TEST_F(StructMath, StructsPrintAsTheyAreBuilt) {
  Program& p = load(R"(
void show() {
  Vector3d v = Vector3d(1, 2.5, 0);
  vector<Vector3d> l;
  l.push(v);
  l.push(-v);
  print(v, " ", l, " ", Isometry3d(), " " + string(Quaterniond(0, 1, 0, 0)) + " " + Vector2d(0.5, -1));
}
)");
  p.root().call("show", {});
  EXPECT_EQ(out.str(),
            "Vector3d(1, 2.5, 0) [Vector3d(1, 2.5, 0), Vector3d(-1, -2.5, -0)] Isometry3d(Vector3d(0, 0, 0), "
            "Quaterniond(1, 0, 0, 0)) Quaterniond(0, 1, 0, 0) Vector2d(0.5, -1)\n");
}

TEST_F(StructMath, TheDebuggerShowsStructsAsPrintDoes) {
  Program& p = load(R"(object probe {
  Vector3d offset = Vector3d(1, 2, 3);
  place go = 1;
  transition t {
    do {
      Vector3d v = offset * 2;
      print(v);
    }
  }
  arrow go -> t;
}
)",
                    "dbg.soml");
  vsd::soml::Debugger d(p);
  d.break_at_line(7);
  std::string locals, prop;
  d.on_stop([&](vsd::soml::Debugger& dd, const vsd::soml::Stop&) {
    for (const auto& v : dd.locals()) locals += v.type + " " + v.name + " = " + v.value;
    prop = dd.print("offset");
    return vsd::soml::Resume::Continue;
  });
  EXPECT_EQ(p.step(1), 1u);
  EXPECT_EQ(locals, "Vector3d v = Vector3d(2, 4, 6)");
  EXPECT_EQ(prop, "offset = Vector3d(1, 2, 3)");
  EXPECT_EQ(out.str(), "Vector3d(2, 4, 6)\n");
}

}  // namespace struct_math_test
