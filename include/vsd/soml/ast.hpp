/** @file
 *  @brief The abstract syntax tree of a SOML++ script.
 *
 *  The parser builds it; the checker annotates it in place: every expression gets its static `Type`,
 *  every name its `Binding` (what it resolved to, and for locals their slot in the frame of the
 *  enclosing function, condition or action), every class-like declaration its resolved base. A later
 *  bytecode compiler walks the annotated tree and needs no name lookup of its own.
 *
 *  Ownership: nodes own their children through `std::unique_ptr`; a `Script` owns the top-level
 *  declarations. Raw pointers in annotations (`Binding::decl`, `Type::decl`) point into the same tree
 *  or at MetaTypes/MetaInstances of the registry, which outlive it.
 *
 *  Node kinds are told apart by their `kind` member; `as<T>()` casts to the concrete node of that kind.
 */
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "vsd/soml/lexer.hpp"
#include "vsd/soml/source.hpp"
#include "vsd/soml/types.hpp"

namespace vsd::soml {

/// @brief A type as written: `int`, `ref<Node>`, `Outer::Inner`, `vector<double>`, `void`, `auto`.
struct TypeName {
  SourceLoc loc;
  std::vector<std::string> name;  ///< qualified name parts; empty for void and auto
  std::vector<TypeName> args;     ///< template arguments
  bool is_void = false;
  bool is_auto = false;
  /// @brief The name as written ("ref<Node>").
  [[nodiscard]] std::string spelling() const;
};

// ---- expressions ------------------------------------------------------------------------------------

enum class ExprKind : unsigned char {
  Int,
  Float,
  String,
  Bool,
  Null,
  This,
  Mark,
  Name,         ///< a simple or qualified name (`x`, `Mode::Idle`)
  Unary,        ///< ! - + and prefix ++ --
  Postfix,      ///< postfix ++ --
  Binary,       ///< arithmetic, comparison, logic
  Assign,       ///< = += -= *= /= %=
  Conditional,  ///< c ? a : b
  Call,
  Member,  ///< object.name
  Index,   ///< object[index]
  New,     ///< new C(args)
  Is,      ///< x is C
  As       ///< x as C
};

struct Expr {
  explicit Expr(ExprKind k, SourceLoc l) : kind(k), loc(l) {}
  virtual ~Expr() = default;
  Expr(const Expr&) = delete;
  Expr& operator=(const Expr&) = delete;
  template <class T>
  [[nodiscard]] T& as() noexcept {
    return static_cast<T&>(*this);
  }
  template <class T>
  [[nodiscard]] const T& as() const noexcept {
    return static_cast<const T&>(*this);
  }

