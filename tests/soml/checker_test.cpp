// Tests of include/vsd/soml/checker.hpp and types.hpp: resolved names, static types, frame slots, the
// net structure, built-in classes through the registry, and the diagnostics API.
#include "vsd/soml/checker.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "vsd/core/declare.hpp"
#include "vsd/core/node.hpp"
#include "vsd/core/registry.hpp"

using testing::HasSubstr;
using testing::Not;
using namespace vsd::soml;

namespace {

enum class TestMode { Slow, Fast };
VSD_ENUM(TestMode, Slow, Fast)

// A built-in class only this test knows: the checker must find it, its properties and methods, in the
// registry it is given.
class TestRobot : public vsd::Node {
  VSD_INSTANCE(TestRobot, vsd::Node)
  VSD_PROPERTY(double, speed, 1.0)
  VSD_PROPERTY(std::int32_t, axes, 6)
  VSD_PROPERTY(std::string, serial, "", vsd::ReadOnly)
  VSD_PROPERTY(TestMode, mode, TestMode::Slow)
 public:
  double scaled(double f) { return speed() * f; }
  VSD_METHOD(scaled)
};

const vsd::Registry& registry() {
  static vsd::Registry r;
  static const bool added = (r.add<TestRobot>(), true);
  (void)added;
  return r;
}

std::unique_ptr<CheckResult> check(const std::string& text) {
  return check_source("c.soml", text, registry());
}

const FunctionDecl& function(const CheckResult& r, const std::string& name) {
  for (const auto& m : r.script.root->members)
    if (m->kind == DeclKind::Function && m->name == name) return m->as<FunctionDecl>();
  throw std::runtime_error("no function " + name);
}

TEST(Checker, SubclassesABuiltInClassThroughTheRegistry) {
  auto r = check(R"(
    class Arm : TestRobot {
      double reach = 1.0;
      double fast() { return speed * 2.0 + scaled(reach) + axes; }
    }
    void f(ref<Arm> a) { a.speed = 3.0; a.name = "arm"; int n = a.axes; string s = a.serial; }
  )");
  ASSERT_TRUE(r->ok()) << r->diagnostics.format();
  const auto& arm = r->script.root->members[0]->as<ClassDecl>();
  ASSERT_NE(arm.base.meta, nullptr);
  EXPECT_EQ(arm.base.meta->name(), "TestRobot");
  // `a.speed` is bound to the MetaProperty of the built-in class.
  const auto& f = function(*r, "f");
  const auto& assign = f.body->body[0]->as<ExprStmt>().expr->as<BinaryExpr>();
  const auto& member = assign.lhs->as<MemberExpr>();
  EXPECT_EQ(member.binding.kind, Binding::Kind::MetaProperty);
  EXPECT_EQ(member.binding.property, TestRobot::static_meta().find_property("speed"));
  EXPECT_EQ(member.type.kind, Type::Kind::Double);
  // An int32 property computes as int and keeps its storage MetaType.
  const auto& n = f.body->body[2]->as<LocalStmt>();
  EXPECT_EQ(n.init->type.kind, Type::Kind::Int);
  EXPECT_EQ(n.init->type.meta, &vsd::meta_type<std::int32_t>());
}

TEST(Checker, BuiltInClassesAreUnknownToAnotherRegistry) {
  vsd::Registry empty;
  auto r = check_source("c.soml", "class Arm : TestRobot {}", empty);
  EXPECT_THAT(r->diagnostics.format(), HasSubstr("undefined class 'TestRobot'"));
}

TEST(Checker, ReadOnlyAndWrongMethodArgumentsAreErrors) {
  auto r = check("void f(ref<TestRobot> t) { t.serial = \"x\"; double d = t.scaled(\"fast\"); t.scaled(); }");
  const std::string out = r->diagnostics.format();
  EXPECT_THAT(out, HasSubstr("property 'serial' of 'TestRobot' is read-only"));
  EXPECT_THAT(out, HasSubstr("argument 1 of method 'scaled' of 'TestRobot' must be 'double', not 'string'"));
  EXPECT_THAT(out, HasSubstr("wrong number of arguments: method 'scaled' of 'TestRobot' takes 1, 0 given"));
  EXPECT_EQ(r->diagnostics.error_count(), 3u);
}

TEST(Checker, EnumsOfTheRegistryByName) {
  auto good =
      check("void f(ref<TestRobot> t) { t.mode = TestMode::Fast; bool slow = t.mode == TestMode::Slow; }");
  EXPECT_TRUE(good->ok()) << good->diagnostics.format();
  auto bad = check("void f(ref<TestRobot> t) { t.mode = 1; t.mode = TestMode::Nope; int m = TestMode; }");
  const std::string out = bad->diagnostics.format();
  EXPECT_THAT(out, HasSubstr("cannot assign 'int' to 'TestMode'"));
  EXPECT_THAT(out, HasSubstr("enum 'TestMode' has no value 'Nope'"));
  EXPECT_THAT(out, HasSubstr("expression is enum 'TestMode', not a value (write TestMode::Value)"));
  EXPECT_EQ(bad->diagnostics.error_count(), 3u) << out;
}

TEST(Checker, KindsInMessagesHaveTheirArticle) {
  auto bad = check(
      "enum Mode { Idle }\nobject o { }\nclass C { }\n"
      "ref<Mode> r;\nclass D : o { }\nvoid f() { int x = o; }\nplace p { enum E { A } }\n");
  const std::string out = bad->diagnostics.format();
  EXPECT_THAT(out, HasSubstr("'Mode' is an enum, not a class (in a reference type)"));
  EXPECT_THAT(out, HasSubstr("'o' is an object, not a class (as a base class)"));
  EXPECT_THAT(out, HasSubstr("a place holds only properties and functions, not an enum"));
  EXPECT_THAT(out, Not(HasSubstr("a enum")));
  EXPECT_THAT(out, Not(HasSubstr("a object")));
}

TEST(Checker, NumbersLocalsIntoReusedSlots) {
  auto r = check(
      "int f(int a, int b) { int c = a; { int d = 1; int e = 2; } int g = 3; for (int i = 0; i < 2; i++) {} "
      "return c + g; }");
  ASSERT_TRUE(r->ok()) << r->diagnostics.format();
  const auto& f = function(*r, "f");
  const auto& body = f.body->body;
  EXPECT_EQ(body[0]->as<LocalStmt>().slot, 2);  // after the parameters
  const auto& inner = body[1]->as<BlockStmt>().body;
  EXPECT_EQ(inner[0]->as<LocalStmt>().slot, 3);
  EXPECT_EQ(inner[1]->as<LocalStmt>().slot, 4);
  EXPECT_EQ(body[2]->as<LocalStmt>().slot, 3);  // the block's slots are free again
  EXPECT_EQ(f.slots, 5);
  // Names are bound to their slots.
  const auto& ret = body[4]->as<ReturnStmt>().value->as<BinaryExpr>();
  EXPECT_EQ(ret.lhs->as<NameExpr>().binding.kind, Binding::Kind::Local);
  EXPECT_EQ(ret.lhs->as<NameExpr>().binding.slot, 2);
  EXPECT_EQ(ret.rhs->as<NameExpr>().binding.slot, 3);
}

TEST(Checker, ResolvesMembersOfEnclosingScopes) {
  auto r = check(R"(
    int total = 0;
    object o {
      int local = 1;
      place p { int visits = 0; void f() { visits = local + total + count; } }
    }
  )");
  ASSERT_TRUE(r->ok()) << r->diagnostics.format();
  const auto& o = r->script.root->members[1]->as<ClassDecl>();
  const auto& p = o.members[1]->as<PlaceDecl>();
  const auto& f = p.members[1]->as<FunctionDecl>();
  const auto& assign = f.body->body[0]->as<ExprStmt>().expr->as<BinaryExpr>();
  EXPECT_EQ(assign.lhs->as<NameExpr>().binding.outer, 0);  // visits: the place itself
  const auto& sum = assign.rhs->as<BinaryExpr>();
  const auto& left = sum.lhs->as<BinaryExpr>();
  EXPECT_EQ(left.lhs->as<NameExpr>().binding.outer, 1);  // local: the object around the place
  EXPECT_EQ(left.rhs->as<NameExpr>().binding.outer, 2);  // total: the script
  EXPECT_EQ(sum.rhs->as<NameExpr>().binding.builtin, Builtin::PlaceCount);
}

TEST(Checker, BuildsTheNetStructure) {
  auto r = check(R"(
    class Job { int n = 0; start cell.q; }
    object cell {
      place<Job> q;
      place<Job> done;
      place res = 2;
      transition t { when mark.n >= 0; }
      arrow q -> t;
      arrow res -> t * 2;
      arrow t -> done;
      arrow t -> res;
    }
  )");
  ASSERT_TRUE(r->ok()) << r->diagnostics.format();
  const auto& job = r->script.root->members[0]->as<ClassDecl>();
  const auto& cell = r->script.root->members[1]->as<ClassDecl>();
  const auto& q = cell.members[0]->as<PlaceDecl>();
  const auto& res = cell.members[2]->as<PlaceDecl>();
  const auto& t = cell.members[3]->as<TransitionDecl>();
  EXPECT_EQ(q.token.decl, &job);
  EXPECT_TRUE(res.token.empty());
  EXPECT_EQ(res.initial_tokens, 2);
  EXPECT_EQ(t.inputs.size(), 2u);
  EXPECT_EQ(t.outputs.size(), 2u);
  EXPECT_EQ(t.mark_place, &q);
  ASSERT_NE(job.start, nullptr);
  EXPECT_EQ(job.start->place_decl, &q);
  EXPECT_EQ(t.when_expr->type.kind, Type::Kind::Bool);
}

TEST(Checker, InvocationGivesTheActionAResult) {
  auto r = check(R"(
    net double measure(int k) { place s; start s; transition t { do { finish k * 1.5; } } arrow s -> t; }
    object o {
      place a;
      transition call { invoke measure(2); do { double d = result; print(d); } }
      arrow a -> call;
    }
  )");
  ASSERT_TRUE(r->ok()) << r->diagnostics.format();
  const auto& o = r->script.root->members[1]->as<ClassDecl>();
  const auto& call = o.members[1]->as<TransitionDecl>();
  ASSERT_NE(call.invoked, nullptr);
  EXPECT_EQ(call.invoked->name, "measure");
  EXPECT_EQ(call.action_slots, 2);  // result, d
}

TEST(Checker, ReportsAllErrorsOfAFileSortedWithCarets) {
  auto r = check("int a = \"x\";\nvoid f() { b = 1; }\nclass C : Nope {}\n");
  EXPECT_EQ(r->diagnostics.error_count(), 3u);
  EXPECT_EQ(r->diagnostics.format(),
            "c.soml:1:9: error: type mismatch: the initial value of 'a' must be 'int', not 'string'\n"
            "  int a = \"x\";\n"
            "          ^\n"
            "c.soml:2:12: error: undefined name 'b'\n"
            "  void f() { b = 1; }\n"
            "             ^\n"
            "c.soml:3:11: error: undefined class 'Nope' (as a base class)\n"
            "  class C : Nope {}\n"
            "            ^\n");
}

// A statement that did not parse is not also reported as a missing return: its error is the one.
TEST(Checker, AStatementLostToAParseErrorAddsNoMissingReturn) {
  for (const std::string& body : {std::string("return 1 +;"), "return " + std::string(1000, '(') + "1" +
                                                                   std::string(1000, ')') + ";",
                                  std::string("while (1 +) {}")}) {
    auto r = check("int f() { " + body + " }\nint g() { }\n");
    EXPECT_EQ(r->diagnostics.error_count(), 2u) << r->diagnostics.format();
    EXPECT_THAT(r->diagnostics.format(), testing::Not(HasSubstr("function 'f' must return")));
    EXPECT_THAT(r->diagnostics.format(), HasSubstr("function 'g' must return"));  // still checked
  }
}

TEST(Checker, BaseClassCyclesAreReportedNotLooped) {
  auto r = check("class A : B { int x; } class B : A { void f() { x = 1; y = 2; } }");
  EXPECT_THAT(r->diagnostics.format(), HasSubstr("derives from itself"));
}

// Each class's chain of bases was walked to its root to find cycles: quadratic, a chain of 100,000
// classes took minutes. One walk per chain now; a cycle is reported once, at its class that comes first.
TEST(Checker, LongChainsOfBasesAndCyclesAreCheckedInOnePass) {
  std::string chain = "class C0 : Node { int v = 0; }\n";
  for (int i = 1; i < 100'000; ++i) chain += "class C" + std::to_string(i) + " : C" + std::to_string(i - 1) + " {}\n";
  chain += "int f(ref<C99999> c) { return c.v; }\n";
  auto r = check(chain);
  EXPECT_TRUE(r->ok()) << r->diagnostics.format().substr(0, 300);
  auto cycle = check("class X : A {}\nclass B : C {}\nclass A : B {}\nclass C : A {}\nclass D : X {}\n");
  EXPECT_EQ(cycle->diagnostics.error_count(), 1u) << cycle->diagnostics.format();
  EXPECT_THAT(cycle->diagnostics.format(), HasSubstr("c.soml:2:11: error: class 'B' derives from itself"));
}

TEST(Checker, OverridesKeepTheSignature) {
  auto r = check(
      "class A { int f(int x) { return x; } } class B : A { int f(int x) { return 2; } } class C : A { "
      "double f() { return 1.0; } }");
  EXPECT_EQ(r->diagnostics.error_count(), 1u) << r->diagnostics.format();
  EXPECT_THAT(r->diagnostics.format(),
              HasSubstr("function 'f' overrides the one of class 'A' (line 1) with a different signature"));
}

TEST(Checker, ConditionsMustNotChangeProperties) {
  auto r = check(
      "object o { int n = 0; place p; transition t { when { n = 1; int local = 0; local = 2; return true; } "
      "} arrow p -> t; }");
  EXPECT_EQ(r->diagnostics.error_count(), 1u) << r->diagnostics.format();
  EXPECT_THAT(r->diagnostics.format(), HasSubstr("a condition must not change properties"));
}

TEST(Checker, HostileInputNeverCrashes) {
  std::string deep = "int f() { return ";
  for (int i = 0; i < 250; ++i) deep += "(";
  deep += "1";
  for (int i = 0; i < 250; ++i) deep += ")";
  deep += "; }";
  EXPECT_TRUE(check(deep)->ok());
  std::string members = "int x = 1";
  for (int i = 0; i < 240; ++i) members += " + x";
  EXPECT_TRUE(check(members + ";")->ok());
  std::string nul("class A { int x = 1; }\0 class B {}", 34);
  EXPECT_FALSE(check(nul)->ok());
  EXPECT_FALSE(check("\xef\xbb\xbf class A {}")->ok());   // a byte order mark is not SOML++
  EXPECT_FALSE(check("string s = \"\xc0\xaf\";")->ok());  // overlong UTF-8
}

}  // namespace
