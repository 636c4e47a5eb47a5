// The SOML++ checker (see checker.hpp). Four passes over the AST:
//   1. declare: member tables of every scope, duplicate names, members in the wrong place;
//   2. headers: base classes (and cycles), property types, function and net signatures, place token
//      classes, start places, arrows (the net structure), marks, substitutions and invocations;
//   3. bodies: initialisers, functions, conditions, actions and arrow conditions, with locals in frames.
// Later passes rely on what earlier ones resolved; anything unresolved has the Error type and stays quiet.
#include "vsd/soml/checker.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "vsd/core/meta_instance.hpp"
#include "vsd/core/meta_method.hpp"
#include "vsd/core/meta_property.hpp"
#include "vsd/core/node.hpp"
#include "vsd/soml/net_classes.hpp"
#include "vsd/soml/parser.hpp"

namespace vsd::soml {

namespace {

using K = Type::Kind;
using BK = Binding::Kind;

std::string q(std::string_view s) { return "'" + std::string(s) + "'"; }

// The kind of @p d with its article: "a class", "an enum", "an object".
std::string a_kind(const Decl& d) {
  const std::string_view k = d.kind_name();
  return (k.find_first_of("aeiou") == 0 ? "an " : "a ") + std::string(k);
}

std::string join(const std::vector<std::string>& parts, const char* sep) {
  std::string s;
  for (const auto& p : parts) {
    if (!s.empty()) s += sep;
    s += p;
  }
  return s;
}

std::string plural(std::size_t n, const char* word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

// ---- frames of locals --------------------------------------------------------------------------------

struct Local {
  std::string name;
  Type type;
  int slot;
  SourceLoc loc;
};

// The locals of one function, condition, action or arrow condition. Slots of a block are reused after
// it ends; `max` is the frame size the compiler allocates. Each block scope has a hash index, so a
// function with very many locals checks in linear time.
struct Frame {
  struct Scope {
    std::vector<Local> locals;
    std::unordered_map<std::string, std::size_t> index;
  };
  std::vector<Scope> scopes{1};
  int next = 0;
  int max = 0;

  void push() { scopes.emplace_back(); }
  void pop() {
    next -= static_cast<int>(scopes.back().locals.size());
    scopes.pop_back();
  }
  const Local* find(const std::string& name) const {
    for (auto s = scopes.rbegin(); s != scopes.rend(); ++s)
      if (auto it = s->index.find(name); it != s->index.end()) return &s->locals[it->second];
    return nullptr;
  }
  const Local* find_innermost(const std::string& name) const {
    const Scope& s = scopes.back();
    auto it = s.index.find(name);
    return it == s.index.end() ? nullptr : &s.locals[it->second];
  }
  int add(std::string name, Type type, SourceLoc loc) {
    Scope& s = scopes.back();
    s.index.emplace(name, s.locals.size());  // a duplicate keeps finding the first one
    s.locals.push_back({std::move(name), type, next, loc});
    max = std::max(max, ++next);
    return next - 1;
  }
};

// Calls report(i, j) for each name i that equals an earlier name j (enum values, parameters); linear.
template <class NameOf, class Report>
void for_each_duplicate(std::size_t n, NameOf name_of, Report report) {
  std::unordered_map<std::string, std::size_t> first;
  for (std::size_t i = 0; i < n; ++i) {
    auto [it, inserted] = first.emplace(name_of(i), i);
    if (!inserted) report(i, it->second);
  }
}

enum class Body { Initializer, Function, Condition, Action, ArrowCondition, Argument };

struct Context {
  const ScopeDecl* scope = nullptr;
  Frame* frame = nullptr;
  Body body = Body::Initializer;
  bool has_mark = false;
  Type mark;
  std::string no_mark;  // why there is no mark here
  Type result = Type::of(K::Void);
  const FunctionDecl* function = nullptr;
  const TransitionDecl* transition = nullptr;
  const ClassDecl* finish_net = nullptr;
  int loops = 0;
};

// What a name found in a scope is.
struct Found {
  const Decl* decl = nullptr;
  const MetaProperty* prop = nullptr;
  const MetaMethod* method = nullptr;
  int outer = 0;
  [[nodiscard]] bool ok() const noexcept { return decl != nullptr || prop != nullptr || method != nullptr; }
};

struct BuiltinFn {
  std::string_view name;
  Builtin id;
};
constexpr BuiltinFn builtin_functions[] = {
    {"print", Builtin::Print}, {"sqrt", Builtin::Sqrt}, {"abs", Builtin::Abs},
    {"floor", Builtin::Floor}, {"ceil", Builtin::Ceil}, {"min", Builtin::Min},
    {"max", Builtin::Max},     {"len", Builtin::Len},   {"find", Builtin::Find}};

// The Eigen structs that have arithmetic in code (docs/soml.md 4.14), by their static type.
enum class Eig : unsigned char { None, V2, V3, V4, Quat, Iso };
Eig eig(const Type& t) noexcept {
  if (t.kind != K::Struct) return Eig::None;
  if (t.meta == &meta_type<Eigen::Vector3d>()) return Eig::V3;
  if (t.meta == &meta_type<Eigen::Vector2d>()) return Eig::V2;
  if (t.meta == &meta_type<Eigen::Vector4d>()) return Eig::V4;
  if (t.meta == &meta_type<Eigen::Quaterniond>()) return Eig::Quat;
  if (t.meta == &meta_type<Eigen::Isometry3d>()) return Eig::Iso;
  return Eig::None;
}
bool is_vec(Eig e) noexcept { return e == Eig::V2 || e == Eig::V3 || e == Eig::V4; }

// The type of `l op r` (+ - * /) when an operand is a struct; the error type when it is not defined.
Type struct_binary(TokenKind op, const Type& l, const Type& r) {
  const Eig a = eig(l), b = eig(r);
  const bool rot = a == Eig::Quat || a == Eig::Iso;
  switch (op) {
    case TokenKind::Plus:
    case TokenKind::Minus:
      if (is_vec(a) && a == b) return l;
      break;
    case TokenKind::Star:
      if (is_vec(a) && r.is_numeric()) return l;
      if (is_vec(b) && l.is_numeric()) return r;
      if (rot && a == b) return l;        // q * q, T * T
      if (rot && b == Eig::V3) return r;  // q * v, T * v
      break;
    case TokenKind::Slash:
      if (is_vec(a) && r.is_numeric()) return l;
      break;
    default:
      break;
  }
  return Type::error();
}

// What struct_binary accepts, for its type mismatch message.
const char* struct_operands(TokenKind op) {
  switch (op) {
    case TokenKind::Plus:
    case TokenKind::Minus:
      return "two numbers or two vectors of one size";
    case TokenKind::Star:
      return "numbers, a vector and a number, two Quaterniond or two Isometry3d, or a Quaterniond or "
             "Isometry3d and a Vector3d";
    default:
      return "numbers, or a vector and a number";
  }
}

// The methods of the Eigen structs: the operation of @p name on a value of kind @p e, if it has one.
bool struct_method(Eig e, std::string_view name, StructOp& op) {
  if (is_vec(e)) {
    if (name == "dot")
      op = StructOp::Dot;
    else if (name == "norm")
      op = StructOp::Norm;
    else if (name == "squared_norm")
      op = StructOp::SquaredNorm;
    else if (name == "normalized")
      op = StructOp::Normalized;
    else if (name == "cross" && e == Eig::V3)
      op = StructOp::Cross;
    else
      return false;
    return true;
  }
  if (e == Eig::Quat) {
    if (name == "normalized")
      op = StructOp::Normalized;
    else if (name == "inverse")
      op = StructOp::Inverse;
    else if (name == "conjugate")
      op = StructOp::Conjugate;
    else
      return false;
    return true;
  }
  if (e == Eig::Iso && name == "inverse") {
    op = StructOp::Inverse;
    return true;
  }
  return false;
}

class CheckerImpl {
 public:
  CheckerImpl(Diagnostics& d, const Registry& r) : diag_(d), reg_(r) {}
  void run(Script& script);

 private:
  // pass 1
  void declare(ScopeDecl& s);
  // pass 2
  void resolve_base(ClassDecl& c);
  void resolve_signatures();
  void resolve_start(StartDecl& s);
  void resolve_arrow(ArrowDecl& a);
  void resolve_transition(TransitionDecl& t);
  void resolve_net(ClassDecl& n);
  void check_override(const FunctionDecl& f);
  // pass 3
  void check_property(PropertyDecl& p);
  void check_place(PlaceDecl& p);
  void check_function(FunctionDecl& f);
  void check_object_args(ClassDecl& c);
  void check_transition(TransitionDecl& t);
  void check_arrow_condition(ArrowDecl& a);

  // lookup
  const std::unordered_map<std::string, Decl*>* members(const ScopeDecl& s) const {
    auto it = members_.find(&s);
    return it == members_.end() ? nullptr : &it->second;
  }
  Found find_own(const ScopeDecl& s, std::string_view name) const;
  Found find_in_class(ClassRef c, std::string_view name) const;
  Found find_member(const ScopeDecl& s, std::string_view name) const;
  Found find_lexical(const ScopeDecl* s, std::string_view name) const;
  ClassRef resolve_class(const std::vector<std::string>& parts, SourceLoc loc, const ScopeDecl& scope,
                         bool allow_object, const char* what);
  Type resolve_type(const TypeName& t, const ScopeDecl& scope);
  Type type_of_meta(const MetaType* m) const;
  // The type of the elements of vector type @p v (a script enum's, or its MetaType's element).
  Type element_of(const Type& v) const;
  struct Endpoint {
    const Decl* decl = nullptr;
    bool local = false;
  };
  Endpoint resolve_endpoint(const std::vector<std::string>& path, SourceLoc loc, const ScopeDecl& scope,
                            const std::string& role);
  static ClassRef class_of(const ScopeDecl& s) {
    return s.is_class_like() ? ClassRef{&s.as<ClassDecl>(), nullptr} : ClassRef{};
  }

  // expressions and statements
  Type check_expr(Expr& e, Context& cx);
  Type check_value(Expr& e, Context& cx);  // an expression that must yield a value
  void expect_type(Expr& e, const Type& want, Context& cx, const std::string& what);
  Type check_name(NameExpr& e, Context& cx);
  Type bind_found(const Found& f, Binding& b, SourceLoc loc, std::string_view name);
  Type check_qualified(NameExpr& e, Context& cx);
  Type check_member(MemberExpr& e, Context& cx);
  Type check_call(CallExpr& e, Context& cx);
  Type check_builtin_call(CallExpr& e, Builtin id, std::string_view name, const Type& self, Context& cx);
  void check_args(std::vector<ExprPtr>& args, const std::vector<Type>& params, SourceLoc loc,
                  const std::string& callee, Context& cx);
  Type check_binary(BinaryExpr& e, Context& cx);
  Type check_assign(BinaryExpr& e, Context& cx);
  bool check_lvalue(Expr& e, Context& cx);
  Type check_new(NewExpr& e, Context& cx);
  void check_stmt(Stmt& s, Context& cx);
  void check_block_in_scope(BlockStmt& b, Context& cx);
  void check_local(LocalStmt& l, Context& cx);
  static bool always_returns(const Stmt& s);
  Type this_type(const Context& cx) const;

  Diagnostics& diag_;
  const Registry& reg_;
  std::unordered_map<const ScopeDecl*, std::unordered_map<std::string, Decl*>> members_;
  std::vector<ClassDecl*> classes_;  // class, object, net (pre-order)
  std::vector<PropertyDecl*> properties_;
  std::vector<FunctionDecl*> functions_;
  std::vector<PlaceDecl*> places_;
  std::vector<TransitionDecl*> transitions_;
  std::vector<ArrowDecl*> arrows_;
  std::vector<StartDecl*> starts_;
  ClassDecl* root_ = nullptr;
};

// ---- pass 1: declarations ----------------------------------------------------------------------------

void CheckerImpl::declare(ScopeDecl& s) {
  auto& table = members_[&s];
  for (DeclPtr& m : s.members) {
    Decl& d = *m;
    // What may stand where.
    if ((s.kind == DeclKind::Place || s.kind == DeclKind::Transition) && d.kind != DeclKind::Property &&
        d.kind != DeclKind::Function) {
      diag_.error(d.loc, "a " + std::string(s.kind_name()) + " holds only properties and functions, not " +
                             a_kind(d));
      continue;
    }
    switch (d.kind) {
      case DeclKind::Arrow:
        arrows_.push_back(&d.as<ArrowDecl>());
        continue;
      case DeclKind::Start:
        if (s.kind == DeclKind::Script) {
          diag_.error(d.loc,
                      "the script itself cannot be a token: 'start' belongs in a class, object or net");
          continue;
        }
        starts_.push_back(&d.as<StartDecl>());
        continue;
      case DeclKind::Function:
        if (d.as<FunctionDecl>().is_constructor) {
          if ((s.kind != DeclKind::Class && s.kind != DeclKind::Object) || d.name != s.name) {
            diag_.error(
                d.loc,
                "function " + q(d.name) +
                    " needs a return type (only a class's constructor, named like the class, has none)");
            continue;
          }
          auto& c = s.as<ClassDecl>();
          if (c.constructor != nullptr) {
            diag_.error(d.loc, "duplicate definition of the constructor of " + q(s.name) +
                                   " (first defined at line " + std::to_string(c.constructor->loc.line) +
                                   ")");
            continue;
          }
          c.constructor = &d.as<FunctionDecl>();
          functions_.push_back(&d.as<FunctionDecl>());
          continue;
        }
        functions_.push_back(&d.as<FunctionDecl>());
        break;
      case DeclKind::Property:
        properties_.push_back(&d.as<PropertyDecl>());
        break;
      case DeclKind::Place:
        places_.push_back(&d.as<PlaceDecl>());
        break;
      case DeclKind::Transition:
        transitions_.push_back(&d.as<TransitionDecl>());
        break;
      case DeclKind::Class:
      case DeclKind::Object:
      case DeclKind::Net:
        classes_.push_back(&d.as<ClassDecl>());
        break;
      case DeclKind::Enum: {
        auto& e = d.as<EnumDecl>();
        for_each_duplicate(
            e.values.size(), [&](std::size_t i) { return e.values[i]; },
            [&](std::size_t i, std::size_t j) {
              diag_.error(e.value_locs[i], "duplicate definition of " + q(e.values[i]) + " in enum " +
                                               q(e.name) + " (first defined at line " +
                                               std::to_string(e.value_locs[j].line) + ")");
            });
        break;
      }
      default:
        break;
    }
    auto [it, inserted] = table.emplace(d.name, &d);
    if (!inserted) {
      diag_.error(d.loc, "duplicate definition of " + q(d.name) + " (first defined at line " +
                             std::to_string(it->second->loc.line) + ")");
      continue;  // the first definition stays; the duplicate is still checked below
    }
  }
  for (DeclPtr& m : s.members)
    if (m->has_members() && members_.find(&m->as<ScopeDecl>()) == members_.end()) declare(m->as<ScopeDecl>());
}

// ---- lookup -------------------------------------------------------------------------------------------

Found CheckerImpl::find_own(const ScopeDecl& s, std::string_view name) const {
  if (const auto* t = members(s)) {
    auto it = t->find(std::string(name));
    if (it != t->end()) return {it->second, nullptr, nullptr, 0};
  }
  return {};
}

Found CheckerImpl::find_in_class(ClassRef c, std::string_view name) const {
  // Script classes first (own, then bases), then the nearest built-in class's meta-information.
  std::size_t guard = 0;
  while (c.decl != nullptr && guard++ <= classes_.size() + 1) {
    Found f = find_own(*c.decl, name);
    if (f.ok()) return f;
    c = c.base();
  }
  if (c.meta != nullptr) {
    if (const MetaProperty* p = c.meta->find_property(name)) return {nullptr, p, nullptr, 0};
    if (const MetaMethod* m = c.meta->find_method(name)) return {nullptr, nullptr, m, 0};
  }
  return {};
}

Found CheckerImpl::find_member(const ScopeDecl& s, std::string_view name) const {
  if (s.is_class_like()) return find_in_class(ClassRef{&s.as<ClassDecl>(), nullptr}, name);
  return find_own(s, name);
}

Found CheckerImpl::find_lexical(const ScopeDecl* s, std::string_view name) const {
  int outer = 0;
  for (; s != nullptr; s = parent_scope(*s), ++outer) {
    Found f = find_member(*s, name);
    if (f.ok()) {
      f.outer = outer;
      return f;
    }
  }
  return {};
}

Type CheckerImpl::type_of_meta(const MetaType* m) const {
  if (m == nullptr) return Type::of(K::Void);
  Type t;
  t.meta = m;
  switch (m->kind()) {
    case TypeKind::Bool:
      t.kind = K::Bool;
      break;
    case TypeKind::Int:
    case TypeKind::UInt:
      t.kind = K::Int;
      break;
    case TypeKind::Float:
    case TypeKind::Double:
      t.kind = K::Double;
      break;
    case TypeKind::String:
      t.kind = K::String;
      break;
    case TypeKind::Enum:
    case TypeKind::Flags:
      t.kind = K::Enum;
      break;
    case TypeKind::Struct:
      t.kind = K::Struct;
      break;
    case TypeKind::Vector:
      t.kind = K::Vector;
      break;
    case TypeKind::Ref:
    case TypeKind::SharedRef:
      t.kind = K::Ref;
      t.cls = ClassRef{nullptr, m->target()};
      t.shared = m->kind() == TypeKind::SharedRef;
      break;
    case TypeKind::RefList:
    case TypeKind::SharedRefList:
      t.kind = K::List;
      t.cls = ClassRef{nullptr, m->target()};
      t.shared = m->kind() == TypeKind::SharedRefList;
      break;
  }
  if ((t.kind == K::Ref || t.kind == K::List) && t.cls.meta == nullptr) return Type::error();
  return t;
}

Type CheckerImpl::element_of(const Type& v) const {
  if (v.enum_decl != nullptr) {
    Type e = Type::of(K::Enum);
    e.enum_decl = v.enum_decl;
    return e;
  }
  return v.meta != nullptr ? type_of_meta(v.meta->element()) : Type::error();
}

ClassRef CheckerImpl::resolve_class(const std::vector<std::string>& parts, SourceLoc loc,
                                    const ScopeDecl& scope, bool allow_object, const char* what) {
  Found f = find_lexical(&scope, parts[0]);
  for (std::size_t i = 1; f.ok() && i < parts.size(); ++i) {
    if (f.decl == nullptr || !f.decl->has_members()) {
      f = {};
      break;
    }
    f = find_member(f.decl->as<ScopeDecl>(), parts[i]);
  }
  const std::string name = join(parts, "::");
  if (f.decl != nullptr) {
    if (f.decl->kind == DeclKind::Class || (allow_object && f.decl->kind == DeclKind::Object))
      return ClassRef{&f.decl->as<ClassDecl>(), nullptr};
    diag_.error(loc, q(name) + " is " + a_kind(*f.decl) + ", not a class (" + what + ")");
    return {};
  }
  if (f.ok()) {
    diag_.error(loc, q(name) + " is not a class (" + what + ")");
    return {};
  }
  if (const MetaInstance* m = reg_.find_class(name)) return ClassRef{nullptr, m};
  diag_.error(loc, "undefined class " + q(name) + " (" + what + ")");
  return {};
}

Type CheckerImpl::resolve_type(const TypeName& t, const ScopeDecl& scope) {
  if (t.is_void) return Type::of(K::Void);
  if (t.is_auto) {
    diag_.error(t.loc, "'auto' is only allowed for local variables with an initialiser");
    return Type::error();
  }
  const std::string name = join(t.name, "::");
  if (!t.args.empty()) {
    const bool is_ref = name == "ref" || name == "shared";
    const bool is_list = name == "list" || name == "shared_list";
    if (is_ref || is_list) {
      if (t.args.size() != 1 || !t.args[0].args.empty() || t.args[0].name.empty()) {
        diag_.error(t.loc, q(name) + " takes one class: " + name + "<Class>");
        return Type::error();
      }
      ClassRef c = resolve_class(t.args[0].name, t.args[0].loc, scope, true, "in a reference type");
      if (c.empty()) return Type::error();
      Type r = Type::reference(c, name == "shared" || name == "shared_list");
      if (is_list) r.kind = K::List;
      return r;
    }
    if (name == "vector") {
      if (t.args.size() != 1) {
        diag_.error(t.loc, "'vector' takes one element type: vector<T>");
        return Type::error();
      }
      Type e = resolve_type(t.args[0], scope);
      if (e.is_error()) return e;
      if (e.kind == K::Enum && e.enum_decl != nullptr) {
        // A script enum has no MetaType before the load: the loader makes its vector type, so that a
        // refused script leaves the Registry as it was.
        Type v = Type::of(K::Vector);
        v.enum_decl = e.enum_decl;
        return v;
      }
      const MetaType* v = e.meta != nullptr ? reg_.find_type("vector<" + e.meta->name() + ">") : nullptr;
      if (v == nullptr) {
        diag_.error(t.loc, q(t.spelling()) + " is not a type the meta-information system knows");
        return Type::error();
      }
      return type_of_meta(v);
    }
    diag_.error(t.loc, q(name) + " is not a generic type (ref, shared, list, shared_list, vector)");
    return Type::error();
  }
  if (t.name.size() == 1) {
    const std::string& n = t.name[0];
    if (n == "bool") return type_of_meta(&meta_type<bool>());
    if (n == "int") return type_of_meta(&meta_type<std::int64_t>());
    if (n == "double") return type_of_meta(&meta_type<double>());
    if (n == "string") return type_of_meta(&meta_type<std::string>());
  }
  Found f = find_lexical(&scope, t.name[0]);
  for (std::size_t i = 1; f.ok() && i < t.name.size(); ++i)
    f = (f.decl != nullptr && f.decl->has_members()) ? find_member(f.decl->as<ScopeDecl>(), t.name[i])
                                                     : Found{};
  if (f.decl != nullptr) {
    if (f.decl->kind == DeclKind::Enum) {
      Type e = Type::of(K::Enum);
      e.enum_decl = &f.decl->as<EnumDecl>();
      return e;
    }
    if (f.decl->kind == DeclKind::Class || f.decl->kind == DeclKind::Object) {
      diag_.error(t.loc, q(name) + " is a class: write ref<" + name + "> or shared<" + name + ">");
      return Type::error();
    }
  }
  if (const MetaType* m = reg_.find_type(name)) return type_of_meta(m);
  if (reg_.find_class(name) != nullptr) {
    diag_.error(t.loc, q(name) + " is a class: write ref<" + name + "> or shared<" + name + ">");
    return Type::error();
  }
  diag_.error(t.loc, "undefined type " + q(name));
  return Type::error();
}

// ---- pass 2: headers and net structure ----------------------------------------------------------------

void CheckerImpl::resolve_base(ClassDecl& c) {
  if (c.kind == DeclKind::Net || c.base_name.empty()) return;
  c.base = resolve_class(c.base_name, c.base_loc, *parent_scope(c), false,
                         c.kind == DeclKind::Class ? "as a base class" : "as the class of an object");
  if (c.base.meta != nullptr && c.base.meta->is_a(Node::static_meta()) == false) {
    diag_.error(c.base_loc, "SOML++ classes derive from Node or its subclasses; " + q(c.base.meta->name()) +
                                " is not a Node");
    c.base = {};
  }
}

void CheckerImpl::resolve_signatures() {
  for (PropertyDecl* p : properties_) {
    if (p->type_name.is_auto) {
      diag_.error(p->type_name.loc,
                  "property " + q(p->name) + " needs a declared type ('auto' is for local variables)");
      continue;
    }
    p->type = resolve_type(p->type_name, *parent_scope(*p));
    if (p->type.kind == K::Void) {
      diag_.error(p->type_name.loc, "property " + q(p->name) + " cannot be void");
      p->type = Type::error();
    }
    // A property may not hide one of a base class: instances have one value per name.
    const ScopeDecl& owner = *parent_scope(*p);
    // Places, transitions and port nets (whose instance is the substitution transition's node) with
    // properties are run-time classes derived from soml::Place and soml::Transition.
    bool port_net = owner.kind == DeclKind::Net && !owner.as<ClassDecl>().params.empty();
    for (const Param& prm : owner.kind == DeclKind::Net ? owner.as<ClassDecl>().params : std::vector<Param>{})
      port_net = port_net && prm.is_place;  // (resolve_net, which sets is_port_net, runs later)
    const bool net_node = owner.kind == DeclKind::Place || owner.kind == DeclKind::Transition || port_net;
    if (owner.kind == DeclKind::Class || owner.kind == DeclKind::Object || net_node) {
      const ClassRef base =
          net_node ? ClassRef{nullptr, owner.kind == DeclKind::Place ? &Place::static_meta()
                                                                     : &Transition::static_meta()}
          : owner.as<ClassDecl>().base.empty() ? ClassRef{nullptr, &Node::static_meta()}
                                               : owner.as<ClassDecl>().base;
      Found f = find_in_class(base, p->name);
      if (f.ok()) {
        const std::string where =
            f.decl != nullptr
                ? "base class " + q(parent_scope(*f.decl)->name)
                : "built-in class " + q(f.prop ? f.prop->owner().name() : f.method->owner().name());
        diag_.error(p->loc, "duplicate definition of " + q(p->name) + " (already a member of " + where + ")");
      }
    }
  }
  for (FunctionDecl* f : functions_) {
    const ScopeDecl& owner = *parent_scope(*f);
    f->result_type = resolve_type(f->result, owner);
    for (std::size_t i = 0; i < f->params.size(); ++i) {
      Param& p = f->params[i];
      if (p.type_name.is_auto) {
        diag_.error(p.type_name.loc, "parameter " + q(p.name) + " needs a declared type");
        p.type = Type::error();
      } else {
        p.type = resolve_type(p.type_name, owner);
        if (p.type.kind == K::Void) {
          diag_.error(p.type_name.loc, "parameter " + q(p.name) + " cannot be void");
          p.type = Type::error();
        }
      }
    }
    for_each_duplicate(
        f->params.size(), [&](std::size_t i) { return f->params[i].name; },
        [&](std::size_t i, std::size_t j) {
          diag_.error(f->params[i].loc, "duplicate definition of parameter " + q(f->params[i].name) +
                                            " (first defined at line " +
                                            std::to_string(f->params[j].loc.line) + ")");
        });
  }
  for (FunctionDecl* f : functions_) check_override(*f);
  for (PlaceDecl* p : places_) {
    if (!p->token_class.empty())
      p->token = resolve_class(p->token_class, p->token_loc, *parent_scope(*p), true,
                               "as the token class of a place");
  }
  for (ClassDecl* c : classes_)
    if (c->kind == DeclKind::Net) resolve_net(*c);
}

// A function of a subclass with the name of a base's function overrides it: same parameters and
// result, so that a call through a base reference type-checks for every subclass.
void CheckerImpl::check_override(const FunctionDecl& f) {
  const ScopeDecl& owner = *parent_scope(f);
  if (f.is_constructor || (owner.kind != DeclKind::Class && owner.kind != DeclKind::Object)) return;
  const ClassRef base = owner.as<ClassDecl>().base.empty() ? ClassRef{nullptr, &Node::static_meta()}
                                                           : owner.as<ClassDecl>().base;
  Found b = find_in_class(base, f.name);
  if (!b.ok()) return;
  if (b.decl == nullptr || b.decl->kind != DeclKind::Function) {
    const std::string where =
        b.decl != nullptr ? "class " + q(parent_scope(*b.decl)->name)
                          : "built-in class " + q(b.prop ? b.prop->owner().name() : b.method->owner().name());
    if (b.method != nullptr) {
      diag_.error(
          f.loc, "function " + q(f.name) + " would hide method " + q(b.method->signature()) + " of " + where);
    } else {
      diag_.error(f.loc, "duplicate definition of " + q(f.name) + " (already a member of " + where + ")");
    }
    return;
  }
  const auto& g = b.decl->as<FunctionDecl>();
  bool same = g.params.size() == f.params.size() && g.result_type.same(f.result_type);
  for (std::size_t i = 0; same && i < f.params.size(); ++i) same = g.params[i].type.same(f.params[i].type);
  if (!same)
    diag_.error(f.loc, "function " + q(f.name) + " overrides the one of class " + q(parent_scope(g)->name) +
                           " (line " + std::to_string(g.loc.line) + ") with a different signature");
}

void CheckerImpl::resolve_net(ClassDecl& n) {
  std::size_t ports = 0;
  for (const Param& p : n.params) ports += p.is_place ? 1 : 0;
  n.result_type = resolve_type(n.result, *parent_scope(n));
  if (ports > 0 && ports < n.params.size())
    diag_.error(n.loc, "net " + q(n.name) +
                           " mixes port places and value parameters: a net either substitutes a transition "
                           "(ports) or is invoked (values)");
  n.is_port_net = ports > 0 && ports == n.params.size();
  if (n.is_port_net && n.result_type.kind != K::Void && !n.result_type.is_error())
    diag_.error(n.result.loc,
                "net " + q(n.name) + " has port places, so it substitutes a transition and has no result");
  // Duplicate parameter names are reported by declare(): each parameter is a member of the net.
}

// Resolves the path of an arrow end or a start place; `role` starts the messages ("arrow from").
CheckerImpl::Endpoint CheckerImpl::resolve_endpoint(const std::vector<std::string>& path, SourceLoc loc,
                                                    const ScopeDecl& scope, const std::string& role) {
  const std::string name = join(path, ".");
  Found f = find_member(scope, path[0]);
  bool local = f.ok();
  if (!f.ok()) f = find_lexical(parent_scope(scope), path[0]);
  for (std::size_t i = 1; f.ok() && i < path.size(); ++i) {
    local = false;
    ClassRef next;
    if (f.decl != nullptr && f.decl->kind == DeclKind::Object) {
      next = ClassRef{&f.decl->as<ClassDecl>(), nullptr};
    } else if (f.decl != nullptr && f.decl->kind == DeclKind::Property &&
               f.decl->as<PropertyDecl>().type.kind == K::Ref) {
      next = f.decl->as<PropertyDecl>().type.cls;
    } else if (f.prop != nullptr && type_of_meta(&f.prop->type()).kind == K::Ref) {
      next = type_of_meta(&f.prop->type()).cls;
    } else {
      diag_.error(loc,
                  role + " " + q(name) + ": " + q(path[i - 1]) + " is neither an object nor a reference");
      return {};
    }
    f = find_in_class(next, path[i]);
  }
  if (!f.ok()) {
    diag_.error(loc, role + " " + q(name) + ", which is not defined");
    return {};
  }
  if (f.decl != nullptr && parent_scope(*f.decl) == &scope) local = true;  // `o.p` written inside o
  if (f.decl == nullptr || (f.decl->kind != DeclKind::Place && f.decl->kind != DeclKind::Transition)) {
    const std::string what = f.decl != nullptr   ? a_kind(*f.decl)
                             : f.prop != nullptr ? "a property"
                                                 : "a function";
    diag_.error(loc, role + " " + q(name) + ", which is " + what + ", not a place or transition");
    return {};
  }
  return {f.decl, local};
}

void CheckerImpl::resolve_arrow(ArrowDecl& a) {
  const ScopeDecl& scope = *parent_scope(a);
  Endpoint from = resolve_endpoint(a.from, a.from_loc, scope, "arrow from");
  Endpoint to = resolve_endpoint(a.to, a.to_loc, scope, "arrow to");
  if (a.weight < 1)
    diag_.error(a.weight_loc, "arrow weight must be at least 1, not " + std::to_string(a.weight));
  if (from.decl == nullptr || to.decl == nullptr) return;
  const std::string fname = join(a.from, "."), tname = join(a.to, ".");
  if (from.decl->kind == to.decl->kind) {
    const bool places = from.decl->kind == DeclKind::Place;
    diag_.error(a.loc, std::string("arrow from ") + (places ? "place " : "transition ") + q(fname) + " to " +
                           (places ? "place " : "transition ") + q(tname) +
                           ": an arrow links a place and a transition");
    return;
  }
  const bool into_transition = to.decl->kind == DeclKind::Transition;
  const Endpoint& place = into_transition ? from : to;
  const Endpoint& transition = into_transition ? to : from;
  const SourceLoc place_loc = into_transition ? a.from_loc : a.to_loc;
  const std::string pname = into_transition ? fname : tname;
  switch (a.arrow) {
    case ArrowKind::Normal:
    case ArrowKind::Inhibitor:
      if (a.arrow == ArrowKind::Inhibitor && !into_transition) {
        diag_.error(a.loc, "an inhibitor arrow goes from a place to a transition");
        return;
      }
      if (!place.local || !transition.local) {
        diag_.error(
            place.local ? (into_transition ? a.to_loc : a.from_loc) : place_loc,
            "arrow between different nets: " + q(place.local ? (into_transition ? tname : fname) : pname) +
                " is not in the net of " + q(scope.name) + "; use a communication arrow '~>'");
        return;
      }
      break;
    case ArrowKind::Communication:
      if (!transition.local) {
        diag_.error(into_transition ? a.to_loc : a.from_loc,
                    "a communication arrow links a transition of this net (" + q(scope.name) +
                        ") with a place of another object's net");
        return;
      }
      if (place.local) {
        diag_.error(place_loc, "communication arrow within one net: " + q(pname) + " is a place of " +
                                   q(scope.name) + "; use '->'");
        return;
      }
      break;
  }
  const auto& p = place.decl->as<PlaceDecl>();
  if (!p.token.empty() && a.weight != 1 && a.weight >= 1)
    diag_.error(a.weight_loc,
                "an arrow of object place " + q(pname) + " has weight 1 (an object is one token)");
  a.from_decl = from.decl;
  a.to_decl = to.decl;
  auto& t = const_cast<TransitionDecl&>(transition.decl->as<TransitionDecl>());
  (into_transition ? t.inputs : t.outputs).push_back(&a);
}

void CheckerImpl::resolve_transition(TransitionDecl& t) {
  if (!t.subst_name.empty() && (!t.inputs.empty() || !t.outputs.empty())) {
    const ArrowDecl* a = !t.inputs.empty() ? t.inputs.front() : t.outputs.front();
    diag_.error(
        a->loc,
        "transition " + q(t.name) +
            " is substituted by a net: connect its ports through the net's arguments, not with arrows");
  }
  // The mark comes from the one object input place.
  for (const ArrowDecl* a : t.inputs) {
    if (a->arrow != ArrowKind::Normal && a->arrow != ArrowKind::Communication) continue;
    const auto& p = a->from_decl->as<PlaceDecl>();
    if (p.token.empty()) continue;
    if (t.mark_place == nullptr) {
      t.mark_place = &p;
    } else if (t.mark_place != &p) {
      diag_.error(a->from_loc, "transition " + q(t.name) + " already takes its mark from place " +
                                   q(t.mark_place->name) +
                                   "; a transition moves one mark, so it has at most one object input place");
    }
  }
  for (const ArrowDecl* a : t.outputs) {
    const auto& p = a->to_decl->as<PlaceDecl>();
    if (p.token.empty()) continue;
    if (t.mark_place == nullptr) {
      diag_.error(a->to_loc, "transition " + q(t.name) + " puts object tokens into place " + q(p.name) +
                                 " but takes none from an object place");
    } else if (!t.mark_place->token.is_a(p.token)) {
      diag_.error(a->to_loc, "place " + q(p.name) + " holds " + q(p.token.name()) +
                                 " tokens, but the marks of transition " + q(t.name) + " are " +
                                 q(t.mark_place->token.name()));
    }
  }
  const ScopeDecl& scope = *parent_scope(t);
  const auto find_net = [&](const std::vector<std::string>& parts, SourceLoc loc) -> const ClassDecl* {
    Found f = find_lexical(&scope, parts[0]);
    for (std::size_t i = 1; f.ok() && i < parts.size(); ++i)
      f = (f.decl != nullptr && f.decl->has_members()) ? find_member(f.decl->as<ScopeDecl>(), parts[i])
                                                       : Found{};
    if (f.decl != nullptr && f.decl->kind == DeclKind::Net) return &f.decl->as<ClassDecl>();
    diag_.error(loc,
                f.ok() ? q(join(parts, "::")) + " is not a net" : "undefined net " + q(join(parts, "::")));
    return nullptr;
  };
  if (!t.subst_name.empty()) {
    t.substituted = find_net(t.subst_name, t.subst_loc);
    if (t.substituted != nullptr && !t.substituted->is_port_net) {
      diag_.error(t.subst_loc, "net " + q(t.substituted->name) +
                                   " has no port places: it is invoked ('invoke " + t.substituted->name +
                                   "(...);'), it cannot substitute a transition");
      t.substituted = nullptr;
    }
  }
  if (!t.invoke_name.empty()) {
    t.invoked = find_net(t.invoke_name, t.invoke_loc);
    if (t.invoked != nullptr && t.invoked->is_port_net) {
      diag_.error(t.invoke_loc, "net " + q(t.invoked->name) +
                                    " has port places: it substitutes a transition ('transition t = " +
                                    t.invoked->name + "(...);'), it cannot be invoked");
      t.invoked = nullptr;
    }
  }
}

void CheckerImpl::resolve_start(StartDecl& s) {
  auto& owner = const_cast<ScopeDecl&>(*parent_scope(s)).as<ClassDecl>();
  if (owner.start != nullptr) {
    diag_.error(s.loc, "duplicate start place in " + q(owner.name) + " (first at line " +
                           std::to_string(owner.start->loc.line) + ")");
    return;
  }
  owner.start = &s;
  Endpoint e = resolve_endpoint(s.place, s.loc, owner, "start place");
  const std::string name = join(s.place, ".");
  if (e.decl == nullptr) return;
  if (e.decl->kind != DeclKind::Place) {
    diag_.error(s.loc, "start place " + q(name) + " is a transition, not a place");
    return;
  }
  const auto& p = e.decl->as<PlaceDecl>();
  s.place_decl = &p;
  if (owner.kind == DeclKind::Net) {
    if (!e.local)
      diag_.error(s.loc, "the start place of net " + q(owner.name) + " must be one of its own places");
    else if (!p.token.empty())
      diag_.error(s.loc, "the start place of net " + q(owner.name) +
                             " receives the invocation's black token; " + q(name) + " holds objects");
    return;
  }
  if (p.token.empty()) {
    diag_.error(s.loc, "start place " + q(name) + " holds black tokens; a token object needs a place<" +
                           owner.name + ">");
    return;
  }
  if (!ClassRef{&owner, nullptr}.is_a(p.token))
    diag_.error(s.loc, q(owner.name) + " is not a " + q(p.token.name()) +
                           ", so it cannot be a token of place " + q(name));
}

// ---- expressions -----------------------------------------------------------------------------------------

Type CheckerImpl::this_type(const Context& cx) const {
  const ScopeDecl* s = cx.scope;
  if (s == nullptr) return Type::error();
  if (s->is_class_like()) return Type::reference(class_of(*s));
  Type t = Type::of(s->kind == DeclKind::Place ? K::Place : K::Transition);
  t.decl = s;
  if (s->kind == DeclKind::Place) t.cls = s->as<PlaceDecl>().token;
  return t;
}

Type CheckerImpl::bind_found(const Found& f, Binding& b, SourceLoc loc, std::string_view name) {
  b.outer = f.outer;
  if (f.prop != nullptr) {
    b.kind = BK::MetaProperty;
    b.property = f.prop;
    return type_of_meta(&f.prop->type());
  }
  if (f.method != nullptr) {
    b.kind = BK::MetaMethod;
    b.method = f.method;
    return Type::of(K::Function);
  }
  const Decl& d = *f.decl;
  b.decl = &d;
  Type t;
  switch (d.kind) {
    case DeclKind::Property:
      b.kind = BK::Property;
      return d.as<PropertyDecl>().type;
    case DeclKind::Function:
      b.kind = BK::Function;
      t = Type::of(K::Function);
      t.decl = &d;
      return t;
    case DeclKind::Place:
      b.kind = BK::Place;
      t = Type::of(K::Place);
      t.decl = &d;
      t.cls = d.as<PlaceDecl>().token;
      return t;
    case DeclKind::Transition:
      b.kind = BK::Transition;
      t = Type::of(K::Transition);
      t.decl = &d;
      return t;
    case DeclKind::Object:
      b.kind = BK::Object;
      return Type::reference(ClassRef{&d.as<ClassDecl>(), nullptr}, true);
    case DeclKind::Class:
      b.kind = BK::Class;
      t = Type::of(K::Class);
      t.cls = ClassRef{&d.as<ClassDecl>(), nullptr};
      return t;
    case DeclKind::Enum:
      b.kind = BK::Enum;
      t = Type::of(K::Class);
      t.enum_decl = &d.as<EnumDecl>();
      return t;
    case DeclKind::Net:
      b.kind = BK::Net;
      t = Type::of(K::Net);
      t.decl = &d;
      return t;
    default:
      break;
  }
  diag_.error(loc, q(name) + " is " + a_kind(d) + ", not a value");
  return Type::error();
}

Type CheckerImpl::check_name(NameExpr& e, Context& cx) {
  if (e.parts.size() > 1) return check_qualified(e, cx);
  const std::string& name = e.parts[0];
  if (cx.frame != nullptr) {
    if (const Local* l = cx.frame->find(name)) {
      e.binding.kind = BK::Local;
      e.binding.slot = l->slot;
      return l->type;
    }
  }
  // The scopes outwards; inside a place, its own count, put and clear come before outer names.
  int outer = 0;
  for (const ScopeDecl* s = cx.scope; s != nullptr; s = parent_scope(*s), ++outer) {
    Found f = find_member(*s, name);
    if (f.ok()) {
      f.outer = outer;
      return bind_found(f, e.binding, e.loc, name);
    }
    if (s->kind == DeclKind::Place && (name == "count" || name == "put" || name == "clear")) {
      e.binding.kind = BK::Builtin;
      e.binding.outer = outer;
      e.binding.decl = s;
      e.binding.builtin = name == "count" ? Builtin::PlaceCount
                          : name == "put" ? Builtin::PlacePut
                                          : Builtin::PlaceClear;
      return name == "count" ? type_of_meta(&meta_type<std::int64_t>()) : Type::of(K::Function);
    }
  }
  for (const BuiltinFn& b : builtin_functions)
    if (b.name == name) {
      e.binding.kind = BK::Builtin;
      e.binding.builtin = b.id;
      return Type::of(K::Function);
    }
  if (name == "int" || name == "double" || name == "string" || name == "bool") {
    e.binding.kind = BK::Conversion;
    return Type::of(K::Function);
  }
  if (const MetaInstance* m = reg_.find_class(name)) {
    e.binding.kind = BK::Class;
    e.binding.meta_class = m;
    Type t = Type::of(K::Class);
    t.cls = ClassRef{nullptr, m};
    return t;
  }
  if (const MetaType* m = reg_.find_type(name); m != nullptr && m->kind() == TypeKind::Struct) {
    e.binding.kind = BK::Construct;  // `Vector3d(1, 2, 3)`: a value built field by field
    e.binding.meta_type = m;
    return Type::of(K::Function);
  }
  if (const MetaType* m = reg_.find_type(name);
      m != nullptr && (m->kind() == TypeKind::Enum || m->kind() == TypeKind::Flags)) {
    e.binding.kind = BK::Enum;
    e.binding.meta_type = m;
    Type t = Type::of(K::Class);
    t.meta = m;
    return t;
  }
  diag_.error(e.loc, "undefined name " + q(name));
  return Type::error();
}

Type CheckerImpl::check_qualified(NameExpr& e, Context& cx) {
  NameExpr head(ExprKind::Name, e.loc);
  head.parts = {e.parts[0]};
  Type cur = check_name(head, cx);
  Binding b = head.binding;
  for (std::size_t i = 1; i < e.parts.size(); ++i) {
    if (cur.is_error()) return cur;
    const std::string& part = e.parts[i];
    const std::string so_far =
        join(std::vector<std::string>(e.parts.begin(), e.parts.begin() + static_cast<long>(i)), "::");
    if (b.kind == BK::Enum) {
      if (b.decl != nullptr) {
        const auto& en = b.decl->as<EnumDecl>();
        auto it = std::find(en.values.begin(), en.values.end(), part);
        if (it == en.values.end()) {
          diag_.error(e.loc, "enum " + q(en.name) + " has no value " + q(part));
          return Type::error();
        }
        b.kind = BK::EnumValue;
        b.slot = static_cast<int>(it - en.values.begin());
        cur = Type::of(K::Enum);
        cur.enum_decl = &en;
      } else {
        std::int64_t v = 0;
        if (!b.meta_type->enum_value(part, v)) {
          diag_.error(e.loc, "enum " + q(b.meta_type->name()) + " has no value " + q(part));
          return Type::error();
        }
        b.kind = BK::EnumValue;
        b.slot = static_cast<int>(v);
        cur = type_of_meta(b.meta_type);
      }
      continue;
    }
    if (b.decl != nullptr && b.decl->has_members() &&
        (b.kind == BK::Class || b.kind == BK::Object || b.kind == BK::Net)) {
      Found f = find_member(b.decl->as<ScopeDecl>(), part);
      if (!f.ok()) {
        diag_.error(e.loc, q(so_far) + " has no member " + q(part));
        return Type::error();
      }
      if (f.decl == nullptr || (f.decl->kind != DeclKind::Enum && f.decl->kind != DeclKind::Class &&
                                f.decl->kind != DeclKind::Object && f.decl->kind != DeclKind::Net)) {
        diag_.error(e.loc, "'::' reaches nested classes, objects, nets and enums; use '.' for " + q(part));
        return Type::error();
      }
      b = Binding{};
      cur = bind_found(f, b, e.loc, part);
      b.outer = 0;
      continue;
    }
    if (b.kind == BK::Construct && b.meta_type == &meta_type<Eigen::Quaterniond>() &&
        part == "from_axis_angle") {
      b.kind = BK::Builtin;
      b.builtin = Builtin::StructOp;
      b.slot = static_cast<int>(StructOp::FromAxisAngle);
      cur = Type::of(K::Function);
      continue;
    }
    diag_.error(e.loc, q(so_far) + " has no member " + q(part) + " reachable with '::'");
    return Type::error();
  }
  e.binding = b;
  return cur;
}

Type CheckerImpl::check_value(Expr& e, Context& cx) {
  Type t = check_expr(e, cx);
  if (t.is_value()) return t;
  if (t.kind == K::Null) return t;
  std::string what;
  switch (t.kind) {
    case K::Void:
      what = "has no value (void)";
      break;
    case K::Function:
      what = "is a function; call it with '(...)'";
      break;
    case K::Place:
      what = "is place " + q(t.decl->name) + ", not a value (read its tokens with '.count')";
      break;
    case K::Transition:
      what = "is transition " + q(t.decl->name) + ", not a value";
      break;
    case K::Net:
      what = "is net " + q(t.decl->name) + ", not a value (invoke it from a transition)";
      break;
    case K::Class: {
      const bool is_enum = t.enum_decl != nullptr || t.meta != nullptr;
      const std::string n = t.enum_decl != nullptr ? t.enum_decl->name
                            : t.meta != nullptr    ? t.meta->name()
                                                   : t.cls.name();
      what = is_enum ? "is enum " + q(n) + ", not a value (write " + n + "::Value)"
                     : "is class " + q(n) + ", not a value";
      break;
    }
    default:
      what = "is a " + t.name() + ", not a value";
      break;
  }
  diag_.error(e.loc, "expression " + what);
  e.type = Type::error();
  return Type::error();
}

void CheckerImpl::expect_type(Expr& e, const Type& want, Context& cx, const std::string& what) {
  Type t = check_value(e, cx);
  if (!assignable(t, want))
    diag_.error(e.loc, "type mismatch: " + what + " must be " + q(want.name()) + ", not " + q(t.name()));
}

Type CheckerImpl::check_member(MemberExpr& e, Context& cx) {
  Type obj = check_expr(*e.object, cx);
  const std::string& n = e.name;
  Type t;
  switch (obj.kind) {
    case K::Error:
      return obj;
    case K::Ref: {
      Found f = find_in_class(obj.cls, n);
      if (!f.ok()) {
        diag_.error(e.name_loc, "class " + q(obj.cls.name()) + " has no member " + q(n));
        return Type::error();
      }
      t = bind_found(f, e.binding, e.name_loc, n);
      e.binding.outer = 0;
      return t;
    }
    case K::Place:
    case K::Transition: {
      const auto& s = obj.decl->as<ScopeDecl>();
      Found f = find_own(s, n);
      if (f.ok()) return bind_found(f, e.binding, e.name_loc, n);
      if (obj.kind == K::Place) {
        e.binding.kind = BK::Builtin;
        e.binding.decl = obj.decl;
        if (n == "count") {
          e.binding.builtin = Builtin::PlaceCount;
          return type_of_meta(&meta_type<std::int64_t>());
        }
        if (n == "put" || n == "clear") {
          e.binding.builtin = n == "put" ? Builtin::PlacePut : Builtin::PlaceClear;
          return Type::of(K::Function);
        }
        e.binding.kind = BK::None;
      }
      diag_.error(e.name_loc, std::string(obj.kind == K::Place ? "place " : "transition ") + q(s.name) +
                                  " has no member " + q(n));
      return Type::error();
    }
    case K::Struct: {
      const auto& fields = obj.meta->fields();
      for (std::size_t i = 0; i < fields.size(); ++i)
        if (fields[i].name == n) {
          e.binding.kind = BK::StructField;
          e.binding.slot = static_cast<int>(i);
          e.binding.meta_type = obj.meta;
          return type_of_meta(fields[i].type);
        }
      if (StructOp op{}; struct_method(eig(obj), n, op)) {  // `v.norm()`: called in check_builtin_call
        e.binding.kind = BK::Builtin;
        e.binding.builtin = Builtin::StructOp;
        e.binding.slot = static_cast<int>(op);
        e.binding.meta_type = obj.meta;
        return Type::of(K::Function);
      }
      const Eig k = eig(obj);
      diag_.error(e.name_loc, "type " + q(obj.name()) + " has no field " + q(n) +
                                  (k == Eig::V3 ? " (its methods: dot, cross, norm, squared_norm, normalized)"
                                   : is_vec(k)  ? " (its methods: dot, norm, squared_norm, normalized)"
                                   : k == Eig::Quat ? " (its methods: inverse, conjugate, normalized)"
                                   : k == Eig::Iso  ? " (its method: inverse)"
                                                    : ""));
      return Type::error();
    }
    case K::Vector:
    case K::List:
      if (n == "size" || n == "push") {
        e.binding.kind = BK::Builtin;
        e.binding.builtin = n == "size" ? Builtin::Size : Builtin::Push;
        return Type::of(K::Function);
      }
      diag_.error(e.name_loc,
                  "type " + q(obj.name()) + " has no member " + q(n) + " (it has size() and push(x))");
      return Type::error();
    case K::Class:
      diag_.error(e.name_loc, "use '::' to reach " + q(n) + " of " +
                                  q(obj.enum_decl != nullptr ? obj.enum_decl->name : obj.cls.name()));
      return Type::error();
    default:
      diag_.error(e.name_loc, "type " + q(obj.name()) + " has no member " + q(n));
      return Type::error();
  }
}

void CheckerImpl::check_args(std::vector<ExprPtr>& args, const std::vector<Type>& params, SourceLoc loc,
                             const std::string& callee, Context& cx) {
  if (args.size() != params.size()) {
    diag_.error(loc, "wrong number of arguments: " + callee + " takes " + std::to_string(params.size()) +
                         ", " + std::to_string(args.size()) + " given");
    for (ExprPtr& a : args) check_expr(*a, cx);
    return;
  }
  for (std::size_t i = 0; i < args.size(); ++i) {
    Type t = check_value(*args[i], cx);
    if (!assignable(t, params[i]))
      diag_.error(args[i]->loc, "type mismatch: argument " + std::to_string(i + 1) + " of " + callee +
                                    " must be " + q(params[i].name()) + ", not " + q(t.name()));
  }
}

Type CheckerImpl::check_builtin_call(CallExpr& e, Builtin id, std::string_view name, const Type& self,
                                     Context& cx) {
  const auto arity = [&](std::size_t n) {
    if (e.args.size() == n) return true;
    diag_.error(e.loc, "wrong number of arguments: " + q(name) + " takes " + std::to_string(n) + ", " +
                           std::to_string(e.args.size()) + " given");
    for (ExprPtr& a : e.args) check_expr(*a, cx);
    return false;
  };
  const auto numeric = [&](Expr& a) {
    Type t = check_value(a, cx);
    if (!t.is_error() && !t.is_numeric())
      diag_.error(a.loc, "type mismatch: " + q(name) + " takes a number, not " + q(t.name()));
    return t;
  };
  const Type dbl = type_of_meta(&meta_type<double>());
  const Type integer = type_of_meta(&meta_type<std::int64_t>());
  switch (id) {
    case Builtin::Print:
      for (ExprPtr& a : e.args) check_value(*a, cx);
      return Type::of(K::Void);
    case Builtin::Sqrt:
    case Builtin::Floor:
    case Builtin::Ceil:
      if (arity(1)) numeric(*e.args[0]);
      return dbl;
    case Builtin::Abs:
      if (!arity(1)) return Type::error();
      return numeric(*e.args[0]).kind == K::Int ? integer : dbl;
    case Builtin::Min:
    case Builtin::Max: {
      if (!arity(2)) return Type::error();
      const Type a = numeric(*e.args[0]), b = numeric(*e.args[1]);
      return a.kind == K::Int && b.kind == K::Int ? integer : dbl;
    }
    case Builtin::Len:
      if (arity(1)) expect_type(*e.args[0], Type::of(K::String), cx, "the argument of 'len'");
      return integer;
    case Builtin::Find:
      if (arity(1)) expect_type(*e.args[0], Type::of(K::String), cx, "the path of 'find'");
      return Type::reference(ClassRef{nullptr, &Node::static_meta()}, true);
    case Builtin::PlaceCount:
      diag_.error(e.loc, "'count' is a property of the place, not a function: write 'p.count'");
      return Type::error();
    case Builtin::PlacePut:
      if (cx.body == Body::Condition || cx.body == Body::ArrowCondition)
        diag_.error(e.loc, "a condition must not change the marking ('put')");
      if (self.cls.empty()) {
        if (e.args.size() > 1)
          arity(1);
        else if (e.args.size() == 1)
          expect_type(*e.args[0], integer, cx, "the number of tokens to put");
      } else if (arity(1)) {
        expect_type(*e.args[0], Type::reference(self.cls, true), cx, "the token to put");
      }
      return Type::of(K::Void);
    case Builtin::PlaceClear:
      if (cx.body == Body::Condition || cx.body == Body::ArrowCondition)
        diag_.error(e.loc, "a condition must not change the marking ('clear')");
      arity(0);
      return Type::of(K::Void);
    case Builtin::Size:
      arity(0);
      return integer;
    case Builtin::Push: {
      if (cx.body == Body::Condition || cx.body == Body::ArrowCondition)
        diag_.error(e.loc, "a condition must not change properties ('push')");
      if (!arity(1)) return Type::of(K::Void);
      Type elem = self.kind == K::List ? Type::reference(self.cls, self.shared) : element_of(self);
      expect_type(*e.args[0], elem, cx, "the element to push");
      return Type::of(K::Void);
    }
    case Builtin::StructOp: {
      std::vector<Type> params;
      Type result = self;
      switch (static_cast<StructOp>(e.binding.slot)) {
        case StructOp::Dot:
          params = {self};
          result = dbl;
          break;
        case StructOp::Norm:
        case StructOp::SquaredNorm:
          result = dbl;
          break;
        case StructOp::Cross:
          params = {self};
          break;
        case StructOp::FromAxisAngle:
          params = {type_of_meta(&meta_type<Eigen::Vector3d>()), dbl};
          result = type_of_meta(&meta_type<Eigen::Quaterniond>());
          break;
        default:  // normalized, inverse, conjugate: no arguments, the struct's own type
          break;
      }
      check_args(e.args, params, e.loc,
                 self.kind == K::Struct ? "method " + q(name) + " of " + q(self.name()) : q(name), cx);
      return result;
    }
    case Builtin::None:
      break;
  }
  return Type::error();
}

Type CheckerImpl::check_call(CallExpr& e, Context& cx) {
  Expr& callee = *e.callee;
  Type self;  // for members: the object's type
  Binding b;
  std::string name;
  if (callee.kind == ExprKind::Name) {
    auto& n = callee.as<NameExpr>();
    name = n.spelling();
    if (cx.frame != nullptr && n.parts.size() == 1 && cx.frame->find(name) != nullptr) {
      diag_.error(callee.loc, q(name) + " is a variable, not a function");
      for (ExprPtr& a : e.args) check_expr(*a, cx);
      return Type::error();
    }
    Type t = check_name(n, cx);
    callee.type = t;
    if (t.is_error()) {
      for (ExprPtr& a : e.args) check_expr(*a, cx);
      return t;
    }
    b = n.binding;
    if (b.kind == BK::Builtin && b.decl != nullptr &&
        b.decl->kind == DeclKind::Place) {  // put() inside a place
      self = Type::of(K::Place);
      self.decl = b.decl;
      self.cls = b.decl->as<PlaceDecl>().token;
    }
  } else if (callee.kind == ExprKind::Member) {
    auto& m = callee.as<MemberExpr>();
    name = m.name;
    Type t = check_member(m, cx);
    callee.type = t;
    if (t.is_error()) {
      for (ExprPtr& a : e.args) check_expr(*a, cx);
      return t;
    }
    self = m.object->type;
    b = m.binding;
  } else {
    check_expr(callee, cx);
    if (!callee.type.is_error()) diag_.error(callee.loc, "this expression is not a function");
    for (ExprPtr& a : e.args) check_expr(*a, cx);
    return Type::error();
  }
  e.binding = b;
  switch (b.kind) {
    case BK::Function: {
      const auto& f = b.decl->as<FunctionDecl>();
      std::vector<Type> params;
      for (const Param& p : f.params) params.push_back(p.type);
      check_args(e.args, params, e.loc, "function " + q(f.name), cx);
      return f.result_type;
    }
    case BK::MetaMethod: {
      std::vector<Type> params;
      for (const MetaType* a : b.method->arguments()) params.push_back(type_of_meta(a));
      check_args(e.args, params, e.loc,
                 "method " + q(b.method->name()) + " of " + q(b.method->owner().name()), cx);
      return type_of_meta(b.method->result());
    }
    case BK::Builtin:
      return check_builtin_call(e, b.builtin, name, self, cx);
    case BK::Conversion: {
      Type to = resolve_type(TypeName{callee.loc, {name}, {}, false, false}, *cx.scope);
      if (e.args.size() != 1) {
        diag_.error(e.loc, "wrong number of arguments: conversion to " + q(name) + " takes 1, " +
                               std::to_string(e.args.size()) + " given");
        for (ExprPtr& a : e.args) check_expr(*a, cx);
        return to;
      }
      Type from = check_value(*e.args[0], cx);
      bool ok = from.is_error();
      if (to.kind == K::Int) ok = ok || from.is_numeric() || from.kind == K::Enum || from.kind == K::Bool;
      if (to.kind == K::Double) ok = ok || from.is_numeric();
      if (to.kind == K::Bool) ok = ok || from.is_numeric() || from.kind == K::Bool;
      if (to.kind == K::String)
        ok = ok || from.is_numeric() || from.kind == K::Bool || from.kind == K::Enum ||
             from.kind == K::String || from.kind == K::Struct;
      if (!ok)
        diag_.error(e.args[0]->loc, "type mismatch: cannot convert " + q(from.name()) + " to " + q(name));
      return to;
    }
    case BK::Construct: {
      // No arguments: the default value; else one per field, in the order of the fields.
      const MetaType& st = *b.meta_type;
      std::vector<Type> params;
      std::string fields;
      for (const MetaType::Field& f : st.fields()) {
        params.push_back(type_of_meta(f.type));
        fields += (fields.empty() ? "" : ", ") + f.type->name() + " " + f.name;
      }
      if (e.args.empty()) return type_of_meta(&st);
      check_args(e.args, params, e.loc, q(st.name()) + " (" + fields + "; or none for the default)", cx);
      return type_of_meta(&st);
    }
    case BK::Class:
      diag_.error(e.loc, q(name) + " is a class: create instances with 'new " + name + "(...)'");
      break;
    case BK::Net:
      diag_.error(e.loc, "net " + q(name) + " is invoked from a transition ('invoke " + name +
                             "(...);'), not called");
      break;
    default:
      diag_.error(callee.loc, q(name) + " is not a function");
      break;
  }
  for (ExprPtr& a : e.args) check_expr(*a, cx);
  return Type::error();
}

bool CheckerImpl::check_lvalue(Expr& e, Context& cx) {
  const Binding* b = nullptr;
  bool local = false;
  if (e.kind == ExprKind::Name) b = &e.as<NameExpr>().binding;
  if (e.kind == ExprKind::Member) b = &e.as<MemberExpr>().binding;
  if (e.kind == ExprKind::Index) {
    const Type& o = e.as<IndexExpr>().object->type;
    if (o.kind == K::Vector || o.kind == K::List) {
      if ((cx.body == Body::Condition || cx.body == Body::ArrowCondition)) {
        diag_.error(
            e.loc, "a condition must not change properties (it is re-tested whenever what it reads changes)");
        return false;
      }
      return true;
    }
  }
  if (b != nullptr) {
    switch (b->kind) {
      case BK::Local:
        local = true;
        break;
      case BK::Property:
        break;
      case BK::StructField: {  // a field of a local (`v.x`, `v.pose.translation.x`) changes the local only
        const Expr* o = e.as<MemberExpr>().object.get();
        while (o->kind == ExprKind::Member && o->as<MemberExpr>().binding.kind == BK::StructField)
          o = o->as<MemberExpr>().object.get();
        local = o->kind == ExprKind::Name && o->as<NameExpr>().binding.kind == BK::Local;
        break;
      }
      case BK::MetaProperty:
        if (b->property->has(ReadOnly)) {
          diag_.error(e.loc, "property " + q(b->property->name()) + " of " + q(b->property->owner().name()) +
                                 " is read-only");
          return false;
        }
        break;
      case BK::Builtin:
        if (b->builtin == Builtin::PlaceCount) {
          diag_.error(
              e.loc,
              "'count' of a place is read-only: change the marking with put() and clear(), or by firing");
          return false;
        }
        [[fallthrough]];
      default:
        b = nullptr;
        break;
    }
  }
  if (b == nullptr) {
    if (!e.type.is_error()) diag_.error(e.loc, "cannot assign to this expression");
    return false;
  }
  if (!local && (cx.body == Body::Condition || cx.body == Body::ArrowCondition)) {
    diag_.error(e.loc,
                "a condition must not change properties (it is re-tested whenever what it reads changes)");
    return false;
  }
  return true;
}

Type CheckerImpl::check_assign(BinaryExpr& e, Context& cx) {
  Type l = check_expr(*e.lhs, cx);
  Type r = check_value(*e.rhs, cx);
  if (l.is_error() || !check_lvalue(*e.lhs, cx)) return Type::of(K::Void);
  switch (e.op) {
    case TokenKind::Equal:
      if (!assignable(r, l))
        diag_.error(e.rhs->loc, "type mismatch: cannot assign " + q(r.name()) + " to " + q(l.name()));
      break;
    case TokenKind::PlusEqual:
      if (l.kind == K::String) {
        if (!r.is_error() && !(r.kind == K::String || r.is_numeric() || r.kind == K::Bool ||
                               r.kind == K::Enum || r.kind == K::Struct))
          diag_.error(e.rhs->loc, "type mismatch: cannot append " + q(r.name()) + " to a string");
        break;
      }
      [[fallthrough]];
    default: {
      if (l.kind == K::Struct) {  // v += w, v *= 2, q *= q, T *= T: the result has the type of v
        const TokenKind op = e.op == TokenKind::MinusEqual   ? TokenKind::Minus
                             : e.op == TokenKind::StarEqual  ? TokenKind::Star
                             : e.op == TokenKind::SlashEqual ? TokenKind::Slash
                             : e.op == TokenKind::PlusEqual  ? TokenKind::Plus
                                                             : TokenKind::Percent;
        if (!r.is_error() && !struct_binary(op, l, r).same(l))
          diag_.error(e.loc, "type mismatch: " + std::string(token_kind_name(e.op)) + " on " + q(l.name()) +
                                 " and " + q(r.name()));
        break;
      }
      const bool modulo = e.op == TokenKind::PercentEqual;
      const bool ok = modulo ? (l.kind == K::Int && (r.kind == K::Int || r.is_error()))
                             : (l.is_numeric() && (r.is_numeric() || r.is_error()) &&
                                !(l.kind == K::Int && r.kind == K::Double));
      if (!ok)
        diag_.error(e.loc, "type mismatch: " + std::string(token_kind_name(e.op)) + " on " + q(l.name()) +
                               " and " + q(r.name()));
    }
  }
  return Type::of(K::Void);
}

Type CheckerImpl::check_binary(BinaryExpr& e, Context& cx) {
  Type l = check_value(*e.lhs, cx);
  Type r = check_value(*e.rhs, cx);
  const std::string op(token_kind_name(e.op));
  const auto mismatch = [&](const char* want) {
    if (!l.is_error() && !r.is_error())
      diag_.error(e.loc,
                  "type mismatch: " + op + " takes " + want + ", not " + q(l.name()) + " and " + q(r.name()));
    return Type::error();
  };
  const Type integer = type_of_meta(&meta_type<std::int64_t>());
  const Type dbl = type_of_meta(&meta_type<double>());
  const Type boolean = type_of_meta(&meta_type<bool>());
  const bool err = l.is_error() || r.is_error();
  switch (e.op) {
    case TokenKind::Plus:
      if (l.kind == K::String || r.kind == K::String) {
        const auto text = [](const Type& t) {
          return t.is_error() || t.kind == K::String || t.is_numeric() || t.kind == K::Bool ||
                 t.kind == K::Enum || t.kind == K::Struct;
        };
        if (text(l) && text(r)) return type_of_meta(&meta_type<std::string>());
        return mismatch("strings, numbers, bools, enums and structs");
      }
      [[fallthrough]];
    case TokenKind::Minus:
    case TokenKind::Star:
    case TokenKind::Slash:
      if (err) return Type::error();
      if (l.kind == K::Struct || r.kind == K::Struct) {  // vector and frame arithmetic (docs/soml.md 4.14)
        Type t = struct_binary(e.op, l, r);
        return t.is_error() ? mismatch(struct_operands(e.op)) : t;
      }
      if (!l.is_numeric() || !r.is_numeric()) return mismatch("numbers");
      return l.kind == K::Int && r.kind == K::Int ? integer : dbl;
    case TokenKind::Percent:
      if (err) return Type::error();
      if (l.kind != K::Int || r.kind != K::Int) return mismatch("integers");
      return integer;
    case TokenKind::Less:
    case TokenKind::LessEqual:
    case TokenKind::Greater:
    case TokenKind::GreaterEqual:
      if (err) return boolean;
      if ((l.is_numeric() && r.is_numeric()) || (l.kind == K::String && r.kind == K::String)) return boolean;
      mismatch("two numbers or two strings");
      return boolean;
    case TokenKind::EqualEqual:
    case TokenKind::BangEqual: {
      if (err) return boolean;
      const bool refs = (l.kind == K::Ref || l.kind == K::Null) && (r.kind == K::Ref || r.kind == K::Null) &&
                        (l.kind == K::Null || r.kind == K::Null || l.cls.is_a(r.cls) || r.cls.is_a(l.cls));
      if (refs || (l.is_numeric() && r.is_numeric()) || (l.same(r) && l.kind != K::Ref)) return boolean;
      mismatch("two values of one type");
      return boolean;
    }
    case TokenKind::AmpAmp:
    case TokenKind::PipePipe:
      if (!err && (l.kind != K::Bool || r.kind != K::Bool)) mismatch("bools");
      return boolean;
    default:
      return Type::error();
  }
}

Type CheckerImpl::check_new(NewExpr& e, Context& cx) {
  const char* what = e.kind == ExprKind::New ? "in 'new'" : e.kind == ExprKind::Is ? "in 'is'" : "in 'as'";
  Type operand;
  if (e.operand) {
    operand = check_value(*e.operand, cx);
    if (!operand.is_error() && operand.kind != K::Ref && operand.kind != K::Null)
      diag_.error(e.operand->loc, std::string("type mismatch: ") +
                                      (e.kind == ExprKind::Is ? "'is'" : "'as'") +
                                      " takes a reference, not " + q(operand.name()));
  }
  ClassRef c = resolve_class(e.class_name.name, e.class_name.loc, *cx.scope, e.kind != ExprKind::New, what);
  e.binding.kind = BK::Class;
  e.binding.decl = c.decl;
  e.binding.meta_class = c.meta;
  if (e.kind == ExprKind::Is) return type_of_meta(&meta_type<bool>());
  if (c.empty()) {
    for (ExprPtr& a : e.args) check_expr(*a, cx);
    return Type::error();
  }
  if (e.kind == ExprKind::As) return Type::reference(c, true);
  if (c.meta != nullptr) {
    if (c.meta->is_abstract()) diag_.error(e.class_name.loc, "class " + q(c.meta->name()) + " is abstract");
    check_args(e.args, {}, e.loc, "built-in class " + q(c.meta->name()) + " (no constructor arguments)", cx);
  } else {
    std::vector<Type> params;
    if (c.decl->constructor != nullptr)
      for (const Param& p : c.decl->constructor->params) params.push_back(p.type);
    check_args(e.args, params, e.loc, "the constructor of " + q(c.decl->name), cx);
  }
  return Type::reference(c);
}

Type CheckerImpl::check_expr(Expr& e, Context& cx) {
  Type t;
  switch (e.kind) {
    case ExprKind::Int:
      t = type_of_meta(&meta_type<std::int64_t>());
      break;
    case ExprKind::Float:
      t = type_of_meta(&meta_type<double>());
      break;
    case ExprKind::String:
      t = type_of_meta(&meta_type<std::string>());
      break;
    case ExprKind::Bool:
      t = type_of_meta(&meta_type<bool>());
      break;
    case ExprKind::Null:
      t = Type::of(K::Null);
      break;
    case ExprKind::This:
      e.as<NameExpr>().binding.kind = BK::This;
      t = this_type(cx);
      break;
    case ExprKind::Mark:
      e.as<NameExpr>().binding.kind = BK::Mark;
      if (cx.has_mark) {
        t = cx.mark;
      } else {
        diag_.error(e.loc, cx.no_mark.empty() ? "'mark' is only available in transitions and arrow conditions"
                                              : cx.no_mark);
        t = Type::error();
      }
      break;
    case ExprKind::Name:
      t = check_name(e.as<NameExpr>(), cx);
      break;
    case ExprKind::Unary:
    case ExprKind::Postfix: {
      auto& u = e.as<UnaryExpr>();
      Type o = check_value(*u.operand, cx);
      if (u.op == TokenKind::Bang) {
        if (!o.is_error() && o.kind != K::Bool)
          diag_.error(e.loc, "type mismatch: '!' takes a bool, not " + q(o.name()));
        t = type_of_meta(&meta_type<bool>());
      } else if ((u.op == TokenKind::Minus || u.op == TokenKind::Plus) && is_vec(eig(o))) {
        t = o;  // -v
      } else if (u.op == TokenKind::Minus || u.op == TokenKind::Plus) {
        if (!o.is_error() && !o.is_numeric())
          diag_.error(e.loc, "type mismatch: " + std::string(token_kind_name(u.op)) +
                                 (o.kind == K::Struct ? " takes a number or a vector, not "
                                                      : " takes a number, not ") +
                                 q(o.name()));
        t = o.is_numeric()
                ? type_of_meta(o.kind == K::Int ? &meta_type<std::int64_t>() : &meta_type<double>())
                : Type::error();
      } else {  // ++ --
        if (!o.is_error() && !o.is_numeric())
          diag_.error(e.loc, "type mismatch: " + std::string(token_kind_name(u.op)) +
                                 " takes a number, not " + q(o.name()));
        else if (!o.is_error())
          check_lvalue(*u.operand, cx);
        t = Type::of(K::Void);
      }
      break;
    }
    case ExprKind::Binary:
      t = check_binary(e.as<BinaryExpr>(), cx);
      break;
    case ExprKind::Assign:
      t = check_assign(e.as<BinaryExpr>(), cx);
      break;
    case ExprKind::Conditional: {
      auto& c = e.as<ConditionalExpr>();
      expect_type(*c.cond, type_of_meta(&meta_type<bool>()), cx, "the condition of '?:'");
      Type a = check_value(*c.then_expr, cx);
      Type b = check_value(*c.else_expr, cx);
      if (a.is_error() || b.is_error())
        t = Type::error();
      else if (assignable(b, a))
        t = a.kind == K::Null ? b : a;
      else if (assignable(a, b))
        t = b;
      else {
        diag_.error(e.loc, "type mismatch: the branches of '?:' are " + q(a.name()) + " and " + q(b.name()));
        t = Type::error();
      }
      break;
    }
    case ExprKind::Call:
      t = check_call(e.as<CallExpr>(), cx);
      break;
    case ExprKind::Member:
      t = check_member(e.as<MemberExpr>(), cx);
      break;
    case ExprKind::Index: {
      auto& ix = e.as<IndexExpr>();
      Type o = check_value(*ix.object, cx);
      expect_type(*ix.index, type_of_meta(&meta_type<std::int64_t>()), cx, "an index");
      if (o.kind == K::Vector)
        t = element_of(o);
      else if (o.kind == K::List)
        t = Type::reference(o.cls, o.shared);
      else {
        if (!o.is_error())
          diag_.error(e.loc, "type " + q(o.name()) + " cannot be indexed (vectors and lists can)");
        t = Type::error();
      }
      break;
    }
    case ExprKind::New:
    case ExprKind::Is:
    case ExprKind::As:
      t = check_new(e.as<NewExpr>(), cx);
      break;
  }
  e.type = t;
  return t;
}

// ---- statements ------------------------------------------------------------------------------------------

bool CheckerImpl::always_returns(const Stmt& s) {
  switch (s.kind) {
    case StmtKind::Return:
    case StmtKind::Finish:
      return true;
    case StmtKind::Block:
      if (s.as<BlockStmt>().lost) return true;  // its parse error said enough
      for (const StmtPtr& c : s.as<BlockStmt>().body)
        if (always_returns(*c)) return true;
      return false;
    case StmtKind::If: {
      const auto& i = s.as<IfStmt>();
      return i.else_stmt && always_returns(*i.then_stmt) && always_returns(*i.else_stmt);
    }
    case StmtKind::While: {  // while (true) without break never falls through
      const auto& w = s.as<WhileStmt>();
      return w.cond->kind == ExprKind::Bool && w.cond->as<LiteralExpr>().bool_value;
    }
    default:
      return false;
  }
}

void CheckerImpl::check_local(LocalStmt& l, Context& cx) {
  Type t;
  if (l.type_name.is_auto) {
    if (!l.init) {
      diag_.error(l.name_loc, "variable " + q(l.name) + " declared 'auto' needs an initialiser");
      t = Type::error();
    } else {
      t = check_value(*l.init, cx);
      if (t.kind == K::Null) {
        diag_.error(l.init->loc, "cannot infer the type of " + q(l.name) + " from 'null'");
        t = Type::error();
      }
    }
  } else {
    t = resolve_type(l.type_name, *cx.scope);
    if (t.kind == K::Void) {
      diag_.error(l.type_name.loc, "variable " + q(l.name) + " cannot be void");
      t = Type::error();
    }
    if (l.init) expect_type(*l.init, t, cx, "the initialiser of " + q(l.name));
  }
  l.type = t;
  if (const Local* prev = cx.frame->find_innermost(l.name)) {
    diag_.error(l.name_loc, "duplicate definition of " + q(l.name) + " (first defined at line " +
                                std::to_string(prev->loc.line) + ")");
  }
  l.slot = cx.frame->add(l.name, t, l.name_loc);
}

void CheckerImpl::check_block_in_scope(BlockStmt& b, Context& cx) {
  for (StmtPtr& s : b.body) check_stmt(*s, cx);
}

void CheckerImpl::check_stmt(Stmt& s, Context& cx) {
  const Type boolean = type_of_meta(&meta_type<bool>());
  switch (s.kind) {
    case StmtKind::Block:
      cx.frame->push();
      check_block_in_scope(s.as<BlockStmt>(), cx);
      cx.frame->pop();
      return;
    case StmtKind::Local:
      check_local(s.as<LocalStmt>(), cx);
      return;
    case StmtKind::If: {
      auto& i = s.as<IfStmt>();
      expect_type(*i.cond, boolean, cx, "the condition of 'if'");
      cx.frame->push();
      check_stmt(*i.then_stmt, cx);
      cx.frame->pop();
      if (i.else_stmt) {
        cx.frame->push();
        check_stmt(*i.else_stmt, cx);
        cx.frame->pop();
      }
      return;
    }
    case StmtKind::While: {
      auto& w = s.as<WhileStmt>();
      expect_type(*w.cond, boolean, cx, "the condition of 'while'");
      ++cx.loops;
      cx.frame->push();
      check_stmt(*w.body, cx);
      cx.frame->pop();
      --cx.loops;
      return;
    }
    case StmtKind::For: {
      auto& f = s.as<ForStmt>();
      cx.frame->push();
      if (f.init) check_stmt(*f.init, cx);
      if (f.cond) expect_type(*f.cond, boolean, cx, "the condition of 'for'");
      if (f.step) check_expr(*f.step, cx);
      ++cx.loops;
      cx.frame->push();
      check_stmt(*f.body, cx);
      cx.frame->pop();
      --cx.loops;
      cx.frame->pop();
      return;
    }
    case StmtKind::ForEach: {
      auto& f = s.as<ForEachStmt>();
      Type r = check_value(*f.range, cx);
      Type elem = Type::error();
      if (r.kind == K::Vector)
        elem = element_of(r);
      else if (r.kind == K::List)
        elem = Type::reference(r.cls, r.shared);
      else if (!r.is_error())
        diag_.error(f.range->loc,
                    "type mismatch: 'for (x : ...)' runs over a vector or list, not " + q(r.name()));
      cx.frame->push();
      Type v = f.var->type_name.is_auto ? elem : resolve_type(f.var->type_name, *cx.scope);
      if (!assignable(elem, v))
        diag_.error(f.var->name_loc,
                    "type mismatch: the elements are " + q(elem.name()) + ", not " + q(v.name()));
      f.var->type = v;
      f.var->slot = cx.frame->add(f.var->name, v, f.var->name_loc);
      ++cx.loops;
      cx.frame->push();
      check_stmt(*f.body, cx);
      cx.frame->pop();
      --cx.loops;
      cx.frame->pop();
      return;
    }
    case StmtKind::Return: {
      auto& r = s.as<ReturnStmt>();
      const std::string where = cx.function != nullptr       ? "function " + q(cx.function->name)
                                : cx.body == Body::Condition ? "a condition"
                                                             : "an action";
      if (cx.result.kind == K::Void) {
        if (r.value) {
          check_expr(*r.value, cx);
          diag_.error(r.value->loc,
                      where + " returns no value" +
                          (cx.body == Body::Action ? " (an invoked net ends with 'finish value;')" : ""));
        }
      } else if (!r.value) {
        diag_.error(s.loc, where + " must return a value of type " + q(cx.result.name()));
      } else {
        expect_type(*r.value, cx.result, cx, "the returned value");
      }
      return;
    }
    case StmtKind::Finish: {
      auto& r = s.as<ReturnStmt>();
      if (cx.finish_net == nullptr) {
        diag_.error(s.loc,
                    "'finish' ends an invoked net: it is only allowed in actions of the transitions of an "
                    "invocable net");
        if (r.value) check_expr(*r.value, cx);
        return;
      }
      const Type& want = cx.finish_net->result_type;
      if (want.kind == K::Void) {
        if (r.value) {
          check_expr(*r.value, cx);
          diag_.error(r.value->loc, "net " + q(cx.finish_net->name) + " has no result: write 'finish;'");
        }
      } else if (!r.value) {
        diag_.error(s.loc,
                    "net " + q(cx.finish_net->name) + " must finish with a value of type " + q(want.name()));
      } else {
        expect_type(*r.value, want, cx, "the result of net " + q(cx.finish_net->name));
      }
      return;
    }
    case StmtKind::Break:
    case StmtKind::Continue:
      if (cx.loops == 0)
        diag_.error(s.loc,
                    std::string(s.kind == StmtKind::Break ? "'break'" : "'continue'") + " outside a loop");
      return;
    case StmtKind::Expr: {
      auto& x = s.as<ExprStmt>();
      check_expr(*x.expr, cx);
      return;
    }
  }
}

// ---- pass 3: bodies --------------------------------------------------------------------------------------

void CheckerImpl::check_property(PropertyDecl& p) {
  if (!p.init) return;
  Frame frame;
  Context cx;
  cx.scope = parent_scope(p);
  cx.frame = &frame;
  expect_type(*p.init, p.type, cx, "the initial value of " + q(p.name));
}

void CheckerImpl::check_place(PlaceDecl& p) {
  if (!p.initial) return;
  Frame frame;
  Context cx;
  cx.scope = parent_scope(p);
  cx.frame = &frame;
  if (!p.token.empty()) {
    diag_.error(p.initial->loc,
                "object place " + q(p.name) + " starts empty (its tokens come from start places and put())");
    return;
  }
  Type t = check_value(*p.initial, cx);
  if (t.is_error()) return;
  if (p.initial->kind != ExprKind::Int) {
    diag_.error(p.initial->loc, "the initial marking of place " + q(p.name) + " must be an integer literal");
    return;
  }
  p.initial_tokens = p.initial->as<LiteralExpr>().int_value;
}

void CheckerImpl::check_function(FunctionDecl& f) {
  Frame frame;
  Context cx;
  cx.scope = parent_scope(f);
  cx.frame = &frame;
  cx.body = Body::Function;
  cx.function = &f;
  cx.result = f.result_type;
  for (const Param& p : f.params) frame.add(p.name, p.type, p.loc);
  // A function in a transition (or in a place, class, ...) sees no mark: only conditions, actions and
  // arrow conditions are evaluated for one.
  cx.no_mark = "'mark' is only available in conditions, actions and arrow conditions; pass it to function " +
               q(f.name) + " as an argument";
  check_block_in_scope(*f.body, cx);
  f.slots = frame.max;
  if (f.result_type.kind != K::Void && !f.result_type.is_error() && !always_returns(*f.body))
    diag_.error(f.loc, "function " + q(f.name) + " must return a value of type " + q(f.result_type.name()) +
                           " on every path");
}

void CheckerImpl::check_object_args(ClassDecl& c) {
  if (c.kind != DeclKind::Object) return;
  Frame frame;
  Context cx;
  cx.scope = parent_scope(c);
  cx.frame = &frame;
  cx.body = Body::Argument;
  std::vector<Type> params;
  std::string callee;
  if (c.base.decl != nullptr) {
    if (c.base.decl->constructor != nullptr)
      for (const Param& p : c.base.decl->constructor->params) params.push_back(p.type);
    callee = "the constructor of " + q(c.base.decl->name);
  } else if (c.base.meta != nullptr) {
    callee = "built-in class " + q(c.base.meta->name()) + " (no constructor arguments)";
  } else if (!c.base_name.empty()) {
    for (ExprPtr& a : c.base_args) check_expr(*a, cx);  // the base did not resolve: already reported
    return;
  } else {
    callee = "an object made from scratch (no constructor arguments)";
  }
  check_args(c.base_args, params, c.has_args ? c.base_loc : c.loc, callee, cx);
}

void CheckerImpl::check_transition(TransitionDecl& t) {
  const ScopeDecl& owner = *parent_scope(t);
  Context base;
  base.scope = &t;
  if (t.mark_place != nullptr) {
    base.has_mark = true;
    base.mark = Type::reference(t.mark_place->token, true);
  } else {
    base.no_mark = "transition " + q(t.name) + " has no object input place, so there is no 'mark'";
  }
  if (t.when_expr || t.when_block) {
    Frame frame;
    Context cx = base;
    cx.frame = &frame;
    cx.body = Body::Condition;
    cx.result = type_of_meta(&meta_type<bool>());
    if (t.when_expr) {
      expect_type(*t.when_expr, cx.result, cx, "the condition of transition " + q(t.name));
    } else {
      check_block_in_scope(*t.when_block, cx);
      if (!always_returns(*t.when_block))
        diag_.error(t.when_block->loc,
                    "the condition of transition " + q(t.name) + " must return a bool on every path");
    }
    t.when_slots = frame.max;
  }
  Frame action_frame;
  if (t.invoked != nullptr) {
    Frame frame;
    Context cx = base;
    cx.frame = &frame;
    cx.body = Body::Argument;
    std::vector<Type> params;
    for (const Param& p : t.invoked->params) params.push_back(p.type);
    check_args(t.invoke_args, params, t.invoke_loc, "net " + q(t.invoked->name), cx);
    if (t.invoked->result_type.kind != K::Void)
      action_frame.add("result", t.invoked->result_type, t.invoke_loc);
  } else {
    Frame frame;
    Context cx = base;
    cx.frame = &frame;
    for (ExprPtr& a : t.invoke_args) check_expr(*a, cx);
  }
  if (!t.subst_name.empty()) {
    Frame frame;
    Context cx = base;
    cx.scope = &owner;
    cx.frame = &frame;
    cx.body = Body::Argument;
    if (t.substituted == nullptr) {
      for (ExprPtr& a : t.subst_args) check_expr(*a, cx);
    } else if (t.subst_args.size() != t.substituted->params.size()) {
      diag_.error(t.subst_loc, "wrong number of arguments: net " + q(t.substituted->name) + " takes " +
                                   plural(t.substituted->params.size(), "port") + ", " +
                                   std::to_string(t.subst_args.size()) + " given");
    } else {
      for (std::size_t i = 0; i < t.subst_args.size(); ++i) {
        Expr& a = *t.subst_args[i];
        Type at = check_expr(a, cx);
        if (at.is_error()) continue;
        const Param& port = t.substituted->params[i];
        if (at.kind != K::Place) {
          diag_.error(a.loc, "port " + q(port.name) + " of net " + q(t.substituted->name) +
                                 " needs a place, not " + q(at.name()));
          continue;
        }
        if (parent_scope(*at.decl) != &owner)
          diag_.error(a.loc, "the socket of port " + q(port.name) + " must be a place of the net of " +
                                 q(owner.name));
        const PlaceDecl* port_place = nullptr;
        for (const DeclPtr& m : t.substituted->members)
          if (m->kind == DeclKind::Place && m->name == port.name) port_place = &m->as<PlaceDecl>();
        if (port_place != nullptr && !(port_place->token == at.cls))
          diag_.error(a.loc, "port " + q(port.name) + " of net " + q(t.substituted->name) + " holds " +
                                 (port_place->token.empty() ? "black tokens"
                                                            : q(port_place->token.name()) + " tokens") +
                                 ", but place " + q(at.decl->name) + " holds " +
                                 (at.cls.empty() ? "black tokens" : q(at.cls.name()) + " tokens"));
      }
    }
  }
  if (t.action) {
    Context cx = base;
    cx.frame = &action_frame;
    cx.body = Body::Action;
    if (owner.kind == DeclKind::Net && !owner.as<ClassDecl>().is_port_net)
      cx.finish_net = &owner.as<ClassDecl>();
    check_block_in_scope(*t.action, cx);
    t.action_slots = action_frame.max;
  }
}

void CheckerImpl::check_arrow_condition(ArrowDecl& a) {
  if (!a.condition) return;
  Frame frame;
  Context cx;
  cx.scope = parent_scope(a);
  cx.frame = &frame;
  cx.body = Body::ArrowCondition;
  if (a.from_decl != nullptr && a.to_decl != nullptr) {
    const bool input = a.to_decl->kind == DeclKind::Transition;
    if (input) {
      const auto& p = a.from_decl->as<PlaceDecl>();
      if (!p.token.empty()) {
        cx.has_mark = true;
        cx.mark = Type::reference(p.token, true);
      } else {
        cx.no_mark = "place " + q(p.name) + " holds black tokens, so this arrow's condition has no 'mark'";
      }
    } else {
      const auto& t = a.from_decl->as<TransitionDecl>();
      if (t.mark_place != nullptr) {
        cx.has_mark = true;
        cx.mark = Type::reference(t.mark_place->token, true);
      } else {
        cx.no_mark = "transition " + q(t.name) + " has no object input place, so there is no 'mark'";
      }
    }
  }
  expect_type(*a.condition, type_of_meta(&meta_type<bool>()), cx, "an arrow condition");
  a.condition_slots = frame.max;
}

void CheckerImpl::run(Script& script) {
  root_ = script.root.get();
  if (root_ == nullptr) return;
  declare(*root_);
  for (ClassDecl* c : classes_) resolve_base(*c);
  // Break base cycles so that every later walk up a hierarchy ends: each chain of bases is walked once
  // (walking every class's chain to its root was quadratic: a chain of 100,000 classes took minutes). A
  // cycle is reported at its class that comes first in the script, whose base is then dropped.
  {
    std::unordered_map<const ClassDecl*, std::size_t> order;  // index in classes_
    for (std::size_t i = 0; i < classes_.size(); ++i) order.emplace(classes_[i], i);
    enum : std::uint8_t { kTodo, kOnPath, kDone };
    std::vector<std::uint8_t> state(classes_.size(), kTodo);
    std::vector<std::size_t> path;
    for (std::size_t i = 0; i < classes_.size(); ++i) {
      for (std::size_t k = i; state[k] == kTodo;) {
        state[k] = kOnPath;
        path.push_back(k);
        const auto up = order.find(classes_[k]->base.decl);
        if (up == order.end()) break;  // no script base
        if (state[up->second] != kOnPath) {
          k = up->second;
          continue;
        }
        const std::size_t first =  // the cycle is the path from `up` on; its class first in the script
            *std::min_element(std::find(path.begin(), path.end(), up->second), path.end());
        diag_.error(classes_[first]->base_loc, "class " + q(classes_[first]->name) + " derives from itself");
        classes_[first]->base = {};
        break;
      }
      for (const std::size_t k : path) state[k] = kDone;
      path.clear();
    }
  }
  resolve_signatures();
  for (StartDecl* s : starts_) resolve_start(*s);
  for (ClassDecl* c : classes_)
    if (c->kind == DeclKind::Net && !c->is_port_net && c->start == nullptr)
      diag_.error(
          c->loc,
          "net " + q(c->name) +
              " is invoked but has no start place: write 'start <place>;' where an invocation begins");
  for (ArrowDecl* a : arrows_) resolve_arrow(*a);
  for (TransitionDecl* t : transitions_) resolve_transition(*t);

  for (PropertyDecl* p : properties_) check_property(*p);
  for (PlaceDecl* p : places_) check_place(*p);
  for (ClassDecl* c : classes_) check_object_args(*c);
  for (FunctionDecl* f : functions_) check_function(*f);
  for (TransitionDecl* t : transitions_) check_transition(*t);
  for (ArrowDecl* a : arrows_) check_arrow_condition(*a);
}

}  // namespace

void check(Script& script, Diagnostics& diagnostics, const Registry& registry) {
  CheckerImpl(diagnostics, registry).run(script);
}

std::unique_ptr<CheckResult> check_source(std::string name, std::string text, const Registry& registry) {
  auto result = std::make_unique<CheckResult>(std::make_unique<Source>(std::move(name), std::move(text)));
  if (const std::size_t bytes = result->source->too_long(); bytes != 0) {
    result->diagnostics.error({}, "the script is " + std::to_string(bytes) + " bytes, larger than the limit of " +
                                      std::to_string(max_source_bytes) + " bytes of a SOML++ source");
    return result;
  }
  result->script = parse(*result->source, result->diagnostics);
  check(result->script, result->diagnostics, registry);
  result->diagnostics.sort();
  return result;
}

}  // namespace vsd::soml
