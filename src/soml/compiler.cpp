// The SOML++ bytecode compiler: annotated AST -> register bytecode (see program_impl.hpp for the
// instruction set). The checker resolved every name and typed every expression, so the compiler does
// no lookup: bindings become register numbers, property slots, function indices and outer plans.
#include <algorithm>
#include <bit>
#include <cstring>
#include <optional>
#include <string>
#include <tuple>

#include "program_impl.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/registry.hpp"

namespace vsd::soml {

using K = Type::Kind;
using BK = Binding::Kind;

RK reg_kind(const Type& t) noexcept {
  switch (t.kind) {
    case K::Bool:
    case K::Int:
    case K::Enum:
      return RK::I;
    case K::Double:
      return RK::D;
    case K::String:
      return RK::S;
    case K::Ref:
    case K::Null:
    case K::Place:
      return RK::R;
    case K::Vector:
      if (t.meta == nullptr) return t.enum_decl != nullptr ? RK::X : RK::None;  // a script enum's: as a Value
      return vector_elem_kind(*t.meta) != RK::None ? RK::V
             : t.meta->ops().vector != nullptr     ? RK::X
                                                   : RK::None;
    case K::Struct:
      return t.meta != nullptr ? RK::X : RK::None;
    default:
      return RK::None;
  }
}

namespace {

// The static type of the elements of vector type t (a register holds them as int, double or string).
Type element_type_of(const MetaType* e);
Type element_type(const Type& t) {
  if (t.kind == K::Vector && t.enum_decl != nullptr) {  // a script enum's (an int in a register)
    Type e = Type::of(K::Enum);
    e.enum_decl = t.enum_decl;
    return e;
  }
  return element_type_of(t.meta != nullptr ? t.meta->element() : nullptr);
}
// The static type of a value of MetaType e as the registers hold it (a vector's element, a struct's field).
Type element_type_of(const MetaType* e) {
  if (e == nullptr) return Type::error();
  switch (e->kind()) {
    case TypeKind::Bool:
      return Type::of(K::Bool);
    case TypeKind::Float:
    case TypeKind::Double:
      return Type::of(K::Double);
    case TypeKind::String:
      return Type::of(K::String);
    case TypeKind::Struct:
    case TypeKind::Vector: {
      Type t = Type::of(e->kind() == TypeKind::Struct ? K::Struct : K::Vector);
      t.meta = e;
      return t;
    }
    default:
      return Type::of(K::Int);
  }
}

// A vector held as a Value (X register): its elements are structs or enums.
bool x_vector(const Type& t) { return t.kind == K::Vector && reg_kind(t) == RK::X; }

}  // namespace

std::string where(const ProgramImpl& p, SourceLoc loc) {
  return p.image().checked->source->name() + ":" + std::to_string(loc.line) + ":" +
         std::to_string(loc.column);
}

void not_supported(const ProgramImpl& p, SourceLoc loc, const std::string& what) {
  throw Error(where(p, loc) + ": error: " + what + " is not supported by the SOML++ runtime yet");
}

namespace {

class Compiler {
 public:
  Compiler(ProgramImpl& p, Function& f, const ScopeDecl* scope, int nlocals)
      : P(p), F(f), top_(nlocals), max_(nlocals) {
    F.scope = scope;
  }

  void finish() {
    close_locals(0);
    F.nregs = max_ + 1;
    F.compiled = true;
    if (max_ > 60000) not_supported(P, SourceLoc{}, "a function with more than 60000 registers");
  }

  // ---- emission ----
  std::size_t emit(Op op, int a = 0, int b = 0, int c = 0) {
    // Operands are 16 bits: registers, table indices (properties, plans, classes, ...) and immediates
    // (already cast). A script that needs more is refused rather than miscompiled.
    if (a < 0 || a > 0xFFFF || b < 0 || b > 0xFFFF || c < 0 || c > 0xFFFF)
      not_supported(P, SourceLoc{0, line_, 1}, "a script or function this large (an operand above 65535)");
    F.code.push_back(Ins{op, 0, static_cast<std::uint16_t>(a), static_cast<std::uint16_t>(b),
                         static_cast<std::uint16_t>(c)});
    F.lines.push_back(line_);
    F.positions.push_back(Function::Pos{pos_.line, pos_.column});
    return F.code.size() - 1;
  }
  // A vector instruction whose x says the element kind (1: strings).
  std::size_t emit_v(Op op, const Type& vec, int a = 0, int b = 0, int c = 0) {
    if (x_vector(vec)) {  // the same instruction on a Value vector
      switch (op) {
        case OP_VGET:
          return emit(OP_XVGET, a, b, c);
        case OP_VSET:
          return emit(OP_XVSET, a, b, c);
        case OP_VPUSH:
          return emit(OP_XVPUSH, a, b, c);
        case OP_VSIZE:
          return emit(OP_XVSIZE, a, b, c);
        default:
          break;
      }
    }
    const std::size_t i = emit(op, a, b, c);
    F.code[i].x = element_type(vec).kind == K::String ? 1 : 0;
    return i;
  }
  std::size_t emit_jump(Op op, int a = 0, int b = 0) {
    // The target goes into c (low 16 bits) and x (high 8 bits); a and b stay free for fused tests.
    return emit(op, a, b, 0);
  }
  std::size_t here() const { return F.code.size(); }
  void patch(std::size_t at, std::size_t target) {
    if (target >= (1u << 24)) not_supported(P, SourceLoc{}, "a function of more than 16M instructions");
    F.code[at].c = static_cast<std::uint16_t>(target & 0xFFFF);
    F.code[at].x = static_cast<std::uint8_t>(target >> 16);
  }
  int xtype(const MetaType* t) {
    auto it = std::find(P.build().xtypes.begin(), P.build().xtypes.end(), t);
    if (it != P.build().xtypes.end()) return static_cast<int>(it - P.build().xtypes.begin());
    P.build().xtypes.push_back(t);
    return static_cast<int>(P.build().xtypes.size() - 1);
  }
  int temp() {
    const int r = top_++;
    if (top_ > max_) max_ = top_;
    return r;
  }
  void at(SourceLoc loc) {
    line_ = loc.line;
    pos_ = loc;
  }
  // The position of an expression or statement while it is compiled: what its own instructions, emitted
  // before and after those of its operands, carry for run-time errors. (line_ keeps the debugger's
  // stepping as it was: the last line set.)
  class Here {
   public:
    Here(Compiler& c, SourceLoc loc) : c_(c), saved_(c.pos_) { c.at(loc); }
    ~Here() { c_.pos_ = saved_; }
    Here(const Here&) = delete;
    Here& operator=(const Here&) = delete;

   private:
    Compiler& c_;
    SourceLoc saved_;
  };

  int konst(std::int64_t v) {
    if (P.build().consts.size() >= 65535)
      not_supported(P, SourceLoc{}, "more than 65535 constants in one script");
    P.build().consts.push_back(v);
    return static_cast<int>(P.build().consts.size() - 1);
  }
  int string_const(const std::string& s) {
    if (P.build().strings.size() >= 65535)
      not_supported(P, SourceLoc{}, "more than 65535 strings in one script");
    P.build().strings.push_back(s);
    return static_cast<int>(P.build().strings.size() - 1);
  }
  void load_int(int r, std::int64_t v) {
    if (v >= -32768 && v <= 32767)
      emit(OP_LOADI, r, static_cast<std::uint16_t>(static_cast<std::int16_t>(v)));
    else
      emit(OP_LOADK, r, konst(v));
  }

  int outer_plan(int outer, SourceLoc loc) {
    OuterPlan plan;
    const Decl* s = F.scope;
    for (int k = 0; k < outer; ++k) {
      const Decl* ps = s->parent;
      if (ps == nullptr) not_supported(P, loc, "this scope");
      if (is_static_instance(*ps)) {
        plan.static_decl = &ps->as<ClassDecl>();
        plan.parents = 0;
      } else if (s->kind == DeclKind::Place || s->kind == DeclKind::Transition ||
                 (s->kind == DeclKind::Object && plan.static_decl == nullptr)) {
        ++plan.parents;
      } else {
        not_supported(P, loc, "reaching the enclosing instance of a nested class");
      }
      s = ps;
    }
    P.build().outer_plans.push_back(plan);
    return static_cast<int>(P.build().outer_plans.size() - 1);
  }
  int self_at(int outer, SourceLoc loc) {
    const int r = temp();
    emit(OP_SELF, r, outer_plan(outer, loc));
    return r;
  }

