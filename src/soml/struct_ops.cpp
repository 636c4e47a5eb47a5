// Arithmetic on the Eigen structs in code (docs/soml.md 4.14): OP_XOP runs Eigen directly on the typed
// storage of the X registers (no per-field access), and the readable text print and string() show.
#include <Eigen/Geometry>
#include <string>

#include "program_impl.hpp"
#include "vsd/core/error.hpp"

namespace vsd::soml {

namespace {

using V2 = Eigen::Vector2d;
using V3 = Eigen::Vector3d;
using V4 = Eigen::Vector4d;
using Quat = Eigen::Quaterniond;
using Iso = Eigen::Isometry3d;

// The MetaType of T, looked up once: meta_type<T>() is a function with a guarded static, and an
// operation compares types three or four times (callgrind: a third of the instructions of `p = t * p`).
template <class T>
const MetaType* const type_of = &meta_type<T>();

// The T a register holds, or null. The checker typed the operands; the test keeps a wrong register (a
// miscompilation) a run-time error instead of undefined behaviour.
template <class T>
inline const T* held(const Value& v) noexcept {
  return v.type() == type_of<T> ? static_cast<const T*>(v.data()) : nullptr;
}

// Stores @p v into register @p dst, in place when it holds a T already (a frame's 128 bytes live on the
// heap: a loop that updates one must not allocate every time).
template <class T>
[[gnu::noinline]] void put_new(Value& dst, const T& v) {
  dst = Value(v);
}
template <class T>
inline void put(Value& dst, const T& v) {
  if (dst.type() == type_of<T>) [[likely]]
    *static_cast<T*>(dst.data()) = v;
  else
    put_new(dst, v);
}

// Vector2d/3d/4d: false when the operands do not fit (the caller fails).
template <class V>
bool eigen_vector_op(StructOp op, const V& a, const Value& xc, const Val& c, Value& dst, Val& rd) {
  const V* b = held<V>(xc);
  switch (op) {
    case StructOp::Add:
      if (b == nullptr) return false;
      put<V>(dst, a + *b);
      return true;
    case StructOp::Sub:
      if (b == nullptr) return false;
      put<V>(dst, a - *b);
      return true;
    case StructOp::Neg:
      put<V>(dst, -a);
      return true;
    case StructOp::Scale:
      put<V>(dst, a * c.d);
      return true;
    case StructOp::Div:
      put<V>(dst, a / c.d);
      return true;
    case StructOp::Dot:
      if (b == nullptr) return false;
      rd.d = a.dot(*b);
      return true;
    case StructOp::Norm:
      rd.d = a.norm();
      return true;
    case StructOp::SquaredNorm:
      rd.d = a.squaredNorm();
      return true;
    case StructOp::Normalized:  // Eigen keeps a zero vector as it is
      put<V>(dst, a.normalized());
      return true;
    case StructOp::Cross:
      if constexpr (V::SizeAtCompileTime == 3) {
        if (b == nullptr) return false;
        put<V>(dst, a.cross(*b));
        return true;
      }
      return false;
    default:
      return false;
  }
}

bool quaternion_op(StructOp op, const Quat& q, const Value& xc, Value& dst) {
  switch (op) {
    case StructOp::Mul:
      if (const Quat* r = held<Quat>(xc)) {
        put<Quat>(dst, q * *r);
        return true;
      }
      return false;
    case StructOp::Apply:  // Eigen's rotation of a vector: q is taken to be a unit quaternion
      if (const V3* v = held<V3>(xc)) {
        put<V3>(dst, q * *v);
        return true;
      }
      return false;
    case StructOp::Inverse:
      put<Quat>(dst, q.inverse());
      return true;
    case StructOp::Conjugate:
      put<Quat>(dst, q.conjugate());
      return true;
    case StructOp::Normalized:
      put<Quat>(dst, q.normalized());
      return true;
    default:
      return false;
  }
}

bool frame_op(StructOp op, const Iso& t, const Value& xc, Value& dst) {
  switch (op) {
    case StructOp::Mul:
      if (const Iso* r = held<Iso>(xc)) {
        put<Iso>(dst, t * *r);
        return true;
      }
      return false;
    case StructOp::Apply:
      if (const V3* v = held<V3>(xc)) {
        put<V3>(dst, t * *v);
        return true;
      }
      return false;
    case StructOp::Inverse:
      put<Iso>(dst, t.inverse(Eigen::Isometry));
      return true;
    default:
      return false;
  }
}

Value read_field(const MetaType::Field& f, const void* obj) {
  if (f.offset != MetaType::npos) return Value(*f.type, static_cast<const unsigned char*>(obj) + f.offset);
  Value v(*f.type);
  f.get(obj, v.data());
  return v;
}

void append_text(const MetaType& t, const void* addr, std::string& out) {
  if (t.kind() == TypeKind::Struct) {
    out += t.name();
    out += '(';
    bool first = true;
    for (const MetaType::Field& f : t.fields()) {
      if (!first) out += ", ";
      first = false;
      const Value v = read_field(f, addr);
      append_text(*f.type, v.data(), out);
    }
    out += ')';
    return;
  }
  if (t.kind() == TypeKind::Vector && t.element() != nullptr && t.element()->kind() == TypeKind::Struct) {
    out += '[';
    const std::size_t n = t.vector_size(addr);
    Value e(*t.element());
    for (std::size_t i = 0; i < n; ++i) {
      if (i > 0) out += ", ";
      t.vector_get(addr, i, e.data());
      append_text(*t.element(), e.data(), out);
    }
    out += ']';
    return;
  }
  out += t.to_text(addr);
}

}  // namespace

std::string value_text(const Value& v) {
  if (v.empty()) return v.to_text();
  std::string out;
  append_text(*v.type(), v.data(), out);
  return out;
}

[[gnu::noinline]] void ProgramImpl::struct_op(const Ins in, const Frame& frame) {
  Val* R = regs_.data() + frame.base;
  Value* X = xregs_.data() + frame.base;
  const auto op = static_cast<StructOp>(in.x);
  const Value& a = X[in.b];
  // Each result is computed before it is stored, so the destination may be an operand (`v = v + w`).
  bool ok = false;
  if (op == StructOp::Text) {
    sregs_[frame.base + in.a] = value_text(a);
    return;
  }
  if (op == StructOp::FromAxisAngle) {
    if (const V3* axis = held<V3>(a)) {
      const double n = axis->norm();
      if (n == 0.0) fail("Quaterniond::from_axis_angle: the axis is the zero vector");
      put<Quat>(X[in.a], Quat(Eigen::AngleAxisd(R[in.c].d, *axis / n)));
      return;
    }
  } else if (const V3* v3 = held<V3>(a)) {
    ok = eigen_vector_op(op, *v3, X[in.c], R[in.c], X[in.a], R[in.a]);
  } else if (const Iso* t = held<Iso>(a)) {
    ok = frame_op(op, *t, X[in.c], X[in.a]);
  } else if (const Quat* q = held<Quat>(a)) {
    ok = quaternion_op(op, *q, X[in.c], X[in.a]);
  } else if (const V2* v2 = held<V2>(a)) {
    ok = eigen_vector_op(op, *v2, X[in.c], R[in.c], X[in.a], R[in.a]);
  } else if (const V4* v4 = held<V4>(a)) {
    ok = eigen_vector_op(op, *v4, X[in.c], R[in.c], X[in.a], R[in.a]);
  }
  if (!ok) fail("bad operands of a struct operation");
}

}  // namespace vsd::soml
