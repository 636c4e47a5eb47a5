// Internal: a loaded program — its image (image.hpp: what the compiler made, never changed) and the
// run-time state of the VM, the net executor, the loader (attach, migrate) and the debugger. Not installed.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "dep_table.hpp"
#include "image.hpp"
#include "opcodes.hpp"
#include "vsd/core/config.hpp"
#include "vsd/core/meta_instance.hpp"
#include "vsd/core/signal.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/core/type_builder.hpp"
#include "vsd/core/value.hpp"
#include "vsd/core/watch.hpp"
#include "vsd/soml/checker.hpp"
#include "vsd/soml/native_abi.hpp"
#include "vsd/soml/net_classes.hpp"
#include "vsd/soml/runtime.hpp"

namespace vsd::soml {

// A register: statically typed code needs no tag. Ints, bools and enums use i, doubles d, references
// the instance id (0 is null). Strings live in a parallel array of std::string (same index).
union Val {
  std::int64_t i;
  double d;
  std::uint64_t id;
};

// A vector register (`vector<T>` values in code): parallel to the registers like the strings. Elements
// of int, bool and double vectors are Vals (the element kind is static, as for registers), elements of
// string vectors strings; the other array stays empty, so the size is v.size() + s.size().
struct VecReg {
  std::vector<Val> v;
  std::vector<std::string> s;
  [[nodiscard]] std::size_t size() const noexcept { return v.size() + s.size(); }
};

// The debugger's hooks (debugger.cpp). Null when none is attached: the VM then meets no OP_BREAK and
// the executor tests one pointer per firing.
class DebugHooks {
 public:
  virtual ~DebugHooks() = default;
  // An OP_BREAK at instruction @p at of the innermost frame (its pc is saved).
  virtual void on_break(const Function& f, std::size_t at) = 0;
  // Transition @p t of @p net is about to fire with mark @p mark.
  virtual void on_fire(const Transition& t, std::uint64_t mark) = 0;
  // The Program is being destroyed: restore the code and never touch the program again.
  virtual void on_program_gone() noexcept = 0;
};

struct NetInst {
  std::uint64_t owner = 0;
  const NetClass* cls = nullptr;
  std::vector<Place*> places;
  std::vector<Transition*> transitions;
  std::uint32_t first_ti = 0;  // index of its first transition in the executor's list
  bool dead = false;           // its owner, a place or a transition was deleted: it fires no more
};

// What the VM runs of a function (run-time state, one per function of the image): a copy of the image's
// code, which a debugger patches (OP_BREAK over line starts; the image's code is the original it restores
// from), and the debugger's trampoline. The VM reads code through Frame::run exactly as it read
// Function::code before the split: no extra indirection per instruction, one per call or return.
struct RunCode {
  const Function* fn;     // the image's function (the VM reaches it from here: no extra load per call)
  std::vector<Ins> code;  // sized once (frames point into it): only instructions are overwritten
  // Per instruction i: the image's code[i], then OP_RESUME to i + 1 (made when first patched; kept after,
  // as a frame may still run in it).
  std::vector<Ins> tramp;
  bool patched = false;  // code differs from the image's (a debugger patched it, not restored yet)
  // Its native code (a library loaded by Program::load_native), called instead of running `code` unless a
  // debugger is attached (native.cpp).
  native::Entry native = nullptr;
};

struct Frame {
  const Function* fn;
  RunCode* run;  // the code it runs (ProgramImpl::run_ of fn)
  const Ins* pc;
  std::uint32_t base;
  std::uint64_t self;
  std::uint64_t mark;
};

// The index of the instruction a frame last started (its call, or where it stopped), also when the
// frame runs in its function's debugger trampoline.
inline std::size_t pc_index(const Frame& f) noexcept {
  const RunCode& fn = *f.run;
  if (!fn.tramp.empty() && f.pc > fn.tramp.data() && f.pc <= fn.tramp.data() + fn.tramp.size())
    return static_cast<std::size_t>(f.pc - fn.tramp.data() - 1) / 2;
  return f.pc > fn.code.data() ? static_cast<std::size_t>(f.pc - fn.code.data()) - 1 : 0;
}

// Undefines the SOML++ run-time classes and enums of @p registry that no live program uses and no
// instance holds (left by programs that went while their states lived on), subclasses first.
void sweep_soml_leftovers(Registry& registry);

class ProgramImpl {
 public:
  ProgramImpl(SimState& state, RunOptions options);
  ~ProgramImpl();

