// The SOML++ virtual machine: a register machine over statically typed 64-bit registers (see
// program_impl.hpp). One switch per instruction, no allocation per call (registers and frames are
// vectors that only grow), property access through the MetaProperties (so every store signals and
// records), a budget of jumps and calls and a depth limit whose errors carry the SOML++ call stack.
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <type_traits>

#include "program_impl.hpp"
#include "vsd/core/database.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/instance.hpp"
#include "vsd/core/meta_method.hpp"
#include "vsd/core/node.hpp"
#include "vsd/core/reference.hpp"
#include "vsd/core/value.hpp"

namespace vsd::soml {

// SOML++'s text of a double: shortest round-trip form, always with a '.' or exponent ("2.0").
std::string fmt_double(double d) {
  if (std::isnan(d)) return "nan";
  if (std::isinf(d)) return d > 0 ? "inf" : "-inf";
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, d);
  std::string s(buf, r.ptr);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

static void to_registers(const MetaType& t, const void* addr, Val& v, std::string& s, VecReg& vr, Value& x);

namespace {

void store_integer(const MetaProperty& p, SimStateInstance& o, std::int64_t v) {
  alignas(8) unsigned char buf[8] = {};
  const std::size_t n = p.type().size();
  if (n == 8) {
    std::memcpy(buf, &v, 8);
  } else if (n == 4) {
    const auto x = static_cast<std::uint32_t>(v);
    std::memcpy(buf, &x, 4);
  } else if (n == 2) {
    const auto x = static_cast<std::uint16_t>(v);
    std::memcpy(buf, &x, 2);
  } else {
    const auto x = static_cast<std::uint8_t>(v);
    std::memcpy(buf, &x, 1);
  }
  p.assign_raw(o, buf);
}

}  // namespace

// ---- vectors ----
// The VM holds vectors of the C++ element types below; the registry's vector<T> of each is the
// std::vector<T> (a run-time vector type has run-time elements: enums and structs, which no register
// holds).
namespace {

template <class... T>
struct TypeList {};
using VecElems = TypeList<bool, std::int8_t, std::int16_t, std::int32_t, std::int64_t, std::uint8_t,
                          std::uint16_t, std::uint32_t, std::uint64_t, float, double, std::string>;

// Calls f((T*)nullptr) for the element type T of vector type vt; false when vt is none of them.
template <class F, class... T>
bool with_vector(const MetaType& vt, F&& f, TypeList<T...> /*unused*/) {
  return ((vt.is<std::vector<T>>() ? (f(static_cast<T*>(nullptr)), true) : false) || ...);
}
template <class F>
bool with_vector(const MetaType& vt, F&& f) {
  return with_vector(vt, std::forward<F>(f), VecElems{});
}

template <class T>
void to_reg(const T& x, Val& v, std::string& s) {
  if constexpr (std::is_same_v<T, std::string>)
    s = x;
  else if constexpr (std::is_floating_point_v<T>)
    v.d = static_cast<double>(x);
  else if constexpr (std::is_same_v<T, bool>)
    v.i = x ? 1 : 0;
  else
    v.i = static_cast<std::int64_t>(x);
}

}  // namespace

RK vector_elem_kind(const MetaType& vt) noexcept {
  RK k = RK::None;
  with_vector(vt, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    k = std::is_same_v<T, std::string> ? RK::S : std::is_floating_point_v<T> ? RK::D : RK::I;
  });
  return k;
}

void vector_load(const MetaType& vt, const void* addr, VecReg& out) {
  out.v.clear();
  out.s.clear();
  with_vector(vt, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const auto& src = *static_cast<const std::vector<T>*>(addr);
    if constexpr (std::is_same_v<T, std::string>) {
      out.s.assign(src.begin(), src.end());
    } else {
      out.v.resize(src.size());
      std::string unused;
      for (std::size_t i = 0; i < src.size(); ++i) to_reg<T>(src[i], out.v[i], unused);
    }
  });
}

std::size_t vector_size(const MetaType& vt, const void* addr) {
  std::size_t n = 0;
  with_vector(vt, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    n = static_cast<const std::vector<T>*>(addr)->size();
  });
  return n;
}

void vector_at(const MetaType& vt, const void* addr, std::size_t i, Val& v, std::string& s) {
  with_vector(vt, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const auto& src = *static_cast<const std::vector<T>*>(addr);
    to_reg<T>(src[i], v, s);
  });
}

Value vector_value(const MetaType& vt, const VecReg& r, const std::string& what) {
  Value out(vt);
  const MetaType& et = *vt.element();
  const bool known = with_vector(vt, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    auto& dst = *static_cast<std::vector<T>*>(out.data());
    if constexpr (std::is_same_v<T, std::string>) {
      dst.assign(r.s.begin(), r.s.end());
    } else {
      dst.reserve(r.v.size());
      for (const Val& x : r.v) {
        if constexpr (std::is_floating_point_v<T>) {
          dst.push_back(static_cast<T>(x.d));
        } else if constexpr (std::is_same_v<T, bool>) {
          dst.push_back(x.i != 0);
        } else {
          if (!std::is_same_v<T, std::int64_t> && !std::is_same_v<T, std::uint64_t> && !et.integer_fits(x.i))
            throw Error("the value " + std::to_string(x.i) + " does not fit " + what + " (elements " +
                        et.name() + ")");
          dst.push_back(static_cast<T>(x.i));
        }
      }
    }
  });
  if (!known) throw Error(what + " of type " + vt.name() + " cannot be stored by the SOML++ runtime");
  return out;
}

std::string vector_text(const MetaType& vt, const VecReg& r) {
  std::string out = "[";
  const RK k = vector_elem_kind(vt);
  const bool is_bool = vt.element() != nullptr && vt.element()->kind() == TypeKind::Bool;
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (i != 0) out += ", ";
    if (k == RK::S) {
      out += '"';
      for (char c : r.s[i]) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
      }
      out += '"';
    } else if (k == RK::D) {
      out += fmt_double(r.v[i].d);
    } else if (is_bool) {
      out += r.v[i].i != 0 ? "true" : "false";
    } else {
      out += std::to_string(r.v[i].i);
    }
  }
  return out + "]";
}

std::string ProgramImpl::stack_text(std::size_t from) const {
  std::string s;
  for (std::size_t i = frames_.size(); i-- > from;) {
    const Frame& f = frames_[i];
    s += frame_text(*f.fn, pc_index(f));
  }
  return s;
}

std::string ProgramImpl::frame_text(const Function& f, std::size_t at) const {
  const Function::Pos pos = at < f.positions.size() ? f.positions[at] : Function::Pos{};
  return "\n  at " + f.name + " (" + image().checked->source->name() + ":" + std::to_string(pos.line) + ":" +
         std::to_string(pos.column) + ")";
}

void ProgramImpl::fail(const std::string& what) { throw Error("SOML++ run-time error: " + what); }

void ProgramImpl::memory_exhausted(std::size_t bytes) {
  fail("memory budget exhausted (" + std::to_string(opt_.memory_budget) +
       " bytes of strings, vectors, values, stored changes and instances in one call; " +
       std::to_string(bytes) + " more asked for): a runaway allocation?");
}

// The heap bytes of a register's value, as the memory budget counts them: buffers by their capacity;
// a vector of strings also its strings' buffers; a Value its type's size and a vector's elements.
static std::size_t heap_bytes(const VecReg& r) {
  std::size_t n = r.v.capacity() * sizeof(Val) + r.s.capacity() * sizeof(std::string);
  for (const std::string& x : r.s) n += x.capacity();
  return n;
}
static std::size_t value_bytes(const MetaType& t, const void* addr) {
  std::size_t n = t.size();
  if (t.kind() == TypeKind::String) n += static_cast<const std::string*>(addr)->capacity();
  if (t.kind() == TypeKind::Vector && t.element() != nullptr) n += t.vector_size(addr) * t.element()->size();
  return n;
}
static std::size_t heap_bytes(const Value& v) {
  return v.type() != nullptr ? value_bytes(*v.type(), v.data()) : 0;
}
// The heap bytes of the register a value of type @p t goes to (to_registers): none for numbers.
static std::size_t register_bytes(const MetaType& t, const std::string& s, const VecReg& v, const Value& x) {
  switch (t.kind()) {
    case TypeKind::Bool:
    case TypeKind::Int:
    case TypeKind::UInt:
    case TypeKind::Enum:
    case TypeKind::Flags:
    case TypeKind::Float:
    case TypeKind::Double:
      return 0;
    case TypeKind::String:
      return s.capacity();
    case TypeKind::Vector:
      if (vector_elem_kind(t) != RK::None) return heap_bytes(v);
      break;
    default:
      break;
  }
  return heap_bytes(x);
}

