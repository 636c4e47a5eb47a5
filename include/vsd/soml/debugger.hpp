/** @file
 *  @brief The SOML++ debugger: breakpoints on source lines and transitions, the call stack and local
 *  variables at a stop, step / next / continue, and the token trace (docs/soml.md, section 9).
 *
 *  @code
 *  vsd::soml::Debugger dbg(program);               // attaches; detaches when destroyed
 *  dbg.break_at_line(12);                          // a line of a function, condition or action
 *  dbg.break_on_transition("cell.go");             // before that transition fires
 *  dbg.on_stop([](vsd::soml::Debugger& d, const vsd::soml::Stop& s) {
 *    for (const auto& f : d.call_stack()) std::cout << f.function << " line " << f.line << "\n";
 *    for (const auto& v : d.locals()) std::cout << v.name << " = " << v.value << "\n";
 *    return vsd::soml::Resume::Next;
 *  });
 *  program.run_until_quiet();                      // stops call on_stop synchronously
 *  @endcode
 *
 *  Stops happen inside the program's own calls (`step()`, `run_until_quiet()`, `call()` of a script
 *  method, the Module's scheduler task): the stop handler runs on that thread, reads the stopped
 *  program through call_stack(), locals() and print(), and returns how to go on. Attaching costs nothing
 *  when no breakpoint is set and nobody steps: the debugger patches a breakpoint instruction over the
 *  first instruction of the lines it must stop at, and restores the code when it no longer needs them.
 */
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/soml/runtime.hpp"

namespace vsd::soml {

/// @brief How to go on after a stop.
enum class Resume : std::uint8_t {
  Continue,  ///< run until the next breakpoint
  Step,      ///< stop at the next source line run, entering called functions
  Next,      ///< stop at the next source line of this function or of one that called it
  Finish     ///< stop at the next source line after this function returned
};

/// @brief Why the program stopped.
enum class StopReason : std::uint8_t {
  Breakpoint,  ///< a line breakpoint
  Transition,  ///< a transition breakpoint: the transition is about to fire
  Step         ///< a step, next or finish ended
};

/// @brief A breakpoint.
struct Breakpoint {
  int id = 0;              ///< 1, 2, ... in the order they were set
  std::uint32_t line = 0;  ///< a line breakpoint: its line (0 for a transition breakpoint)
  std::string transition;  ///< a transition breakpoint: "owner.name" or "name" (empty for a line)
  std::uint64_t hits = 0;  ///< how often it stopped the program
};

/// @brief A stop, as the stop handler receives it.
struct Stop {
  StopReason reason = StopReason::Step;
  int breakpoint = 0;                      ///< the breakpoint's id (0 for a step)
  std::string function;                    ///< the code stopped in ("" at a transition breakpoint)
  std::uint32_t line = 0;                  ///< its source line (0 at a transition breakpoint)
  const Transition* transition = nullptr;  ///< at a transition breakpoint: the one about to fire
  vsd::Id mark = 0;                        ///< at a transition breakpoint: its mark (0: none)
};

/// @brief One frame of the SOML++ call stack.
struct StackFrame {
  std::string function;  ///< "Demo.time_to", "cell.go (condition)", ...
  std::string file;      ///< the script's name
  std::uint32_t line = 0;
  vsd::Id self = 0;  ///< the instance the code runs on (a transition for conditions and actions)
  vsd::Id mark = 0;  ///< the token now testing or traversing (0: none)
};

/// @brief A local variable or parameter of a frame.
struct Variable {
  std::string name;
  std::string type;   ///< its SOML++ type ("int", "shared<Node>", ...)
  std::string value;  ///< as print() writes it; strings quoted
};

/// @brief A debugger attached to one Program (at most one at a time). It may outlive the Program: it
/// is detached then (attached() is false) and its calls that need the program throw.
class Debugger {
 public:
  /// @brief Attaches to @p program.
  /// @throws vsd::Error when another debugger is attached to it.
  explicit Debugger(Program& program);
  /// @brief Detaches: removes every breakpoint instruction and restores the previous firing trace.
  ~Debugger();
  Debugger(const Debugger&) = delete;
  Debugger& operator=(const Debugger&) = delete;

