// The two-robot cell as two processes (docs/workcell.md, "Two processes"): a `controller` — the cell as
// run_cell() builds and runs it, the seed of a vsd::dist domain — and a `ui`, a replica of the controller's
// state in another process. The ui's operator commands are writes to the `operator` node, which the ui
// owns; the controller's plant reacts to them and answers on `session`. At the end the ui sends a digest
// of its replica's vsd::io binary save and the controller compares it with its own.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "cell.hpp"
#include "vsd/core/sim_state.hpp"

namespace vsd_workcell {

/// The options that choose how many processes run the cell, taken out of the command line.
struct ProcessOptions {
  int processes = 1;        ///< 1: run_cell() here; 2: the controller here, the ui as a child process
  std::string role;         ///< "controller" or "ui" (run by hand), empty otherwise
  std::uint32_t domain = 0; ///< the DDS domain; with --processes 2 and no --domain: 100 + pid % 100
  bool has_domain = false;
  bool commands = true;     ///< the ui sends the demo's operator commands (--no-commands: none)
};

/// Takes --processes N, --role R, --domain N and --no-commands out of @p args.
/// @throws vsd::Error naming the bad option and why.
void take_process_options(std::vector<std::string>& args, ProcessOptions& p);

/// What the two processes did.
struct TwoProcessReport {
  CellReport cell;               ///< the controller's run
  std::string controller_digest; ///< "N bytes, fnv1a XXXXXXXXXXXXXXXX" of its vsd::io binary save
  std::string replica_digest;    ///< the same of the ui's replica, as the ui sent it
  bool replica_equal = false;    ///< the two digests are equal
  int ui_exit = -1;              ///< the ui process's exit code (--processes 2), -1 when none was started
};

/// The controller: runs the cell as the seed of @p domain, waits (up to 30 s) for the ui to join, and at
/// the end for its digest. With @p ui_program not empty it starts that program as
/// `--role ui --domain D` (with the scripts and URDF of @p o) and waits for it to exit.
/// @throws vsd::Error when the ui does not join or does not answer, and what run_cell() throws.
/// @p ui_args are added to the ui's command line (e.g. `--serve 0 --no-linger`).
TwoProcessReport run_controller(const CellOptions& o, std::uint32_t domain, const std::string& ui_program,
                                bool ui_commands, std::ostream& out, const std::vector<std::string>& ui_args = {});

/// What the ui lets its caller do with the replica (e.g. serve it in the browser).
struct UiHooks {
  /// The replica has its first copy of the controller's state; the ui steps it until the end.
  std::function<void(vsd::Environment&, vsd::SimState& replica)> joined;
  /// The controller has compared the replica (@p equal). Whatever `joined` attached must let go here.
  std::function<void(vsd::Environment&, bool equal)> finished;
};

/// The ui: joins @p domain, follows the cell until the controller says it has finished, sends the
/// operator commands of the demo when @p commands (inject a part of kind 2 at once, pause robot_b at
/// t = 2 s and resume it at t = 6 s, move the first part that lies at the conveyor's sensor by 1 cm),
/// prints what it does and sees on @p out. @return 0 when the controller found the replica equal.
/// @throws vsd::Error when the controller does not answer.
int run_ui(const CellOptions& o, std::uint32_t domain, bool commands, std::ostream& out, const UiHooks& hooks = {});

/// "N bytes, fnv1a XXXXXXXXXXXXXXXX": what the two processes compare.
std::string digest(const std::vector<std::uint8_t>& bytes);

}  // namespace vsd_workcell
