// Fuzzes SOML++ (lexer, parser, checker, and for clean scripts the loader, VM and executor): any input
// must end with diagnostics or a vsd::Error, never a crash, a hang or a sanitizer report. Beyond that it
// checks what the checker promises:
//  - every diagnostic points into the source (line in range, column at most one past the line's end);
//  - checking is deterministic (the same text gives the same diagnostics);
//  - a script without errors is fully annotated: no expression has the Error type, every arrow has both
//    ends and every start statement its place (the Error type is only for what was reported).
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/soml.hpp"

namespace {

using namespace vsd::soml;

void require(bool ok) {
  if (!ok) std::abort();
}

void walk(const Expr* e);
void walk(const Stmt* s);

void walk_all(const std::vector<ExprPtr>& list) {
  for (const auto& e : list) walk(e.get());
}

void walk(const Expr* e) {
  if (e == nullptr) return;
  require(!e->type.is_error());
  switch (e->kind) {
    case ExprKind::Unary:
    case ExprKind::Postfix:
      walk(e->as<UnaryExpr>().operand.get());
      break;
    case ExprKind::Binary:
    case ExprKind::Assign:
      walk(e->as<BinaryExpr>().lhs.get());
      walk(e->as<BinaryExpr>().rhs.get());
      break;
    case ExprKind::Conditional:
      walk(e->as<ConditionalExpr>().cond.get());
      walk(e->as<ConditionalExpr>().then_expr.get());
      walk(e->as<ConditionalExpr>().else_expr.get());
      break;
    case ExprKind::Call:
      walk(e->as<CallExpr>().callee.get());
      walk_all(e->as<CallExpr>().args);
      break;
    case ExprKind::Member:
      walk(e->as<MemberExpr>().object.get());
      break;
    case ExprKind::Index:
      walk(e->as<IndexExpr>().object.get());
      walk(e->as<IndexExpr>().index.get());
      break;
    case ExprKind::New:
    case ExprKind::Is:
    case ExprKind::As:
      walk(e->as<NewExpr>().operand.get());
      walk_all(e->as<NewExpr>().args);
      break;
    default:
      break;
  }
}

void walk(const Stmt* s) {
  if (s == nullptr) return;
  switch (s->kind) {
    case StmtKind::Block:
      for (const auto& c : s->as<BlockStmt>().body) walk(c.get());
      break;
    case StmtKind::Local:
      walk(s->as<LocalStmt>().init.get());
      break;
    case StmtKind::If:
      walk(s->as<IfStmt>().cond.get());
      walk(s->as<IfStmt>().then_stmt.get());
      walk(s->as<IfStmt>().else_stmt.get());
      break;
    case StmtKind::While:
      walk(s->as<WhileStmt>().cond.get());
      walk(s->as<WhileStmt>().body.get());
      break;
    case StmtKind::For:
      walk(s->as<ForStmt>().init.get());
      walk(s->as<ForStmt>().cond.get());
      walk(s->as<ForStmt>().step.get());
      walk(s->as<ForStmt>().body.get());
      break;
    case StmtKind::ForEach:
      walk(s->as<ForEachStmt>().range.get());
      walk(s->as<ForEachStmt>().body.get());
      break;
    case StmtKind::Return:
    case StmtKind::Finish:
      walk(s->as<ReturnStmt>().value.get());
      break;
    case StmtKind::Expr:
      walk(s->as<ExprStmt>().expr.get());
      break;
    default:
      break;
  }
}

void walk(const Decl& d) {
  switch (d.kind) {
    case DeclKind::Property:
      walk(d.as<PropertyDecl>().init.get());
      return;
    case DeclKind::Function:
      walk(d.as<FunctionDecl>().body.get());
      return;
    case DeclKind::Arrow:
      require(d.as<ArrowDecl>().from_decl != nullptr && d.as<ArrowDecl>().to_decl != nullptr);
      walk(d.as<ArrowDecl>().condition.get());
      return;
    case DeclKind::Start:
      require(d.as<StartDecl>().place_decl != nullptr);
      return;
    case DeclKind::Place:
      walk(d.as<PlaceDecl>().initial.get());
      break;
    case DeclKind::Transition: {
      const auto& t = d.as<TransitionDecl>();
      walk(t.when_expr.get());
      walk(t.when_block.get());
      walk(t.action.get());
      walk_all(t.invoke_args);
      walk_all(t.subst_args);
      break;
    }
    case DeclKind::Object:
      walk_all(d.as<ClassDecl>().base_args);
      break;
    default:
      break;
  }
  if (d.has_members())
    for (const auto& m : d.as<ScopeDecl>().members) walk(*m);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const auto result = check_source("fuzz.soml", text);
  const Source& source = *result->source;
  for (const Diagnostic& d : result->diagnostics.all()) {
    require(d.loc.line >= 1 && d.loc.line <= source.line_count());
    require(d.loc.column >= 1 && d.loc.column <= source.line_text(d.loc.line).size() + 2);
  }
  const std::string formatted = result->diagnostics.format();
  require(check_source("fuzz.soml", text)->diagnostics.format() == formatted);
  if (result->ok()) {
    walk(*result->script.root);
    // A clean script is loaded and run briefly: load errors ("not supported yet") and run-time errors
    // are vsd::Errors; anything else (a crash, a hang, a sanitizer report) is a bug. Each input gets a
    // registry of its own, so the classes it defines go with it.
    vsd::Registry registry;
    vsd::Environment env(0, registry);
    std::ostringstream out;
    RunOptions options;
    options.instruction_budget = 20000;
    options.max_depth = 64;
    options.out = &out;
    try {
      auto program = Program::load(env.main_state(), "fuzz.soml", text, options);
      program->step(200);
    } catch (const vsd::Error&) {
    }
  }
  return 0;
}
