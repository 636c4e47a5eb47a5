// Internal: the SOML++ opcodes in one table (name and operand shape of each), used by the VM's enum, the
// compiler and the disassembler (`vsd-soml disasm`). Not installed.
//
// Operands a, b, c are 16 bits each, x is a spare byte (a jump's target uses c and x: 24 bits). The shape
// of an opcode is three characters, one per operand a, b, c:
//   -  unused             r  register (of the frame)     i  signed 16-bit immediate   n  a plain number
//   k  consts index       s  strings index               p  props index (a property)  f  functions index
//   v  virtual slot       c  classes index               m  methods index (MetaMethod)
//   o  outer plan index   y  xtypes index (value type)   t  jump target (c, and x for the high bits)
// x carries an opcode-specific detail when it is not part of a target (vector element kind, struct field,
// StructOp); the disassembler prints it when it is not 0.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace vsd::soml {

// X(name, shape): one line per opcode, in opcode order (the enum's values follow this order).
#define VSD_SOML_OPCODES(X)                                                                                  \
  X(NOP, "---")                                                                                              \
  X(LOADI, "ri-") /* a = (int16) b */                                                                        \
  X(LOADK, "rk-") /* a = consts[b]            (ints and doubles as raw bits) */                              \
  X(LOADS, "rs-") /* S[a] = strings[b] */                                                                    \
  X(MOV, "rr-")   /* a = b */                                                                                \
  X(MOVS, "rr-")  /* S[a] = S[b] */                                                                          \
  X(ADDI, "rrr")                                                                                             \
  X(SUBI, "rrr")                                                                                             \
  X(MULI, "rrr")                                                                                             \
  X(DIVI, "rrr")                                                                                             \
  X(MODI, "rrr")                                                                                             \
  X(ADDD, "rrr")                                                                                             \
  X(SUBD, "rrr")                                                                                             \
  X(MULD, "rrr")                                                                                             \
  X(DIVD, "rrr")                                                                                             \
  X(ADDIK, "rri") /* a = b + (int16) c */                                                                    \
  X(MULIK, "rri") /* a = b * (int16) c */                                                                    \
  X(DIVIK, "rri") /* a = b / (int16) c   (c not 0 or -1) */                                                  \
  X(MODIK, "rri") /* a = b % (int16) c   (c not 0 or -1) */                                                  \
  X(NEGI, "rr-")                                                                                             \
  X(NEGD, "rr-")                                                                                             \
  X(NOT, "rr-")                                                                                              \
  X(I2D, "rr-")                                                                                              \
  X(D2I, "rr-")                                                                                              \
  X(LTI, "rrr")                                                                                              \
  X(LEI, "rrr")                                                                                              \
  X(EQI, "rrr")                                                                                              \
  X(NEI, "rrr")                                                                                              \
  X(LTD, "rrr")                                                                                              \
  X(LED, "rrr")                                                                                              \
  X(EQD, "rrr")                                                                                              \
  X(NED, "rrr")                                                                                              \
  X(LTS, "rrr")                                                                                              \
  X(LES, "rrr")                                                                                              \
  X(EQS, "rrr")                                                                                              \
  X(NES, "rrr")                                                                                              \
  X(CONCAT, "rrr") /* S[a] = S[b] + S[c] */                                                                  \
  X(TOSTR, "rrn")  /* S[a] = text of b; c: 0 int, 1 double, 2 bool, 3+k enum k */                            \
  X(STR2B, "rr-")  /* a = !S[b].empty() */                                                                   \
  X(JMP, "--t")    /* pc = target */                                                                         \
  X(JMPF, "r-t")   /* if (!a) pc = target */                                                                 \
  X(JMPT, "r-t")   /* if (a) pc = target */                                                                  \
  X(JGEI, "rrt")   /* if (a >= b) pc = target   (fused loop test) */                                         \
  X(JGTI, "rrt")   /* if (a > b) pc = target */                                                              \
  X(JLTI, "rrt")   /* if (a < b) pc = target */                                                              \
  X(JLEI, "rrt")   /* if (a <= b) pc = target */                                                             \
  X(JEQI, "rrt")   /* if (a == b) pc = target */                                                             \
  X(JNEI, "rrt")   /* if (a != b) pc = target */                                                             \
  /* The same against a constant: if (a op (int16) b) pc = target (an `if` or loop test `n < 2`). */         \
  X(JGEIK, "rit")                                                                                            \
  X(JGTIK, "rit")                                                                                            \
  X(JLTIK, "rit")                                                                                            \
  X(JLEIK, "rit")                                                                                            \
  X(JEQIK, "rit")                                                                                            \
  X(JNEIK, "rit")                                                                                            \
  /* The step and test of `for (...; i < n; i++)` at the loop's bottom: a = a + 1 (checked), then if         \
     (a < b) pc = target (backward: one unit of the budget). K: b is an int16 constant. */                   \
  X(LOOPLT, "rrt")                                                                                           \
  X(LOOPLE, "rrt")                                                                                           \
  X(LOOPLTK, "rit")                                                                                          \
  X(LOOPLEK, "rit")                                                                                          \
  X(CALL, "rfr")   /* call functions[b] with frame at a, self in register c; result in a */                  \
  X(VCALL, "rvr")  /* like CALL, but b is a virtual slot resolved on the class of self */                    \
  X(CALLS, "rf-")  /* like CALL, on this frame's self (a function of the same scope: no SELF) */             \
  X(RET, "r--")    /* return register a */                                                                   \
  X(RET0, "---")   /* return nothing */                                                                      \
  X(RETV, "r--")   /* return vector register a (a function whose result is a vector) */                      \
  X(SELF, "ro-")   /* a = instance of scope b levels out (outer plan b) */                                   \
  X(MARK, "r--")   /* a = mark */                                                                            \
  X(OBJ, "rk-")    /* a = id of object consts[b] */                                                          \
  X(GETP, "rrp")   /* a = property props[c] of instance b */                                                 \
  X(SETP, "rrp")   /* property props[c] of instance a = b */                                                 \
  X(PLACE, "rrn")  /* a = place node c of net instance b (c & kPortPlace: a port net's, of copy b) */        \
  X(PCOUNT, "rr-") /* a = count of place b */                                                                \
  X(PPUT, "rrn")   /* place a .put(b) */                                                                     \
  X(PCLEAR, "r--") /* place a .clear() */                                                                    \
  X(LSIZE, "rrp")  /* a = size of list props[c] of b */                                                      \
  X(LGET, "rrp")   /* a = element (id) R[a] of list props[c] of b   (a holds the index on entry) */          \
  X(LPUSH, "rrp")  /* list props[c] of a .push(b) */                                                         \
  X(NEW, "rcn")    /* a = new classes[b]; arguments from a+1, c of them */                                   \
  X(ISA, "rrc")    /* a = instance b is_a classes[c] */                                                      \
  X(AS, "rrc")     /* a = instance b if is_a classes[c] else null */                                         \
  X(MCALL, "rm-") /* a = MetaMethod methods[b] on instance R[a], arguments from a+1 (count in the method) */ \
  X(BUILTIN, "rnn") /* a = builtin b over registers a.. (c: variant) */                                      \
  X(PRINT, "rnn")   /* print registers a .. a+b-1; kinds from print_kinds[c] */                              \
  X(NULLCHK, "r--") /* error "null" unless a */                                                              \
  X(RANGE, "rk-")   /* check that a fits the storage type consts[b] (int properties narrower than int64) */  \
  X(FAIL, "-s-")    /* run-time error strings[b] */                                                          \
  X(BREAK, "---") /* debugger: patched over a line start; calls the hook, then runs Function::tramp[2 pc] */ \
  X(RESUME, "--t") /* the second instruction of a trampoline: pc = target (no budget) */                     \
  /* Vectors (x: 1 when the elements are strings, else 0; for OP_EQV 0 int, 1 double, 2 string). */          \
  X(MOVV, "rr-")   /* V[a] = V[b] (a copy: vectors are values) */                                            \
  X(VCLEAR, "r--") /* V[a] = {} */                                                                           \
  X(VSIZE, "rr-")  /* a = size of V[b] */                                                                    \
  X(VGET, "rrr")   /* a = V[b][R[c]]            (range-checked) */                                           \
  X(VSET, "rrr")   /* V[a][R[b]] = c            (range-checked) */                                           \
  X(VPUSH, "rr-")  /* V[a].push(b) */                                                                        \
  X(EQV, "rrr")    /* a = V[b] == V[c] */                                                                    \
  X(PVSIZE, "rrp") /* a = size of vector property props[c] of instance b (no copy) */                        \
  X(PVGET, "rrp")  /* a = element R[a] of vector property props[c] of instance b (no copy; range-checked) */ \
  X(FIND, "rr-")   /* a = the node at path S[b] from the database, or null */                                \
  /* Values (X registers: structs, vectors of structs and enums; out of line like the vector ones). */       \
  X(XDEF, "ry-")   /* X[a] = default value of xtypes[b] */                                                   \
  X(MOVX, "rr-")   /* X[a] = X[b] (a copy) */                                                                \
  X(XGETF, "rr-")  /* a = field x of struct X[b]          (register kind from the field's type) */           \
  X(XSETF, "rr-")  /* field x of struct X[a] = b */                                                          \
  X(EQX, "rrr")    /* a = X[b] == X[c] */                                                                    \
  X(RETX, "r--")   /* return X register a (a function whose result is a Value) */                            \
  X(XVSIZE, "rr-") /* a = size of vector X[b] */                                                             \
  X(XVGET, "rrr")  /* a = X[b][R[c]]                     (range-checked) */                                  \
  X(XVSET, "rrr")  /* X[a][R[b]] = c                     (range-checked) */                                  \
  X(XVPUSH, "rr-") /* X[a].push(b) */                                                                        \
  X(XOP, "rrr")    /* a = StructOp x over b and c (struct_ops.cpp): structs in X, scalars in D, Text into S */