  void load(std::string name, std::string text);
  // load() in two halves: check, define the run-time classes and enums, compile (define); then make the
  // database content (populate). A reload (migrate.cpp) defines, then migrates instead of populating.
  void define(std::string name, std::string text);
  void define_image(std::string name, std::string text);  // define()'s body: writes build()
  void populate();
  void connect_listeners();
  void make_source();  // the SourceFile node and its SourceComponents
  // The run-time classes this program defined (script classes, places and transitions with members of
  // their own), subclasses first.
  [[nodiscard]] std::vector<const MetaInstance*> runtime_classes() const;
  const ProgramImpl* previous_ = nullptr;      // the running version, while a reload defines this one
  std::vector<const MetaType*> reused_enums_;  // enums of previous_ this version kept
  // The classes and enums define() added to the Registry (not those an attach adopted), in definition
  // order: a refused load undefines them (undefine_own), so that loading the fixed script works.
  std::vector<const MetaInstance*> defined_classes_;
  std::vector<const MetaType*> defined_enums_;
  void undefine_own() noexcept;
  const MetaInstance& define_class(ClassBuilder& b);
  const MetaType& define_enum(EnumBuilder& b);
  // The run-time class (enum) of a declaration when loading: defined, or, when the Registry has one of
  // that name — the same script loaded in another Environment on the same Registry, or a class whose
  // instances outlive their program — shared if it has the same definition; another definition is an
  // error naming what differs.
  const MetaInstance& class_for(ClassBuilder& b, const std::string& name, const MetaInstance& base,
                                const ScopeDecl& decl);
  const MetaType& enum_for(EnumBuilder& b, const std::string& name, const EnumDecl& decl);
  // Every run-time class and enum this program uses (defined or shared), in definition order. A program
  // counts as a user of them once it is registered (register_program); when the last user goes, they go
  // too (Registry::undefine; a class whose instances outlive its programs stays until a load replaces
  // it). docs/soml.md 8.1.
  std::vector<const MetaInstance*> used_classes_;
  std::vector<const MetaType*> used_enums_;
  bool counted_ = false;  // register_program counted this program's uses
  // The state's Registry, kept apart: a program may outlive its state (an Environment destroys its states
  // before its modules, which own the programs), never the Registry.
  Registry& registry_;
  // Stops using them: each whose last user this was is undefined when @p undefine (a reload undefines the
  // running version's classes itself).
  void release_uses(bool undefine) noexcept;
  // Before a definition: undefines the SOML++ classes and enums no program uses and no instance holds.
  void sweep_leftovers();  // sweep_soml_leftovers(registry_)
  // Program::load and Program::attach: define and populate, all or nothing (a refused load leaves the
  // Registry and the SimState as they were).
  void load_or_undo(std::string name, std::string text);

