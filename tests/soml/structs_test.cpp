// SOML++ structs and vectors of structs as values in code (docs/soml.md 4.14): locals, parameters and
// results, fields read and written, `Vector3d(x, y, z)`, ==; struct and vector<Vector3d> properties read
// in place and written whole, by field or by element through their setter (one change that signals,
// records and replays); MetaMethods called from C++ with Values; errors with their position.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "script_fixture.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"
#ifdef VSD_SOML_TEST_SCENE
#include "vsd/scene.hpp"
#endif

namespace structs_test {

// A built-in class with a property of each struct type the VM holds, and a vector of them.
class Rigid : public vsd::Node {
  VSD_INSTANCE(Rigid, vsd::Node)
  VSD_PROPERTY(Eigen::Vector2d, uv, Eigen::Vector2d(1, 2))
  VSD_PROPERTY(Eigen::Vector3d, pos, Eigen::Vector3d(1, 2, 3))
  VSD_PROPERTY(Eigen::Vector4d, color, Eigen::Vector4d(0, 0, 0, 1))
  VSD_PROPERTY(Eigen::Quaterniond, turn, Eigen::Quaterniond::Identity())
  VSD_PROPERTY(Eigen::Isometry3d, pose, Eigen::Isometry3d::Identity())
  VSD_PROPERTY(std::vector<Eigen::Vector3d>, trail, {})
};

}  // namespace structs_test