enum Op : std::uint8_t {
#define VSD_SOML_OP_ENUM(name, shape) OP_##name,
  VSD_SOML_OPCODES(VSD_SOML_OP_ENUM)
#undef VSD_SOML_OP_ENUM
};

#define VSD_SOML_OP_COUNT(name, shape) +1
/// The number of opcodes.
inline constexpr std::size_t kOpCount = 0 VSD_SOML_OPCODES(VSD_SOML_OP_COUNT);
#undef VSD_SOML_OP_COUNT

struct OpInfo {
  std::string_view name;   // "LOADI"
  std::string_view shape;  // "ri-": operands a, b, c (see above)
};

inline constexpr OpInfo kOps[] = {
#define VSD_SOML_OP_INFO(name, shape) OpInfo{#name, shape},
    VSD_SOML_OPCODES(VSD_SOML_OP_INFO)
#undef VSD_SOML_OP_INFO
};
static_assert(sizeof(kOps) / sizeof(kOps[0]) == kOpCount);
static_assert(kOpCount <= 256, "opcodes are one byte");

/// The name and operand shape of opcode @p op; an opcode past the table reads as "?" (never met in code
/// the compiler made).
constexpr OpInfo op_info(std::uint8_t op) noexcept { return op < kOpCount ? kOps[op] : OpInfo{"?", "---"}; }

/// Whether opcode @p op may jump: its operand c (with x for the high bits) is a target.
constexpr bool op_jumps(std::uint8_t op) noexcept { return op_info(op).shape[2] == 't'; }

// OP_PLACE's operand c with this bit: a place of a port net (index into port_places_), found from the
// copy's instance.
inline constexpr std::size_t kPortPlace = 0x8000;

struct Ins {
  std::uint8_t op;
  std::uint8_t x;  // spare
  std::uint16_t a;
  std::uint16_t b;
  std::uint16_t c;
};
static_assert(sizeof(Ins) == 8);

}  // namespace vsd::soml