  // ---- VM ----
  // Runs function @p f on @p self with arguments in args (count f.nparams); returns the result.
  Val exec(std::size_t entry);
  void vector_op(Ins in, const Frame& frame);  // OP_MOVV .. OP_PVGET (vm.cpp)
  void store_vector(const MetaProperty& p, SimStateInstance& o, const VecReg& v);
  // OP_MCALL (vm.cpp): a vector argument appended to @p args, a vector result into @p out.
  void method_vector_arg(const MetaMethod& m, std::size_t i, const VecReg& v, std::vector<Value>& args);
  void method_vector_result(const MetaMethod& m, const Value& r, VecReg& out);
  void value_op(Ins in, const Frame& frame);               // OP_XDEF .. OP_XVPUSH (vm.cpp)
  void struct_op(Ins in, const Frame& frame);              // OP_XOP (struct_ops.cpp)
  std::uint64_t new_instance(Ins in, const Frame& frame);  // OP_NEW
  std::uint64_t find_node(const std::string& path) const;  // OP_FIND
  // Vector arguments come from @p vargs (indexed like args), a vector result goes to @p vresult.
  // Value arguments (structs, ...) come from @p xargs, a Value result goes to @p xresult.
  Val run(int f, std::uint64_t self, std::uint64_t mark, const Val* args, const std::string* sargs,
          std::string* sresult = nullptr, const VecReg* vargs = nullptr, VecReg* vresult = nullptr,
          const Value* xargs = nullptr, Value* xresult = nullptr);
  // run()'s VM part (run() calls native code itself), with @p f = the function of index @p fi.
  Val run_vm(const Function& f, int fi, std::uint64_t self, std::uint64_t mark, const Val* args,
             const std::string* sargs, std::string* sresult, const VecReg* vargs, VecReg* vresult,
             const Value* xargs, Value* xresult);
  Value call_from_cpp(int f, SimStateInstance& self, std::span<const Value> args);
  // The body of the MetaMethod of function @p f of @p weak: runs it in the program that runs the state
  // of @p self (the method's own program, or another attached to a replica or a loaded copy that uses
  // the same classes; found by the function's name).
  static Value dispatch(const std::weak_ptr<ProgramImpl>& weak, int f, const std::string& fname,
                        SimStateInstance& self, std::span<const Value> args);
  // Programs by the state they run (dispatch): registered once loaded or attached, gone with them.
  void register_program();
  SimStateInstance& instantiate(const ClassInfo& ci, Node* parent, std::string name, const Val* args,
                                const std::string* sargs, int nargs, const VecReg* vargs = nullptr,
                                const Value* xargs = nullptr);
  [[noreturn]] void fail(const std::string& what);
  // Properties (vm.cpp), shared by the VM's OP_GETP/OP_SETP/OP_SELF and native code's callbacks: the same
  // errors, the same path of a store (the state's transaction, signals, re-tests).
  [[noreturn, gnu::cold, gnu::noinline]] void no_instance(std::uint64_t id);  // null or deleted
  [[noreturn, gnu::cold, gnu::noinline]] void no_property(const SimStateInstance& o, const MetaProperty& p);
  void check_settable(const SimStateInstance& o, const MetaProperty& p);  // its class's, not read-only
  std::uint64_t enclosing(std::uint64_t id, int parents);                  // OP_SELF @p parents levels up
  // Stores @p v into a property of a scalar kind (scalar_property); false for the other kinds.
  bool store_scalar(const PropSlot& ps, SimStateInstance& o, Val v);
  // OP_GETP and OP_SETP of a scalar property props[@p prop] of instance @p id, whole (native code).
  Val read_scalar(std::uint64_t id, std::size_t prop);
  void write_scalar(std::uint64_t id, std::size_t prop, Val v);
  // "integer overflow: a op b does not fit an int (64 bits)", and "what(a)" for unary operations.
  [[noreturn, gnu::cold, gnu::noinline]] void int_overflow(std::int64_t a, const char* op, std::int64_t b);
  [[noreturn, gnu::cold, gnu::noinline]] void int_overflow(const char* what, std::int64_t a);
  // "instruction budget exhausted (...): an endless loop?" (a backward jump found the budget spent).
  [[noreturn, gnu::cold, gnu::noinline]] void loop_budget_exhausted();

  // ---- executor ----
  std::uint64_t step(std::uint64_t n);  // step_loop, then sync_state (also on an error)
  std::uint64_t step_loop(std::uint64_t n);
  bool refresh();  // re-tests dirty transitions; true when some is enabled
  void put_token(Place& p, SimStateInstance* obj, std::int64_t n);
  // "place 'p' would hold more than 2^63-1 tokens": a token count never wraps.
  // (produced by @p arrow, when given: its position ends the message)
  [[noreturn, gnu::cold]] void too_many_tokens(const Place& p, std::int64_t n,
                                               const ArrowDecl* arrow = nullptr);
  // For a firing without a savepoint: throws (before anything changed) when producing would take a place
  // past 2^63-1 tokens, naming the arrow.
  void check_token_room(NetInst& net, const TransitionInfo& t);