namespace {

using ::testing::HasSubstr;
using vsd::soml::Program;
using V3 = Eigen::Vector3d;

struct Structs : soml_test::ScriptTest {};

TEST_F(Structs, FunctionsWithStructsAreMetaMethodsCalledWithValues) {
  Program& p = load(R"(
Vector3d mid(Vector3d a, Vector3d b) { return Vector3d((a.x + b.x) / 2, (a.y + b.y) / 2, (a.z + b.z) / 2); }
// A copy is a copy: the callee changes its parameter, the caller's value stays.
void clobber(Vector3d v) { v.x = 99; }
vector<Vector3d> line(int n) {
  vector<Vector3d> out;
  for (int i = 0; i < n; i++) out.push(Vector3d(i, 2 * i, 0));
  return out;
}
double sum_x(vector<Vector3d> v) { double s = 0; for (Vector3d p : v) s += p.x; return s; }
bool copies() { Vector3d a = Vector3d(1, 2, 3); Vector3d b = a; b.y = 7; clobber(a); return a == Vector3d(1, 2, 3) && b != a; }
Isometry3d moved(Isometry3d t, double dz) { t.translation.z += dz; return t; }
)");
  vsd::Node& root = p.root();
  EXPECT_EQ(root.call("mid", {vsd::Value(V3(1, 2, 3)), vsd::Value(V3(3, 4, 5))}).as<V3>(), V3(2, 3, 4));
  EXPECT_EQ(root.call("line", {vsd::Value(std::int64_t{3})}).as<std::vector<V3>>(),
            (std::vector<V3>{V3(0, 0, 0), V3(1, 2, 0), V3(2, 4, 0)}));
  EXPECT_DOUBLE_EQ(root.call("sum_x", {vsd::Value(std::vector<V3>{V3(1, 0, 0), V3(2.5, 0, 0)})}).as<double>(),
                   3.5);
  EXPECT_TRUE(root.call("copies", {}).as<bool>());
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = V3(1, 2, 3);
  const Eigen::Isometry3d m = root.call("moved", {vsd::Value(t), vsd::Value(0.5)}).as<Eigen::Isometry3d>();
  EXPECT_EQ(m.translation(), V3(1, 2, 3.5));
  // A wrong argument is a vsd::Error naming both types, never a crash.
  EXPECT_THAT(soml_test::error_of([&] {
                root.call("mid", {vsd::Value(1.0), vsd::Value(V3(0, 0, 0))});
              }),
              HasSubstr("mid argument 1: expected Vector3d, got double"));
  EXPECT_THAT(soml_test::error_of([&] { root.call("sum_x", {vsd::Value(std::vector<double>{1.0})}); }),
              HasSubstr("sum_x argument 1: expected vector<Vector3d>, got vector<double>"));
}

TEST_F(Structs, PropertyWritesGoThroughTheSetterOnceAndReplay) {
  Program& p = load(R"(
class Body : Node {
  Vector3d offset = Vector3d(0.5, 0, 0);
  vector<Vector3d> path;
}
shared<Body> body = new Body();
void move() {
  body.offset.x += 1;                    // read, change the field, store: one change
  body.offset = Vector3d(body.offset.x, 2, 3);
  body.path.push(Vector3d(1, 1, 1));
  body.path.push(body.offset);
  body.path[0].z = 9;                    // one change of path
  body.path[1] = Vector3d(4, 5, 6);
}
double z0() { return body.path[0].z + body.path.size(); }   // read in place
)");
  vsd::Node& root = p.root();
  const vsd::Node* body = root.get<vsd::SharedRef<vsd::Node>>("body").get();
  ASSERT_NE(body, nullptr);
  EXPECT_EQ(body->get<V3>("offset"), V3(0.5, 0, 0)) << "a property initialiser of struct type";

  std::vector<std::string> changed;
  auto c = env.main_state().on_property_changed().connect(
      [&](vsd::SimStateInstance&, const vsd::MetaProperty& mp) { changed.push_back(mp.name()); });
  vsd::SimState& replica = env.create_state("replica");
  replica.copy_from(env.main_state());
  env.main_state().start_recording();
  root.call("move", {});
  vsd::Transaction t = env.main_state().stop_recording();

  EXPECT_EQ(body->get<V3>("offset"), V3(1.5, 2, 3));
  EXPECT_EQ(body->get<std::vector<V3>>("path"), (std::vector<V3>{V3(1, 1, 9), V3(4, 5, 6)}));
  EXPECT_DOUBLE_EQ(root.call("z0", {}).as<double>(), 11.0);
  EXPECT_EQ(std::count(changed.begin(), changed.end(), "offset"), 2);
  EXPECT_EQ(std::count(changed.begin(), changed.end(), "path"), 4);
  replica.apply(t);
  std::string diff;
  EXPECT_TRUE(replica.equals(env.main_state(), &diff)) << diff;
}

TEST_F(Structs, AConditionReadingAStructOrItsVectorIsRetestedWhenItChanges) {
  Program& p = load(R"(
Vector3d target;
vector<Vector3d> points;
int hits = 0;
place watch = 1;
transition near {
  when target.z > 1.0 && points.size() > 0 && points[0].x == target.x;
  do { hits += 1; }
}
arrow watch -> near;
)");
  EXPECT_EQ(p.run_until_quiet(), 0u);
  p.root().set("target", vsd::Value(V3(2, 0, 5)));
  EXPECT_EQ(p.run_until_quiet(), 0u);
  p.root().set("points", vsd::Value(std::vector<V3>{V3(2, 0, 0)}));
  EXPECT_EQ(p.run_until_quiet(), 1u) << "the change of points re-tested the condition";
  EXPECT_EQ(p.root().get<std::int64_t>("hits"), 1);
}

TEST_F(Structs, VectorsOfRegistryEnumsAndStringsAreValuesAndPrint) {
  const vsd::MetaType& shade = vsd::EnumBuilder("Shade").value("Dark", 0).value("Light", 3).define(reg);
  const vsd::MetaType& shades = reg.vector_type(shade);
  Program& p = load(R"(
vector<Shade> shades;
vector<string> names;
vector<Shade> flipped(vector<Shade> in) {
  vector<Shade> out;
  for (Shade s : in) out.push(s == Shade::Dark ? Shade::Light : Shade::Dark);
  return out;
}
void f() {
  vector<Shade> l;
  l.push(Shade::Light);
  l.push(Shade::Dark);
  shades = flipped(l);
  shades[1] = Shade::Light;
  names.push("a");
  print(l, " ", shades, " ", names, " ", shades[0] == Shade::Dark, " ", l.size());
}
)");
  p.root().call("f", {});
  EXPECT_EQ(out.str(), "[\"Light\", \"Dark\"] [\"Dark\", \"Light\"] [\"a\"] true 2\n");
  const vsd::Value v = p.root().get("shades");
  ASSERT_EQ(v.type(), &shades);
  EXPECT_EQ(v.to_text(), R"(["Dark", "Light"])");
}

TEST_F(Structs, AConditionMayChangeAFieldOfALocalButNotOfAProperty) {
  Program& p = load(R"(
Vector3d target = Vector3d(1, 2, 3);
int hits = 0;
place watch = 1;
transition near {
  when { Vector3d v = target; v.z = 0; return v == Vector3d(1, 2, 0); }
  do { hits += 1; }
}
arrow watch -> near;
)");
  EXPECT_EQ(p.run_until_quiet(), 1u);
  EXPECT_THAT(soml_test::error_of([&] {
                load(
                    "Vector3d target;\nplace w = 1;\ntransition t { when { target.z = 0; return true; } "
                    "}\narrow w -> t;\n",
                    "cond.soml");
              }),
              HasSubstr("cond.soml:3:29: error: a condition must not change properties"));
}

TEST_F(Structs, MistakesAreReportedWithTheirPosition) {
  const std::string e = soml_test::error_of([&] {
    load(R"(void f() {
  Vector3d v;
  v.w = 1;
  double d = v;
  vector<Vector3d> l;
  l.push(1.0);
  Vector3d u = Vector3d(1, 2);
  bool b = v == 1.0;
}
)",
         "bad.soml");
  });
  EXPECT_THAT(e, HasSubstr("bad.soml:3:5: error: type 'Vector3d' has no field 'w'"));
  EXPECT_THAT(e,
              HasSubstr("bad.soml:4:14: error: type mismatch: the initialiser of 'd' must be 'double', not "
                        "'Vector3d'"));
  EXPECT_THAT(e, HasSubstr("bad.soml:6:10: error: type mismatch: the element to push must be 'Vector3d', not "
                           "'double'"));
  EXPECT_THAT(e, HasSubstr("bad.soml:7:24: error: wrong number of arguments: 'Vector3d' (double x, double y, "
                           "double z; or none for the default) takes 3, 2 given"));
  EXPECT_THAT(e, HasSubstr("bad.soml:8:14: error: type mismatch"));
}