// int arithmetic never wraps: a result outside [-2^63, 2^63-1] is an error, like a division by zero.
void ProgramImpl::int_overflow(std::int64_t a, const char* op, std::int64_t b) {
  fail(std::string("integer overflow: ") + std::to_string(a) + " " + op + " " + std::to_string(b) +
       " does not fit an int (64 bits)");
}
void ProgramImpl::int_overflow(const char* what, std::int64_t a) {
  fail(std::string("integer overflow: ") + what + "(" + std::to_string(a) +
       ") does not fit an int (64 bits)");
}

void ProgramImpl::loop_budget_exhausted() {
  fail("instruction budget exhausted (" + std::to_string(opt_.instruction_budget) +
       " jumps and calls): an endless loop?");
}

Val ProgramImpl::run(int fi, std::uint64_t self, std::uint64_t mark, const Val* args,
                     const std::string* sargs, std::string* sresult, const VecReg* vargs, VecReg* vresult,
                     const Value* xargs, Value* xresult) {
  const Function& f = *image().functions[static_cast<std::size_t>(fi)];
  const std::size_t entry = frames_.size();
  if (entry == 0) {
    if (native_depth_ == 0) {  // a call from outside (not from a listener while native code runs)
      budget_ = opt_.instruction_budget == 0 ? 1 : opt_.instruction_budget;
      mem_left_ = opt_.memory_budget;
    }
    frames_.reserve(static_cast<std::size_t>(opt_.max_depth) + 8);
  }
  if (entry >= static_cast<std::size_t>(opt_.max_depth))
    fail("call depth limit (" + std::to_string(opt_.max_depth) + ") reached calling " + f.name +
         stack_text(0));
  if (native::Entry e = run_[static_cast<std::size_t>(fi)].native; e != nullptr && debug_ == nullptr) {
    // Native code (Program::load_native) takes scalar arguments and returns a scalar: nothing to move.
    return call_native(e, self, mark, args, entry + 1);
  }
  return run_vm(f, fi, self, mark, args, sargs, sresult, vargs, vresult, xargs, xresult);
}

// run() in the VM: out of line, so that a call of native code (a condition tested on every firing) does
// not pay for this part's frame (its registers and exception handling).
[[gnu::noinline]] Val ProgramImpl::run_vm(const Function& f, int fi, std::uint64_t self, std::uint64_t mark,
                                          const Val* args, const std::string* sargs, std::string* sresult,
                                          const VecReg* vargs, VecReg* vresult, const Value* xargs,
                                          Value* xresult) {
  const std::size_t entry = frames_.size();
  const std::uint32_t saved_top = top_;
  const std::uint32_t base = top_;
  if (regs_.size() < base + static_cast<std::size_t>(f.nregs) + 1) {
    regs_.resize((base + static_cast<std::size_t>(f.nregs) + 1) * 2);
    sregs_.resize(regs_.size());
    vregs_.resize(regs_.size());
    xregs_.resize(regs_.size());
  }
  for (int i = 0; i < f.nparams; ++i) {
    regs_[base + static_cast<std::size_t>(i)] = args[i];
    if (f.param_kinds[static_cast<std::size_t>(i)] == RK::S)
      sregs_[base + static_cast<std::size_t>(i)] = sargs[i];
    else if (f.param_kinds[static_cast<std::size_t>(i)] == RK::V)
      vregs_[base + static_cast<std::size_t>(i)] = vargs != nullptr ? vargs[i] : VecReg{};
    else if (f.param_kinds[static_cast<std::size_t>(i)] == RK::X)
      xregs_[base + static_cast<std::size_t>(i)] = xargs != nullptr ? xargs[i] : Value{};
  }
  RunCode& rc = run_[static_cast<std::size_t>(fi)];
  frames_.push_back(Frame{&f, &rc, rc.code.data(), base, self, mark});
  top_ = base + static_cast<std::uint32_t>(f.nregs);
  try {
    Val v = exec(entry);
    if (sresult != nullptr && f.result == RK::S) *sresult = std::move(sregs_[base]);
    if (vresult != nullptr && f.result == RK::V) *vresult = std::move(vregs_[base]);
    if (xresult != nullptr && f.result == RK::X) *xresult = std::move(xregs_[base]);
    top_ = saved_top;
    return v;
  } catch (const Error& e) {
    std::string msg = e.what();
    if (msg.rfind("SOML++ run-time error: ", 0) != 0) msg = "SOML++ run-time error: " + msg;
    msg += stack_text(entry);
    frames_.resize(entry);
    top_ = saved_top;
    throw Error(msg);
  }
}

// `new C(args)`, out of line (its argument arrays would weigh on the interpreter loop's frame).
// Each instance it makes (the object, and the places, transitions and arrows of its net) takes its class's
// size and kInstanceBytes from the memory budget: up front for the object, afterwards for the rest, which
// its initialisers and constructor made (their own stores were charged as they ran).
[[gnu::noinline]] std::uint64_t ProgramImpl::new_instance(const Ins in, const Frame& frame) {
  const Val* R = regs_.data() + frame.base;
  const std::string* S = sregs_.data() + frame.base;
  const ClassInfo* ci = image().classes[in.b];
  const MetaInstance& cls = ci != nullptr ? *ci->meta : *image().class_metas[in.b];
  charge(cls.size() + kInstanceBytes);
  const std::size_t before = state_.size() + 1;
  auto rest = [&] {
    if (state_.size() > before) charge((state_.size() - before) * kInstanceBytes);
  };
  if (ci == nullptr) {
    const std::uint64_t id = state_.create(cls).id();
    rest();
    return id;
  }
  const Function* ctor =
      ci->ctor >= 0 ? image().functions[static_cast<std::size_t>(ci->ctor)].get() : nullptr;
  if (in.c > 8) fail("more than 8 constructor arguments");
  std::string sargs[8];
  VecReg vargs[8];
  Value xargs[8];
  Val args[8];
  for (int i = 0; i < in.c; ++i) {
    const RK k = ctor != nullptr ? ctor->param_kinds[static_cast<std::size_t>(i)] : RK::None;
    if (k == RK::S) sargs[i] = S[in.a + 1 + i];
    if (k == RK::V) vargs[i] = vregs_[frame.base + in.a + 1 + i];
    if (k == RK::X) xargs[i] = xregs_[frame.base + in.a + 1 + i];
    args[i] = R[in.a + 1 + i];
  }
  const std::uint64_t id = instantiate(*ci, nullptr, "", args, sargs, in.c, vargs, xargs).id();
  rest();
  return id;
}

// find(path): names from the database down, separated by '/', as Node::path() writes them (a leading
// '/' is optional; "/" is the database). Each step is the first child of that name; null when a step
// is missing or a name is empty.
[[gnu::noinline]] std::uint64_t ProgramImpl::find_node(const std::string& path) const {
  const Node* n = &state_.database();
  std::string_view rest = path;
  if (!rest.empty() && rest.front() == '/') rest.remove_prefix(1);
  if (rest.empty()) return path.empty() ? 0 : n->id();
  while (n != nullptr) {
    const std::size_t slash = rest.find('/');
    const std::string_view name = rest.substr(0, slash);
    if (name.empty()) return 0;
    n = n->find_child(name);
    if (slash == std::string_view::npos) break;
    rest.remove_prefix(slash + 1);
  }
  return n != nullptr ? n->id() : 0;
}