  int prop_slot(const Binding& b, SourceLoc loc) {
    if (b.kind == BK::Property) {
      auto it = P.build().prop_slot.find(&b.decl->as<PropertyDecl>());
      if (it == P.build().prop_slot.end()) not_supported(P, loc, "this property");
      return it->second;
    }
    const int slot = meta_slot(b.property);
    // What the VM cannot move between a property and a register is refused here, at load, never at run
    // time (every kind is handled today; a new one must be added to meta_slot and the VM first).
    const PropSlot& ps = P.build().props[static_cast<std::size_t>(slot)];
    if (ps.kind == PK::Other && ps.prop->type().kind() != TypeKind::Float)
      not_supported(P, loc, "property '" + ps.prop->name() + "' of type " + ps.prop->type().name());
    return slot;
  }
  int meta_slot(const MetaProperty* mp) {
    auto it = P.build().meta_prop_slot.find(mp);
    if (it != P.build().meta_prop_slot.end()) return it->second;
    PropSlot s;
    s.prop = mp;
    const MetaType& t = mp->type();
    switch (t.kind()) {
      case TypeKind::Bool:
        s.kind = PK::Bool;
        break;
      case TypeKind::Int:
      case TypeKind::UInt:
        s.kind = &t == &meta_type<std::int64_t>() ? PK::I64 : PK::Int;
        break;
      case TypeKind::Double:
        s.kind = PK::Double;
        break;
      case TypeKind::Float:
        s.kind = PK::Other;
        break;
      case TypeKind::String:
        s.kind = PK::String;
        break;
      case TypeKind::Enum:
      case TypeKind::Flags:
        s.kind = PK::Enum;
        break;
      case TypeKind::Ref:
      case TypeKind::SharedRef:
        s.kind = PK::Ref;
        break;
      case TypeKind::RefList:
      case TypeKind::SharedRefList:
        s.kind = PK::List;
        break;
      // Structs (Vector3d, Quaterniond, Isometry3d, VSD_STRUCTs) and vectors of structs or enums of a
      // built-in class are Values in X registers, as those of script classes are (prop_kind).
      case TypeKind::Struct:
        s.kind = PK::Value;
        break;
      case TypeKind::Vector:
        s.kind = vector_elem_kind(t) != RK::None ? PK::Vector : PK::Value;
        break;
      default:
        s.kind = PK::Other;  // float: through the MetaType's width (the VM's default cases)
    }
    P.build().props.push_back(s);
    const int i = static_cast<int>(P.build().props.size() - 1);
    P.build().meta_prop_slot[mp] = i;
    return i;
  }

  static bool in_port_net(const PlaceDecl& pd) {
    const auto* owner = parent_scope(pd);
    return owner != nullptr && owner->kind == DeclKind::Net && owner->as<ClassDecl>().is_port_net;
  }
  // A place of a port net, named in its code: each copy has its own places (a port is its copy's
  // socket), so OP_PLACE finds it at run time from the copy's instance, the substitution transition's
  // node (operand c: kPortPlace | index into build().port_places).
  int port_place(const PlaceDecl& pd, SourceLoc loc) {
    auto it = std::find(P.build().port_places.begin(), P.build().port_places.end(), &pd);
    if (it == P.build().port_places.end()) {
      if (P.build().port_places.size() >= kPortPlace - 1)
        not_supported(P, loc, "this many places of port nets");
      P.build().port_places.push_back(&pd);
      it = P.build().port_places.end() - 1;
    }
    return static_cast<int>(kPortPlace | static_cast<std::size_t>(it - P.build().port_places.begin()));
  }

  int place_index(const PlaceDecl& pd, SourceLoc loc) {
    const auto* owner = parent_scope(pd);
    if (in_port_net(pd))
      not_supported(P, loc, "naming place '" + pd.name + "' of a port net through another instance");
    if (owner == nullptr || !owner->is_class_like()) not_supported(P, loc, "this place");
    auto it = P.build().class_info.find(&owner->as<ClassDecl>());
    if (it == P.build().class_info.end() || !it->second->net) not_supported(P, loc, "this place");
    const auto& places = it->second->net->places;
    for (std::size_t i = 0; i < places.size(); ++i)
      if (places[i] == &pd) return static_cast<int>(i);
    not_supported(P, loc, "this place");
  }

  int class_operand(const ClassRef& c, SourceLoc loc) {
    const MetaInstance* m = c.meta;
    const ClassInfo* ci = nullptr;
    if (c.decl != nullptr) {
      auto it = P.build().class_info.find(c.decl);
      if (it == P.build().class_info.end()) not_supported(P, loc, "this class");
      ci = it->second.get();
      m = ci->meta;
    }
    P.build().classes.push_back(ci);
    P.build().class_metas.push_back(m);
    return static_cast<int>(P.build().classes.size() - 1);
  }

  // ---- expressions ----
  int coerce(int r, const Type& from, const Type& to) {
    if (to.kind == K::Double && from.kind == K::Int) {
      const int t = temp();
      emit(OP_I2D, t, r);
      return t;
    }
    return r;
  }
  void move(int dst, int src, RK k) {
    if (dst == src) return;
    emit(k == RK::S ? OP_MOVS : k == RK::V ? OP_MOVV : k == RK::X ? OP_MOVX : OP_MOV, dst, src);
  }
  void expr_to(const Expr& e, int dst, const Type& want) {
    const int save = top_;
    if (e.kind == ExprKind::Binary && reg_kind(e.type) == reg_kind(want) && reg_kind(want) != RK::S) {
      const auto& b = e.as<BinaryExpr>();
      if (b.op != TokenKind::AmpAmp && b.op != TokenKind::PipePipe) {
        binary_into(b, dst);
        top_ = save;
        return;
      }
    }
    int r = expr(e);
    r = coerce(r, e.type, want);
    move(dst, r, reg_kind(want));
    top_ = save;
  }
  // Evaluates into a fresh register (a copy of a local when needed), so the caller may keep it.
  int expr_fresh(const Expr& e, const Type& want) {
    const int r = temp();
    expr_to(e, r, want);
    top_ = r + 1;
    return r;
  }

  int value_check(const Expr& e) {
    const RK k = reg_kind(e.type);
    if (k == RK::None) not_supported(P, e.loc, "a value of type '" + e.type.name() + "'");
    return 0;
  }

  int expr(const Expr& e) {
    const Here at_node(*this, e.loc);
    switch (e.kind) {
      case ExprKind::Int: {
        const int r = temp();
        load_int(r, e.as<LiteralExpr>().int_value);
        return r;
      }
      case ExprKind::Float: {
        const int r = temp();
        emit(OP_LOADK, r, konst(std::bit_cast<std::int64_t>(e.as<LiteralExpr>().float_value)));
        return r;
      }
      case ExprKind::String: {
        const int r = temp();
        emit(OP_LOADS, r, string_const(e.as<LiteralExpr>().string_value));
        return r;
      }
      case ExprKind::Bool: {
        const int r = temp();
        load_int(r, e.as<LiteralExpr>().bool_value ? 1 : 0);
        return r;
      }
      case ExprKind::Null: {
        const int r = temp();
        load_int(r, 0);
        return r;
      }
      case ExprKind::This:
        return self_at(0, e.loc);
      case ExprKind::Mark: {
        const int r = temp();
        emit(OP_MARK, r);
        return r;
      }
      case ExprKind::Name:
        return name(e.as<NameExpr>());
      case ExprKind::Member:
        return member(e.as<MemberExpr>());
      case ExprKind::Unary:
      case ExprKind::Postfix:
        return unary(e.as<UnaryExpr>());
      case ExprKind::Binary:
        return binary(e.as<BinaryExpr>());
      case ExprKind::Assign:
        assign(e.as<BinaryExpr>());
        return -1;
      case ExprKind::Conditional: {
        const auto& c = e.as<ConditionalExpr>();
        value_check(e);
        const int r = temp();
        const int cr = expr(*c.cond);
        const std::size_t jf = emit_jump(OP_JMPF, cr);
        top_ = r + 1;
        expr_to(*c.then_expr, r, e.type);
        const std::size_t je = emit_jump(OP_JMP);
        patch(jf, here());
        top_ = r + 1;
        expr_to(*c.else_expr, r, e.type);
        patch(je, here());
        top_ = r + 1;
        return r;
      }
      case ExprKind::Call:
        return call(e.as<CallExpr>());
      case ExprKind::Index:
        return index(e.as<IndexExpr>());
      case ExprKind::New:
        return make_new(e.as<NewExpr>());
      case ExprKind::Is:
      case ExprKind::As: {
        const auto& n = e.as<NewExpr>();
        const int o = expr(*n.operand);
        const int r = temp();
        ClassRef c = n.binding.decl != nullptr && n.binding.decl->is_class_like()
                         ? ClassRef{&n.binding.decl->as<ClassDecl>(), nullptr}
                         : ClassRef{nullptr, n.binding.meta_class};
        if (c.empty()) c = e.kind == ExprKind::As ? e.type.cls : ClassRef{};
        if (c.empty()) not_supported(P, e.loc, "this class test");
        emit(e.kind == ExprKind::Is ? OP_ISA : OP_AS, r, o, class_operand(c, e.loc));
        return r;
      }
    }
    not_supported(P, e.loc, "this expression");
  }

