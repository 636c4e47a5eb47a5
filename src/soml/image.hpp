// Internal: the SOML++ program image — what the compiler makes of a script (functions' bytecode,
// constants, operand tables, class layouts, net structure), immutable once made. Not installed.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "opcodes.hpp"
#include "vsd/core/meta_instance.hpp"
#include "vsd/soml/checker.hpp"

namespace vsd::soml {

// Register kinds of a static type (V: a vector, its elements of kind vector_elem_kind(); X: any other
// value as a vsd::Value in the fourth parallel array: structs, and vectors of structs and enums).
enum class RK : std::uint8_t { I, D, S, R, V, X, None };

struct Function {
  std::string name;                  // "Demo.time_to", "cell.go (condition)"
  std::vector<Ins> code;             // as compiled; the VM runs a copy (RunCode) that a debugger may patch
  std::vector<std::uint32_t> lines;  // per instruction: its line as the debugger steps through them
  // Per instruction: the line and column of the expression or statement it computes (its operator, its
  // call's '(', its statement), which run-time errors name (file:line:col).
  struct Pos {
    std::uint32_t line = 0, column = 0;
  };
  std::vector<Pos> positions;
  std::vector<std::uint32_t> targets;  // jump targets by jump id
  int nparams = 0;
  int nregs = 0;
  const ScopeDecl* scope = nullptr;  // the innermost instance scope (self)
  std::vector<RK> param_kinds;
  std::vector<const MetaInstance*> param_classes;  // reference parameters: the class they need
  RK result = RK::None;
  Type result_type;
  bool compiled = false;
  // For the debugger: parameters and locals by name, each visible in code [from, to).
  struct Local {
    std::string name;
    int slot = 0;
    Type type;
    std::uint32_t from = 0, to = 0;
  };
  std::vector<Local> locals;
};

// How to reach the instance `outer` levels out of a function's scope: a fixed object, or parents.
struct OuterPlan {
  const ClassDecl* static_decl = nullptr;  // a fixed instance (its id: ProgramImpl::outer_ids_, once linked)
  int parents = 0;
};

enum class PK : std::uint8_t { I64, Bool, Double, String, Int, Enum, Ref, List, Vector, Value, Other };

struct PropSlot {
  const MetaProperty* prop = nullptr;
  PK kind = PK::Other;
};

// One step of a communication arrow's path: a fixed object, or a reference property of the instance
// reached so far.
struct PathStep {
  const ClassDecl* object = nullptr;  // a static object (its id once created)
  const MetaProperty* prop = nullptr;
};

struct ArrowInfo {
  const ArrowDecl* decl = nullptr;
  int place = -1;              // index into the net's places (-1 for a communication arrow)
  bool remote = false;         // communication arrow: the place is found through `path`
  std::vector<PathStep> path;  // from the owner of the transition to the remote instance
  const PlaceDecl* remote_place = nullptr;
  std::int64_t weight = 1;
  bool inhibitor = false;
  bool object = false;  // the place holds object tokens
  int cond = -1;        // function index of the arrow condition
  // An arrow of a substituted sub-net: the substitution transition (index in the net) whose node is the
  // port net's instance, `this` of its condition and the start of its path; -1: the net's owner.
  int holder = -1;
};

struct TransitionInfo {
  const TransitionDecl* decl = nullptr;
  int index = 0;  // in the net class
  std::vector<ArrowInfo> in, out;
  int mark_in = -1;  // index into in of the object input arrow
  int cond = -1, action = -1;
  // Substitution (4.11): a substitution transition is inert (it never fires; its sub-net's places and
  // transitions are its children); `holder` is the transition whose sub-net this one belongs to.
  bool inert = false;
  int holder = -1;
  // A substitution transition: its port net's places (ports too) -> index in the net (OP_PLACE).
  std::unordered_map<const Decl*, int> sub_places;
  // Invocation: the net it invokes and the function that sets the new instance's value parameters.
  const struct ClassInfo* invoke = nullptr;
  int invoke_args = -1;
  // It runs SOML++ code when it fires (action, invocation, output arrow conditions): it fires under a
  // savepoint, so that an error undoes it whole.
  bool guarded = false;
  // The black tokens its output arrows give, summed (at most 2^63-1): a firing without a savepoint first
  // checks that no place would pass 2^63-1 tokens only when some output place holds more than
  // 2^63-1 - out_weight.
  std::int64_t out_weight = 0;
};

// The net of a class-like declaration (its own places and transitions, bases' first).
struct NetClass {
  std::vector<const PlaceDecl*> places;
  std::vector<TransitionInfo> transitions;
  std::vector<int> place_holder;  // per place: the substitution transition holding it, -1: the owner
  bool invocable = false;         // the net of an invocable net (its instances can `finish`)
};

struct ClassInfo {
  const ClassDecl* decl = nullptr;
  const MetaInstance* meta = nullptr;
  const ClassInfo* base = nullptr;  // script base
  int init = -1;                    // property initialisers
  int ctor = -1;
  int object_ctor = -1;           // object derived with arguments: the constructor call
  std::unique_ptr<NetClass> net;  // null when it has no places or transitions (own or inherited)
  std::unordered_map<const FunctionDecl*, int> vtable;  // root function -> implementation
  int result_slot = -1;  // invocable net with a result: props_ slot of its `result` property
  int start_place = -1;  // invocable net: index of its start place
};

// What the compiler made of a script: the program image. Built once by ProgramImpl::define() (which also
// defines the run-time classes and enums in the Registry, which the image refers to), then never changed:
// the VM, the net executor, the loader (attach, migrate), the debugger and the disassembler read it.
// Everything a run changes lives in ProgramImpl (registers, frames, the executor's tables) — including
// the two things that look like code but are run-time: the constants holding the ids of static objects
// (linked once the objects exist, ProgramImpl::consts_) and the code the VM runs, a copy of each
// Function::code that a debugger patches (ProgramImpl::run_, RunCode). Drake's System/Context and
// Pinocchio's Model/Data are the same split.
//
// It points into the checked script (checked: declarations, types) and into the Registry (MetaInstance,
// MetaProperty, MetaMethod, MetaType): it lives as long as the program that made it.
struct ProgramImage {
  std::unique_ptr<CheckResult> checked;  // the script, checked: the declarations the tables point to
  std::string stem;                      // the script's class name ("soml::<stem>")