// A vector property store, out of line like the vector instructions: through the setter like every
// other store, so the change signals and records.
[[gnu::noinline]] void ProgramImpl::store_vector(const MetaProperty& p, SimStateInstance& o,
                                                 const VecReg& v) {
  const Value value = vector_value(p.type(), v, "property '" + p.name() + "'");
  p.assign_raw(o, value.data());
}

// Vector arguments and results of a built-in class's MetaMethod (OP_MCALL), out of line like the vector
// instructions: argument @p i appended to @p args as a Value of the method's std::vector<T> (range-checked),
// and the result into a vector register.
[[gnu::noinline]] void ProgramImpl::method_vector_arg(const MetaMethod& m, std::size_t i, const VecReg& v,
                                                      std::vector<Value>& args) {
  const MetaType* want = i < m.arguments().size() ? m.arguments()[i] : nullptr;
  if (want == nullptr || vector_elem_kind(*want) == RK::None)
    fail("argument " + std::to_string(i + 1) + " of method '" + m.name() + "' is not a vector");
  try {
    args.push_back(
        vector_value(*want, v, "argument " + std::to_string(i + 1) + " of method '" + m.name() + "'"));
  } catch (const Error& e) {
    fail(e.what());
  }
}

[[gnu::noinline]] void ProgramImpl::method_vector_result(const MetaMethod& m, const Value& r, VecReg& out) {
  if (r.type() == nullptr || r.type() != m.result() || vector_elem_kind(*r.type()) == RK::None)
    fail("method '" + m.name() + "' returned " + (r.type() != nullptr ? r.type()->name() : "nothing") +
         ", not " + (m.result() != nullptr ? m.result()->name() : "a vector"));
  vector_load(*r.type(), r.data(), out);
}

// The vector instructions, out of line: they are rare next to the arithmetic and calls that the
// interpreter loop keeps in registers (fib(27) and the 10^7 loop of benchmarks/ must not pay for them).
[[gnu::noinline]] void ProgramImpl::vector_op(const Ins in, const Frame& frame) {
  Val* R = regs_.data() + frame.base;
  std::string* S = sregs_.data() + frame.base;
  VecReg* V = vregs_.data() + frame.base;
  auto obj = [&](std::uint64_t id) -> SimStateInstance& {
    SimStateInstance* o = id == 0 ? nullptr : state_.find(id);
    if (o == nullptr)
      fail(id == 0 ? "null reference" : "reference to a deleted instance (id " + std::to_string(id) + ")");
    return *o;
  };
  switch (in.op) {
    case OP_MOVV: {
      const std::size_t before = heap_bytes(V[in.a]);
      V[in.a] = V[in.b];
      grew(before, heap_bytes(V[in.a]));
      break;
    }
    case OP_VCLEAR: {
      VecReg& v = V[in.a];
      v.v.clear();
      v.s.clear();
      break;
    }
    case OP_VSIZE:
      R[in.a].i = static_cast<std::int64_t>(V[in.b].size());
      break;
    case OP_VGET:
    case OP_VSET: {
      VecReg& v = V[(in.op == OP_VGET ? in.b : in.a)];
      const std::int64_t i = R[in.op == OP_VGET ? in.c : in.b].i;
      if (i < 0 || static_cast<std::size_t>(i) >= v.size()) {
        fail("index " + std::to_string(i) + " out of range (size " + std::to_string(v.size()) + ")");
      }
      const auto k = static_cast<std::size_t>(i);
      if (in.op == OP_VGET) {
        if (in.x != 0) {
          grew(S[in.a].capacity(), v.s[k].size());
          S[in.a] = v.s[k];
        } else {
          R[in.a] = v.v[k];
        }
      } else if (in.x != 0) {
        grew(v.s[k].capacity(), S[in.c].size());
        v.s[k] = S[in.c];
      } else {
        v.v[k] = R[in.c];
      }
      break;
    }
    case OP_VPUSH: {  // the new element, and the doubling of the buffer when it is full
      VecReg& v = V[in.a];
      if (in.x != 0) {
        charge(S[in.b].size() + (v.s.size() == v.s.capacity() ? std::max<std::size_t>(1, v.s.size()) : 0) *
                                    sizeof(std::string));
        v.s.push_back(S[in.b]);
      } else {
        if (v.v.size() == v.v.capacity()) charge(std::max<std::size_t>(1, v.v.size()) * sizeof(Val));
        v.v.push_back(R[in.b]);
      }
      break;
    }
    case OP_EQV: {
      const VecReg& l = V[in.b];
      const VecReg& r = V[in.c];
      bool eq = l.size() == r.size();
      if (eq && in.x == 2) {
        eq = l.s == r.s;
      } else {
        for (std::size_t k = 0; eq && k < l.v.size(); ++k)
          eq = in.x == 1 ? l.v[k].d == r.v[k].d : l.v[k].i == r.v[k].i;
      }
      R[in.a].i = eq ? 1 : 0;
      break;
    }
    case OP_PVSIZE:
    case OP_PVGET: {
      const std::uint64_t id = R[in.b].id;
      SimStateInstance& o = obj(id);
      const MetaProperty& p = *image().props[in.c].prop;
      if (!o.meta().is_a(p.owner())) {
        fail("instance of " + o.meta().name() + " has no property '" + p.name() + "'");
      }
      if (deps_ != nullptr) deps_->emplace_back(id, &p);
      const void* addr = p.address(o);
      const bool value = image().props[in.c].kind == PK::Value;  // a vector of structs or enums
      const std::size_t n = value ? p.type().vector_size(addr) : vector_size(p.type(), addr);
      if (in.op == OP_PVSIZE) {
        R[in.a].i = static_cast<std::int64_t>(n);
        break;
      }
      const std::int64_t i = R[in.a].i;
      if (i < 0 || static_cast<std::size_t>(i) >= n) {
        fail("index " + std::to_string(i) + " out of range (size " + std::to_string(n) + ")");
      }
      const MetaType& et = *p.type().element();
      const std::size_t before = register_bytes(et, S[in.a], V[in.a], xregs_[frame.base + in.a]);
      if (value) {
        Value e(*p.type().element());
        p.type().vector_get(addr, static_cast<std::size_t>(i), e.data());
        to_registers(*p.type().element(), e.data(), R[in.a], S[in.a], V[in.a], xregs_[frame.base + in.a]);
      } else {
        vector_at(p.type(), addr, static_cast<std::size_t>(i), R[in.a], S[in.a]);
      }
      grew(before, register_bytes(et, S[in.a], V[in.a], xregs_[frame.base + in.a]));
      break;
    }
    default:
      fail("bad instruction");
  }
}

// ---- values (X registers) ----
// A struct field or a vector element moves between its storage and the register of its kind: numbers,
// bools and enums in R, strings in S, vectors of those in V, anything else (structs, vectors of structs
// and enums) as a Value in X. Out of line like the vector instructions.
namespace {

Value field_value(const MetaType::Field& f, const void* obj) {
  if (f.offset != MetaType::npos) return Value(*f.type, static_cast<const unsigned char*>(obj) + f.offset);
  Value v(*f.type);
  f.get(obj, v.data());
  return v;
}

void set_field(const MetaType::Field& f, void* obj, const void* in) {
  if (f.offset != MetaType::npos)
    f.type->assign(static_cast<unsigned char*>(obj) + f.offset, in);
  else
    f.set(obj, in);
}

}  // namespace

static void to_registers(const MetaType& t, const void* addr, Val& v, std::string& s, VecReg& vr, Value& x) {
  switch (t.kind()) {
    case TypeKind::Bool:
      v.i = *static_cast<const bool*>(addr) ? 1 : 0;
      return;
    case TypeKind::Int:
    case TypeKind::UInt:
    case TypeKind::Enum:
    case TypeKind::Flags:
      v.i = t.load_integer(addr);
      return;
    case TypeKind::Float:
      v.d = *static_cast<const float*>(addr);
      return;
    case TypeKind::Double:
      v.d = *static_cast<const double*>(addr);
      return;
    case TypeKind::String:
      s = *static_cast<const std::string*>(addr);
      return;
    case TypeKind::Vector:
      if (vector_elem_kind(t) != RK::None) {
        vector_load(t, addr, vr);
        return;
      }
      break;
    default:
      break;
  }
  x = Value(t, addr);
}