  ExprKind kind;
  SourceLoc loc;
  Type type;  ///< set by the checker
};
using ExprPtr = std::unique_ptr<Expr>;

struct LiteralExpr : Expr {
  using Expr::Expr;
  std::int64_t int_value = 0;
  double float_value = 0.0;
  bool bool_value = false;
  std::string string_value;
};

struct NameExpr : Expr {
  using Expr::Expr;
  std::vector<std::string> parts;  ///< one part for `x`, more for `A::B`
  Binding binding;                 ///< set by the checker
  [[nodiscard]] std::string spelling() const;
};

struct UnaryExpr : Expr {  // also Postfix
  using Expr::Expr;
  TokenKind op = TokenKind::Minus;
  ExprPtr operand;
};

struct BinaryExpr : Expr {  // also Assign
  using Expr::Expr;
  TokenKind op = TokenKind::Plus;
  ExprPtr lhs, rhs;
};

struct ConditionalExpr : Expr {
  using Expr::Expr;
  ExprPtr cond, then_expr, else_expr;
};

struct CallExpr : Expr {
  using Expr::Expr;
  ExprPtr callee;
  std::vector<ExprPtr> args;
  Binding binding;  ///< what is called (function, method, built-in, conversion), set by the checker
};

struct MemberExpr : Expr {
  using Expr::Expr;
  ExprPtr object;
  std::string name;
  SourceLoc name_loc;
  Binding binding;  ///< the member (property, method, place, ...), set by the checker
};

struct IndexExpr : Expr {
  using Expr::Expr;
  ExprPtr object, index;
};

struct NewExpr : Expr {  // also Is and As (then `operand` is set and `args` is empty)
  using Expr::Expr;
  TypeName class_name;
  ExprPtr operand;
  std::vector<ExprPtr> args;
  Binding binding;  ///< the class (and for `new`, its constructor), set by the checker
};

// ---- statements -------------------------------------------------------------------------------------

enum class StmtKind : unsigned char {
  Block,
  Local,
  If,
  While,
  For,
  ForEach,
  Return,
  Finish,
  Break,
  Continue,
  Expr
};

struct Stmt {
  explicit Stmt(StmtKind k, SourceLoc l) : kind(k), loc(l) {}
  virtual ~Stmt() = default;
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;
  template <class T>
  [[nodiscard]] T& as() noexcept {
    return static_cast<T&>(*this);
  }
  template <class T>
  [[nodiscard]] const T& as() const noexcept {
    return static_cast<const T&>(*this);
  }
  StmtKind kind;
  SourceLoc loc;
};
using StmtPtr = std::unique_ptr<Stmt>;

struct BlockStmt : Stmt {
  using Stmt::Stmt;
  std::vector<StmtPtr> body;
  /// A statement of it did not parse (its error is reported) or the file ended inside it: the checker
  /// takes the block as returning, so that the lost statement adds no "must return" error of its own.
  bool lost = false;
};

struct LocalStmt : Stmt {  // `T name = init;`; also the variable of a ForEach
  using Stmt::Stmt;
  TypeName type_name;
  std::string name;
  SourceLoc name_loc;
  ExprPtr init;
  Type type;      ///< the variable's type (resolved, `auto` inferred), set by the checker
  int slot = -1;  ///< frame slot, set by the checker
};

struct IfStmt : Stmt {
  using Stmt::Stmt;
  ExprPtr cond;
  StmtPtr then_stmt, else_stmt;
};

struct WhileStmt : Stmt {
  using Stmt::Stmt;
  ExprPtr cond;
  StmtPtr body;
};

struct ForStmt : Stmt {
  using Stmt::Stmt;
  StmtPtr init;  ///< LocalStmt or ExprStmt or null
  ExprPtr cond, step;
  StmtPtr body;
};

struct ForEachStmt : Stmt {
  using Stmt::Stmt;
  std::unique_ptr<LocalStmt> var;
  ExprPtr range;
  StmtPtr body;
};

struct ReturnStmt : Stmt {  // also Finish
  using Stmt::Stmt;
  ExprPtr value;
};

struct ExprStmt : Stmt {
  using Stmt::Stmt;
  ExprPtr expr;
};

// ---- declarations -----------------------------------------------------------------------------------

enum class DeclKind : unsigned char {
  Enum,
  Class,
  Object,
  Net,
  Place,
  Transition,
  Arrow,
  Start,
  Function,  ///< also constructors (FunctionDecl::is_constructor)
  Property,
  Script  ///< the implicit script object
};

/// @brief Arrow types.
enum class ArrowKind : unsigned char { Normal, Inhibitor, Communication };

struct Decl {
  Decl(DeclKind k, SourceLoc l) : kind(k), loc(l) {}
  virtual ~Decl() = default;
  Decl(const Decl&) = delete;
  Decl& operator=(const Decl&) = delete;
  template <class T>
  [[nodiscard]] T& as() noexcept {
    return static_cast<T&>(*this);
  }
  template <class T>
  [[nodiscard]] const T& as() const noexcept {
    return static_cast<const T&>(*this);
  }
  /// @brief True for declarations with members and instances: class, object, net, script.
  [[nodiscard]] bool is_class_like() const noexcept {
    return kind == DeclKind::Class || kind == DeclKind::Object || kind == DeclKind::Net ||
           kind == DeclKind::Script;
  }
  /// @brief True for declarations that have a member scope (class-like, place, transition).
  [[nodiscard]] bool has_members() const noexcept {
    return is_class_like() || kind == DeclKind::Place || kind == DeclKind::Transition;
  }
  [[nodiscard]] std::string_view kind_name() const noexcept;

