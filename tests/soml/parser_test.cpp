// Tests of include/vsd/soml/parser.hpp and ast.hpp: the tree for each construct, precedence, error
// recovery, and hostile input that must never crash.
#include "vsd/soml/parser.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>
#include <string>

using testing::HasSubstr;
using namespace vsd::soml;

namespace {

struct Parsed {
  Source source;
  Diagnostics diag;
  Script script;
  explicit Parsed(std::string text) : source("p.soml", std::move(text)), diag(source) {
    script = parse(source, diag);
  }
  const Decl& member(std::size_t i) const { return *script.root->members.at(i); }
};

// The expression of `int v = <text>;` printed with full parentheses.
std::string show(const Expr& e);
std::string show_all(const std::vector<ExprPtr>& args) {
  std::string s;
  for (const auto& a : args) s += (s.empty() ? "" : ", ") + show(*a);
  return s;
}
std::string show(const Expr& e) {
  switch (e.kind) {
    case ExprKind::Int:
      return std::to_string(e.as<LiteralExpr>().int_value);
    case ExprKind::Name:
      return e.as<NameExpr>().spelling();
    case ExprKind::Mark:
      return "mark";
    case ExprKind::Unary: {
      std::string op(token_kind_name(e.as<UnaryExpr>().op));
      return "(" + op.substr(1, op.size() - 2) + show(*e.as<UnaryExpr>().operand) + ")";
    }
    case ExprKind::Binary:
    case ExprKind::Assign: {
      const auto& b = e.as<BinaryExpr>();
      std::string op(token_kind_name(b.op));
      return "(" + show(*b.lhs) + " " + op.substr(1, op.size() - 2) + " " + show(*b.rhs) + ")";
    }
    case ExprKind::Conditional: {
      const auto& c = e.as<ConditionalExpr>();
      return "(" + show(*c.cond) + " ? " + show(*c.then_expr) + " : " + show(*c.else_expr) + ")";
    }
    case ExprKind::Call:
      return show(*e.as<CallExpr>().callee) + "(" + show_all(e.as<CallExpr>().args) + ")";
    case ExprKind::Member:
      return show(*e.as<MemberExpr>().object) + "." + e.as<MemberExpr>().name;
    case ExprKind::Index:
      return show(*e.as<IndexExpr>().object) + "[" + show(*e.as<IndexExpr>().index) + "]";
    case ExprKind::New:
      return "new " + e.as<NewExpr>().class_name.spelling() + "(" + show_all(e.as<NewExpr>().args) + ")";
    case ExprKind::Is:
      return "(" + show(*e.as<NewExpr>().operand) + " is " + e.as<NewExpr>().class_name.spelling() + ")";
    default:
      return "?";
  }
}

std::string expr(const std::string& text) {
  Parsed p("void f() { " + text + "; }");
  EXPECT_FALSE(p.diag.has_errors()) << p.diag.format();
  const auto& f = p.member(0).as<FunctionDecl>();
  return show(*f.body->body.at(0)->as<ExprStmt>().expr);
}

TEST(Parser, PrecedenceAndAssociativity) {
  EXPECT_EQ(expr("a = b = 1 + 2 * 3 - 4"), "(a = (b = ((1 + (2 * 3)) - 4)))");
  EXPECT_EQ(expr("x = a || b && c == d < e + f"), "(x = (a || (b && (c == (d < (e + f))))))");
  EXPECT_EQ(expr("x = c ? a : b ? 1 : 2"), "(x = (c ? a : (b ? 1 : 2)))");
  EXPECT_EQ(expr("o.f(1, g(2))[3].h"), "o.f(1, g(2))[3].h");
  EXPECT_EQ(expr("x = mark.n is Node"), "(x = (mark.n is Node))");
  EXPECT_EQ(expr("x = new Mod::C(1) == y"), "(x = (new Mod::C(1) == y))");
  EXPECT_EQ(expr("x += -a * b"), "(x += ((-a) * b))");
}

TEST(Parser, DeclarationsOfEveryKind) {
  Parsed p(R"(
    enum Mode { A, B }
    class C : Node { int x = 1, y; C(int a) { x = a; } int f(int a) { return a; } start o.q; }
    object o : C(2) { place<C> q; place b = 3; transition t { when mark.x > 0; do { } invoke n(1); } }
    net int n(int a) { place s; start s; }
    net Port(place<C> in, place out) {}
    arrow b -> t * 2 when true;
    arrow b -o t;
    arrow t ~> o.q;
    transition s = Port(q, b);
  )");
  ASSERT_FALSE(p.diag.has_errors()) << p.diag.format();
  ASSERT_EQ(p.script.root->members.size(), 9u);
  EXPECT_EQ(p.member(0).as<EnumDecl>().values, (std::vector<std::string>{"A", "B"}));
  const auto& c = p.member(1).as<ClassDecl>();
  EXPECT_EQ(c.base_name, std::vector<std::string>{"Node"});
  ASSERT_EQ(c.members.size(), 5u);  // x, y, constructor, f, start
  EXPECT_TRUE(c.members[2]->as<FunctionDecl>().is_constructor);
  const auto& o = p.member(2).as<ClassDecl>();
  EXPECT_TRUE(o.has_args);
  EXPECT_EQ(o.base_args.size(), 1u);
  const auto& t = o.members[2]->as<TransitionDecl>();
  EXPECT_TRUE(t.when_expr);
  EXPECT_TRUE(t.action);
  EXPECT_EQ(t.invoke_name, std::vector<std::string>{"n"});
  const auto& n = p.member(3).as<ClassDecl>();
  EXPECT_EQ(n.result.spelling(), "int");
  EXPECT_EQ(n.members.front()->kind, DeclKind::Property);  // the value parameter
  const auto& port = p.member(4).as<ClassDecl>();
  EXPECT_TRUE(port.result.is_void);
  EXPECT_EQ(port.members.size(), 2u);  // the two port places
  EXPECT_TRUE(port.members[0]->as<PlaceDecl>().is_port);
  const auto& a1 = p.member(5).as<ArrowDecl>();
  EXPECT_EQ(a1.weight, 2);
  EXPECT_TRUE(a1.condition);
  EXPECT_EQ(p.member(6).as<ArrowDecl>().arrow, ArrowKind::Inhibitor);
  EXPECT_EQ(p.member(7).as<ArrowDecl>().arrow, ArrowKind::Communication);
  EXPECT_EQ(p.member(7).as<ArrowDecl>().to, (std::vector<std::string>{"o", "q"}));
  EXPECT_EQ(p.member(8).as<TransitionDecl>().subst_name, std::vector<std::string>{"Port"});
}

TEST(Parser, TellsDeclarationsFromExpressions) {
  Parsed p(
      "void f() { ref<Node> a = null; vector<double> v; Mod::T t; a < b; x = y; auto z = 1; for (int i : v) "
      "{} for (;;) {} }");
  ASSERT_FALSE(p.diag.has_errors()) << p.diag.format();
  const auto& body = p.member(0).as<FunctionDecl>().body->body;
  ASSERT_EQ(body.size(), 8u);
  EXPECT_EQ(body[0]->kind, StmtKind::Local);
  EXPECT_EQ(body[0]->as<LocalStmt>().type_name.spelling(), "ref<Node>");
  EXPECT_EQ(body[1]->kind, StmtKind::Local);
  EXPECT_EQ(body[2]->kind, StmtKind::Local);
  EXPECT_EQ(body[3]->kind, StmtKind::Expr);
  EXPECT_EQ(body[4]->kind, StmtKind::Expr);
  EXPECT_EQ(body[5]->kind, StmtKind::Local);
  EXPECT_EQ(body[6]->kind, StmtKind::ForEach);
  EXPECT_EQ(body[7]->kind, StmtKind::For);
}

TEST(Parser, InhibitorNeedsTheOAttached) {
  Parsed p("arrow a - o t;");
  EXPECT_THAT(p.diag.format(), HasSubstr("expected an arrow type ('->', '-o' or '~>'), found '-'"));
}

TEST(Parser, RecoversAndReportsEveryError) {
  Parsed p(
      "class A { int x = ; void f() { int a = 1 +; if (a > 1 { a = 3; } return; } }\nint ok = 1;\nobject o : "
      "A(1, ;\n");
  EXPECT_EQ(p.diag.error_count(), 4u) << p.diag.format();
  // What follows the errors was still parsed.
  ASSERT_GE(p.script.root->members.size(), 2u);
  EXPECT_EQ(p.member(1).name, "ok");
  const auto& a = p.member(0).as<ClassDecl>();
  ASSERT_EQ(a.members.size(), 2u);  // x (without its initialiser) and f
  const auto& f = a.members[1]->as<FunctionDecl>();
  EXPECT_EQ(f.body->body.size(), 3u);  // the local a (without its initialiser), the block, return
}

TEST(Parser, DuplicateClausesOfATransitionAreErrors) {
  Parsed p("transition t { when true; when false; do {} do {} invoke a(); invoke b(); }");
  EXPECT_EQ(p.diag.error_count(), 3u) << p.diag.format();
  EXPECT_THAT(p.diag.format(), HasSubstr("more than one condition"));
}

TEST(Parser, DeepNestingIsAnErrorNotACrash) {
  const std::pair<std::string, std::string> nestings[] = {{"(", ")"}, {"{", "}"}, {"a[", "]"}, {"f(", ")"}};
  for (const auto& [open, close] : nestings) {
    std::string text = open == "{" ? "void f() " : "void f() { x = ";
    for (int i = 0; i < 100000; ++i) text += open;
    text += "1";
    for (int i = 0; i < 100000; ++i) text += close;
    text += open == "{" ? "" : "; }";
    Parsed p(text);
    EXPECT_THAT(p.diag.format(), HasSubstr("nesting is too deep")) << open;
    EXPECT_EQ(p.diag.error_count(), 1u) << p.diag.format();  // the deep region is skipped, not re-reported
  }
  Parsed unary("int x = " + std::string(100000, '-') + "1;");
  EXPECT_THAT(unary.diag.format(), HasSubstr("nesting is too deep"));
  std::string chain = "int x = 1";
  for (int i = 0; i < 100000; ++i) chain += " + 1";
  Parsed long_chain(chain + ";");
  EXPECT_THAT(long_chain.diag.format(), HasSubstr("nesting is too deep"));
  std::string classes;
  for (int i = 0; i < 10000; ++i) classes += "class C {";
  Parsed nested_classes(classes);
  EXPECT_THAT(nested_classes.diag.format(), HasSubstr("nesting is too deep"));
  EXPECT_EQ(nested_classes.diag.error_count(), 2u) << "the depth, and one missing '}' at the end";
  std::string types = "vector<";
  for (int i = 0; i < 10000; ++i) types += "vector<";
  Parsed nested_types(types + "int> x;");
  EXPECT_TRUE(nested_types.diag.has_errors());
}

TEST(Parser, HugeLiteralsAndGarbageNeverCrash) {
  Parsed big("int x = " + std::string(100000, '9') + "; string s = \"" + std::string(100000, 'a') + "\";");
  EXPECT_EQ(big.diag.error_count(), 1u);
  // Random bytes and random token soup: any result is fine, as long as it ends.
  std::mt19937 rng(1234);
  const std::string alphabet = "classobjectplacetransitionarrow{}()[];:<>-o~=+*/!&|\"\n 0123456789.xyz\xff";
  for (int round = 0; round < 200; ++round) {
    std::string text;
    const int n = static_cast<int>(rng() % 400);
    for (int i = 0; i < n; ++i) text += alphabet[rng() % alphabet.size()];
    Parsed p(text);
    (void)p;
  }
  SUCCEED();
}

}  // namespace