  int name(const NameExpr& e) {
    const Binding& b = e.binding;
    switch (b.kind) {
      case BK::Local:
        return b.slot;
      case BK::Property:
      case BK::MetaProperty: {
        value_check(e);
        const int s = self_at(b.outer, e.loc);
        emit(OP_GETP, s, s, prop_slot(b, e.loc));
        return s;
      }
      case BK::EnumValue: {
        const int r = temp();
        load_int(r, b.slot);
        return r;
      }
      case BK::Object: {
        if (!is_static_instance(*b.decl)) not_supported(P, e.loc, "naming an object nested in a class");
        const int r = temp();
        P.build().object_refs.push_back({konst(0), &b.decl->as<ClassDecl>()});
        emit(OP_OBJ, r, P.build().object_refs.back().first);
        return r;
      }
      case BK::Place: {
        const int s = self_at(b.outer, e.loc);
        const auto& pd = b.decl->as<PlaceDecl>();
        emit(OP_PLACE, s, s, in_port_net(pd) ? port_place(pd, e.loc) : place_index(pd, e.loc));
        return s;
      }
      case BK::Builtin:
        if (b.builtin == Builtin::PlaceCount) {
          const int s = self_at(b.outer, e.loc);
          emit(OP_PCOUNT, s, s);
          return s;
        }
        break;
      case BK::This:
        return self_at(0, e.loc);
      case BK::Mark: {
        const int r = temp();
        emit(OP_MARK, r);
        return r;
      }
      default:
        break;
    }
    not_supported(P, e.loc, "using '" + e.spelling() + "' as a value");
  }

  int member(const MemberExpr& e) {
    const Binding& b = e.binding;
    switch (b.kind) {
      case BK::Property:
      case BK::MetaProperty: {
        value_check(e);
        const int o = expr(*e.object);
        const int r = temp();
        emit(OP_GETP, r, o, prop_slot(b, e.loc));
        return r;
      }
      case BK::Place: {
        const int o = expr(*e.object);
        const int r = temp();
        emit(OP_PLACE, r, o, place_index(b.decl->as<PlaceDecl>(), e.loc));
        return r;
      }
      case BK::StructField: {
        value_check(e);
        const int o = expr(*e.object);
        const int r = temp();
        at(e.loc);
        field_op(OP_XGETF, r, o, b.slot);
        return r;
      }
      case BK::Builtin:
        if (b.builtin == Builtin::PlaceCount) {
          const int o = expr(*e.object);
          const int r = temp();
          emit(OP_PCOUNT, r, o);
          return r;
        }
        break;
      default:
        break;
    }
    not_supported(P, e.loc, "member '" + e.name + "' as a value");
  }

  void field_op(Op op, int a, int b, int field) {
    if (field > 255) not_supported(P, SourceLoc{0, line_, 1}, "a struct with more than 256 fields");
    const std::size_t i = emit(op, a, b);
    F.code[i].x = static_cast<std::uint8_t>(field);
  }

  // The holder register and property slot of a list-valued expression (a property of a list type).
  std::pair<int, int> list_of(const Expr& e) {
    if (e.kind == ExprKind::Member) {
      const auto& m = e.as<MemberExpr>();
      if (m.binding.kind == BK::Property || m.binding.kind == BK::MetaProperty) {
        const int slot = prop_slot(m.binding, e.loc);
        if (P.build().props[slot].kind == PK::List) return {expr(*m.object), slot};
      }
    } else if (e.kind == ExprKind::Name) {
      const auto& n = e.as<NameExpr>();
      if (n.binding.kind == BK::Property || n.binding.kind == BK::MetaProperty) {
        const int slot = prop_slot(n.binding, e.loc);
        if (P.build().props[slot].kind == PK::List) return {self_at(n.binding.outer, e.loc), slot};
      }
    }
    not_supported(P, e.loc, "this list or vector expression (lists are reached as properties)");
  }

  // The holder register and property slot when e is a vector property (read in place, written through
  // the setter); {-1, -1} for any other vector expression (a value in a vector register).
  std::pair<int, int> vector_property(const Expr& e) {
    const Binding* b = nullptr;
    if (e.kind == ExprKind::Member || e.kind == ExprKind::Name)
      b = e.kind == ExprKind::Member ? &e.as<MemberExpr>().binding : &e.as<NameExpr>().binding;
    if (b == nullptr || (b->kind != BK::Property && b->kind != BK::MetaProperty)) return {-1, -1};
    const int slot = prop_slot(*b, e.loc);
    if (P.build().props[slot].kind != PK::Vector &&
        !(P.build().props[slot].kind == PK::Value && x_vector(e.type)))
      not_supported(P, e.loc, "a value of type '" + e.type.name() + "'");
    const int h = e.kind == ExprKind::Member ? expr(*e.as<MemberExpr>().object) : self_at(b->outer, e.loc);
    return {h, slot};
  }
  // The vector register of a vector-valued expression that is not a property (a local: its slot).
  int vector_reg(const Expr& e) {
    value_check(e);
    return expr(e);
  }

  int vector_index(const IndexExpr& e) {
    auto [h, slot] = vector_property(*e.object);
    if (h >= 0) {
      const int r = temp();
      expr_to(*e.index, r, e.index->type);
      at(e.loc);
      emit(OP_PVGET, r, h, slot);
      return r;
    }
    const int v = vector_reg(*e.object);
    const int i = expr(*e.index);
    const int r = temp();
    at(e.loc);
    emit_v(OP_VGET, e.object->type, r, v, i);
    return r;
  }

  // `v[i] = x` and `v[i] op= x`: a local is changed in its register; a property is read, changed and
  // written back through its setter (so the change signals and records). @p op is None for `=`.
  void store_element(const IndexExpr& ix, TokenKind op, const Expr* rhs, int value, const Type& vt) {
    const Type& vec = ix.object->type;
    const Type elem = element_type(vec);
    int h = -1, slot = -1, v = -1;
    if (ix.object->kind == ExprKind::Name && ix.object->as<NameExpr>().binding.kind == BK::Local) {
      v = ix.object->as<NameExpr>().binding.slot;
    } else {
      std::tie(h, slot) = vector_property(*ix.object);
      if (h < 0) not_supported(P, ix.loc, "assigning to an element of a temporary vector");
      v = temp();
      at(ix.loc);
      emit(OP_GETP, v, h, slot);
    }
    const int i = expr_fresh(*ix.index, ix.index->type);
    if (op != TokenKind::Eof) {  // compound: the current element, the operation, back
      const int cur = temp();
      at(ix.loc);
      emit_v(OP_VGET, vec, cur, v, i);
      int r;
      Type rt;
      if (rhs != nullptr) {
        r = expr(*rhs);
        rt = rhs->type;
      } else {
        r = temp();
        load_int(r, 1);
        rt = Type::of(K::Int);
      }
      Type result = elem;
      if (result.kind == K::Int && rt.kind == K::Double) result = Type::of(K::Double);
      value = arith(op, cur, elem, r, rt, result, ix.loc);
      if (result.kind == K::Double && elem.kind == K::Int) {
        const int t = temp();
        emit(OP_D2I, t, value);
        value = t;
      }
    } else {
      value = coerce(value, vt, elem);
    }
    at(ix.loc);
    emit_v(OP_VSET, vec, v, i, value);
    if (h >= 0) emit(OP_SETP, h, v, slot);
  }

  int index(const IndexExpr& e) {
    if (e.object->type.kind == K::Vector) return vector_index(e);
    auto [h, slot] = list_of(*e.object);
    const int r = temp();
    expr_to(*e.index, r, e.index->type);
    emit(OP_LGET, r, h, slot);
    return r;
  }

  int unary(const UnaryExpr& e) {
    const bool inc = e.op == TokenKind::PlusPlus || e.op == TokenKind::MinusMinus;
    if (inc) {
      store_compound(*e.operand, e.op == TokenKind::PlusPlus ? TokenKind::Plus : TokenKind::Minus, nullptr);
      return -1;
    }
    const int o = expr(*e.operand);
    const int r = temp();
    switch (e.op) {
      case TokenKind::Bang:
        emit(OP_NOT, r, o);
        return r;
      case TokenKind::Minus:
        if (e.type.kind == K::Struct) {
          emit_struct(StructOp::Neg, r, o);
          return r;
        }
        emit(e.type.kind == K::Double ? OP_NEGD : OP_NEGI, r, o);
        return r;
      case TokenKind::Plus:
        move(r, o, reg_kind(e.type));
        return r;
      default:
        not_supported(P, e.loc, "this operator");
    }
  }