static void from_registers(const MetaType& t, void* addr, const Val& v, const std::string& s,
                           const VecReg& vr, const Value& x, const std::string& what) {
  switch (t.kind()) {
    case TypeKind::Bool:
      *static_cast<bool*>(addr) = v.i != 0;
      return;
    case TypeKind::Int:
    case TypeKind::UInt:
    case TypeKind::Enum:
    case TypeKind::Flags:
      if (!t.integer_fits(v.i))
        throw Error("the value " + std::to_string(v.i) + " does not fit " + what + " (" + t.name() + ")");
      t.store_integer(addr, v.i);
      return;
    case TypeKind::Float:
      *static_cast<float*>(addr) = static_cast<float>(v.d);
      return;
    case TypeKind::Double:
      *static_cast<double*>(addr) = v.d;
      return;
    case TypeKind::String:
      *static_cast<std::string*>(addr) = s;
      return;
    case TypeKind::Vector:
      if (vector_elem_kind(t) != RK::None) {
        const Value val = vector_value(t, vr, what);
        t.assign(addr, val.data());
        return;
      }
      break;
    default:
      break;
  }
  if (x.type() == nullptr || !detail::same_definition(*x.type(), t))
    throw Error(what + " of type " + t.name() + " cannot hold a " +
                (x.type() != nullptr ? x.type()->name() : std::string("missing value")));
  t.assign(addr, x.data());
}

[[gnu::noinline]] void ProgramImpl::value_op(const Ins in, const Frame& frame) {
  Val* R = regs_.data() + frame.base;
  std::string* S = sregs_.data() + frame.base;
  VecReg* V = vregs_.data() + frame.base;
  Value* X = xregs_.data() + frame.base;
  auto index = [&](const MetaType& vt, const Value& vec, std::int64_t i) {
    const std::size_t n = vt.vector_size(vec.data());
    if (i < 0 || static_cast<std::size_t>(i) >= n)
      fail("index " + std::to_string(i) + " out of range (size " + std::to_string(n) + ")");
    return static_cast<std::size_t>(i);
  };
  auto vec_type = [&](const Value& v) -> const MetaType& {
    if (v.type() == nullptr || v.type()->kind() != TypeKind::Vector) fail("not a vector");
    return *v.type();
  };
  // What each writes grows by comes from the memory budget (measured after: the values are small or
  // copies of what exists; a vector grows by one element at a time).
  switch (in.op) {
    case OP_XDEF: {
      const std::size_t before = heap_bytes(X[in.a]);
      X[in.a] = Value(*image().xtypes[in.b]);
      grew(before, heap_bytes(X[in.a]));
      break;
    }
    case OP_MOVX: {
      const std::size_t before = heap_bytes(X[in.a]);
      X[in.a] = X[in.b];
      grew(before, heap_bytes(X[in.a]));
      break;
    }
    case OP_XGETF:
    case OP_XSETF: {
      Value& st = X[in.op == OP_XGETF ? in.b : in.a];
      const MetaType* t = st.type();
      if (t == nullptr || t->kind() != TypeKind::Struct || in.x >= t->fields().size()) fail("not a struct");
      const MetaType::Field& f = t->fields()[in.x];
      if (in.op == OP_XGETF) {
        const Value fv = field_value(f, st.data());
        const std::size_t before = register_bytes(*f.type, S[in.a], V[in.a], X[in.a]);
        to_registers(*f.type, fv.data(), R[in.a], S[in.a], V[in.a], X[in.a]);
        grew(before, register_bytes(*f.type, S[in.a], V[in.a], X[in.a]));
      } else {
        Value fv(*f.type);
        from_registers(*f.type, fv.data(), R[in.b], S[in.b], V[in.b], X[in.b], "field '" + f.name + "'");
        const std::size_t before = heap_bytes(st);
        set_field(f, st.data(), fv.data());
        grew(before, heap_bytes(st));
      }
      break;
    }
    case OP_EQX:
      R[in.a].i = X[in.b] == X[in.c] ? 1 : 0;
      break;
    case OP_XVSIZE:
      R[in.a].i = static_cast<std::int64_t>(vec_type(X[in.b]).vector_size(X[in.b].data()));
      break;
    case OP_XVGET: {
      const Value& vec = X[in.b];
      const MetaType& vt = vec_type(vec);
      const std::size_t i = index(vt, vec, R[in.c].i);
      Value e(*vt.element());
      vt.vector_get(vec.data(), i, e.data());
      const std::size_t before = register_bytes(*vt.element(), S[in.a], V[in.a], X[in.a]);
      to_registers(*vt.element(), e.data(), R[in.a], S[in.a], V[in.a], X[in.a]);
      grew(before, register_bytes(*vt.element(), S[in.a], V[in.a], X[in.a]));
      break;
    }
    case OP_XVSET:
    case OP_XVPUSH: {
      Value& vec = X[in.a];
      const MetaType& vt = vec_type(vec);
      const int from = in.op == OP_XVSET ? in.c : in.b;
      Value e(*vt.element());
      from_registers(*vt.element(), e.data(), R[from], S[from], V[from], X[from], "an element");
      if (in.op == OP_XVSET) {
        vt.vector_set(vec.data(), index(vt, vec, R[in.b].i), e.data());
      } else {
        charge(vt.element()->size());
        vt.vector_push(vec.data(), e.data());
      }
      break;
    }
    default:
      fail("bad instruction");
  }
}

// A property of a scalar kind (what a register holds without a side array: ints, bools, enums, doubles,
// floats, references) at @p addr into @p v; false for the others. OP_GETP and native code (read_scalar).
static bool load_scalar(const PropSlot& ps, const void* addr, Val& v) {
  switch (ps.kind) {
    case PK::I64:
      v.i = *static_cast<const std::int64_t*>(addr);
      return true;
    case PK::Bool:
      v.i = *static_cast<const bool*>(addr) ? 1 : 0;
      return true;
    case PK::Double:
      v.d = *static_cast<const double*>(addr);
      return true;
    case PK::Int:
    case PK::Enum:
      v.i = ps.prop->type().load_integer(addr);
      return true;
    case PK::Ref: {
      const SimStateInstance* t = static_cast<const RefBase*>(addr)->get();
      v.id = t != nullptr ? t->id() : 0;
      return true;
    }
    case PK::Other:
      if (ps.prop->type().kind() != TypeKind::Float) return false;
      v.d = *static_cast<const float*>(addr);
      return true;
    default:
      return false;
  }
}

bool scalar_property(const PropSlot& ps) noexcept {
  if (ps.prop == nullptr) return false;
  switch (ps.kind) {
    case PK::I64:
    case PK::Bool:
    case PK::Double:
    case PK::Int:
    case PK::Enum:
    case PK::Ref:
      return true;
    case PK::Other:
      return ps.prop->type().kind() == TypeKind::Float;
    default:
      return false;
  }
}

void ProgramImpl::no_instance(std::uint64_t id) {
  fail(id == 0 ? "null reference" : "reference to a deleted instance (id " + std::to_string(id) + ")");
}

void ProgramImpl::no_property(const SimStateInstance& o, const MetaProperty& p) {
  fail("instance of " + o.meta().name() + " has no property '" + p.name() + "'");
}

void ProgramImpl::check_settable(const SimStateInstance& o, const MetaProperty& p) {
  if (!o.meta().is_a(p.owner())) no_property(o, p);
  if (p.has(ReadOnly)) fail("property '" + p.name() + "' is read-only");
}

std::uint64_t ProgramImpl::enclosing(std::uint64_t id, int parents) {
  for (int k = 0; k < parents; ++k) {
    SimStateInstance* o = id == 0 ? nullptr : state_.find(id);
    if (o == nullptr) no_instance(id);
    Node* n = o->as<Node>();
    Node* up = n != nullptr ? n->parent() : nullptr;
    if (up == nullptr) fail("the enclosing instance of " + std::to_string(id) + " is gone");
    id = up->id();
  }
  return id;
}