  std::weak_ptr<ProgramImpl> weak_self_;
  std::function<void()> on_dirty_;  // called when a transition needs a test (the Module triggers its task)
  SimStateInstance& create_node(const ClassInfo& ci, Node* parent, const std::string& name);
  void setup(const ClassInfo& ci, SimStateInstance& inst, const Val* args, const std::string* sargs,
             int nargs, const VecReg* vargs = nullptr, const Value* xargs = nullptr);
  void build_net(const ClassInfo& ci, SimStateInstance& inst);
  // Hands a net (built or found) to the executor: its transitions are listed and marked for a test.
  void register_net(std::unique_ptr<NetInst> net, const ClassInfo& ci, SimStateInstance& inst);

  // ---- attaching to content already in the state (attach.cpp) ----
  bool attaching_ = false;
  Executor* exec_ = nullptr;  // the executor's database state (a child of the script object)
  // A class the state has already (a file defined it): checked against the script's, then used.
  const MetaInstance& adopt_class(ClassBuilder& b, const std::string& name, const MetaInstance& base,
                                  const ScopeDecl& decl);
  const MetaType& adopt_enum(EnumBuilder& b, const std::string& name, const EnumDecl& decl);
  std::vector<std::pair<std::string, const MetaType*>> adopted_props_;  // the class being adopted's
  struct AdoptedMethod {
    std::string name;
    std::vector<const MetaType*> args;
    const MetaType* result = nullptr;
  };
  std::vector<AdoptedMethod> adopted_methods_;  // the class being adopted's
  // Classes of the state that get the script's functions as MetaMethods once the attach succeeded (a
  // class a file defined has properties only).
  std::vector<std::pair<const MetaInstance*, ClassBuilder>> pending_methods_;
  void bind_pending_methods();
  void attach_content();
  // The places and transitions of @p owner's net, found among its children as build_net made them.
  // @throws vsd::Error naming what does not match.
  std::unique_ptr<NetInst> find_net(const ClassInfo& ci, SimStateInstance& owner);
  // Writes rng_, firings_, enabled_ and dirty_ into exec_ (where they differ).
  void sync_state();
  // Invocation (invocation.cpp): the first half of an invoking transition's firing (a new net instance
  // under the transition, its parameters, its start token) and the second, when the instance finished.
  SimStateInstance& start_invocation(const TransitionInfo& t, Transition& tn, std::uint64_t mark);
  bool finished(const NetInst& net) const;
  // The invoking transition of a finished instance runs its action with the result (may throw; then
  // nothing changed but `finished` is reset); returns the invoking transition's index in its net.
  std::pair<NetInst*, int> complete_action(const NetInst& inner);
  void complete_outputs(NetInst& outer, int t, std::uint64_t instance);

  // ---- data ----
  SimState& state_;
  RunOptions opt_;
  // The program image (image.hpp): made by define(), never changed afterwards. define() writes it
  // through build(), which is valid only while define() runs; everything else reads image().
  std::shared_ptr<const ProgramImage> image_ = std::make_shared<const ProgramImage>();
  ProgramImage* build_ = nullptr;
  [[nodiscard]] const ProgramImage& image() const noexcept { return *image_; }
  ProgramImage& build() noexcept {
    VSD_ASSERT(build_ != nullptr, "the program image is written only while define() runs");
    return *build_;
  }
  // Run-time copies of what the VM reads of the image and a run changes (made by define(), linked by
  // link_objects()): the constants (OP_OBJ slots get the ids of the static objects), the ids of the
  // outer plans' fixed instances, and each function's code (RunCode: the debugger patches it).
  std::vector<std::int64_t> consts_;
  std::vector<std::uint64_t> outer_ids_;
  std::vector<RunCode> run_;
  void prepare_run();
  // Once the static objects exist (object_ids_): their ids into consts_ and outer_ids_.
  void link_objects();