  int arith(TokenKind op, int l, const Type& lt, int r, const Type& rt, const Type& result, SourceLoc loc,
            int into = -1) {
    const int d = into >= 0 && result.kind != K::String ? into : temp();
    if (result.kind == K::Struct) {  // vectors, quaternions, frames (docs/soml.md 4.14)
      struct_arith(op, d, l, lt, r, rt);
      return d;
    }
    if (result.kind == K::String) {  // concatenation
      const int ls = to_string(l, lt), rs = to_string(r, rt);
      emit(OP_CONCAT, d, ls, rs);
      return d;
    }
    const bool dbl = result.kind == K::Double;
    if (dbl) {
      l = coerce(l, lt, result);
      r = coerce(r, rt, result);
    }
    Op o;
    switch (op) {
      case TokenKind::Plus:
        o = dbl ? OP_ADDD : OP_ADDI;
        break;
      case TokenKind::Minus:
        o = dbl ? OP_SUBD : OP_SUBI;
        break;
      case TokenKind::Star:
        o = dbl ? OP_MULD : OP_MULI;
        break;
      case TokenKind::Slash:
        o = dbl ? OP_DIVD : OP_DIVI;
        break;
      case TokenKind::Percent:
        o = OP_MODI;
        break;
      default:
        not_supported(P, loc, "this operator");
    }
    emit(o, d, l, r);
    return d;
  }

  // One struct operation (OP_XOP): the checker typed the operands.
  void emit_struct(StructOp op, int a, int b, int c = 0) {
    const std::size_t i = emit(OP_XOP, a, b, c);
    F.code[i].x = static_cast<std::uint8_t>(op);
  }

  // d = l op r where the result is a struct: v + w, v - w, v * s, s * v, v / s, q * q, q * v, T * T, T * v.
  void struct_arith(TokenKind op, int d, int l, const Type& lt, int r, const Type& rt) {
    if (lt.kind != K::Struct) {  // s * v: the scalar goes second
      struct_arith(op, d, r, rt, l, lt);
      return;
    }
    StructOp o = StructOp::Mul;
    if (rt.kind != K::Struct) {
      r = coerce(r, rt, Type::of(K::Double));
      o = op == TokenKind::Slash ? StructOp::Div : StructOp::Scale;
    } else if (op == TokenKind::Plus) {
      o = StructOp::Add;
    } else if (op == TokenKind::Minus) {
      o = StructOp::Sub;
    } else if (rt.meta != lt.meta) {  // q * v, T * v
      o = StructOp::Apply;
    }
    emit_struct(o, d, l, r);
  }

  int to_string(int r, const Type& t) {
    if (t.kind == K::String) return r;
    const int d = temp();
    if (t.kind == K::Struct) {
      emit_struct(StructOp::Text, d, r);
      return d;
    }
    int variant = 0;
    switch (t.kind) {
      case K::Int:
        variant = 0;
        break;
      case K::Double:
        variant = 1;
        break;
      case K::Bool:
        variant = 2;
        break;
      case K::Enum: {
        const MetaType* m = t.meta;
        if (t.enum_decl != nullptr) {
          auto it = P.enums_.find(t.enum_decl);
          if (it != P.enums_.end()) m = it->second;
        }
        if (m == nullptr) not_supported(P, SourceLoc{}, "this enum");
        P.build().enum_types.push_back(m);
        variant = 3 + static_cast<int>(P.build().enum_types.size() - 1);
        break;
      }
      case K::Ref:
      case K::Null:
        variant = 2 + 60000;  // never used: the checker rejects it
        not_supported(P, SourceLoc{}, "converting a reference to a string");
      default:
        not_supported(P, SourceLoc{}, "converting '" + t.name() + "' to a string");
    }
    emit(OP_TOSTR, d, r, variant);
    return d;
  }

  int compare(TokenKind op, int l, const Type& lt, int r, const Type& rt, int into = -1) {
    const int d = into >= 0 ? into : temp();
    if (lt.kind == K::Struct || x_vector(lt)) {  // values: == and != (the checker allows no other)
      emit(OP_EQX, d, l, r);
      if (op == TokenKind::BangEqual) emit(OP_NOT, d, d);
      return d;
    }
    if (lt.kind == K::Vector) {  // == and != (the checker allows no other)
      const K ek = element_type(lt).kind;
      const std::size_t i = emit(OP_EQV, d, l, r);
      F.code[i].x = ek == K::String ? 2 : ek == K::Double ? 1 : 0;
      if (op == TokenKind::BangEqual) emit(OP_NOT, d, d);
      return d;
    }
    const bool dbl = (lt.kind == K::Double || rt.kind == K::Double);
    const bool str = lt.kind == K::String;
    if (dbl) {
      Type td = Type::of(K::Double);
      l = coerce(l, lt, td);
      r = coerce(r, rt, td);
    }
    bool swap = false;
    Op o;
    switch (op) {
      case TokenKind::Less:
        o = str ? OP_LTS : dbl ? OP_LTD : OP_LTI;
        break;
      case TokenKind::LessEqual:
        o = str ? OP_LES : dbl ? OP_LED : OP_LEI;
        break;
      case TokenKind::Greater:
        o = str ? OP_LTS : dbl ? OP_LTD : OP_LTI;
        swap = true;
        break;
      case TokenKind::GreaterEqual:
        o = str ? OP_LES : dbl ? OP_LED : OP_LEI;
        swap = true;
        break;
      case TokenKind::EqualEqual:
        o = str ? OP_EQS : dbl ? OP_EQD : OP_EQI;
        break;
      default:
        o = str ? OP_NES : dbl ? OP_NED : OP_NEI;
        break;
    }
    if (swap) std::swap(l, r);
    emit(o, d, l, r);
    return d;
  }

  int binary(const BinaryExpr& e) {
    if (e.op == TokenKind::AmpAmp || e.op == TokenKind::PipePipe) {
      const int r = temp();
      expr_to(*e.lhs, r, e.type);
      const std::size_t j = emit_jump(e.op == TokenKind::AmpAmp ? OP_JMPF : OP_JMPT, r);
      top_ = r + 1;
      expr_to(*e.rhs, r, e.type);
      patch(j, here());
      top_ = r + 1;
      return r;
    }
    const int d = temp();
    binary_into(e, d);
    top_ = d + 1;
    return d;
  }

  // An int operation with a small constant right operand: one instruction with an immediate.
  bool immediate(const BinaryExpr& e, int dst) {
    if (e.type.kind != K::Int || e.lhs->type.kind != K::Int || e.rhs->kind != ExprKind::Int) return false;
    const std::int64_t k = e.rhs->as<LiteralExpr>().int_value;
    if (k < -32767 || k > 32767) return false;
    Op o;
    std::int64_t v = k;
    switch (e.op) {
      case TokenKind::Plus:
        o = OP_ADDIK;
        break;
      case TokenKind::Minus:
        o = OP_ADDIK;
        v = -k;
        break;
      case TokenKind::Star:
        o = OP_MULIK;
        break;
      case TokenKind::Slash:
        if (k == 0 || k == -1) return false;
        o = OP_DIVIK;
        break;
      case TokenKind::Percent:
        if (k == 0 || k == -1) return false;
        o = OP_MODIK;
        break;
      default:
        return false;
    }
    const int l = expr(*e.lhs);
    emit(o, dst, l, static_cast<std::uint16_t>(static_cast<std::int16_t>(v)));
    return true;
  }

  // Computes a (non-logical) binary expression into register dst.
  void binary_into(const BinaryExpr& e, int dst) {
    const Here at_node(*this, e.loc);
    const int save = top_;
    if (immediate(e, dst)) {
      top_ = save;
      return;
    }
    const int l = expr(*e.lhs);
    const int r = expr(*e.rhs);
    int d;
    switch (e.op) {
      case TokenKind::Plus:
      case TokenKind::Minus:
      case TokenKind::Star:
      case TokenKind::Slash:
      case TokenKind::Percent:
        d = arith(e.op, l, e.lhs->type, r, e.rhs->type, e.type, e.loc, dst);
        break;
      default:
        d = compare(e.op, l, e.lhs->type, r, e.rhs->type, dst);
    }
    move(dst, d, reg_kind(e.type));
    top_ = save;
  }