  DeclKind kind;
  SourceLoc loc;  ///< the declaration's name
  std::string name;
  Decl* parent = nullptr;  ///< the enclosing declaration (null for the script)
};
using DeclPtr = std::unique_ptr<Decl>;

struct EnumDecl : Decl {
  using Decl::Decl;
  std::vector<std::string> values;
  std::vector<SourceLoc> value_locs;
};

struct Param {
  TypeName type_name;
  std::string name;
  SourceLoc loc;
  bool is_place = false;                 ///< a port place of a net
  std::vector<std::string> token_class;  ///< port place: its token class (empty: black tokens)
  Type type;                             ///< set by the checker
};

/// @brief Base of declarations that hold members: class, object, net, place, transition, script.
struct ScopeDecl : Decl {
  using Decl::Decl;
  std::vector<DeclPtr> members;
};

/// @brief The scope that declares @p d (every parent is a ScopeDecl), or null for the script.
[[nodiscard]] inline const ScopeDecl* parent_scope(const Decl& d) noexcept {
  return d.parent != nullptr ? &static_cast<const ScopeDecl&>(*d.parent) : nullptr;
}

/// @brief True for an instance that exists once per program: the script object, and objects not
/// inside a class or net (only inside objects and the script).
[[nodiscard]] inline bool is_static_instance(const Decl& d) noexcept {
  if (d.kind == DeclKind::Script) return true;
  if (d.kind != DeclKind::Object) return false;
  for (const Decl* p = d.parent; p != nullptr; p = p->parent)
    if (p->kind != DeclKind::Object && p->kind != DeclKind::Script) return false;
  return true;
}

/// @brief Class, object, net and the script object.
struct ClassDecl : ScopeDecl {
  using ScopeDecl::ScopeDecl;
  std::vector<std::string> base_name;  ///< as written; empty when none
  SourceLoc base_loc;
  bool has_args = false;           ///< object: `: C(args)` was written
  std::vector<ExprPtr> base_args;  ///< object: constructor arguments
  // Nets
  TypeName result;  ///< net result type (void when none)
  std::vector<Param> params;
  // Set by the checker
  ClassRef base;                                     ///< the resolved base class
  const struct FunctionDecl* constructor = nullptr;  ///< own constructor, if any
  const struct StartDecl* start = nullptr;           ///< own start-place statement, if any
  Type result_type;
  bool is_port_net = false;
};

struct PlaceDecl : ScopeDecl {
  using ScopeDecl::ScopeDecl;
  std::vector<std::string> token_class;  ///< empty: black tokens
  SourceLoc token_loc;
  ExprPtr initial;  ///< initial marking (black places)
  // Set by the checker
  ClassRef token;  ///< the token class (empty for black tokens)
  std::int64_t initial_tokens = 0;
  bool is_port = false;  ///< a net's port parameter (the parser adds one place per port)
};

struct ArrowDecl;

struct TransitionDecl : ScopeDecl {
  using ScopeDecl::ScopeDecl;
  ExprPtr when_expr;                      ///< `when expr;`
  std::unique_ptr<BlockStmt> when_block;  ///< `when { ... }`
  std::unique_ptr<BlockStmt> action;      ///< `do { ... }`
  std::vector<std::string> invoke_name;   ///< `invoke net(args);`
  SourceLoc invoke_loc;
  std::vector<ExprPtr> invoke_args;
  std::vector<std::string> subst_name;  ///< `transition t = Net(args);`
  SourceLoc subst_loc;
  std::vector<ExprPtr> subst_args;
  // Set by the checker
  std::vector<const ArrowDecl*> inputs, outputs;  ///< arrows into and out of the transition
  const PlaceDecl* mark_place = nullptr;          ///< the object input place (gives `mark` its type)
  const ClassDecl* invoked = nullptr;
  const ClassDecl* substituted = nullptr;
  int when_slots = 0, action_slots = 0;  ///< frame sizes
};

struct ArrowDecl : Decl {
  using Decl::Decl;
  ArrowKind arrow = ArrowKind::Normal;
  std::vector<std::string> from, to;
  SourceLoc from_loc, to_loc;
  std::int64_t weight = 1;
  SourceLoc weight_loc;
  ExprPtr condition;
  // Set by the checker
  const Decl* from_decl = nullptr;  ///< PlaceDecl or TransitionDecl
  const Decl* to_decl = nullptr;
  int condition_slots = 0;
};

struct StartDecl : Decl {
  using Decl::Decl;
  std::vector<std::string> place;
  const PlaceDecl* place_decl = nullptr;  ///< set by the checker
};

struct FunctionDecl : Decl {
  using Decl::Decl;
  bool is_constructor = false;
  TypeName result;
  std::vector<Param> params;
  std::unique_ptr<BlockStmt> body;
  // Set by the checker
  Type result_type;
  int slots = 0;  ///< frame size: parameters first, then locals
};

struct PropertyDecl : Decl {
  using Decl::Decl;
  TypeName type_name;
  ExprPtr init;
  bool is_param = false;  ///< a net's value parameter (the parser adds one property per parameter)
  Type type;              ///< set by the checker
};

/// @brief A parsed script: the implicit script object and its members.
struct Script {
  std::unique_ptr<ClassDecl> root;
};

}  // namespace vsd::soml
