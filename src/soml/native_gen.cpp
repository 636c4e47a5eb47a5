// The native code generator (docs/soml.md, "Native compilation"): the program image's bytecode translated
// to C++, one C++ function per SOML++ function whose instructions all have a translation here (the
// "native subset": int and double arithmetic, comparisons, jumps and loops, calls of other such
// functions, print of numbers, fail; self, marks, static objects and properties of scalar kinds, read and
// written through the runtime's callbacks). Each register becomes two typed C++ variables (i<n>, d<n>): the VM's
// register is a union read by static type, so an instruction reads and writes the view of its type, and
// a move copies both (the optimiser drops the dead one). Jumps become gotos to the instruction's label;
// the checks the VM makes (overflow, division by zero, budget on backward jumps and calls, call depth)
// are made at the same instructions and report through the Context (native_abi.hpp), so a native run
// fails where and as the VM's does. Counted loops also get a copy without the budget test, run while the
// budget covers them (counted_loop, emit_function); calls pass the frames still allowed (`left`).
#include <cstring>
#include <sstream>

#include "native.hpp"
#include "program_impl.hpp"

namespace vsd::soml {

namespace {

bool scalar(RK k) { return k == RK::I || k == RK::D || k == RK::R; }

// The int compare-and-jumps (JGEI ... JNEIK): they test registers and write none.
bool is_compare_jump(std::uint8_t op) {
  switch (op) {
    case OP_JGEI:
    case OP_JGTI:
    case OP_JLTI:
    case OP_JLEI:
    case OP_JEQI:
    case OP_JNEI:
    case OP_JGEIK:
    case OP_JGTIK:
    case OP_JLTIK:
    case OP_JLEIK:
    case OP_JEQIK:
    case OP_JNEIK:
      return true;
    default:
      return false;
  }
}

// Whether every instruction of @p f has a translation (calls checked against @p ok, the functions known
// to be translatable so far).
bool translatable(const ProgramImage& img, const Function& f, const std::vector<char>& ok) {
  if (!f.compiled || f.code.empty()) return false;
  for (RK k : f.param_kinds)
    if (!scalar(k)) return false;
  if (!scalar(f.result) && f.result != RK::None) return false;
  for (const Ins& in : f.code) {
    if (is_compare_jump(in.op)) continue;
    switch (in.op) {
      case OP_NOP:
      case OP_LOADI:
      case OP_LOADK:
      case OP_MOV:
      case OP_ADDI:
      case OP_SUBI:
      case OP_MULI:
      case OP_DIVI:
      case OP_MODI:
      case OP_ADDD:
      case OP_SUBD:
      case OP_MULD:
      case OP_DIVD:
      case OP_ADDIK:
      case OP_MULIK:
      case OP_DIVIK:
      case OP_MODIK:
      case OP_NEGI:
      case OP_NEGD:
      case OP_NOT:
      case OP_I2D:
      case OP_D2I:
      case OP_LTI:
      case OP_LEI:
      case OP_EQI:
      case OP_NEI:
      case OP_LTD:
      case OP_LED:
      case OP_EQD:
      case OP_NED:
      case OP_JMP:
      case OP_JMPF:
      case OP_JMPT:
      case OP_LOOPLT:
      case OP_LOOPLE:
      case OP_LOOPLTK:
      case OP_LOOPLEK:
      case OP_RET:
      case OP_RET0:
      case OP_FAIL:
        break;
      case OP_CALL:
      case OP_CALLS:
        if (!ok[in.b]) return false;
        break;
      case OP_SELF:
      case OP_MARK:
      case OP_OBJ:
        break;
      case OP_GETP:
      case OP_SETP:
        if (!scalar_property(img.props[in.c])) return false;
        break;
      case OP_BUILTIN:
        switch (static_cast<Builtin>(in.b)) {
          case Builtin::Sqrt:
          case Builtin::Floor:
          case Builtin::Ceil:
          case Builtin::Abs:
          case Builtin::Min:
          case Builtin::Max:
            break;
          default:
            return false;
        }
        break;
      case OP_PRINT:
        for (RK k : img.print_kinds[in.c])
          if (k != RK::I && k != RK::D) return false;
        break;
      default:
        return false;
    }
  }
  return true;
}

// @p text for a comment or a string literal of the generated code: a control character (a newline in a
// file name would end a comment) becomes '?'.
std::string one_line(const std::string& text) {
  std::string out = text;
  for (char& ch : out)
    if (static_cast<unsigned char>(ch) < 0x20) ch = '?';
  return out;
}

const char* ctype(RK k) { return k == RK::D ? "double" : "std::int64_t"; }
// What a translated function returns: its result and the budget left (both in registers: a struct of two
// 8-byte scalars is returned in two registers).
const char* rtype(RK k) { return k == RK::D ? "RD" : "RI"; }
char view(RK k) { return k == RK::D ? 'd' : 'i'; }

std::uint32_t target_of(const Ins& in) { return (static_cast<std::uint32_t>(in.x) << 16) | in.c; }

std::string imm(std::uint16_t v) {
  return "std::int64_t{" + std::to_string(static_cast<std::int16_t>(v)) + "}";
}

// Whether instruction @p in may write its register a (everything but jumps that only test, returns,
// fail, stores and print; a loop instruction writes its counter).
bool writes_a(const Ins& in) {
  if (is_compare_jump(in.op)) return false;
  switch (in.op) {
    case OP_NOP:
    case OP_JMP:
    case OP_JMPF:
    case OP_JMPT:
    case OP_RET:
    case OP_RET0:
    case OP_FAIL:
    case OP_SETP:
    case OP_PRINT:
      return false;
    default:
      return true;
  }
}

bool is_loop(std::uint8_t op) {
  return op == OP_LOOPLT || op == OP_LOOPLE || op == OP_LOOPLTK || op == OP_LOOPLEK;
}

// Whether the loop closed by the LOOP* instruction at @p at is counted: between its target and itself
// nothing writes the counter (register a) or the bound (register b of LOOPLT/LOOPLE), nothing jumps
// backward (no inner loop), and nothing spends budget or calls back into the runtime (no call, no
// property, no print, no enclosing instance). Then each pass through the loop instruction adds one to
// the counter and the backward jumps left are known from the counter and the bound: when the budget
// covers them all, a copy of the loop without the budget test runs (emit_function).
bool counted_loop(const Function& f, std::size_t at) {
  const Ins& lp = f.code[at];
  const std::uint32_t top = target_of(lp);
  if (!is_loop(lp.op) || top > at) return false;
  const bool reg_bound = lp.op == OP_LOOPLT || lp.op == OP_LOOPLE;
  for (std::size_t k = top; k < at; ++k) {
    const Ins& in = f.code[k];
    switch (in.op) {
      case OP_CALL:
      case OP_CALLS:
      case OP_SETP:
      case OP_GETP:
      case OP_SELF:
      case OP_PRINT:
        return false;
      default:
        break;
    }
    if (op_jumps(in.op) && target_of(in) <= k) return false;
    if (writes_a(in) && (in.a == lp.a || (reg_bound && in.a == lp.b))) return false;
  }
  return true;
}

// The body of function @p fi (translatable) as C++.
void emit_function(std::ostream& out, const ProgramImage& img, std::size_t fi) {
  std::ostringstream o;  // the fast copies of counted loops are rewritten in place (below)
  const Function& f = *img.functions[fi];
  const std::string F = std::to_string(fi) + "u";
  std::vector<char> label(f.code.size() + 1, 0);
  for (const Ins& in : f.code)
    if (op_jumps(in.op)) label[target_of(in)] = 1;
  o << "// " << one_line(f.name) << "\n";
  o << rtype(f.result) << " f" << fi
    << "([[maybe_unused]] Context* c, [[maybe_unused]] std::uint32_t left, std::uint64_t budget, "
       "[[maybe_unused]] std::uint64_t self, [[maybe_unused]] std::uint64_t mark";
  for (int p = 0; p < f.nparams; ++p)
    o << ", " << ctype(f.param_kinds[static_cast<std::size_t>(p)]) << " p" << p;
  o << ") {\n";
  for (int r = 0; r < f.nregs + 1; ++r) {
    o << "  [[maybe_unused]] std::int64_t i" << r << " = 0;\n";
    o << "  [[maybe_unused]] double d" << r << " = 0;\n";
  }
  for (int p = 0; p < f.nparams; ++p)
    o << "  " << view(f.param_kinds[static_cast<std::size_t>(p)]) << p << " = p" << p << ";\n";
  std::vector<char> counted(f.code.size(), 0);  // the counted loops (counted_loop), by their LOOP*
  for (std::size_t at = 0; at < f.code.size(); ++at)
    if (counted_loop(f, at)) {
      counted[at] = 1;
      label[at + 1] = 1;
      o << "  [[maybe_unused]] std::uint64_t vb" << at << " = 0;  // the fast copy's budget + counter\n";
    }
  // The budget travels in a register: a parameter, returned with the result (no memory traffic per call
  // or iteration); it goes to the Context only when failing (fail() takes it) and at the entry (e<n>).
  auto I = [](int r) { return "i" + std::to_string(r); };
  auto D = [](int r) { return "d" + std::to_string(r); };
  // Counted loops (counted_loop) get a second copy of their body, emitted after the function's code, with
  // labels V<loop>_<instruction>: the checked copy's loop instruction jumps into it when the budget left
  // covers every backward jump the loop can still make, and its exit falls to the instruction after.
  std::size_t fast = f.code.size();  // the loop whose fast copy is being emitted (size(): none)
  auto lab = [&](std::uint32_t t) {
    if (fast < f.code.size())  // in the fast copy: its own labels, or the exits that set the budget
      return (t >= target_of(f.code[fast]) && t <= fast ? "V" : "X") + std::to_string(fast) + "_" +
             std::to_string(t);
    return "L" + std::to_string(t);
  };
  auto emit = [&](std::size_t at) {
    const Ins in = f.code[at];
    const std::string AT = std::to_string(at) + "u";
    const std::string T = lab(in.op < kOpCount && op_jumps(in.op) ? target_of(in) : 0);
    // Checked int arithmetic into register a. The message needs the operands; when a is one of them (s +=
    // i), passing the old value would make GCC keep a copy of it in the loop: for + and - the failing
    // path recomputes it from the wrapped result t instead (t - y, t + y, x - t: exact modulo 2^64).
    // @p xr, @p yr: the operands' registers (-1: an immediate).
    auto checked = [&](const char* builtin, const std::string& x, const std::string& y, const char* fault,
                       int xr, int yr) {
      auto u = [](const std::string& v) { return "static_cast<std::uint64_t>(" + v + ")"; };
      std::string fx = x, fy = y;
      const bool add = fault[0] == 'A', sub = fault[0] == 'S';
      if ((add || sub) && xr == in.a && yr != in.a)
        fx = "static_cast<std::int64_t>(" + u("t") + (add ? " - " : " + ") + u(y) + ")";
      else if ((add || sub) && yr == in.a && xr != in.a)
        fy = "static_cast<std::int64_t>(" + (add ? u("t") + " - " + u(x) : u(x) + " - " + u("t")) + ")";
      o << "  { std::int64_t t; if (" << builtin << "(" << x << ", " << y
        << ", &t)) [[unlikely]] fail(c, budget, Fault::" << fault << ", " << F << ", " << AT << ", " << fx
        << ", " << fy << "); " << I(in.a) << " = t; }\n";
    };
    auto budget = [&](const char* fault) {
      o << "{ if (--budget == 0) [[unlikely]] fail(c, budget, Fault::" << fault << ", " << F << ", " << AT
        << "); } ";
    };
    // LOOPLT/LOOPLE: counter + 1 (an overflow means the counter was INT64_MAX: the message's operand is
    // that constant, so that no copy of the old counter is kept for it), then the backward jump while
    // the counter is below (at most) the bound.
    auto loop = [&](const char* cmp, const std::string& bound) {
      const bool le = cmp[1] == '=';
      const std::string top = std::to_string(target_of(in));
      const std::string ovf = "fail(c, budget, Fault::Add, " + F + ", " + AT + ", 9223372036854775807ll, 1); ";
      if (fast == at) {
        // The fast copy, entered with counter < bound (<= for LOOPLE), which nothing in the body changes:
        // counter + 1 overflows only for LOOPLE at INT64_MAX; the budget was found to cover every
        // backward jump, so it only counts them.
        // At the exit the counter is one past the last jump's: the budget is vb - counter + 1.
        if (le)
          o << "  { std::int64_t t; if (__builtin_add_overflow(" << I(in.a)
            << ", std::int64_t{1}, &t)) [[unlikely]] " << ovf << I(in.a) << " = t; }";
        else
          o << "  " << I(in.a) << " = " << I(in.a) << " + 1;";
        o << " if (" << I(in.a) << " " << cmp << " " << bound << ") goto " << T << "; budget = budget + 1;\n";
        return;
      }
      o << "  { std::int64_t t; if (__builtin_add_overflow(" << I(in.a) << ", std::int64_t{1}, &t)) [[unlikely]] "
        << ovf << I(in.a) << " = t; if (t " << cmp << " " << bound << ") { ";
      budget("LoopBudget");
      if (counted[at]) {
        // Backward jumps left after this one: bound - t - 1 (LOOPLT) or bound - t (LOOPLE), each needing
        // the budget above 0 after it: the fast copy when the budget covers them (unsigned: bound - t is
        // exact, it is positive and below 2^64).
        o << "if (static_cast<std::uint64_t>(" << bound << ") - static_cast<std::uint64_t>(t) "
          << (le ? "<" : "<=") << " budget) { vb" << at << " = budget + static_cast<std::uint64_t>(t); goto V"
          << at << "_" << top << "; } ";
      }
      o << "goto " << T << "; } }\n";
    };
    auto cmp = [&](const char* op, char v) {
      o << "  " << I(in.a) << " = " << v << in.b << " " << op << " " << v << in.c << ";\n";
    };
    auto jump = [&](const char* op, const std::string& rhs) {
      o << "  if (" << I(in.a) << " " << op << " " << rhs << ") goto " << T << ";\n";
    };
    switch (in.op) {
      case OP_NOP:
        break;
      case OP_LOADI:
        o << "  " << I(in.a) << " = " << imm(in.b) << ";\n";
        break;
      case OP_LOADK: {
        const auto bits = static_cast<std::uint64_t>(img.consts[in.b]);
        o << "  " << I(in.a) << " = static_cast<std::int64_t>(0x" << std::hex << bits << std::dec << "ull); "
          << D(in.a) << " = __builtin_bit_cast(double, " << I(in.a) << ");\n";
        break;
      }
      case OP_MOV:
        o << "  " << I(in.a) << " = " << I(in.b) << "; " << D(in.a) << " = " << D(in.b) << ";\n";
        break;
      case OP_ADDI:
        checked("__builtin_add_overflow", I(in.b), I(in.c), "Add", in.b, in.c);
        break;
      case OP_SUBI:
        checked("__builtin_sub_overflow", I(in.b), I(in.c), "Sub", in.b, in.c);
        break;
      case OP_MULI:
        checked("__builtin_mul_overflow", I(in.b), I(in.c), "Mul", in.b, in.c);
        break;
      case OP_ADDIK:
        checked("__builtin_add_overflow", I(in.b), imm(in.c), "Add", in.b, -1);
        break;
      case OP_MULIK:
        checked("__builtin_mul_overflow", I(in.b), imm(in.c), "Mul", in.b, -1);
        break;
      case OP_DIVI:
      case OP_MODI: {
        const bool div = in.op == OP_DIVI;
        o << "  { const std::int64_t x = " << I(in.b) << ", y = " << I(in.c)
          << "; if (y == 0) [[unlikely]] fail(c, budget, "
          << "Fault::DivisionByZero, " << F << ", " << AT << "); ";
        if (div)
          o << "if (y == -1) { if (x == (-9223372036854775807ll - 1)) [[unlikely]] fail(c, budget, "
               "Fault::Div, "
            << F << ", " << AT << ", x, y); " << I(in.a) << " = -x; } else " << I(in.a) << " = x / y; }\n";
        else
          o << I(in.a) << " = y == -1 ? 0 : x % y; }\n";
        break;
      }
      case OP_DIVIK:
        o << "  " << I(in.a) << " = " << I(in.b) << " / " << imm(in.c) << ";\n";
        break;
      case OP_MODIK:
        o << "  " << I(in.a) << " = " << I(in.b) << " % " << imm(in.c) << ";\n";
        break;
      case OP_ADDD:
        o << "  " << D(in.a) << " = " << D(in.b) << " + " << D(in.c) << ";\n";
        break;
      case OP_SUBD:
        o << "  " << D(in.a) << " = " << D(in.b) << " - " << D(in.c) << ";\n";
        break;
      case OP_MULD:
        o << "  " << D(in.a) << " = " << D(in.b) << " * " << D(in.c) << ";\n";
        break;
      case OP_DIVD:
        o << "  " << D(in.a) << " = " << D(in.b) << " / " << D(in.c) << ";\n";
        break;
      case OP_NEGI:
        o << "  if (" << I(in.b)
          << " == (-9223372036854775807ll - 1)) [[unlikely]] fail(c, budget, Fault::Neg, " << F << ", " << AT
          << ", " << I(in.b) << "); " << I(in.a) << " = -" << I(in.b) << ";\n";
        break;
      case OP_NEGD:
        o << "  " << D(in.a) << " = -" << D(in.b) << ";\n";
        break;
      case OP_NOT:
        o << "  " << I(in.a) << " = " << I(in.b) << " == 0 ? 1 : 0;\n";
        break;
      case OP_I2D:
        o << "  " << D(in.a) << " = static_cast<double>(" << I(in.b) << ");\n";
        break;
      case OP_D2I:
        o << "  if (!(" << D(in.b) << " >= -9.2233720368547758e18 && " << D(in.b)
          << " < 9.2233720368547758e18)) [[unlikely]] fail(c, budget, Fault::DoubleToInt, " << F << ", " << AT
          << ", __builtin_bit_cast(std::int64_t, " << D(in.b) << ")); " << I(in.a)
          << " = static_cast<std::int64_t>(" << D(in.b) << ");\n";
        break;
      case OP_LTI:
        cmp("<", 'i');
        break;
      case OP_LEI:
        cmp("<=", 'i');
        break;
      case OP_EQI:
        cmp("==", 'i');
        break;
      case OP_NEI:
        cmp("!=", 'i');
        break;
      case OP_LTD:
        cmp("<", 'd');
        break;
      case OP_LED:
        cmp("<=", 'd');
        break;
      case OP_EQD:
        cmp("==", 'd');
        break;
      case OP_NED:
        cmp("!=", 'd');
        break;
      case OP_JMP:
        o << "  ";
        if (target_of(in) <= at) budget("LoopBudget");  // backward: one unit of the budget, as in the VM
        o << "goto " << T << ";\n";
        break;
      case OP_JMPF:
        o << "  if (" << I(in.a) << " == 0) goto " << T << ";\n";
        break;
      case OP_JMPT:
        o << "  if (" << I(in.a) << " != 0) goto " << T << ";\n";
        break;
      case OP_JGEI:
        jump(">=", I(in.b));
        break;
      case OP_JGTI:
        jump(">", I(in.b));
        break;
      case OP_JLTI:
        jump("<", I(in.b));
        break;
      case OP_JLEI:
        jump("<=", I(in.b));
        break;
      case OP_JEQI:
        jump("==", I(in.b));
        break;
      case OP_JNEI:
        jump("!=", I(in.b));
        break;
      case OP_JGEIK:
        jump(">=", imm(in.b));
        break;
      case OP_JGTIK:
        jump(">", imm(in.b));
        break;
      case OP_JLTIK:
        jump("<", imm(in.b));
        break;
      case OP_JLEIK:
        jump("<=", imm(in.b));
        break;
      case OP_JEQIK:
        jump("==", imm(in.b));
        break;
      case OP_JNEIK:
        jump("!=", imm(in.b));
        break;
      case OP_LOOPLT:
        loop("<", I(in.b));
        break;
      case OP_LOOPLE:
        loop("<=", I(in.b));
        break;
      case OP_LOOPLTK:
        loop("<", imm(in.b));
        break;
      case OP_LOOPLEK:
        loop("<=", imm(in.b));
        break;
      case OP_CALL:
      case OP_CALLS: {
        // As the VM: a null self, the depth limit, then the budget; then the call, whose frame the
        // runtime adds to the reported call stack when an error passes it.
        const Function& callee = *img.functions[in.b];
        const std::string self = in.op == OP_CALLS ? "self" : "static_cast<std::uint64_t>(" + I(in.c) + ")";
        o << "  ";
        if (in.op == OP_CALL)
          o << "{ if (" << I(in.c) << " == 0) [[unlikely]] fail(c, budget, Fault::NullReference, " << F
            << ", " << AT << "); } ";
        // `left`: the frames that may still be added (the entry computed it from the depth and
        // max_depth), so that the test reads no memory.
        o << "{ if (left == 0) [[unlikely]] fail(c, budget, Fault::Depth, " << F << ", " << AT << ", 0, " << in.b
          << "); } ";
        budget("CallBudget");
        o << "\n  try { const auto r = f" << in.b << "(c, left - 1, budget, " << self << ", mark";
        for (int p = 0; p < callee.nparams; ++p)
          o << ", " << view(callee.param_kinds[static_cast<std::size_t>(p)]) << in.a + p;
        o << "); " << (callee.result == RK::D ? D(in.a) : I(in.a))
          << " = r.v; budget = r.budget; } catch (...) { "
          << "c->unwind(c, " << F << ", " << AT << "); throw; }\n";
        break;
      }
      case OP_SELF: {
        const OuterPlan& plan = img.outer_plans[in.b];
        if (plan.static_decl != nullptr)
          o << "  " << I(in.a) << " = static_cast<std::int64_t>(c->outer_ids[" << in.b << "]);\n";
        else if (plan.parents == 0)
          o << "  " << I(in.a) << " = static_cast<std::int64_t>(self);\n";
        else
          o << "  " << I(in.a) << " = static_cast<std::int64_t>(c->outer(c, " << F << ", " << AT << ", self, "
            << plan.parents << "u));\n";
        break;
      }
      case OP_MARK:
        o << "  " << I(in.a) << " = static_cast<std::int64_t>(mark);\n";
        break;
      case OP_OBJ:
        o << "  " << I(in.a) << " = c->consts[" << in.b << "];\n";
        break;
      case OP_GETP:
        // Through the runtime (read_scalar): the instance is found by its id, the read recorded as a
        // dependency while a condition is tested.
        o << "  { const Reg r = c->getp(c, " << F << ", " << AT << ", static_cast<std::uint64_t>(" << I(in.b)
          << "), " << in.c << "u); " << I(in.a) << " = r.i; " << D(in.a) << " = r.d; }\n";
        break;
      case OP_SETP: {
        // Through the runtime (write_scalar): recorded, signalled, conditions re-tested; the budget goes
        // with it (a listener may run SOML++ code).
        const bool dbl = img.props[in.c].kind == PK::Double || img.props[in.c].kind == PK::Other;
        o << "  { Reg r; r." << (dbl ? 'd' : 'i') << " = " << (dbl ? D(in.b) : I(in.b))
          << "; c->budget = budget; c->setp(c, " << F << ", " << AT << ", static_cast<std::uint64_t>("
          << I(in.a) << "), " << in.c << "u, r); budget = c->budget; }\n";
        break;
      }
      case OP_RET:
        o << "  return {" << view(f.result) << in.a << ", budget};\n";
        break;
      case OP_RET0:
        o << "  return {0, budget};\n";
        break;
      case OP_FAIL:
        o << "  fail(c, budget, Fault::Fail, " << F << ", " << AT << ", 0, " << in.b << ");\n";
        break;
      case OP_BUILTIN: {
        const std::string a = I(in.a), d = D(in.a), a1 = I(in.a + 1), d1 = D(in.a + 1);
        switch (static_cast<Builtin>(in.b)) {
          case Builtin::Sqrt:
            o << "  " << d << " = std::sqrt(" << d << ");\n";
            break;
          case Builtin::Floor:
            o << "  " << d << " = std::floor(" << d << ");\n";
            break;
          case Builtin::Ceil:
            o << "  " << d << " = std::ceil(" << d << ");\n";
            break;
          case Builtin::Abs:
            if (in.c != 0)
              o << "  " << d << " = std::fabs(" << d << ");\n";
            else
              o << "  if (" << a
                << " == (-9223372036854775807ll - 1)) [[unlikely]] fail(c, budget, Fault::Abs, " << F << ", "
                << AT << ", " << a << "); " << a << " = " << a << " < 0 ? -" << a << " : " << a << ";\n";
            break;
          case Builtin::Min:
            if (in.c != 0)
              o << "  " << d << " = std::min(" << d << ", " << d1 << ");\n";
            else
              o << "  " << a << " = std::min(" << a << ", " << a1 << ");\n";
            break;
          case Builtin::Max:
            if (in.c != 0)
              o << "  " << d << " = std::max(" << d << ", " << d1 << ");\n";
            else
              o << "  " << a << " = std::max(" << a << ", " << a1 << ");\n";
            break;
          default:
            break;
        }
        break;
      }
      case OP_PRINT: {
        const auto& kinds = img.print_kinds[in.c];
        o << "  { Reg r[" << std::max<std::size_t>(1, kinds.size()) << "];";
        for (std::size_t k = 0; k < kinds.size(); ++k)
          o << " r[" << k << "]." << view(kinds[k]) << " = " << view(kinds[k]) << in.a + static_cast<int>(k)
            << ";";
        o << " c->print(c, " << in.c << "u, r); }\n";
        break;
      }
      default:
        o << "  fail(c, budget, Fault::Fail, " << F << ", " << AT << ", 0, 0);  // not translated\n";
    }
  };
  for (std::size_t at = 0; at < f.code.size(); ++at) {
    if (label[at]) o << "L" << at << ":\n";
    emit(at);
  }
  if (label[f.code.size()]) o << "L" << f.code.size() << ":\n";
  o << "  return {0, budget};\n";
  // The fast copy does not count the budget down: every backward jump also adds one to the counter, so
  // the budget is vb<loop> - counter throughout (vb set on entry); it is computed where it is needed —
  // at a failure, a return, the exits — and the loop carries nothing for it.
  for (std::size_t at = 0; at < f.code.size(); ++at) {
    if (!counted[at]) continue;
    fast = at;
    const std::uint32_t top = target_of(f.code[at]);
    const std::string V = std::to_string(at);
    std::vector<char> vlabel(at + 1, 0);        // only the labels jumped to (no unused label)
    std::vector<char> exit(f.code.size() + 1, 0);  // targets outside the loop
    vlabel[top] = 1;
    for (std::size_t k = top; k < at; ++k)
      if (op_jumps(f.code[k].op)) (target_of(f.code[k]) <= at ? vlabel : exit)[target_of(f.code[k])] = 1;
    const auto start = o.str().size();
    o << "  // the loop of instruction " << at << " while the budget covers it\n";
    for (std::size_t k = top; k <= at; ++k) {
      if (vlabel[k]) o << "V" << V << "_" << k << ":\n";
      emit(k);
    }
    o << "  goto L" << at + 1 << ";\n";
    for (std::size_t t = 0; t < exit.size(); ++t)
      if (exit[t]) o << "X" << V << "_" << t << ":\n  budget = budget;\n  goto L" << t << ";\n";
    // Every `budget` of the copy read as vb - counter ("budget = budget" assigns it at the exits).
    std::string text = o.str(), copy = text.substr(start);
    const std::string bud = "(vb" + V + " - static_cast<std::uint64_t>(" + I(f.code[at].a) + "))";
    for (const char* w : {"c, budget,", ", budget}", "= budget;", "= budget + 1;"}) {
      const std::string from = w;
      std::string to = from;
      to.replace(to.find("budget"), 6, bud);
      for (std::size_t pos = 0; (pos = copy.find(from, pos)) != std::string::npos; pos += to.size())
        copy.replace(pos, from.size(), to);
    }
    o.str(text.substr(0, start) + copy);
    o.seekp(0, std::ios_base::end);
  }
  fast = f.code.size();
  o << "}\n\n";
  out << o.str();
}

}  // namespace

std::uint64_t image_hash(const ProgramImage& img) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  auto num = [&](std::uint64_t v) { mix(&v, sizeof v); };
  auto str = [&](const std::string& s) {
    num(s.size());
    mix(s.data(), s.size());
  };
  num(native::kNativeAbi);
  num(img.functions.size());
  // Not the functions' names: those of initialisers carry the script's file name (its class), which
  // may differ between the compile and the load of the same text.
  for (const auto& f : img.functions) {
    num(static_cast<std::uint64_t>(f->nparams));
    num(static_cast<std::uint64_t>(f->nregs));
    num(static_cast<std::uint64_t>(f->result));
    for (RK k : f->param_kinds) num(static_cast<std::uint64_t>(k));
    num(f->code.size());
    for (const Ins& in : f->code) {
      num(in.op);
      num(in.x);
      num(in.a);
      num(in.b);
      num(in.c);
    }
    for (const Function::Pos& p : f->positions) num((std::uint64_t{p.line} << 32) | p.column);
  }
  num(img.consts.size());
  for (std::int64_t k : img.consts) num(static_cast<std::uint64_t>(k));
  num(img.strings.size());
  for (const std::string& s : img.strings) str(s);
  // What native code assumes of the run-time tables: each property slot (its kind, type, where it lives
  // in its class, the class's size — another class layout gives another hash) and each outer plan.
  num(img.props.size());
  for (const PropSlot& ps : img.props) {
    if (ps.prop == nullptr) {
      num(0);
      continue;
    }
    str(ps.prop->name());
    num(static_cast<std::uint64_t>(ps.kind));
    num(static_cast<std::uint64_t>(ps.prop->type().kind()));
    num(ps.prop->type().size());
    num(ps.prop->offset());
    num(ps.prop->owner().size());
  }
  num(img.outer_plans.size());
  for (const OuterPlan& op : img.outer_plans) {
    num(op.static_decl != nullptr ? 1 : 0);
    num(static_cast<std::uint64_t>(op.parents));
  }
  num(img.print_kinds.size());
  for (const auto& ks : img.print_kinds) {
    num(ks.size());
    for (RK k : ks) num(static_cast<std::uint64_t>(k));
  }
  return h;
}