  // Stores register v (of type vt) into the place lvalue e designates.
  void store(const Expr& e, int v, const Type& vt) {
    at(e.loc);
    if (e.kind == ExprKind::Name) {
      const auto& n = e.as<NameExpr>();
      if (n.binding.kind == BK::Local) {
        move(n.binding.slot, coerce(v, vt, e.type), reg_kind(e.type));
        return;
      }
      if (n.binding.kind == BK::Property || n.binding.kind == BK::MetaProperty) {
        const int s = self_at(n.binding.outer, e.loc);
        emit(OP_SETP, s, coerce(v, vt, e.type), prop_slot(n.binding, e.loc));
        return;
      }
    } else if (e.kind == ExprKind::Member) {
      const auto& m = e.as<MemberExpr>();
      if (m.binding.kind == BK::Property || m.binding.kind == BK::MetaProperty) {
        const int o = expr(*m.object);
        emit(OP_SETP, o, coerce(v, vt, e.type), prop_slot(m.binding, e.loc));
        return;
      }
      if (m.binding.kind == BK::StructField) {
        // A field of a local changes in its register; of anything else (a property, an element, a field
        // of those): the whole value is read, changed and stored back, so a property changes once
        // through its setter (it signals and records).
        const Expr& o = *m.object;
        v = coerce(v, vt, e.type);
        if (o.kind == ExprKind::Name && o.as<NameExpr>().binding.kind == BK::Local) {
          at(e.loc);
          field_op(OP_XSETF, o.as<NameExpr>().binding.slot, v, m.binding.slot);
          return;
        }
        const int keep = temp();
        move(keep, v, reg_kind(e.type));
        const int cur = temp();
        expr_to(o, cur, o.type);
        at(e.loc);
        field_op(OP_XSETF, cur, keep, m.binding.slot);
        store(o, cur, o.type);
        return;
      }
    } else if (e.kind == ExprKind::Index && e.as<IndexExpr>().object->type.kind == K::Vector) {
      store_element(e.as<IndexExpr>(), TokenKind::Eof, nullptr, v, vt);
      return;
    }
    not_supported(P, e.loc, "assigning to this expression");
  }

  void store_compound(const Expr& target, TokenKind op, const Expr* rhs) {
    const int save = top_;
    if (target.kind == ExprKind::Name && target.as<NameExpr>().binding.kind == BK::Local &&
        target.type.kind == K::Int && (op == TokenKind::Plus || op == TokenKind::Minus) &&
        (rhs == nullptr || (rhs->kind == ExprKind::Int && rhs->as<LiteralExpr>().int_value >= -32767 &&
                            rhs->as<LiteralExpr>().int_value <= 32767))) {
      std::int64_t k = rhs == nullptr ? 1 : rhs->as<LiteralExpr>().int_value;
      if (op == TokenKind::Minus) k = -k;
      const int slot = target.as<NameExpr>().binding.slot;
      emit(OP_ADDIK, slot, slot, static_cast<std::uint16_t>(static_cast<std::int16_t>(k)));
      return;
    }
    if (target.kind == ExprKind::Index && target.as<IndexExpr>().object->type.kind == K::Vector) {
      store_element(target.as<IndexExpr>(), op, rhs, -1, Type());
      top_ = save;
      return;
    }
    const int cur = expr(target);
    int r;
    Type rt;
    if (rhs != nullptr) {
      r = expr(*rhs);
      rt = rhs->type;
    } else {
      r = temp();
      load_int(r, 1);
      rt = Type::of(K::Int);
    }
    Type result = target.type;
    if (result.kind == K::Int && rt.kind == K::Double) result = Type::of(K::Double);
    if (target.type.kind == K::String) result = Type::of(K::String);
    // A local int or double whose result has its own kind: computed straight into its register (`s += i`
    // is one ADDI; the instruction writes only after its checks, so an error leaves the local as it was).
    const bool in_place = target.kind == ExprKind::Name && target.as<NameExpr>().binding.kind == BK::Local &&
                          (result.kind == K::Int || result.kind == K::Double) &&
                          result.kind == target.type.kind;
    int v = arith(op, cur, target.type, r, rt, result, target.loc, in_place ? cur : -1);
    if (result.kind == K::Double && target.type.kind == K::Int) {
      const int t = temp();
      emit(OP_D2I, t, v);
      v = t;
    }
    store(target, v, target.type);
    top_ = save;
  }

  void assign(const BinaryExpr& e) {
    const int save = top_;
    if (e.op == TokenKind::Equal) {
      if (e.lhs->kind == ExprKind::Name && e.lhs->as<NameExpr>().binding.kind == BK::Local) {
        expr_to(*e.rhs, e.lhs->as<NameExpr>().binding.slot, e.lhs->type);
      } else {
        const int v = expr(*e.rhs);
        store(*e.lhs, v, e.rhs->type);
      }
      top_ = save;
      return;
    }
    TokenKind op = TokenKind::Plus;
    switch (e.op) {
      case TokenKind::MinusEqual:
        op = TokenKind::Minus;
        break;
      case TokenKind::StarEqual:
        op = TokenKind::Star;
        break;
      case TokenKind::SlashEqual:
        op = TokenKind::Slash;
        break;
      case TokenKind::PercentEqual:
        op = TokenKind::Percent;
        break;
      default:
        break;
    }
    store_compound(*e.lhs, op, e.rhs.get());
  }

  // Arguments into consecutive fresh registers starting at the returned one.
  int args_at(const std::vector<ExprPtr>& args, const std::vector<Type>& want) {
    const int base = top_;
    for (std::size_t i = 0; i < args.size(); ++i) temp();
    for (std::size_t i = 0; i < args.size(); ++i) {
      const int save = top_;
      expr_to(*args[i], base + static_cast<int>(i), i < want.size() ? want[i] : args[i]->type);
      top_ = save;
    }
    return base;
  }

  int call(const CallExpr& e) {
    const Binding& b = e.binding;
    const Expr& callee = *e.callee;
    switch (b.kind) {
      case BK::Function: {
        const auto& fd = b.decl->as<FunctionDecl>();
        auto v = P.build().vslot_of.find(&fd);
        const bool virt = v != P.build().vslot_of.end();
        // A plain call of a function of this scope runs on this frame's self: OP_CALLS, no SELF.
        const bool same_self = callee.kind != ExprKind::Member && b.outer == 0 && !virt;
        int self = -1;
        if (callee.kind == ExprKind::Member)
          self = expr(*callee.as<MemberExpr>().object);
        else if (!same_self)
          self = self_at(b.outer, callee.loc);
        std::vector<Type> want;
        for (const Param& p : fd.params) want.push_back(p.type);
        const int base = args_at(e.args, want);
        if (base == top_) temp();  // the result register
        at(e.loc);
        if (virt)
          emit(OP_VCALL, base, v->second, self);
        else if (same_self)
          emit(OP_CALLS, base, P.build().function_index.at(&fd));
        else
          emit(OP_CALL, base, P.build().function_index.at(&fd), self);
        top_ = base + 1;
        return base;
      }
      case BK::MetaMethod: {
        const int r = temp();
        if (callee.kind == ExprKind::Member) {
          const int o = expr(*callee.as<MemberExpr>().object);
          move(r, o, RK::R);
        } else {
          const int o = self_at(b.outer, callee.loc);
          move(r, o, RK::R);
        }
        top_ = r + 1;
        std::vector<Type> want;
        args_at(e.args, want);
        if (reg_kind(e.type) == RK::None && e.type.kind != K::Void)
          not_supported(P, e.loc, "a method returning '" + e.type.name() + "'");
        P.build().methods.push_back(b.method);
        P.build().method_kinds.emplace_back();
        for (const ExprPtr& a : e.args) {
          if (reg_kind(a->type) == RK::None)
            not_supported(P, a->loc, "an argument of type '" + a->type.name() + "'");
          P.build().method_kinds.back().push_back(reg_kind(a->type));
        }
        P.build().method_results.push_back(reg_kind(e.type));
        at(e.loc);
        emit(OP_MCALL, r, static_cast<int>(P.build().methods.size() - 1));
        top_ = r + 1;
        return r;
      }
      case BK::Builtin:
        return builtin(e);
      case BK::Construct: {  // a default value, then the fields in order
        const MetaType& st = *b.meta_type;
        std::vector<Type> want;
        for (const MetaType::Field& f : st.fields()) {
          Type t = element_type_of(f.type);
          want.push_back(t);
        }
        const int base = args_at(e.args, want);
        const int r = temp();
        at(e.loc);
        emit(OP_XDEF, r, xtype(&st));
        for (std::size_t i = 0; i < e.args.size(); ++i)
          field_op(OP_XSETF, r, base + static_cast<int>(i), static_cast<int>(i));
        return r;
      }
      case BK::Conversion: {
        const Expr& a = *e.args.at(0);
        const int o = expr(a);
        const int r = temp();
        switch (e.type.kind) {
          case K::Int:
            if (a.type.kind == K::Double)
              emit(OP_D2I, r, o);
            else if (a.type.kind == K::String)
              not_supported(P, e.loc, "int(string)");
            else
              move(r, o, RK::I);
            return r;
          case K::Double:
            if (a.type.kind == K::Double)
              move(r, o, RK::D);
            else if (a.type.kind == K::String)
              not_supported(P, e.loc, "double(string)");
            else
              emit(OP_I2D, r, o);
            return r;
          case K::String:
            return to_string(o, a.type);
          case K::Bool: {
            if (a.type.kind == K::String) {
              emit(OP_STR2B, r, o);
              return r;
            }
            if (a.type.kind == K::Double) {
              const int z = temp();
              emit(OP_LOADK, z, konst(std::bit_cast<std::int64_t>(0.0)));
              emit(OP_NED, r, o, z);
              return r;
            }
            const int z = temp();
            load_int(z, 0);
            emit(OP_NEI, r, o, z);
            return r;
          }
          default:
            not_supported(P, e.loc, "this conversion");
        }
      }
      default:
        break;
    }
    not_supported(P, e.loc, "this call");
  }

