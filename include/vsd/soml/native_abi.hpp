/// @file
/// @brief The interface between the SOML++ runtime and the C++ that `vsd-soml compile` generates from a
/// script (docs/soml.md, "Native compilation"). Generated code includes only this header (it compiles in
/// a fraction of a second per thousand lines); nothing else of vsd is needed to build a native module.
/// The layout is versioned by kNativeAbi: a module of another version is refused when loaded.
#pragma once

#include <cstdint>

namespace vsd::soml::native {

/// The ABI version a module was generated for (Program::load_native refuses any other).
inline constexpr std::uint32_t kNativeAbi = 2;

/// A register as the VM holds it: ints, bools and enums in i, doubles in d, references as ids.
union Reg {
  std::int64_t i;
  double d;
  std::uint64_t id;
};

/// What a failing instruction reports (the runtime words the message exactly as the VM does).
enum class Fault : std::uint32_t {
  Add,  ///< a + b does not fit an int
  Sub,  ///< a - b does not fit an int
  Mul,  ///< a * b does not fit an int
  Div,  ///< a / b does not fit an int
  Neg,  ///< -a does not fit an int
  Abs,  ///< abs(a) does not fit an int
  DivisionByZero,
  NullReference,  ///< a call on a null instance
  DoubleToInt,    ///< the double whose bits are a does not fit an int
  LoopBudget,     ///< a backward jump found the instruction budget spent
  CallBudget,     ///< a call found the instruction budget spent
  Depth,          ///< the call depth limit reached calling function b
  Fail,           ///< OP_FAIL: run-time error strings[b]
};

/// The runtime's side: the budget and depth limit the VM keeps, the run-time tables native code reads,
/// and the calls back for what native code does not do itself (errors, print, properties). Filled by the
/// runtime before every entry into native code.
struct Context {
  std::uint64_t budget;     ///< jumps and calls left (the VM's count: backward jumps and calls)
  std::uint32_t max_depth;  ///< RunOptions::max_depth: frames (VM and native) at most
  std::uint32_t pad;
  void* runtime;  ///< the ProgramImpl
  /// Throws the run-time error of @p fault at instruction @p at of function @p fn (never returns).
  void (*fail)(Context* ctx, Fault fault, std::uint32_t fn, std::uint32_t at, std::int64_t a, std::int64_t b);
  /// An exception passes the call at instruction @p at of function @p fn: the runtime adds the frame to
  /// the call stack it reports.
  void (*unwind)(Context* ctx, std::uint32_t fn, std::uint32_t at);
  /// OP_PRINT number @p index of the image (its print_kinds) over @p regs.
  void (*print)(Context* ctx, std::uint32_t index, const Reg* regs);
  /// The program's constants as linked (OP_OBJ: the ids of the static objects) and the ids of the outer
  /// plans' fixed instances (OP_SELF of a static object).
  const std::int64_t* consts;
  const std::uint64_t* outer_ids;
  /// OP_GETP: property props[@p prop] of instance @p id, as the VM reads it (a null or deleted instance,
  /// a property of another class fail at instruction @p at of function @p fn; a condition's read is
  /// recorded as its dependency).
  Reg (*getp)(Context* ctx, std::uint32_t fn, std::uint32_t at, std::uint64_t id, std::uint32_t prop);
  /// OP_SETP: property props[@p prop] of instance @p id = @p v, through the VM's path (recorded in the
  /// state's transaction, signalled, re-testing the conditions that read it). The budget goes through
  /// ctx->budget (listeners of the change may run SOML++ code).
  void (*setp)(Context* ctx, std::uint32_t fn, std::uint32_t at, std::uint64_t id, std::uint32_t prop, Reg v);
  /// OP_SELF of an instance @p parents levels up from @p id (the enclosing instance gone: an error).
  std::uint64_t (*outer)(Context* ctx, std::uint32_t fn, std::uint32_t at, std::uint64_t id,
                         std::uint32_t parents);
};

/// A function of the module as the runtime calls it: arguments in @p args (as the VM's registers), the
/// result (0 for none) returned; @p depth frames are active (the new one counted); @p mark is the object
/// token of the firing under way (OP_MARK; 0 outside a firing).
using Entry = Reg (*)(Context* ctx, std::uint32_t depth, std::uint64_t self, std::uint64_t mark,
                      const Reg* args);

/// One compiled function: its index in the program image and its entry.
struct FunctionEntry {
  std::uint32_t index;
  Entry entry;
};

/// The functions of one script (a native library holds one or more).
struct Module {
  std::uint32_t abi;         ///< kNativeAbi of the generator
  std::uint32_t count;       ///< functions
  std::uint64_t image_hash;  ///< the hash of the image it was generated from (Program::image_hash)
  const FunctionEntry* functions;
  const char* script;  ///< the script's name when it was compiled (for messages)
};

/// What a native library exports: an extern "C" function of this name, of type Modules, that returns
/// its modules (Program::load_native picks the one generated from the program's image).
inline constexpr const char* kModulesSymbol = "vsd_soml_native_modules";
using Modules = const Module* const* (*)(std::uint32_t* count);

/// What fail() calls, with the function and the instruction in one argument (@p site: fn << 32 | at): six
/// arguments, all in registers (a seventh would go on the stack, and the pushes on the failing paths made
/// GCC keep a frame pointer in the functions that call it).
[[noreturn, gnu::cold, gnu::noinline]] inline void fail_site(Context* c, std::uint64_t budget, Fault f,
                                                             std::uint64_t site, std::int64_t a,
                                                             std::int64_t b) {
  c->budget = budget;
  c->fail(c, f, static_cast<std::uint32_t>(site >> 32), static_cast<std::uint32_t>(site), a, b);
  __builtin_unreachable();
}

/// Generated code fails through this: @p budget (what is left, kept in a local) goes back to the Context
/// first, then the runtime throws.
[[noreturn, gnu::always_inline]] inline void fail(Context* c, std::uint64_t budget, Fault f, std::uint32_t fn,
                                                  std::uint32_t at, std::int64_t a = 0, std::int64_t b = 0) {
  fail_site(c, budget, f, (std::uint64_t{fn} << 32) | at, a, b);
}

}  // namespace vsd::soml::native