  // Operand tables of the bytecode (opcodes.hpp says which operand indexes which).
  std::vector<std::unique_ptr<Function>> functions;
  std::vector<std::int64_t> consts;  // OP_LOADK; OP_OBJ slots hold 0 here (linked at run time)
  std::vector<std::string> strings;
  std::vector<PropSlot> props;
  std::vector<const MetaMethod*> methods;
  std::vector<const ClassInfo*> classes;         // by NEW/ISA operand (script classes)
  std::vector<const MetaInstance*> class_metas;  // by NEW/ISA operand
  std::vector<const MetaType*> enum_types;       // TOSTR of enums
  std::vector<const MetaType*> range_types;
  std::vector<const MetaType*> xtypes;  // OP_XDEF, OP_XGETF, OP_XSETF operands (value types)
  std::vector<std::vector<RK>> print_kinds;
  std::vector<std::vector<const MetaType*>> print_types;  // per print: the vector types of V arguments
  std::vector<OuterPlan> outer_plans;
  std::vector<const FunctionDecl*> vslots;                // virtual slot -> root function
  std::unordered_map<const FunctionDecl*, int> vslot_of;  // overridden functions -> virtual slot
  std::vector<int> vslot_default;                         // virtual slot -> function of the root declaration
  std::vector<std::vector<RK>> method_kinds;              // MCALL argument kinds
  std::vector<RK> method_results;
  std::vector<std::pair<int, const ClassDecl*>> object_refs;  // consts slot -> object
  std::vector<const PlaceDecl*> port_places;                  // places of port nets named in code

  // Classes, their nets and the linkage of declarations.
  std::unordered_map<const Decl*, int> scope_init;  // place/transition property initialisers
  std::unordered_map<const ClassDecl*, std::unique_ptr<ClassInfo>> class_info;
  std::vector<const ClassDecl*> class_order;               // bases first
  std::unordered_map<const PropertyDecl*, int> prop_slot;  // decl -> props index
  std::unordered_map<const MetaProperty*, int> meta_prop_slot;
  std::unordered_map<const FunctionDecl*, int> function_index;
};

/// The bytecode of @p img as text (disasm.cpp; `vsd-soml disasm`): per function its name, file:line,
/// parameters, registers, locals and instructions (index, opcode name, operands, line:column), then the
/// constants and strings.
std::string disassemble(const ProgramImage& img);

}  // namespace vsd::soml