  int builtin(const CallExpr& e) {
    const Binding& b = e.binding;
    const Expr& callee = *e.callee;
    auto place_reg = [&]() {
      if (callee.kind == ExprKind::Member) return expr(*callee.as<MemberExpr>().object);
      return self_at(b.outer, callee.loc);
    };
    switch (b.builtin) {
      case Builtin::Print: {
        const int base = top_;
        std::vector<RK> kinds;
        std::vector<const MetaType*> types;
        for (std::size_t i = 0; i < e.args.size(); ++i) temp();
        for (std::size_t i = 0; i < e.args.size(); ++i) {
          const Expr& a = *e.args[i];
          const int save = top_;
          int r = expr(a);
          if (a.type.kind == K::Enum || a.type.kind == K::Bool) r = to_string(r, a.type);
          RK k = a.type.kind == K::Enum || a.type.kind == K::Bool ? RK::S : reg_kind(a.type);
          if (k == RK::None) not_supported(P, a.loc, "printing a value of type '" + a.type.name() + "'");
          move(base + static_cast<int>(i), r, k);
          kinds.push_back(k);
          types.push_back(k == RK::V ? a.type.meta : nullptr);
          top_ = save;
        }
        P.build().print_kinds.push_back(std::move(kinds));
        P.build().print_types.push_back(std::move(types));
        at(e.loc);
        emit(OP_PRINT, base, static_cast<int>(e.args.size()),
             static_cast<int>(P.build().print_kinds.size() - 1));
        top_ = base;
        return -1;
      }
      case Builtin::Sqrt:
      case Builtin::Floor:
      case Builtin::Ceil:
      case Builtin::Abs:
      case Builtin::Min:
      case Builtin::Max:
      case Builtin::Len: {
        std::vector<Type> want;
        const bool dbl = e.type.kind == K::Double;
        for (std::size_t i = 0; i < e.args.size(); ++i)
          want.push_back(dbl || b.builtin == Builtin::Sqrt ? Type::of(K::Double) : e.args[i]->type);
        const int base = args_at(e.args, want);
        if (base == top_) temp();
        at(e.loc);
        emit(OP_BUILTIN, base, static_cast<int>(b.builtin), dbl ? 1 : 0);
        top_ = base + 1;
        return base;
      }
      case Builtin::StructOp: {  // v.norm(), v.cross(w), q.inverse(), Quaterniond::from_axis_angle(a, t)
        const auto op = static_cast<StructOp>(b.slot);
        const int self = callee.kind == ExprKind::Member ? expr(*callee.as<MemberExpr>().object) : 0;
        std::vector<Type> want;
        for (const ExprPtr& a : e.args)
          want.push_back(a->type.kind == K::Int ? Type::of(K::Double) : a->type);
        const int base = args_at(e.args, want);
        const int r = temp();
        at(e.loc);
        if (op == StructOp::FromAxisAngle)
          emit_struct(op, r, base, base + 1);
        else
          emit_struct(op, r, self, e.args.empty() ? 0 : base);
        return r;
      }
      case Builtin::Find: {
        const int path = expr(*e.args.at(0));
        const int r = temp();
        at(e.loc);
        emit(OP_FIND, r, path);
        return r;
      }
      case Builtin::PlaceCount: {
        const int p = place_reg();
        const int r = temp();
        emit(OP_PCOUNT, r, p);
        return r;
      }
      case Builtin::PlacePut: {
        const int p = place_reg();
        const Expr& a = *e.args.at(0);
        const int v = expr(a);
        at(e.loc);
        emit(OP_PPUT, p, v, a.type.kind == K::Int ? 0 : 1);
        return -1;
      }
      case Builtin::PlaceClear: {
        const int p = place_reg();
        at(e.loc);
        emit(OP_PCLEAR, p);
        return -1;
      }
      case Builtin::Size: {
        if (callee.kind != ExprKind::Member) break;
        const Expr& o = *callee.as<MemberExpr>().object;
        if (o.type.kind == K::Vector) {
          auto [vh, vslot] = vector_property(o);
          const int r = temp();
          if (vh >= 0)
            emit(OP_PVSIZE, r, vh, vslot);
          else
            emit_v(OP_VSIZE, o.type, r, vector_reg(o));
          return r;
        }
        auto [h, slot] = list_of(o);
        const int r = temp();
        emit(OP_LSIZE, r, h, slot);
        return r;
      }
      case Builtin::Push: {
        if (callee.kind != ExprKind::Member) break;
        const Expr& o = *callee.as<MemberExpr>().object;
        if (o.type.kind == K::Vector) {
          // A property: read, push, write back through the setter (signals and records).
          auto [vh, vslot] = vector_property(o);
          int v;
          if (vh >= 0) {
            v = temp();
            emit(OP_GETP, v, vh, vslot);
          } else if (o.kind == ExprKind::Name && o.as<NameExpr>().binding.kind == BK::Local) {
            v = o.as<NameExpr>().binding.slot;
          } else {
            not_supported(P, e.loc, "pushing onto a temporary vector");
          }
          const int x = expr_fresh(*e.args.at(0), element_type(o.type));
          at(e.loc);
          emit_v(OP_VPUSH, o.type, v, x);
          if (vh >= 0) emit(OP_SETP, vh, v, vslot);
          return -1;
        }
        auto [h, slot] = list_of(o);
        const int v = expr(*e.args.at(0));
        at(e.loc);
        emit(OP_LPUSH, h, v, slot);
        return -1;
      }
      default:
        break;
    }
    not_supported(P, e.loc, "this built-in");
  }

  int make_new(const NewExpr& e) {
    ClassRef c = e.type.cls;
    const int r = temp();
    std::vector<Type> want;
    if (c.decl != nullptr && c.decl->constructor != nullptr)
      for (const Param& p : c.decl->constructor->params) want.push_back(p.type);
    args_at(e.args, want);
    at(e.loc);
    emit(OP_NEW, r, class_operand(c, e.loc), static_cast<int>(e.args.size()));
    top_ = r + 1;
    return r;
  }

  // ---- statements ----
  struct Loop {
    std::vector<std::size_t> breaks, continues;
  };
  std::vector<Loop> loops_;

  void block(const BlockStmt& b) {
    const std::size_t open = open_.size();
    for (const StmtPtr& s : b.body) stmt(*s);
    close_locals(open);
  }

  // The debugger's table of local names: a local is visible from the end of its initialisation to the
  // end of its block (or of the loop that declares it).
  std::vector<std::size_t> open_;  // indices into F.locals still in scope
  void declare(const std::string& name, int slot, const Type& type) {
    F.locals.push_back(Function::Local{name, slot, type, static_cast<std::uint32_t>(here()), 0});
    open_.push_back(F.locals.size() - 1);
  }
  void close_locals(std::size_t n) {
    while (open_.size() > n) {
      F.locals[open_.back()].to = static_cast<std::uint32_t>(here());
      open_.pop_back();
    }
  }