TEST_F(Structs, AnElementOutOfRangeIsARunTimeErrorWithTheCallStack) {
  Program& p = load(R"(vector<Vector3d> points;
double at(int i) { return points[i].y; }
double local(int i) { vector<Vector3d> v = points; v[i].x = 1; return v[i].x; }
)");
  p.root().set("points", vsd::Value(std::vector<V3>{V3(1, 2, 3)}));
  EXPECT_DOUBLE_EQ(p.root().call("at", {vsd::Value(std::int64_t{0})}).as<double>(), 2.0);
  EXPECT_THAT(soml_test::error_of([&] { p.root().call("at", {vsd::Value(std::int64_t{1})}); }),
              HasSubstr("index 1 out of range (size 1)\n  at at (test.soml:2:33)"));
  EXPECT_THAT(soml_test::error_of([&] { p.root().call("local", {vsd::Value(std::int64_t{-1})}); }),
              HasSubstr("index -1 out of range (size 1)\n  at local (test.soml:3:53)"));
}

// docs/soml.md promises the properties of built-in classes and struct values: a struct property of a C++
// class passed the checker and the loader, and then every read failed at run time ("cannot be read as a
// value yet"), in a condition silently (only condition_errors() said so).
TEST_F(Structs, StructPropertiesOfBuiltInClassesAreReadWrittenAndWatched) {
  using structs_test::Rigid;
  reg.add<Rigid>();
  Program& p = load(R"(
shared<Rigid> body;
int seen = 0;
place armed = 1;
transition far {
  when body != null && body.pos.x > 5.0 && body.pose.translation.z > 0.5;   // read in a condition
  do { seen += 1; }
}
arrow armed -> far;
string show() {
  return string(body.uv) + " " + string(body.pos) + " " + string(body.color) + " " + string(body.turn) + " " +
         string(body.pose) + " " + string(body.trail.size());
}
void move() {
  Vector3d p = body.pos;                        // a copy
  body.pos = p + Vector3d(1, 0, 0);             // written whole, through the setter
  body.pos.y = 7;                               // a field: read, change, store
  body.pos += Vector3d(0, 0, 1);                // a compound assignment of the whole
  body.pos.x *= 2;                              // and of a field
  body.uv.x -= 1;
  body.color = Vector4d(1, 0.5, 0.25, 1);
  body.turn = Quaterniond::from_axis_angle(Vector3d(0, 0, 1), 0);
  body.pose.translation.z += 1;                 // a nested field of a frame
  body.trail.push(body.pos);
  body.trail[0].z = 9;
}
)");
  auto& body = env.main_state().create<Rigid>();
  p.root().set("body", vsd::Value(vsd::SharedRef<vsd::Node>(&body)));
  EXPECT_EQ(p.run_until_quiet(), 0u);
  EXPECT_TRUE(p.condition_errors().empty()) << p.condition_errors().front();
  EXPECT_EQ(p.root().call("show", {}).as<std::string>(),
            "Vector2d(1, 2) Vector3d(1, 2, 3) Vector4d(0, 0, 0, 1) Quaterniond(1, 0, 0, 0) "
            "Isometry3d(Vector3d(0, 0, 0), Quaterniond(1, 0, 0, 0)) 0");
  std::vector<std::string> changed;
  auto c = env.main_state().on_property_changed().connect(
      [&](vsd::SimStateInstance&, const vsd::MetaProperty& mp) { changed.push_back(mp.name()); });
  p.root().call("move", {});
  EXPECT_EQ(body.pos(), V3(4, 7, 4));
  EXPECT_EQ(body.uv(), Eigen::Vector2d(0, 2));
  EXPECT_EQ(body.color(), Eigen::Vector4d(1, 0.5, 0.25, 1));
  EXPECT_EQ(body.pose().translation(), V3(0, 0, 1));
  EXPECT_EQ(body.trail(), (std::vector<V3>{V3(4, 7, 9)}));
  EXPECT_EQ(std::count(changed.begin(), changed.end(), "pos"), 4) << "each write one change, through the setter";
  EXPECT_EQ(std::count(changed.begin(), changed.end(), "pose"), 1);
  // The condition read pos and pose: their changes re-tested it.
  EXPECT_EQ(p.run_until_quiet(), 0u) << "pos.x is 4";
  body.set_pos(V3(6, 0, 0));
  EXPECT_EQ(p.run_until_quiet(), 1u);
  EXPECT_EQ(p.root().get<std::int64_t>("seen"), 1);
  EXPECT_TRUE(p.condition_errors().empty());
}