  Node* root_ = nullptr;
  SourceFile* source_node_ = nullptr;
  // The node of place port_places[k] in the copy of its port net whose instance is @p copy; 0: none.
  std::uint64_t port_place_id(std::uint64_t copy, std::size_t k) const;
  std::unordered_map<const ClassDecl*, std::uint64_t> object_ids_;  // top-level objects
  // The Registry's classes and enums of the image's declarations, by declaration and by class (the
  // loader's, not the compiler's: emptied when they are undefined — a refused load, a reload — so that
  // no lookup matches a class at a recycled address).
  std::unordered_map<const EnumDecl*, const MetaType*> enums_;
  std::unordered_map<const Decl*, const MetaInstance*> scope_meta_;  // place/transition classes too
  std::unordered_map<const MetaInstance*, const ClassInfo*> by_meta_;
  std::unordered_map<const Decl*, SourceComponent*> components_;

  // VM state
  std::vector<Val> regs_;
  std::vector<std::string> sregs_;
  std::vector<VecReg> vregs_;
  std::vector<Value> xregs_;  // X registers, parallel like the strings
  std::vector<Frame> frames_;
  std::uint32_t top_ = 0;  // first free register of the outermost frame stack
  std::uint64_t budget_ = 0;
  // The memory budget left to the call from outside under way (RunOptions::memory_budget): every
  // instruction that makes memory grow takes its bytes from it first (charge), and a store, list append or
  // creation also the record of the change when the state records (every guarded firing does).
  std::uint64_t mem_left_ = 0;
  static constexpr std::size_t kRecordBytes = 32;     // a recorded change, besides its values
  static constexpr std::size_t kInstanceBytes = 256;  // an instance's id, index and record, besides its size
  void charge(std::size_t bytes) {
    if (bytes > mem_left_) memory_exhausted(bytes);
    mem_left_ -= bytes;
  }
  // What grew from @p before to @p after bytes.
  void grew(std::size_t before, std::size_t after) {
    if (after > before) charge(after - before);
  }
  // A change recorded (when the state records) with values of @p value_bytes.
  void charge_record(std::size_t value_bytes) {
    if (state_.recording()) charge(kRecordBytes + 2 * value_bytes);
  }
  [[noreturn, gnu::cold, gnu::noinline]] void memory_exhausted(std::size_t bytes);
  int entry_depth_ = 0;
  // ---- native code (native.cpp) ----
  // Routes the functions of the library at @p path generated from this image to native code; returns
  // how many. @throws vsd::Error when it cannot be loaded or holds no module of this image.
  std::size_t load_native(const std::string& path);
  // Calls native @p e with @p depth frames active (its own counted): the budget goes in and comes back,
  // an error gets the native frames of its call stack (the caller adds the VM's).
  Val call_native(native::Entry e, std::uint64_t self, std::uint64_t mark, const Val* args, std::size_t depth);
  int native_depth_ = 0;  // native calls under way (a listener's call into the VM is then no outer call)
  native::Context nctx_{};
  std::vector<std::pair<std::uint32_t, std::uint32_t>> native_sites_;  // (function, instruction) of an error
  std::shared_ptr<void> native_lib_;                                   // the dlopen handle
  std::size_t native_count_ = 0;
  // "\n  at NAME (FILE:LINE:COL)": one frame of a reported call stack, at instruction @p at of @p f.
  std::string frame_text(const Function& f, std::size_t at) const;
  std::vector<std::pair<std::uint64_t, const MetaProperty*>>* deps_ = nullptr;
  std::string stack_text(std::size_t from) const;