bool ProgramImpl::store_scalar(const PropSlot& ps, SimStateInstance& o, Val v) {
  const MetaProperty& p = *ps.prop;
  switch (ps.kind) {
    case PK::I64:
      p.set<std::int64_t>(o, v.i);
      return true;
    case PK::Bool:
      p.set<bool>(o, v.i != 0);
      return true;
    case PK::Double:
      p.set<double>(o, v.d);
      return true;
    case PK::Int:
      if (!p.type().integer_fits(v.i))
        fail("the value " + std::to_string(v.i) + " does not fit property '" + p.name() + "' (" +
             p.type().name() + ")");
      store_integer(p, o, v.i);
      return true;
    case PK::Enum:
      store_integer(p, o, v.i);
      return true;
    case PK::Ref: {
      SimStateInstance* t = v.id == 0 ? nullptr : state_.find(v.id);
      if (v.id != 0 && t == nullptr) no_instance(v.id);
      if (t != nullptr && p.type().target() != nullptr && !t->meta().is_a(*p.type().target()))
        fail("a " + t->meta().name() + " cannot be stored in property '" + p.name() + "' (" + p.type().name() +
             ")");
      if (p.type().kind() == TypeKind::Ref) {
        Ref<SimStateInstance> r(t);
        p.assign_raw(o, &r);
      } else {
        SharedRef<SimStateInstance> r(t);
        p.assign_raw(o, &r);
      }
      return true;
    }
    case PK::Other:
      if (p.type().kind() != TypeKind::Float) return false;
      {
        const auto f = static_cast<float>(v.d);
        p.assign_raw(o, &f);
      }
      return true;
    default:
      return false;
  }
}

Val ProgramImpl::read_scalar(std::uint64_t id, std::size_t prop) {
  SimStateInstance* o = id == 0 ? nullptr : state_.find(id);
  if (o == nullptr) no_instance(id);
  const PropSlot& ps = image().props[prop];
  if (!o->meta().is_a(ps.prop->owner())) no_property(*o, *ps.prop);
  if (deps_ != nullptr) deps_->emplace_back(id, ps.prop);
  Val v{};
  load_scalar(ps, ps.prop->address(*o), v);
  return v;
}

void ProgramImpl::write_scalar(std::uint64_t id, std::size_t prop, Val v) {
  SimStateInstance* o = id == 0 ? nullptr : state_.find(id);
  if (o == nullptr) no_instance(id);
  const PropSlot& ps = image().props[prop];
  check_settable(*o, *ps.prop);
  charge_record(8);
  store_scalar(ps, *o, v);
}