  void stmt(const Stmt& s) {
    const int save = top_;
    const std::size_t open = open_.size();
    const Here at_node(*this, s.loc);
    switch (s.kind) {
      case StmtKind::Block:
        block(s.as<BlockStmt>());
        break;
      case StmtKind::Local: {
        const auto& l = s.as<LocalStmt>();
        const RK k = reg_kind(l.type);
        if (k == RK::None) not_supported(P, l.loc, "a local of type '" + l.type.name() + "'");
        if (l.init) {
          expr_to(*l.init, l.slot, l.type);
        } else if (k == RK::S) {
          emit(OP_LOADS, l.slot, string_const(""));
        } else if (k == RK::V) {
          emit(OP_VCLEAR, l.slot);
        } else if (k == RK::X) {
          const MetaType* t = storage_type(P, P.state_.environment().registry(), l.type);
          if (t == nullptr) not_supported(P, l.loc, "a local of type '" + l.type.name() + "'");
          emit(OP_XDEF, l.slot, xtype(t));
        } else if (k == RK::D) {
          emit(OP_LOADK, l.slot, konst(std::bit_cast<std::int64_t>(0.0)));
        } else {
          load_int(l.slot, 0);
        }
        declare(l.name, l.slot, l.type);
        break;
      }
      case StmtKind::If: {
        const auto& i = s.as<IfStmt>();
        const std::size_t jf = cond_jump(*i.cond);
        top_ = save;
        stmt(*i.then_stmt);
        if (i.else_stmt) {
          const std::size_t je = emit_jump(OP_JMP);
          patch(jf, here());
          stmt(*i.else_stmt);
          patch(je, here());
        } else {
          patch(jf, here());
        }
        break;
      }
      case StmtKind::While: {
        const auto& w = s.as<WhileStmt>();
        const std::size_t top = here();
        const std::size_t jf = cond_jump(*w.cond);
        top_ = save;
        loops_.emplace_back();
        stmt(*w.body);
        const std::size_t back = emit_jump(OP_JMP);
        patch(back, top);
        patch(jf, here());
        close_loop(top, here());
        break;
      }
      case StmtKind::For: {
        const auto& f = s.as<ForStmt>();
        if (f.init) stmt(*f.init);
        if (const int i = counted_slot(f); i >= 0) {
          counted_for(f, i, save);
          break;
        }
        const std::size_t top = here();
        std::size_t jf = static_cast<std::size_t>(-1);
        if (f.cond) jf = cond_jump(*f.cond);
        top_ = save;
        loops_.emplace_back();
        stmt(*f.body);
        const std::size_t cont = here();
        if (f.step) {
          at(f.step->loc);
          step_expr(*f.step);
          top_ = save;
        }
        const std::size_t back = emit_jump(OP_JMP);
        patch(back, top);
        if (jf != static_cast<std::size_t>(-1)) patch(jf, here());
        close_loop(cont, here());
        break;
      }
      case StmtKind::ForEach: {
        const auto& f = s.as<ForEachStmt>();
        if (f.range->type.kind == K::Vector) {
          for_vector(f);
          break;
        }
        auto [h, slot] = list_of(*f.range);
        const int hold = temp();
        move(hold, h, RK::R);
        const int i = temp();
        const int n = temp();
        load_int(i, 0);
        const std::size_t top = here();
        emit(OP_LSIZE, n, hold, slot);
        const std::size_t jf = emit_jump(OP_JGEI, i, n);
        move(f.var->slot, i, RK::I);
        emit(OP_LGET, f.var->slot, hold, slot);
        declare(f.var->name, f.var->slot, f.var->type);
        loops_.emplace_back();
        stmt(*f.body);
        const std::size_t cont = here();
        emit(OP_ADDIK, i, i, 1);
        const std::size_t back = emit_jump(OP_JMP);
        patch(back, top);
        patch(jf, here());
        close_loop(cont, here());
        break;
      }
      case StmtKind::Return: {
        const auto& r = s.as<ReturnStmt>();
        if (r.value && (F.result == RK::I || F.result == RK::D || F.result == RK::R) &&
            r.value->kind == ExprKind::Name && r.value->as<NameExpr>().binding.kind == BK::Local &&
            r.value->type.kind == F.result_type.kind) {
          emit(OP_RET, r.value->as<NameExpr>().binding.slot);  // a local of the result's kind: no copy
        } else if (r.value) {
          const int v = temp();
          expr_to(*r.value, v, F.result_type);
          emit(F.result == RK::V ? OP_RETV : F.result == RK::X ? OP_RETX : OP_RET, v);
        } else {
          emit(OP_RET0);
        }
        break;
      }
      case StmtKind::Finish:
        finish_stmt(s.as<ReturnStmt>());
        break;
      case StmtKind::Break:
        loops_.back().breaks.push_back(emit_jump(OP_JMP));
        break;
      case StmtKind::Continue:
        loops_.back().continues.push_back(emit_jump(OP_JMP));
        break;
      case StmtKind::Expr:
        step_expr(*s.as<ExprStmt>().expr);
        break;
    }
    if (s.kind != StmtKind::Local) close_locals(open);
    top_ = save;
  }

  void step_expr(const Expr& e) { (void)expr(e); }

  // `for (T x : v)` over a vector: over a copy taken before the first iteration (a property is read
  // once), so changing the vector in the body does not change the run.
  void for_vector(const ForEachStmt& f) {
    const Type& vec = f.range->type;
    const Type elem = element_type(vec);
    const int hold = temp();
    expr_to(*f.range, hold, vec);
    const int i = temp();
    const int n = temp();
    const int e = temp();
    load_int(i, 0);
    emit_v(OP_VSIZE, vec, n, hold);
    const std::size_t top = here();
    const std::size_t jf = emit_jump(OP_JGEI, i, n);
    emit_v(OP_VGET, vec, e, hold, i);
    move(f.var->slot, coerce(e, elem, f.var->type), reg_kind(f.var->type));
    declare(f.var->name, f.var->slot, f.var->type);
    loops_.emplace_back();
    stmt(*f.body);
    const std::size_t cont = here();
    emit(OP_ADDIK, i, i, 1);
    const std::size_t back = emit_jump(OP_JMP);
    patch(back, top);
    patch(jf, here());
    close_loop(cont, here());
  }

  // `finish v;` (4.11): the result and `finished` become properties of the invoked net's instance (so
  // the finish is database state, recorded and saved); the executor completes the invocation after
  // the action. The action ends here.
  void finish_stmt(const ReturnStmt& r) {
    int outer = 0;
    const Decl* d = F.scope;
    for (; d != nullptr && d->kind != DeclKind::Net; d = d->parent) ++outer;
    if (d == nullptr) not_supported(P, r.loc, "'finish' outside an invoked net");
    auto it = P.build().class_info.find(&d->as<ClassDecl>());
    if (it == P.build().class_info.end()) not_supported(P, r.loc, "'finish' in this net");
    const ClassInfo& ci = *it->second;
    if (r.value && ci.result_slot >= 0) {
      const int v = temp();
      expr_to(*r.value, v, d->as<ClassDecl>().result_type);
      const int inst = self_at(outer, r.loc);
      at(r.loc);
      emit(OP_SETP, inst, v, ci.result_slot);
    }
    const int inst = self_at(outer, r.loc);
    const int one = temp();
    load_int(one, 1);
    at(r.loc);
    emit(OP_SETP, inst, one, meta_slot(&Invocation::vsd_prop_finished()));
    emit(OP_RET0);
  }

  // Jump when the condition is false. A comparison of two ints fuses into one compare-and-jump
  // instruction (JGEI ..., against a small constant JGEIK ...): the condition's value is never stored.
  std::size_t cond_jump(const Expr& c) {
    at(c.loc);
    if (c.kind == ExprKind::Binary) {
      const auto& b = c.as<BinaryExpr>();
      Op reg = OP_NOP, imm = OP_NOP;  // jump when the comparison is false
      switch (b.op) {
        case TokenKind::Less:
          reg = OP_JGEI, imm = OP_JGEIK;
          break;
        case TokenKind::LessEqual:
          reg = OP_JGTI, imm = OP_JGTIK;
          break;
        case TokenKind::Greater:
          reg = OP_JLEI, imm = OP_JLEIK;
          break;
        case TokenKind::GreaterEqual:
          reg = OP_JLTI, imm = OP_JLTIK;
          break;
        case TokenKind::EqualEqual:
          reg = OP_JNEI, imm = OP_JNEIK;
          break;
        case TokenKind::BangEqual:
          reg = OP_JEQI, imm = OP_JEQIK;
          break;
        default:
          break;
      }
      if (reg != OP_NOP && b.lhs->type.kind == K::Int && b.rhs->type.kind == K::Int) {
        const Here at_node(*this, b.loc);
        const int l = expr(*b.lhs);
        if (const auto k = small_literal(*b.rhs)) return emit_jump(imm, l, static_cast<std::uint16_t>(*k));
        const int r = expr(*b.rhs);
        return emit_jump(reg, l, r);
      }
    }
    const int r = expr(c);
    return emit_jump(OP_JMPF, r);
  }

  // An int literal, or a negated one (`-3`), that fits an int16 immediate; or nothing.
  static std::optional<std::int16_t> small_literal(const Expr& e) {
    const bool neg = e.kind == ExprKind::Unary && e.as<UnaryExpr>().op == TokenKind::Minus;
    const Expr& lit = neg ? *e.as<UnaryExpr>().operand : e;
    if (lit.kind != ExprKind::Int) return std::nullopt;
    const std::int64_t v = lit.as<LiteralExpr>().int_value;
    if (v < -32768 || v > 32768) return std::nullopt;  // (the literal 2^63 and beyond never reach here)
    const std::int64_t k = neg ? -v : v;
    if (k < -32768 || k > 32767) return std::nullopt;
    return static_cast<std::int16_t>(k);
  }