  /// @brief Stops at source line @p line of the script (in every function, condition, action, arrow
  /// condition or initialiser that has code on it). @return the breakpoint's id.
  /// @throws vsd::Error when no code starts on that line (saying which lines nearby have code).
  int break_at_line(std::uint32_t line);
  /// @brief Like break_at_line(), for "FILE:LINE" or "LINE"; FILE must name the program's script (its
  /// name as loaded, or that name's last path component).
  /// @throws vsd::Error for a malformed location, another file, or a line without code.
  int break_at(std::string_view location);
  /// @brief Stops before transition @p name fires: "owner.name" (owner: the object's name, empty for
  /// the script object) or a bare transition name for every transition so called.
  /// @throws vsd::Error when no transition of the program has that name.
  int break_on_transition(std::string_view name);
  /// @brief Removes breakpoint @p id. @return false when there is none with that id.
  bool remove(int id);
  /// @brief The breakpoints, in the order they were set.
  [[nodiscard]] const std::vector<Breakpoint>& breakpoints() const noexcept;

  /// @brief Sets the stop handler (none: every stop continues). It runs inside the program's call and
  /// may read the program (call_stack(), locals(), print()); it must not run the program (step(),
  /// call()) itself.
  void on_stop(std::function<Resume(Debugger&, const Stop&)> fn);
  /// @brief With @p on, stops at the first source line the program runs next (before a run: step into
  /// it); with false, cancels that.
  void step_into_next(bool on = true);
  /// @brief Calls @p fn after every firing (the token trace; Program::on_firing keeps working).
  void on_firing(std::function<void(const Firing&)> fn);

  /// @brief True while the stop handler runs.
  [[nodiscard]] bool stopped() const noexcept;
  /// @brief The SOML++ call stack at a stop, innermost frame first (empty when not stopped).
  [[nodiscard]] std::vector<StackFrame> call_stack() const;
  /// @brief The parameters and locals of frame @p frame (0: the innermost) visible at its line, in
  /// declaration order. @throws vsd::Error when not stopped or @p frame is out of range.
  [[nodiscard]] std::vector<Variable> locals(std::size_t frame = 0) const;
  /// @brief The value of @p path in frame @p frame: a local or parameter, `this`, `mark`, a property
  /// of the frame's instance (or of an enclosing one), or a top-level object, followed by `.name`
  /// steps through properties (and places, whose marking is shown). Works between runs too (frame 0
  /// is then the script object). @throws vsd::Error naming what is unknown.
  [[nodiscard]] std::string print(std::string_view path, std::size_t frame = 0) const;
  /// @brief The marking of every place, one "owner.place = 3" or "owner.place = [a, b]" per line.
  [[nodiscard]] std::string marking() const;

  /// @brief The program debugged. @throws vsd::Error when it is gone (see attached()).
  [[nodiscard]] Program& program() const;
  /// @brief False once the program was destroyed (its state went, or the Module stopped serving it): the
  /// debugger may outlive its program, and every call that needs the program then throws vsd::Error.
  [[nodiscard]] bool attached() const noexcept;
  /// @brief The script's name as loaded and its source text (for a front end that shows the lines).
  [[nodiscard]] const std::string& file() const;
  [[nodiscard]] const std::string& source() const;
  /// @brief The source lines where code starts, ascending: the lines break_at_line() accepts.
  [[nodiscard]] std::vector<std::uint32_t> lines() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// @brief "owner.place" for a place or transition node ("place" for those of the script object), as
/// the trace and the debugger name them.
[[nodiscard]] std::string net_node_label(const vsd::Node* node);

}  // namespace vsd::soml