Val ProgramImpl::exec(std::size_t entry) {
  Frame* fr = &frames_.back();
  const Ins* code = fr->run->code.data();
  const Ins* pc = fr->pc;
  Val* R = regs_.data() + fr->base;
  std::string* S = sregs_.data() + fr->base;
  const std::int64_t* K = consts_.data();
  const ProgramImage& img = image();  // immutable: read once
  const std::size_t max_frames = static_cast<std::size_t>(opt_.max_depth);

#define VSD_SAVE() (fr->pc = pc)
#define VSD_TARGET(in) (code + ((static_cast<std::uint32_t>((in).x) << 16) | (in).c))
#define VSD_REFRESH()             \
  do {                            \
    R = regs_.data() + fr->base;  \
    S = sregs_.data() + fr->base; \
  } while (0)
// R[a] = x op y of ints, checked: one overflow flag test (a jump never taken), the error out of line.
#define VSD_CHECKED(builtin, x, y, op)     \
  do {                                     \
    std::int64_t v_;                       \
    if (builtin(x, y, &v_)) [[unlikely]] { \
      VSD_SAVE();                          \
      int_overflow(x, op, y);              \
    }                                      \
    R[in.a].i = v_;                        \
  } while (0)
#define VSD_IMM(field) static_cast<std::int64_t>(static_cast<std::int16_t>(field))
// The bottom of a counting loop (OP_LOOPLT and kin): the counter's checked increment, then the test and,
// when it holds, the backward jump, which costs one unit of the budget like OP_JMP's.
#define VSD_LOOP(cmp, bound)                                      \
  do {                                                            \
    std::int64_t v_;                                              \
    if (__builtin_add_overflow(R[in.a].i, 1, &v_)) [[unlikely]] { \
      VSD_SAVE();                                                 \
      int_overflow(R[in.a].i, "+", 1);                            \
    }                                                             \
    R[in.a].i = v_;                                               \
    if (v_ cmp(bound)) {                                          \
      if (--budget_ == 0) [[unlikely]] {                          \
        VSD_SAVE();                                               \
        loop_budget_exhausted();                                  \
      }                                                           \
      pc = VSD_TARGET(in);                                        \
    }                                                             \
  } while (0)

  auto obj = [&](std::uint64_t id) -> SimStateInstance& {
    SimStateInstance* o = id == 0 ? nullptr : state_.find(id);
    if (o == nullptr) {
      VSD_SAVE();
      no_instance(id);
    }
    return *o;
  };
  auto place_of = [&](std::uint64_t id) -> Place& {
    Place* p = obj(id).as<Place>();
    if (p == nullptr) {
      VSD_SAVE();
      fail("not a place");
    }
    return *p;
  };
  // String register dst is about to hold @p size bytes: what its buffer grows by comes from the budget.
  auto string_room = [&](const std::string& dst, std::size_t size) {
    if (size > dst.capacity()) [[unlikely]] {
      VSD_SAVE();
      charge(size - dst.capacity());
    }
  };

  for (;;) {
    const Ins in = *pc++;
    switch (in.op) {
      case OP_NOP:
        break;
      case OP_LOADI:
        R[in.a].i = static_cast<std::int16_t>(in.b);
        break;
      case OP_LOADK:
        R[in.a].i = K[in.b];
        break;
      case OP_LOADS:
        string_room(S[in.a], img.strings[in.b].size());
        S[in.a] = img.strings[in.b];
        break;
      case OP_MOV:
        R[in.a] = R[in.b];
        break;
      case OP_MOVS:
        string_room(S[in.a], S[in.b].size());
        S[in.a] = S[in.b];
        break;
      case OP_ADDI:
        VSD_CHECKED(__builtin_add_overflow, R[in.b].i, R[in.c].i, "+");
        break;
      case OP_SUBI:
        VSD_CHECKED(__builtin_sub_overflow, R[in.b].i, R[in.c].i, "-");
        break;
      case OP_MULI:
        VSD_CHECKED(__builtin_mul_overflow, R[in.b].i, R[in.c].i, "*");
        break;
      case OP_DIVI:
      case OP_MODI: {
        const std::int64_t x = R[in.b].i, y = R[in.c].i;
        if (y == 0) {
          VSD_SAVE();
          fail("division by zero");
        }
        if (y == -1) {  // x / -1 overflows for x = -2^63 only; x % -1 is 0 (representable) for every x
          if (in.op == OP_DIVI && x == std::numeric_limits<std::int64_t>::min()) {
            VSD_SAVE();
            int_overflow(x, "/", y);
          }
          R[in.a].i = in.op == OP_DIVI ? -x : 0;
        } else {
          R[in.a].i = in.op == OP_DIVI ? x / y : x % y;
        }
        break;
      }
      case OP_ADDD:
        R[in.a].d = R[in.b].d + R[in.c].d;
        break;
      case OP_SUBD:
        R[in.a].d = R[in.b].d - R[in.c].d;
        break;
      case OP_MULD:
        R[in.a].d = R[in.b].d * R[in.c].d;
        break;
      case OP_DIVD:
        R[in.a].d = R[in.b].d / R[in.c].d;
        break;
      case OP_ADDIK:  // also ++, --, `i += 1` of a local and the counters of loops
        VSD_CHECKED(__builtin_add_overflow, R[in.b].i, std::int64_t{static_cast<std::int16_t>(in.c)}, "+");
        break;
      case OP_MULIK:
        VSD_CHECKED(__builtin_mul_overflow, R[in.b].i, std::int64_t{static_cast<std::int16_t>(in.c)}, "*");
        break;
      case OP_DIVIK:
        R[in.a].i = R[in.b].i / static_cast<std::int16_t>(in.c);
        break;
      case OP_MODIK:
        R[in.a].i = R[in.b].i % static_cast<std::int16_t>(in.c);
        break;
      case OP_NEGI:
        if (R[in.b].i == std::numeric_limits<std::int64_t>::min()) [[unlikely]] {
          VSD_SAVE();
          int_overflow("-", R[in.b].i);
        }
        R[in.a].i = -R[in.b].i;
        break;
      case OP_NEGD:
        R[in.a].d = -R[in.b].d;
        break;
      case OP_NOT:
        R[in.a].i = R[in.b].i == 0 ? 1 : 0;
        break;
      case OP_I2D:
        R[in.a].d = static_cast<double>(R[in.b].i);
        break;
      case OP_D2I: {
        const double d = R[in.b].d;
        if (!(d >= -9.2233720368547758e18 && d < 9.2233720368547758e18)) {
          VSD_SAVE();
          fail("the double " + fmt_double(d) + " does not fit an int");
        }
        R[in.a].i = static_cast<std::int64_t>(d);
        break;
      }
      case OP_LTI:
        R[in.a].i = R[in.b].i < R[in.c].i;
        break;
      case OP_LEI:
        R[in.a].i = R[in.b].i <= R[in.c].i;
        break;
      case OP_EQI:
        R[in.a].i = R[in.b].i == R[in.c].i;
        break;
      case OP_NEI:
        R[in.a].i = R[in.b].i != R[in.c].i;
        break;
      case OP_LTD:
        R[in.a].i = R[in.b].d < R[in.c].d;
        break;
      case OP_LED:
        R[in.a].i = R[in.b].d <= R[in.c].d;
        break;
      case OP_EQD:
        R[in.a].i = R[in.b].d == R[in.c].d;
        break;
      case OP_NED:
        R[in.a].i = R[in.b].d != R[in.c].d;
        break;
      case OP_LTS:
        R[in.a].i = S[in.b] < S[in.c];
        break;
      case OP_LES:
        R[in.a].i = S[in.b] <= S[in.c];
        break;
      case OP_EQS:
        R[in.a].i = S[in.b] == S[in.c];
        break;
      case OP_NES:
        R[in.a].i = S[in.b] != S[in.c];
        break;
      case OP_CONCAT: {
        string_room(S[in.a], S[in.b].size() + S[in.c].size());  // before it is made: s = s + s doubles
        std::string t;
        t.reserve(S[in.b].size() + S[in.c].size());
        t += S[in.b];
        t += S[in.c];
        S[in.a] = std::move(t);
        break;
      }
      case OP_TOSTR:
        if (in.c == 0) {
          S[in.a] = std::to_string(R[in.b].i);
        } else if (in.c == 1) {
          S[in.a] = fmt_double(R[in.b].d);
        } else if (in.c == 2) {
          S[in.a] = R[in.b].i != 0 ? "true" : "false";
        } else {
          const MetaType& t = *img.enum_types[in.c - 3u];
          const std::string_view n = t.enum_name(R[in.b].i);
          S[in.a] = n.empty() ? std::to_string(R[in.b].i) : std::string(n);
        }
        break;
      case OP_STR2B:
        R[in.a].i = S[in.b].empty() ? 0 : 1;
        break;
      case OP_JMP: {
        const Ins* t = VSD_TARGET(in);
        if (t < pc && --budget_ == 0) [[unlikely]] {
          VSD_SAVE();
          loop_budget_exhausted();
        }
        pc = t;
        break;
      }
      case OP_JMPF:
        if (R[in.a].i == 0) pc = VSD_TARGET(in);
        break;
      case OP_JMPT:
        if (R[in.a].i != 0) pc = VSD_TARGET(in);
        break;
      case OP_JGEI:
        if (R[in.a].i >= R[in.b].i) pc = VSD_TARGET(in);
        break;
      case OP_JGTI:
        if (R[in.a].i > R[in.b].i) pc = VSD_TARGET(in);
        break;
      case OP_JLTI:
        if (R[in.a].i < R[in.b].i) pc = VSD_TARGET(in);
        break;
      case OP_JLEI:
        if (R[in.a].i <= R[in.b].i) pc = VSD_TARGET(in);
        break;
      case OP_JEQI:
        if (R[in.a].i == R[in.b].i) pc = VSD_TARGET(in);
        break;
      case OP_JNEI:
        if (R[in.a].i != R[in.b].i) pc = VSD_TARGET(in);
        break;
      case OP_JGEIK:
        if (R[in.a].i >= VSD_IMM(in.b)) pc = VSD_TARGET(in);
        break;
      case OP_JGTIK:
        if (R[in.a].i > VSD_IMM(in.b)) pc = VSD_TARGET(in);
        break;
      case OP_JLTIK:
        if (R[in.a].i < VSD_IMM(in.b)) pc = VSD_TARGET(in);
        break;
      case OP_JLEIK:
        if (R[in.a].i <= VSD_IMM(in.b)) pc = VSD_TARGET(in);
        break;
      case OP_JEQIK:
        if (R[in.a].i == VSD_IMM(in.b)) pc = VSD_TARGET(in);
        break;
      case OP_JNEIK:
        if (R[in.a].i != VSD_IMM(in.b)) pc = VSD_TARGET(in);
        break;
      case OP_LOOPLT:
        VSD_LOOP(<, R[in.b].i);
        break;
      case OP_LOOPLE:
        VSD_LOOP(<=, R[in.b].i);
        break;
      case OP_LOOPLTK:
        VSD_LOOP(<, VSD_IMM(in.b));
        break;
      case OP_LOOPLEK:
        VSD_LOOP(<=, VSD_IMM(in.b));
        break;
      case OP_CALL:
      case OP_CALLS:
      case OP_VCALL: {
        VSD_SAVE();
        const std::uint64_t self = in.op == OP_CALLS ? fr->self : R[in.c].id;
        int fi = in.b;
        if (in.op == OP_VCALL) {
          fi = img.vslot_default[in.b];
          const SimStateInstance& o = obj(self);
          auto ci = by_meta_.find(&o.meta());
          if (ci != by_meta_.end()) {
            auto v = ci->second->vtable.find(img.vslots[in.b]);
            if (v != ci->second->vtable.end()) fi = v->second;
          }
        } else if (self == 0) {
          fail("null reference");
        }
        RunCode& rc = run_[static_cast<std::size_t>(fi)];
        const Function& callee = *rc.fn;
        if (frames_.size() >= max_frames)
          fail("call depth limit (" + std::to_string(opt_.max_depth) + ") reached calling " + callee.name);
        if (--budget_ == 0)
          fail("instruction budget exhausted (" + std::to_string(opt_.instruction_budget) +
               " jumps and calls): runaway recursion?");
        if (rc.native != nullptr && debug_ == nullptr) [[unlikely]] {
          // Native code: arguments from R[a], the result into R[a], as if the callee had run here.
          R[in.a] = call_native(rc.native, self, fr->mark, &R[in.a], frames_.size() + 1);
          break;
        }
        const std::uint32_t nb = fr->base + in.a;
        const std::size_t need = nb + static_cast<std::size_t>(callee.nregs) + 1;
        if (regs_.size() < need) {
          regs_.resize(need * 2);
          sregs_.resize(regs_.size());
          vregs_.resize(regs_.size());
          xregs_.resize(regs_.size());
        }
        const std::uint64_t mark = fr->mark;
        frames_.push_back(Frame{&callee, &rc, rc.code.data(), nb, self, mark});
        fr = &frames_.back();
        code = rc.code.data();
        pc = code;
        top_ = nb + static_cast<std::uint32_t>(callee.nregs);
        VSD_REFRESH();
        break;
      }
      case OP_RETX:  // a Value result: into the frame's first X register, then as OP_RET
        if (in.a != 0) xregs_[fr->base] = std::move(xregs_[fr->base + in.a]);
        [[fallthrough]];
      case OP_RETV:  // a vector result: into the frame's first vector register, then as OP_RET
        if (in.op == OP_RETV && in.a != 0) vregs_[fr->base] = std::move(vregs_[fr->base + in.a]);
        [[fallthrough]];
      case OP_RET:
      case OP_RET0: {
        Val v{};
        if (in.op != OP_RET0) {
          v = R[in.a];
          if (fr->fn->result == RK::S && in.a != 0) S[0] = std::move(S[in.a]);
        }
        R[0] = v;
        frames_.pop_back();
        if (frames_.size() == entry) return v;
        fr = &frames_.back();
        code = fr->run->code.data();
        pc = fr->pc;
        top_ = fr->base + static_cast<std::uint32_t>(fr->fn->nregs);
        VSD_REFRESH();
        break;
      }
      case OP_SELF: {
        const OuterPlan& p = img.outer_plans[in.b];
        if (p.static_decl != nullptr) {
          R[in.a].id = outer_ids_[in.b];
        } else if (p.parents == 0) {
          R[in.a].id = fr->self;
        } else {
          VSD_SAVE();
          R[in.a].id = enclosing(fr->self, p.parents);
        }
        break;
      }
      case OP_MARK:
        R[in.a].id = fr->mark;
        break;
      case OP_OBJ:
        R[in.a].id = static_cast<std::uint64_t>(K[in.b]);
        break;
      case OP_GETP: {
        const std::uint64_t id = R[in.b].id;
        SimStateInstance& o = obj(id);
        const PropSlot& ps = img.props[in.c];
        if (!o.meta().is_a(ps.prop->owner())) {
          VSD_SAVE();
          no_property(o, *ps.prop);
        }
        if (deps_ != nullptr) deps_->emplace_back(id, ps.prop);
        const void* addr = ps.prop->address(o);
        if (load_scalar(ps, addr, R[in.a])) break;
        switch (ps.kind) {
          case PK::String:
            string_room(S[in.a], static_cast<const std::string*>(addr)->size());
            S[in.a] = *static_cast<const std::string*>(addr);
            break;
          case PK::Vector: {
            VSD_SAVE();
            VecReg& v = vregs_[fr->base + in.a];
            const std::size_t before = heap_bytes(v);
            vector_load(ps.prop->type(), addr, v);
            grew(before, heap_bytes(v));
            break;
          }
          case PK::Value: {
            VSD_SAVE();
            Value& x = xregs_[fr->base + in.a];
            const std::size_t before = heap_bytes(x);
            x = Value(ps.prop->type(), addr);
            grew(before, heap_bytes(x));
            break;
          }
          default:
            VSD_SAVE();
            fail("property '" + ps.prop->name() + "' of type " + ps.prop->type().name() +
                 " cannot be read as a value yet");
        }
        break;
      }
      case OP_SETP: {
        VSD_SAVE();
        SimStateInstance& o = obj(R[in.a].id);
        const PropSlot& ps = img.props[in.c];
        const MetaProperty& p = *ps.prop;
        check_settable(o, p);
        // The memory budget first (nothing changed if it is exhausted): what the stored value grows by,
        // and the record of the change.
        switch (ps.kind) {
          case PK::String:
          case PK::Vector:
          case PK::Value: {
            const std::size_t now = value_bytes(p.type(), p.address(o));
            const std::size_t next = ps.kind == PK::String   ? S[in.b].size()
                                     : ps.kind == PK::Vector ? heap_bytes(vregs_[fr->base + in.b])
                                                             : heap_bytes(xregs_[fr->base + in.b]);
            grew(now, next);
            charge_record(next);
            break;
          }
          default:
            charge_record(8);
        }
        if (store_scalar(ps, o, R[in.b])) {
          VSD_REFRESH();  // listeners of the change may have called into the VM
          break;
        }
        switch (ps.kind) {
          case PK::String:
            p.assign_raw(o, &S[in.b]);
            break;
          case PK::Vector:
            store_vector(p, o, vregs_[fr->base + in.b]);
            break;
          case PK::Value: {
            const Value& x = xregs_[fr->base + in.b];
            if (x.type() == nullptr || !detail::same_definition(*x.type(), p.type()))
              fail("property '" + p.name() + "' (" + p.type().name() + ") cannot hold a " +
                   (x.type() != nullptr ? x.type()->name() : std::string("missing value")));
            p.assign_raw(o, x.data());
            break;
          }
          default:
            fail("property '" + p.name() + "' of type " + p.type().name() + " cannot be assigned yet");
        }
        VSD_REFRESH();  // listeners of the change may have called into the VM
        break;
      }
      case OP_PLACE: {
        if ((in.c & kPortPlace) != 0) {
          R[in.a].id = port_place_id(R[in.b].id, in.c & (kPortPlace - 1));
          if (R[in.a].id == 0) {
            VSD_SAVE();
            fail("instance " + std::to_string(R[in.b].id) + " is no copy of a port net");
          }
          break;
        }
        const NetInst* n = net_of(R[in.b].id);
        if (n == nullptr || in.c >= n->places.size()) {
          VSD_SAVE();
          fail("instance " + std::to_string(R[in.b].id) + " has no net");
        }
        R[in.a].id = n->places[in.c]->id();
        break;
      }
      case OP_PCOUNT: {
        Place& p = place_of(R[in.b].id);
        if (deps_ != nullptr)
          deps_->emplace_back(p.id(),
                              p.object_tokens() ? &Place::vsd_prop_objects() : &Place::vsd_prop_tokens());
        R[in.a].i = p.count();
        break;
      }
      case OP_PPUT: {
        VSD_SAVE();
        Place& p = place_of(R[in.a].id);
        if (in.c == 0) {
          if (p.object_tokens()) fail("put(n) on a place of object tokens");
          if (R[in.b].i < 0) fail("put(" + std::to_string(R[in.b].i) + "): a negative number of tokens");
          charge_record(8);
          put_token(p, nullptr, R[in.b].i);
        } else {
          if (!p.object_tokens()) fail("put(object) on a place of black tokens");
          charge(sizeof(void*) * 2);  // an entry of the place's list
          charge_record(8);
          put_token(p, &obj(R[in.b].id), 1);
        }
        VSD_REFRESH();
        break;
      }
      case OP_PCLEAR: {
        VSD_SAVE();
        Place& p = place_of(R[in.a].id);
        charge_record(8 * static_cast<std::size_t>(p.object_tokens() ? p.objects().size() : 1));
        if (p.object_tokens())
          p.edit_objects().clear();
        else
          p.set_tokens(0);
        VSD_REFRESH();
        break;
      }
      case OP_LSIZE:
      case OP_LGET:
      case OP_LPUSH: {
        VSD_SAVE();
        const std::uint64_t id = R[in.op == OP_LPUSH ? in.a : in.b].id;
        SimStateInstance& o = obj(id);
        const MetaProperty& p = *img.props[in.c].prop;
        if (!o.meta().is_a(p.owner()))
          fail("instance of " + o.meta().name() + " has no property '" + p.name() + "'");
        const auto& list = *static_cast<const RefListBase*>(p.address(o));
        if (in.op == OP_LSIZE) {
          if (deps_ != nullptr) deps_->emplace_back(id, &p);
          R[in.a].i = static_cast<std::int64_t>(list.size());
        } else if (in.op == OP_LGET) {
          const std::int64_t i = R[in.a].i;
          if (i < 0 || static_cast<std::size_t>(i) >= list.size())
            fail("index " + std::to_string(i) + " out of range (size " + std::to_string(list.size()) + ")");
          if (deps_ != nullptr) deps_->emplace_back(id, &p);
          const SimStateInstance* t = list.at(static_cast<std::size_t>(i));
          R[in.a].id = t != nullptr ? t->id() : 0;
        } else {
          charge(sizeof(void*) * 2);  // the list's new entry
          charge_record(8);
          o.list_insert(p, list.size(), obj(R[in.b].id));
          VSD_REFRESH();
        }
        break;
      }
      case OP_NEW: {
        VSD_SAVE();
        const std::uint64_t made = new_instance(in, *fr);
        VSD_REFRESH();
        R[in.a].id = made;
        break;
      }
      case OP_ISA:
      case OP_AS: {
        const std::uint64_t id = R[in.b].id;
        const SimStateInstance* o = id == 0 ? nullptr : state_.find(id);
        const bool yes = o != nullptr && o->meta().is_a(*img.class_metas[in.c]);
        if (in.op == OP_ISA)
          R[in.a].i = yes ? 1 : 0;
        else
          R[in.a].id = yes ? id : 0;
        break;
      }
      case OP_MCALL: {
        VSD_SAVE();
        SimStateInstance& o = obj(R[in.a].id);
        // What a C++ method reads is invisible here: a condition that calls one watches every property
        // of the instance (a null property: see on_change).
        if (deps_ != nullptr) deps_->emplace_back(o.id(), nullptr);
        const MetaMethod& m = *img.methods[in.b];
        const auto& kinds = img.method_kinds[in.b];
        std::vector<Value> args;
        args.reserve(kinds.size());
        for (std::size_t i = 0; i < kinds.size(); ++i) {
          const Val v = R[in.a + 1 + i];
          const MetaType* want = i < m.arguments().size() ? m.arguments()[i] : nullptr;
          switch (kinds[i]) {
            case RK::I:
              if (want != nullptr && want->kind() == TypeKind::Bool)
                args.emplace_back(v.i != 0);
              else
                args.emplace_back(v.i);
              break;
            case RK::D:
              args.emplace_back(v.d);
              break;
            case RK::S:
              args.emplace_back(S[in.a + 1 + i]);
              break;
            case RK::X:
              args.push_back(xregs_[fr->base + in.a + 1 + i]);
              break;
            case RK::V:
              method_vector_arg(m, i, vregs_[fr->base + in.a + 1 + i], args);
              break;
            default: {
              SimStateInstance* t = v.id == 0 ? nullptr : &obj(v.id);
              args.emplace_back(SharedRef<SimStateInstance>(t));
              break;
            }
          }
        }
        Value r = o.meta().call(o, m.name(), args);
        VSD_REFRESH();
        switch (img.method_results[in.b]) {
          case RK::I:
            if (r.is<bool>())
              R[in.a].i = r.as<bool>() ? 1 : 0;
            else if (r.type() != nullptr &&
                     (r.type()->kind() == TypeKind::Enum || r.type()->kind() == TypeKind::Flags))
              R[in.a].i = r.type()->load_integer(r.data());
            else
              R[in.a].i = r.convert_to(meta_type<std::int64_t>()).as<std::int64_t>();
            break;
          case RK::D:
            R[in.a].d = r.convert_to(meta_type<double>()).as<double>();
            break;
          case RK::S:  // a method's results are values in registers like any other (what it allocates
                       // itself is its own)
            string_room(S[in.a], r.as<std::string>().size());
            S[in.a] = r.as<std::string>();
            break;
          case RK::R: {
            const SimStateInstance* t = r.type() != nullptr && r.type()->is_reference()
                                            ? static_cast<const RefBase*>(r.data())->get()
                                            : nullptr;
            R[in.a].id = t != nullptr ? t->id() : 0;
            break;
          }
          case RK::X: {
            Value& x = xregs_[fr->base + in.a];
            const std::size_t before = heap_bytes(x);
            x = std::move(r);
            grew(before, heap_bytes(x));
            break;
          }
          case RK::V: {
            VecReg& v = vregs_[fr->base + in.a];
            const std::size_t before = heap_bytes(v);
            method_vector_result(m, r, v);
            grew(before, heap_bytes(v));
            break;
          }
          default:
            break;
        }
        break;
      }
      case OP_BUILTIN: {
        Val* a = &R[in.a];
        switch (static_cast<Builtin>(in.b)) {
          case Builtin::Sqrt:
            a->d = std::sqrt(a->d);
            break;
          case Builtin::Floor:
            a->d = std::floor(a->d);
            break;
          case Builtin::Ceil:
            a->d = std::ceil(a->d);
            break;
          case Builtin::Abs:
            if (in.c != 0) {
              a->d = std::fabs(a->d);
            } else if (a->i == std::numeric_limits<std::int64_t>::min()) {
              VSD_SAVE();
              int_overflow("abs", a->i);
            } else {
              a->i = a->i < 0 ? -a->i : a->i;
            }
            break;
          case Builtin::Min:
            if (in.c != 0)
              a->d = std::min(a[0].d, a[1].d);
            else
              a->i = std::min(a[0].i, a[1].i);
            break;
          case Builtin::Max:
            if (in.c != 0)
              a->d = std::max(a[0].d, a[1].d);
            else
              a->i = std::max(a[0].i, a[1].i);
            break;
          case Builtin::Len:
            a->i = static_cast<std::int64_t>(S[in.a].size());
            break;
          default:
            break;
        }
        break;
      }
      case OP_PRINT: {
        std::ostream& out = opt_.out != nullptr ? *opt_.out : std::cout;
        const auto& kinds = img.print_kinds[in.c];
        std::string line;
        for (int i = 0; i < in.b; ++i) {
          switch (kinds[static_cast<std::size_t>(i)]) {
            case RK::I:
              line += std::to_string(R[in.a + i].i);
              break;
            case RK::D:
              line += fmt_double(R[in.a + i].d);
              break;
            case RK::S:
              line += S[in.a + i];
              break;
            case RK::V:
              line += vector_text(*img.print_types[in.c][static_cast<std::size_t>(i)],
                                  vregs_[fr->base + in.a + i]);
              break;
            case RK::X: {
              const Value& x = xregs_[fr->base + in.a + i];
              line += value_text(x);
              break;
            }
            default: {
              const std::uint64_t id = R[in.a + i].id;
              const SimStateInstance* o = id == 0 ? nullptr : state_.find(id);
              const auto* n = o != nullptr ? o->as<NamedModelInstance>() : nullptr;
              line += o == nullptr ? std::string("null")
                                   : (n != nullptr && !n->name().empty()
                                          ? n->name()
                                          : o->meta().name() + "#" + std::to_string(id));
            }
          }
        }
        out << line << '\n';
        break;
      }
      case OP_FAIL:
        VSD_SAVE();
        fail(img.strings[in.b]);
      case OP_BREAK: {
        // Only a debugger patches this in (a line start or a breakpoint). After its hook, the original
        // instruction runs from the function's trampoline (original, then OP_RESUME back here), so the
        // hot loop has no extra test and no second dispatch path.
        VSD_SAVE();
        const auto at = static_cast<std::size_t>(pc - 1 - code);
        if (debug_ != nullptr) debug_->on_break(*fr->fn, at);
        VSD_REFRESH();
        pc = fr->run->tramp.data() + 2 * at;
        break;
      }
      case OP_RESUME:
        pc = VSD_TARGET(in);
        break;
      case OP_MOVV:
      case OP_VCLEAR:
      case OP_VSIZE:
      case OP_VGET:
      case OP_VSET:
      case OP_VPUSH:
      case OP_EQV:
      case OP_PVSIZE:
      case OP_PVGET:
        VSD_SAVE();
        vector_op(in, *fr);
        break;
      case OP_FIND:
        R[in.a].id = find_node(S[in.b]);
        break;
      case OP_XDEF:
      case OP_MOVX:
      case OP_XGETF:
      case OP_XSETF:
      case OP_EQX:
      case OP_XVSIZE:
      case OP_XVGET:
      case OP_XVSET:
      case OP_XVPUSH:
        VSD_SAVE();
        value_op(in, *fr);
        break;
      case OP_XOP: {  // a struct (fixed size) into X, or its text into S
        VSD_SAVE();
        const std::size_t before = heap_bytes(xregs_[fr->base + in.a]) + S[in.a].capacity();
        struct_op(in, *fr);
        VSD_REFRESH();
        grew(before, heap_bytes(xregs_[fr->base + in.a]) + S[in.a].capacity());
        break;
      }
      default:
        VSD_SAVE();
        fail("bad instruction");
    }
  }
#undef VSD_SAVE
#undef VSD_TARGET
#undef VSD_REFRESH
#undef VSD_CHECKED
#undef VSD_IMM
#undef VSD_LOOP
}

}  // namespace vsd::soml