  // The local int a `for` loop counts up by one (`for (...; i < n; i++)`, `++i` or `i += 1`, the bound
  // a local int or a small constant): its step and test fuse into one instruction at the loop's bottom
  // (OP_LOOPLT and kin). -1 for any other loop.
  static int counted_slot(const ForStmt& f) {
    if (!f.cond || !f.step || f.cond->kind != ExprKind::Binary) return -1;
    const auto& c = f.cond->as<BinaryExpr>();
    if (c.op != TokenKind::Less && c.op != TokenKind::LessEqual) return -1;
    auto local_int = [](const Expr& e) {
      return e.kind == ExprKind::Name && e.as<NameExpr>().binding.kind == BK::Local && e.type.kind == K::Int
                 ? e.as<NameExpr>().binding.slot
                 : -1;
    };
    const int i = local_int(*c.lhs);
    if (i < 0 || (local_int(*c.rhs) < 0 && !small_literal(*c.rhs))) return -1;
    const Expr& st = *f.step;
    if (st.kind == ExprKind::Unary || st.kind == ExprKind::Postfix) {
      const auto& u = st.as<UnaryExpr>();
      return u.op == TokenKind::PlusPlus && local_int(*u.operand) == i ? i : -1;
    }
    if (st.kind == ExprKind::Assign) {
      const auto& a = st.as<BinaryExpr>();
      const auto k = small_literal(*a.rhs);
      return a.op == TokenKind::PlusEqual && k && *k == 1 && local_int(*a.lhs) == i ? i : -1;
    }
    return -1;
  }

  // `for (init; i < n; i++) body` as: the test once at the top (jump out when false), the body, then
  // OP_LOOPLT i, n -> body (step, test and backward jump in one instruction, at the step's position and
  // line: its overflow and budget errors name the step as before).
  void counted_for(const ForStmt& f, int i, int save) {
    const std::size_t jf = cond_jump(*f.cond);
    top_ = save;
    const std::size_t body = here();
    loops_.emplace_back();
    stmt(*f.body);
    const std::size_t cont = here();
    at(f.step->loc);
    const auto& c = f.cond->as<BinaryExpr>();
    const bool le = c.op == TokenKind::LessEqual;
    std::size_t back;
    if (const auto k = small_literal(*c.rhs))
      back = emit_jump(le ? OP_LOOPLEK : OP_LOOPLTK, i, static_cast<std::uint16_t>(*k));
    else
      back = emit_jump(le ? OP_LOOPLE : OP_LOOPLT, i, c.rhs->as<NameExpr>().binding.slot);
    patch(back, body);
    patch(jf, here());
    close_loop(cont, here());
  }

  void close_loop(std::size_t cont, std::size_t end) {
    for (std::size_t j : loops_.back().breaks) patch(j, end);
    for (std::size_t j : loops_.back().continues) patch(j, cont);
    loops_.pop_back();
  }

  ProgramImpl& P;
  Function& F;
  int top_;
  int max_;
  std::uint32_t line_ = 0;
  SourceLoc pos_{0, 0, 0};
};

}  // namespace

int compile_function(ProgramImpl& p, int index, const FunctionDecl& fd) {
  Function& f = *p.build().functions[index];
  f.result_type = fd.result_type;
  f.result = reg_kind(fd.result_type);
  Compiler c(p, f, parent_scope(fd), fd.slots);
  for (const Param& prm : fd.params) {
    const RK k = reg_kind(prm.type);
    if (k == RK::None) not_supported(p, prm.loc, "a parameter of type '" + prm.type.name() + "'");
    c.declare(prm.name, static_cast<int>(f.param_kinds.size()), prm.type);
    f.param_kinds.push_back(k);
  }
  f.nparams = static_cast<int>(fd.params.size());
  if (fd.result_type.kind != K::Void && f.result == RK::None)
    not_supported(p, fd.loc, "a result of type '" + fd.result_type.name() + "'");
  c.block(*fd.body);
  c.at(fd.body->loc);
  if (fd.result_type.kind == K::Void)
    c.emit(OP_RET0);
  else
    c.emit(OP_FAIL, 0, c.string_const("function '" + fd.name + "' ended without returning a value"));
  c.finish();
  return index;
}

int new_function(ProgramImpl& p, std::string name) {
  p.build().functions.push_back(std::make_unique<Function>());
  p.build().functions.back()->name = std::move(name);
  return static_cast<int>(p.build().functions.size() - 1);
}

int compile_condition(ProgramImpl& p, const TransitionDecl& t, const std::string& name) {
  const int i = new_function(p, name);
  Function& f = *p.build().functions[i];
  f.result = RK::I;
  f.result_type = Type::of(K::Bool);
  Compiler c(p, f, &t, t.when_slots);
  if (t.when_expr) {
    c.at(t.when_expr->loc);  // the line table (run-time errors, the debugger)
    const int r = c.temp();
    c.expr_to(*t.when_expr, r, f.result_type);
    c.emit(OP_RET, r);
  } else {
    c.block(*t.when_block);
    c.emit(OP_FAIL, 0, c.string_const("the condition ended without returning a value"));
  }
  c.finish();
  return i;
}

int compile_action(ProgramImpl& p, const TransitionDecl& t, const std::string& name) {
  const int i = new_function(p, name);
  Function& f = *p.build().functions[i];
  Compiler c(p, f, &t, t.action_slots);
  c.block(*t.action);
  c.emit(OP_RET0);
  c.finish();
  return i;
}

int compile_arrow_condition(ProgramImpl& p, const ArrowDecl& a, const std::string& name) {
  const int i = new_function(p, name);
  Function& f = *p.build().functions[i];
  f.result = RK::I;
  f.result_type = Type::of(K::Bool);
  Compiler c(p, f, parent_scope(a), a.condition_slots);
  c.at(a.condition->loc);
  const int r = c.temp();
  c.expr_to(*a.condition, r, f.result_type);
  c.emit(OP_RET, r);
  c.finish();
  return i;
}

// Property initialisers of a class-like declaration, place or transition (self: the new instance).
int compile_init(ProgramImpl& p, const ScopeDecl& s, const std::string& name) {
  const int i = new_function(p, name);
  Function& f = *p.build().functions[i];
  Compiler c(p, f, &s, 0);
  for (const DeclPtr& m : s.members) {
    if (m->kind != DeclKind::Property) continue;
    const auto& pd = m->as<PropertyDecl>();
    if (!pd.init) continue;
    if (reg_kind(pd.type) == RK::None)
      not_supported(p, pd.init->loc, "an initial value of type '" + pd.type.name() + "'");
    const int v = c.temp();
    c.at(pd.init->loc);
    c.expr_to(*pd.init, v, pd.type);
    const int self = c.self_at(0, pd.loc);
    c.at(pd.loc);
    c.emit(OP_SETP, self, v, p.build().prop_slot.at(&pd));
    c.top_ = 0;
  }
  c.emit(OP_RET0);
  c.finish();
  return i;
}

// The constructor call of an object derived from a class with arguments: slot 0 is the new object,
// self is the object's parent scope (where the arguments are evaluated).
int compile_object_ctor(ProgramImpl& p, const ClassDecl& obj, int ctor, const FunctionDecl& fd) {
  const int i = new_function(p, obj.name + " (constructor arguments)");
  Function& f = *p.build().functions[i];
  f.nparams = 1;
  f.param_kinds = {RK::R};
  Compiler c(p, f, parent_scope(obj), 1);
  std::vector<Type> want;
  for (const Param& prm : fd.params) want.push_back(prm.type);
  const int base = c.args_at(obj.base_args, want);
  if (base == c.top_) c.temp();
  c.at(obj.base_loc);
  c.emit(OP_CALL, base, ctor, 0);
  c.emit(OP_RET0);
  c.finish();
  return i;
}

// The arguments of an invoking transition (self: the transition, slot 0: the new net instance): each is
// evaluated where the transition is (its mark included) and set as the value parameter's property.
int compile_invoke_args(ProgramImpl& p, const TransitionDecl& t, const std::string& name) {
  const int i = new_function(p, name);
  Function& f = *p.build().functions[i];
  f.nparams = 1;
  f.param_kinds = {RK::R};
  Compiler c(p, f, &t, 1);
  const ClassDecl& net = *t.invoked;
  for (std::size_t k = 0; k < net.params.size() && k < t.invoke_args.size(); ++k) {
    const PropertyDecl* pd = nullptr;
    for (const DeclPtr& m : net.members)
      if (m->kind == DeclKind::Property && m->as<PropertyDecl>().is_param && m->name == net.params[k].name)
        pd = &m->as<PropertyDecl>();
    auto slot = pd != nullptr ? p.build().prop_slot.find(pd) : p.build().prop_slot.end();
    if (slot == p.build().prop_slot.end()) not_supported(p, t.invoke_args[k]->loc, "this net parameter");
    if (reg_kind(pd->type) == RK::None)
      not_supported(p, t.invoke_args[k]->loc, "a net parameter of type '" + pd->type.name() + "'");
    const int v = c.temp();
    c.expr_to(*t.invoke_args[k], v, pd->type);
    c.at(t.invoke_args[k]->loc);
    c.emit(OP_SETP, 0, v, slot->second);
    c.top_ = 1;
  }
  c.emit(OP_RET0);
  c.finish();
  return i;
}

}  // namespace vsd::soml