#ifdef VSD_SOML_TEST_SCENE
// The frame a script class inherits from scene::Node3D: read in code and in a condition, written by
// field through the setter, so the world frames below follow.
TEST_F(Structs, TheFrameAScriptClassInheritsFromNode3DIsAValue) {
  env.use<vsd::scene::Module>();
  Program& p = load(R"(
class Box : Node3D {
  double height() { return frame.translation.z; }
  void lift(double dz) { frame.translation.z += dz; }
}
shared<Box> box = new Box();
int high = 0;
place watch = 1;
transition up {
  when box.frame.translation.z > 1.0 && box.height() > 1.0;
  do { high += 1; box.frame = Isometry3d(box.frame.translation * 2, box.frame.rotation); }
}
arrow watch -> up;
)");
  auto* box = p.root().get<vsd::SharedRef<vsd::Node>>("box").get()->as<vsd::scene::Node3D>();
  ASSERT_NE(box, nullptr);
  auto& child = env.main_state().create<vsd::scene::Node3D>();
  box->add_child(child);
  EXPECT_EQ(p.run_until_quiet(), 0u);
  box->call("lift", {vsd::Value(0.75)});
  EXPECT_EQ(p.run_until_quiet(), 0u);
  box->call("lift", {vsd::Value(0.75)});
  EXPECT_DOUBLE_EQ(box->call("height", {}).as<double>(), 1.5);
  EXPECT_EQ(p.run_until_quiet(), 1u) << "the lift re-tested the condition";
  EXPECT_EQ(p.root().get<std::int64_t>("high"), 1);
  EXPECT_EQ(child.world_frame().translation(), V3(0, 0, 3)) << "written through the setter";
  EXPECT_TRUE(p.condition_errors().empty()) << p.condition_errors().front();
}
#endif

}  // namespace
