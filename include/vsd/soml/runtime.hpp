/** @file
 *  @brief Loading a SOML++ script into a SimState and running it: `Program`.
 *
 *  @code
 *  vsd::Environment env;
 *  auto& soml = env.use<vsd::soml::Module>();
 *  vsd::soml::Program& p = soml.load(env.main_state(), "cell.soml", text);   // throws vsd::Error
 *  p.object("cell")->call("reset", {});                                        // MetaMethods
 *  p.run_until_quiet();                                                        // fire transitions
 *  @endcode
 *
 *  Loading checks the script, makes a `SourceFile` with one `SourceComponent` per declaration, defines
 *  a run-time class for every class, object and the script object ("soml::Demo"; properties become
 *  MetaProperties, functions MetaMethods), makes the script enums run-time enums, compiles every
 *  function, condition and action to bytecode, and creates the script object, its objects, their
 *  places, transitions and arrows as database nodes under the SimState's Database.
 *
 *  Execution: `step()` fires one enabled transition (a seeded, deterministic choice among the enabled
 *  ones); `run_until_quiet()` fires until none is enabled. Transitions are re-tested only when
 *  something they read changed (a marking, or a property their condition read last time).
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/core/fwd.hpp"
#include "vsd/soml/net_classes.hpp"

namespace vsd::soml {

/// @brief Limits and settings of a loaded program.
struct RunOptions {
  std::uint64_t instruction_budget = 50'000'000;  ///< per call from outside (a call, a test, a firing)
  /// @brief Bytes of memory the code may take per call from outside (docs/soml.md 8.2): string, vector
  /// and value registers that grow, values stored in properties, instances created, references appended,
  /// and the records of changes under a savepoint.
  std::uint64_t memory_budget = std::uint64_t{256} << 20;
  int max_depth = 256;                            ///< nested SOML++ calls
  std::uint64_t seed = 1;                         ///< the choice among enabled transitions
  std::ostream* out = nullptr;                    ///< where print() writes (std::cout when null)
};

/// @brief Black tokens that one firing took from or put into one place.
struct TokenMove {
  const Place* place = nullptr;  ///< the place (a remote one for a communication arrow)
  std::int64_t count = 0;        ///< how many tokens
};

/// @brief What a firing did besides moving tokens (net invocation, docs/soml.md 4.11).
enum class FiringKind : std::uint8_t {
  Plain,     ///< an ordinary firing
  Invoke,    ///< an invoking transition's first half: it consumed its inputs and started a net instance
  Finish,    ///< a transition of an invoked net ran `finish`: the instance ends
  Complete,  ///< an invoking transition's second half, right after the Finish (same step): its action
             ///< ran with the result and it produced its outputs; `from` is null
};

/// @brief One firing, as the trace reports it: which token moved from where to where, through which
/// transition, at which step.
struct Firing {
  std::uint64_t step = 0;                  ///< number of the firing (1 for the first)
  const Transition* transition = nullptr;  ///< what fired
  vsd::Id mark = 0;                        ///< the token it moved (0: none)
  const Place* from = nullptr;             ///< where the mark came from (object input place)
  const Place* to = nullptr;               ///< where the mark went (null: it left the net, or waits)
  FiringKind kind = FiringKind::Plain;     ///< see FiringKind
  vsd::Id invocation = 0;                  ///< the net instance started, finished or completed (0: Plain)
  std::vector<TokenMove> taken;            ///< black tokens consumed, in arrow order
  std::vector<TokenMove> given;            ///< black tokens produced, in arrow order
};

/// @brief What Program::reload did (shaped like vsd::io::LoadReport: what changed, and the warnings of
/// schema evolution: values dropped or not converted, tokens in removed places).
struct MigrationReport {
  std::size_t migrated = 0;  ///< live instances moved to the new version of their class
  std::size_t created = 0;   ///< objects the new version declares that the running one had not
  std::size_t deleted = 0;   ///< objects the new version no longer declares (deleted with their nets)
  /// Per migrated or new property of a class: "Demo.count: kept", "Demo.limit: new", "Demo.old: removed",
  /// "Demo.size: type changed from int64 to double" (one line per class and property, in declaration
  /// order); the members of a place or transition (a port-net copy too) as "Demo.done.visits: kept".
  std::vector<std::string> properties;
  /// Schema differences handled with a loss: removed properties' values, values that did not convert,
  /// tokens in removed places, retired classes that could not be undefined.
  std::vector<std::string> warnings;
};

class ProgramImpl;

/// @brief A SOML++ script loaded into one SimState.
class Program {
 public:
  /// @brief Checks, compiles and loads @p text (shown as @p name in messages) into @p state.
  /// @throws vsd::Error with every diagnostic (file:line:col) when the script has errors, or with the
  /// position of a construct the runtime cannot run yet; nothing is added to the state then.
  static std::unique_ptr<Program> load(SimState& state, std::string name, std::string text,
                                       RunOptions options = {});
  /// @brief Attaches to a run of @p text that is already in @p state — loaded by vsd::io, or a replica
  /// that applied the recorded bundles — and continues it exactly as the original would have: the script
  /// is checked and compiled as for load(), the run-time classes and enums the state has are checked
  /// against the script's and used, and the script object, its objects, every net (invocations included)
  /// and the executor's state (its "(executor)" node: generator, firings, enabled transitions in choice
  /// order) are found in the state instead of created. Nothing is created or changed. @p options.seed is
  /// not used (the state's generator goes on). The script's functions become MetaMethods of the classes
  /// the state defined (a file's carry properties only) once the attach succeeded; a C++ call() runs in
  /// the program that runs the instance's state.
  /// @throws vsd::Error when the script has errors, or naming what of the state does not match it (no
  /// script object, a different source text, a class, object, place or transition that differs, no
  /// executor state).
  static std::unique_ptr<Program> attach(SimState& state, std::string name, std::string text,
                                         RunOptions options = {});
  ~Program();
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  /// @brief Replaces the running script by a changed version of it (docs/soml.md, "Changing a running
  /// program"): its classes are redefined, live objects migrate to the new classes (properties kept by
  /// name, converted where the type changed, new ones initialised, removed ones reported), markings stay
  /// where the places still exist, transitions, arrows and functions are the new ones. Migrated objects
  /// are new instances (new ids); every reference to them held in a database property is redirected,
  /// pointers to the old instances are invalid afterwards.
  /// @return what changed.
  /// @throws vsd::Error with every diagnostic (file:line:col) of the new text, or what cannot be
  /// migrated; then the state, this Program and its classes are exactly as before.
  MigrationReport reload(std::string name, std::string text);
  /// @brief Follows, on a replica with a Registry of its own, a reload made on the source (docs/soml.md
  /// 8.6): retires this program's classes as reload() does, defines those of @p text (the new version
  /// the source loaded), applies @p bundle — the source's recording from the reload on, which creates
  /// instances of the new classes — and attaches to the result as attach() does. The bundles recorded
  /// before the reload must have been applied first.
  /// @throws vsd::Error with the diagnostics of @p text, when the bundle does not apply, or when the
  /// result does not match @p text; then the state, this Program and its classes are as before.
  void follow_reload(std::string name, std::string text, const Transaction& bundle);

  /// @brief The script object's node (a child of the Database).
  [[nodiscard]] vsd::Node& root() const noexcept;
  /// @brief The top-level object named @p name, or nullptr.
  [[nodiscard]] vsd::Node* object(std::string_view name) const;
  /// @brief The place @p name of object @p owner (nullptr: the script object), or nullptr.
  [[nodiscard]] Place* place(std::string_view name, const vsd::Node* owner = nullptr) const;
  /// @brief Every place of every net instance, in creation order.
  [[nodiscard]] std::vector<Place*> places() const;
  /// @brief The run-time class of script class or object @p name ("Demo"), or nullptr.
  [[nodiscard]] const MetaInstance* script_class(std::string_view name) const;

  /// @brief Fires at most @p n transitions. @return how many fired.
  /// @throws vsd::Error (with the SOML++ call stack) when an action fails; that firing is undone whole
  /// (docs/soml.md 5.2): every property, marking, created and deleted instance is as before it.
  std::uint64_t step(std::uint64_t n = 1);
  /// @brief Fires until no transition is enabled or @p limit firings happened. @return how many fired.
  std::uint64_t run_until_quiet(std::uint64_t limit = 10'000'000);
  /// @brief True when some transition is enabled.
  [[nodiscard]] bool enabled_any();
  /// @brief Fires @p transition (a Transition node of one of this program's nets) if it is enabled, as
  /// step() would have fired it had its choice fallen on it (an interactive fire button, a test).
  /// @return false, changing nothing, when it is not enabled or not one of this program's live nets.
  /// @throws vsd::Error as step() does when its action fails (the firing is undone whole).
  bool fire(const Transition& transition);
  /// @brief Firings so far.
  [[nodiscard]] std::uint64_t firings() const noexcept;
  /// @brief Calls @p fn after every firing (empty: no trace).
  void on_firing(std::function<void(const Firing&)> fn);
  /// @brief Condition evaluations so far (to see that conditions are not polled).
  [[nodiscard]] std::uint64_t condition_tests() const noexcept;
  /// @brief (instance, property) pairs that some transition's last test read and that are watched now.
  [[nodiscard]] std::size_t watched_properties() const noexcept;
  /// @brief Entries of the executor's transition table: one per transition of every net instance, plus
  /// those of deleted nets (finished invocations, deleted objects) not dropped yet. Dead entries are
  /// dropped at the start of a step() once they are the majority, so a long run stays bounded.
  [[nodiscard]] std::size_t executor_entries() const noexcept;
  /// @brief Run-time errors of conditions so far (a failing condition counts as not enabled).
  [[nodiscard]] const std::vector<std::string>& condition_errors() const noexcept;

  /// @brief The bytecode this program runs, as text (`vsd-soml disasm`; docs/soml.md, "Disassembly"): per
  /// function its name, file:line, parameters, registers, locals and each instruction with its index,
  /// opcode name, operands and line:column; then the constants and strings. As compiled: debugger
  /// patches are not shown, constants naming objects show 0 (their ids are linked at run time).
  [[nodiscard]] std::string disassemble() const;

  /// @brief Runs the functions that the native library at @p path holds for this program's image in
  /// native code from now on (docs/soml.md, "Native compilation"): calls from C++ (MetaMethods), from
  /// VM code and from native code. The library is made by `vsd-soml compile` (or the CMake function
  /// vsd_add_soml_module) from the same script; functions it does not hold keep running in the VM, and
  /// so does everything while a debugger is attached. A second call replaces the first library.
  /// @return how many functions run natively.
  /// @throws vsd::Error when the library cannot be opened, is no SOML++ native library, was made for
  /// another native ABI, or holds no code of this version of the script (another image hash); the
  /// program then runs as before.
  std::size_t load_native(const std::string& path);
  /// @brief How many functions run natively (0 until load_native succeeded).
  [[nodiscard]] std::size_t native_functions() const noexcept;
  /// @brief The hash of the compiled program that a native library must have been generated from.
  [[nodiscard]] std::uint64_t image_hash() const;

  /// @brief The implementation (for the Module and the tools).
  [[nodiscard]] ProgramImpl& impl() noexcept { return *impl_; }

 private:
  explicit Program(std::shared_ptr<ProgramImpl> impl);
  std::shared_ptr<ProgramImpl> impl_;
};

/// @brief The C++ source of a native library (`vsd-soml compile`; docs/soml.md, "Native compilation")
/// holding the functions of each of @p programs that have a native translation: one module per program,
/// found by its image hash when loaded. It includes only vsd/soml/native_abi.hpp.
[[nodiscard]] std::string native_library_source(const std::vector<const Program*>& programs);

}  // namespace vsd::soml