std::vector<char> native_functions(const ProgramImage& img) {
  std::vector<char> ok(img.functions.size(), 0);
  // Optimistic first (recursion: a function may call itself or another not decided yet), then drop every
  // function that calls one that was dropped, until nothing changes.
  for (std::size_t i = 0; i < ok.size(); ++i) ok[i] = 1;
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t i = 0; i < ok.size(); ++i)
      if (ok[i] && !translatable(img, *img.functions[i], ok)) {
        ok[i] = 0;
        changed = true;
      }
  }
  return ok;
}

void native_module_source(std::ostream& o, const ProgramImage& img, const std::string& ns,
                          const std::string& script) {
  const std::vector<char> ok = native_functions(img);
  o << "namespace " << ns << " {\n\n";
  // Declarations first: functions call each other in any order.
  for (std::size_t i = 0; i < ok.size(); ++i) {
    if (!ok[i]) continue;
    const Function& f = *img.functions[i];
    o << rtype(f.result) << " f" << i << "(Context*, std::uint32_t, std::uint64_t, std::uint64_t, std::uint64_t";
    for (int p = 0; p < f.nparams; ++p) o << ", " << ctype(f.param_kinds[static_cast<std::size_t>(p)]);
    o << ");\n";
  }
  o << "\n";
  for (std::size_t i = 0; i < ok.size(); ++i)
    if (ok[i]) emit_function(o, img, i);
  // The entries the runtime calls: arguments from the VM's registers, the result back into one.
  std::size_t count = 0;
  for (std::size_t i = 0; i < ok.size(); ++i) {
    if (!ok[i]) continue;
    ++count;
    const Function& f = *img.functions[i];
    o << "Reg e" << i
      << "(Context* c, std::uint32_t depth, std::uint64_t self, std::uint64_t mark, "
         "[[maybe_unused]] const Reg* a) {\n"
      << "  const std::uint32_t left = depth >= c->max_depth ? 0 : c->max_depth - depth;\n"
      << "  const auto x = f" << i << "(c, left, c->budget, self, mark";
    for (int p = 0; p < f.nparams; ++p)
      o << ", a[" << p << "]." << view(f.param_kinds[static_cast<std::size_t>(p)]);
    o << ");\n  c->budget = x.budget;\n  Reg r;\n  r." << view(f.result) << " = x.v;\n  return r;\n}\n";
  }
  o << "\nconst FunctionEntry functions[] = {\n";
  for (std::size_t i = 0; i < ok.size(); ++i)
    if (ok[i]) o << "    {" << i << "u, &e" << i << "},\n";
  if (count == 0) o << "    {0u, nullptr},\n";
  std::string quoted;
  for (char ch : one_line(script)) {  // a C++ string literal
    if (ch == '"' || ch == '\\') quoted += '\\';
    quoted += ch;
  }
  o << "};\nconst Module module{kNativeAbi, " << count << "u, 0x" << std::hex << image_hash(img) << std::dec
    << "ull, functions, \"" << quoted << "\"};\n\n}  // namespace " << ns << "\n\n";
}