  // executor state
  std::unordered_map<std::uint64_t, std::unique_ptr<NetInst>> nets_;  // owner id -> net
  std::vector<NetInst*> net_order_;
  std::vector<std::unique_ptr<NetInst>> dead_nets_;  // replaced by a revived one, kept for tis_
  std::size_t dead_tis_ = 0;                         // entries of tis_ that belong to dead nets
  // Drops the dead nets and their entries of tis_ once they are the majority, renumbering what refers to
  // an entry (a long run that creates and deletes objects with nets would grow without bound otherwise).
  // Only between firings: nothing may hold a TI index or a NetInst pointer across it.
  void compact_nets();
  struct TI {
    std::vector<DepKey> deps;  // what its last test read (sorted): where it is listed in deps_map_
    NetInst* net;
    int t;
    bool dirty = true;
    bool enabled = false;
    std::uint64_t mark = 0;
    std::int32_t enabled_pos = -1;
    // No condition, no arrow condition, no communication arrow: its test only compares the counts of
    // its input places, and reads no property (test() takes a short way; register_net sets it).
    bool counts_only = false;
  };
  std::vector<TI> tis_;
  std::vector<std::uint32_t> dirty_;
  std::vector<std::uint32_t> enabled_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> place_watch_;  // place id -> TIs
  DepTable deps_map_;
  bool whole_instance_deps_ = false;  // some test called a C++ method: deps_map_ has (id, null) keys
  std::vector<std::pair<std::uint64_t, const MetaProperty*>> dep_scratch_;
  // What the executor hears (connect_listeners): markings of places, deletions of nodes, and the class
  // properties that some test read (cover). Per class, so instances of classes no condition reads keep
  // their one-branch setters while a program is loaded.
  std::optional<Watch> watch_;
  const MetaProperty* tokens_property_ = &Place::vsd_prop_tokens();    // looked up once: on_change compares
  const MetaProperty* objects_property_ = &Place::vsd_prop_objects();  // every change it hears with them
  // What the Watch covers already, by class index: bit i of a class's row = its property of index i (a
  // test's reads change with every token, so this is asked often and answered without hashing).
  std::vector<std::vector<std::uint64_t>> covered_properties_;
  std::unordered_set<const MetaInstance*> covered_classes_;  // all properties watched (C++ methods)
  void cover(std::uint64_t id, const MetaProperty* prop) {
    // A test's reads change with every token, so this is asked often: a property covered already is
    // answered here, without the call.
    if (prop != nullptr && watch_) {
      const std::size_t cls = prop->owner().index();
      const std::size_t i = prop->index();
      if (cls < covered_properties_.size() && i / 64 < covered_properties_[cls].size() &&
          (covered_properties_[cls][i / 64] & (std::uint64_t{1} << (i % 64))) != 0)
        return;
    }
    cover_new(id, prop);
  }
  void cover_new(std::uint64_t id, const MetaProperty* prop);  // cover()'s body (program.cpp)
  static void heard(void* self, SimStateInstance& inst, const MetaProperty* p, Changes what);
  void stop_listening() noexcept { watch_.reset(); }
  std::unordered_map<std::uint64_t, NetInst*> node_net_;  // owner, place and transition ids -> net
  void on_deleted(SimStateInstance& inst);
  std::uint64_t rng_ = 1;
  std::uint64_t firings_ = 0;
  std::uint64_t tests_ = 0;
  std::vector<std::string> condition_errors_;
  std::function<void(const Firing&)> trace_;
  DebugHooks* debug_ = nullptr;