void native_library_source(std::ostream& o, const std::vector<const ProgramImage*>& images,
                           const std::vector<std::string>& scripts) {
  o << "// Generated by vsd-soml compile from the SOML++ program image" << (images.size() > 1 ? "s" : "")
    << " of ";
  for (std::size_t i = 0; i < scripts.size(); ++i) o << (i ? ", " : "") << one_line(scripts[i]);
  o << ". Do not edit: regenerate.\n"
       "// Build: c++ -std=c++20 -O2 -fPIC -shared -I<vsd include dir> THIS.cpp -o THIS.so\n"
       "// Load: Program::load_native(path) (docs/soml.md, \"Native compilation\").\n"
       "#include <algorithm>\n#include <cmath>\n#include <cstdint>\n\n#include "
       "\"vsd/soml/native_abi.hpp\"\n\n"
       // Translated instruction by instruction: several statements share a line, and a script's own `x < x`
       // stays `i1 < i1`. Neither is a fault of the build that compiles this file, which may use -Wall
       // (GCC and clang both take these pragmas; the tests build the file with -Wall -Wextra -Wpedantic).
       "#pragma GCC diagnostic ignored \"-Wmisleading-indentation\"\n"
       "#pragma GCC diagnostic ignored \"-Wtautological-compare\"\n"
       // A script's endless recursion is its own (it fails at the depth limit, as in the VM).
       "#if defined(__clang__) || __GNUC__ >= 12\n#pragma GCC diagnostic ignored \"-Winfinite-recursion\"\n#endif\n\n"
       "namespace {\n\nusing namespace vsd::soml::native;\n\n"
       "struct RI {\n  std::int64_t v;\n  std::uint64_t budget;\n};\nstruct RD {\n  double v;\n  "
       "std::uint64_t budget;\n};\n\n";
  for (std::size_t i = 0; i < images.size(); ++i)
    native_module_source(o, *images[i], "s" + std::to_string(i), scripts[i]);
  o << "const Module* const modules[] = {";
  for (std::size_t i = 0; i < images.size(); ++i) o << (i ? ", " : "") << "&s" << i << "::module";
  o << "};\n\n}  // namespace\n\n"
       "extern \"C\" __attribute__((visibility(\"default\"))) const vsd::soml::native::Module* const* "
       "vsd_soml_native_modules(std::uint32_t* count) {\n  *count = "
    << images.size() << "u;\n  return modules;\n}\n";
}

}  // namespace vsd::soml