  void mark_dirty(std::uint32_t ti) {
    if (!tis_[ti].dirty && !tis_[ti].net->dead) {
      tis_[ti].dirty = true;
      if (dirty_.empty() && on_dirty_) on_dirty_();
      dirty_.push_back(ti);
    }
  }
  void on_change(SimStateInstance& inst, const MetaProperty& p);
  NetInst* net_of(std::uint64_t owner) const {
    auto it = nets_.find(owner);
    return it == nets_.end() || it->second->dead ? nullptr : it->second.get();
  }
  bool test(TI& ti);
  // The remote place of a communication arrow (null when the path meets a null reference); records what
  // it read as dependencies while a test runs.
  Place* remote_place(const ArrowInfo& a, const NetInst& net);
  // `this` of an arrow's condition and the start of a communication arrow's path (ArrowInfo::holder).
  static std::uint64_t arrow_self(const NetInst& net, const ArrowInfo& a) {
    return a.holder < 0 ? net.owner : net.transitions[static_cast<std::size_t>(a.holder)]->id();
  }
  void fire(std::uint32_t ti);
  bool fire_chosen(const Transition& node);  // Program::fire
  void fire_body(std::uint32_t ti);          // fire() without the savepoint
  // Undoes a failed firing: the SimState back to @p sp, nets killed since killed_[killed] revived.
  void roll_back(const SimState::Savepoint& sp, std::size_t killed, const std::string& why);
  // A net whose nodes a rolled-back firing deleted and re-created: registered again from its nodes.
  void revive(NetInst* dead);
  std::vector<NetInst*> killed_;  // nets that died in the guarded firing under way (roll_back revives them)
  bool guarding_ = false;         // a guarded firing is under way
  std::vector<Firing> pending_;   // the trace of the firing under way, reported once it succeeded
  Id finished_instance_ = 0;      // an invocation the firing under way finished: deleted after the trace
  // Produces the output tokens of a firing; returns the place the mark went to (null: it left the net).
  /// Produces the outputs of @p t; appends the black tokens given to @p given when it is not null.
  Place* produce(NetInst& net, const TransitionInfo& t, std::uint64_t mark,
                 std::vector<TokenMove>* given = nullptr);
  void set_enabled(std::uint32_t ti, bool on);
};

// Program::reload (migrate.cpp): moves the state from the running version @p old to @p nw (made, not
// loaded), all or nothing.
MigrationReport migrate(ProgramImpl& old, ProgramImpl& nw, std::string name, std::string text);

/// Whether property slot @p ps holds a scalar (int, bool, enum, double, float, reference): what native
/// code reads and writes (vm.cpp).
bool scalar_property(const PropSlot& ps) noexcept;

// Loader helpers shared by the compiler.
RK reg_kind(const Type& t) noexcept;
// The MetaType that stores a value of static type @p t (script enums and vectors of them: the run-time
// enum of this load and its vector); null for types without one.
const MetaType* storage_type(ProgramImpl& p, Registry& reg, const Type& t);
int compile_function(ProgramImpl& p, int index, const FunctionDecl& fd);
int new_function(ProgramImpl& p, std::string name);
int compile_condition(ProgramImpl& p, const TransitionDecl& t, const std::string& name);
int compile_action(ProgramImpl& p, const TransitionDecl& t, const std::string& name);
int compile_arrow_condition(ProgramImpl& p, const ArrowDecl& a, const std::string& name);
int compile_init(ProgramImpl& p, const ScopeDecl& s, const std::string& name);
int compile_object_ctor(ProgramImpl& p, const ClassDecl& obj, int ctor, const FunctionDecl& fd);
int compile_invoke_args(ProgramImpl& p, const TransitionDecl& t, const std::string& name);
[[noreturn]] void not_supported(const ProgramImpl& p, SourceLoc loc, const std::string& what);
std::string where(const ProgramImpl& p, SourceLoc loc);

/// SOML++'s text of a double (vm.cpp): what `string(x)` and `print` show, and the debugger too.
std::string fmt_double(double d);

// Vectors in code (vm.cpp). The element types a vector register holds: bool, the integers, float and
// double (as Vals) and string; the C++ std::vector<T> of the registry is the storage.
/// The register kind of the elements of vector MetaType @p vt (I, D or S); None when the VM cannot
/// hold them (structs, enums).
RK vector_elem_kind(const MetaType& vt) noexcept;
/// Copies the std::vector<T> at @p addr (of MetaType @p vt) into @p out.
void vector_load(const MetaType& vt, const void* addr, VecReg& out);
/// The size of the std::vector<T> at @p addr.
std::size_t vector_size(const MetaType& vt, const void* addr);
/// Element @p i (in range) of the std::vector<T> at @p addr into @p v or @p s.
void vector_at(const MetaType& vt, const void* addr, std::size_t i, Val& v, std::string& s);
/// A Value of MetaType @p vt holding the elements of @p r. @throws vsd::Error (without the SOML++ prefix)
/// when an element does not fit the element type, naming @p what ("property 'joints'").
Value vector_value(const MetaType& vt, const VecReg& r, const std::string& what);
/// The text of a vector register ("[1, 2]", strings quoted), for the debugger.
std::string vector_text(const MetaType& vt, const VecReg& r);
/// The text print and string() show of an X register's Value (struct_ops.cpp): a struct as it is built,
/// `Vector3d(1, 2.5, 0)`, `Isometry3d(Vector3d(1, 2, 3), Quaterniond(1, 0, 0, 0))`, vectors of structs as
/// lists of those; anything else in its vsd-text form.
std::string value_text(const Value& v);

}  // namespace vsd::soml
