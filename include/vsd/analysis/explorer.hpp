/** @file
 *  @brief State-space exploration of a PtNet: reachable markings, firings, token bounds, dead markings,
 *  unboundedness, under a memory limit and on several threads.
 *
 *  explore() builds the reachability set breadth-first, level by level. Counts follow the Model Checking
 *  Contest's StateSpace examination: `states` is the number of reachable markings and `edges` the number
 *  of firings, one per (reachable marking, transition enabled in it), so two transitions leading from one
 *  marking to the same marking count twice.
 *
 *  How (see docs/analysis.md for the details):
 *  - Markings are stored packed, b bits per place with b in {1, 2, 4, 8, 16, 32}, in one arena of
 *    64-bit words. When the net proves bounds on its places (P-semiflows covering every place, or no
 *    transition adding tokens), b holds the largest bound; otherwise b starts from the initial marking
 *    and the exploration restarts with 2b when a place outgrows it.
 *  - A sharded open-addressing hash set holds state indices (no allocation per marking).
 *  - Enabling is incremental: a successor's enabled set is its parent's, with only the transitions that
 *    read a place the fired transition changed (as input or inhibitor place) tested again.
 *  - Each level is expanded by `threads` threads. On nets with structural bounds the threads add new
 *    markings to the hash set themselves, at once, so the numbering follows the timing: states, edges,
 *    levels, token bounds, deadlock and the length of the (shortest) firing sequence to a dead marking
 *    are the same for any thread count, but which dead marking and sequence may differ with more than one
 *    thread. Other nets (those needing the unboundedness check) number new markings in a fixed order, so
 *    every result is the same for any thread count.
 *  - Unboundedness: a new marking M' that strictly covers an ancestor M on its breadth-first path (and
 *    equals it on every inhibitor place) proves the net unbounded: the sequence from M to M' can fire
 *    again forever. The exploration stops and reports the pair. Nets with structural bounds (above)
 *    skip this check. For nets with inhibitor arcs the test is sound but not complete (their boundedness
 *    is undecidable); the memory limit ends the rest.
 *  - Memory: every phase (compiling the net, the place bounds, preparing the exploration, the
 *    exploration itself) is held to the limit before it allocates: the place bounds give up rather than
 *    pass it, the others stop the run with Status::memory_limit and a message that names the phase,
 *    instead of an out-of-memory kill.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "vsd/analysis/pt_net.hpp"

namespace vsd::analysis {

/// @brief Knobs of explore().
struct ExploreOptions {
  /// @brief Worker threads; 0 = the number of hardware threads.
  unsigned threads = 1;
  /// @brief Also split levels among the threads while the hash set is small (at most 1 MiB). By default
  /// such levels are expanded by one thread with fused lookups, which costs less CPU and less wall time
  /// than the phased multi-threaded path on small state spaces; results are the same either way (tests
  /// set this to exercise the multi-threaded path on small nets).
  bool split_small_levels = false;
  /// @brief Memory limit in bytes for everything explore() makes (the compiled net, the place bounds,
  /// the states, the hash set, the buffers, the result); 0 = default_memory_limit().
  std::size_t memory_limit = 0;
  /// @brief When the progress line (states, edges, level, states/s, memory) is written to stderr.
  enum class Progress { automatic, always, never };
  /// @brief automatic: only when stderr is a terminal (and the run lasts more than a second).
  Progress progress = Progress::automatic;
};

/// @brief What explore() found.
struct ExploreResult {
  /// @brief How the exploration ended.
  enum class Status {
    complete,      ///< Every reachable marking was visited: all figures are exact.
    unbounded,     ///< Stopped: the net is unbounded (see unbounded_*); figures count what was visited.
    memory_limit,  ///< Stopped at the memory limit; figures count what was visited.
  };
  Status status = Status::complete;
  std::uint64_t states = 0;  ///< Reachable markings (visited ones unless complete).
  std::uint64_t edges = 0;   ///< Firings: one per (marking, enabled transition), over expanded markings.
  bool deadlock = false;     ///< A reachable marking enables no transition.
  /// @brief A shortest firing sequence (transition indices) from the initial marking to a dead marking
  /// (its length is the same for any thread count; which one, see the file comment).
  std::vector<std::uint32_t> dead_trace;
  /// @brief The dead marking dead_trace leads to (one entry per place).
  std::vector<std::uint32_t> dead_marking;
  std::uint32_t max_tokens_place = 0;    ///< Most tokens in one place in one reachable marking.
  std::uint64_t max_tokens_marking = 0;  ///< Most tokens in one reachable marking (sum over places).
  /// @brief Unbounded: firing sequence to the covered marking, and from it to the covering marking.
  std::vector<std::uint32_t> unbounded_prefix;
  std::vector<std::uint32_t> unbounded_cycle;
  std::vector<std::uint32_t> unbounded_covered;   ///< The covered marking M.
  std::vector<std::uint32_t> unbounded_covering;  ///< The marking M' > M.
  std::uint32_t levels = 0;                       ///< Breadth-first levels (the longest shortest path + 1).
  unsigned bits_per_place = 0;                    ///< The marking encoding the run ended with.
  /// @brief The most bytes held or asked for at once: within the limit, unless the compiled net alone
  /// passes it.
  std::size_t peak_memory = 0;
  std::size_t memory_limit = 0;                   ///< The limit that applied.
  double seconds = 0;                             ///< Wall time of the exploration.
  unsigned threads = 1;                           ///< Threads used.
  std::string message;                            ///< Why it stopped, for unbounded and memory_limit.

  /// @brief True when the figures are exact (status complete).
  bool complete() const noexcept { return status == Status::complete; }
};

/// @brief Explores the reachable markings of @p net (see the file comment).
/// @throws vsd::Error when a place would exceed 2^32-1 tokens or the states exceed 2^32-2.
ExploreResult explore(const PtNet& net, const ExploreOptions& options = {});

/// @brief The default memory limit: three quarters of the memory available now (MemAvailable), at
/// least 64 MiB.
std::size_t default_memory_limit();

/// @brief Parses a size such as "512M", "4G", "1.5GiB", "100000" (bytes). @throws vsd::Error if bad.
std::size_t parse_size(const std::string& text);

/// @brief The transition ids of a firing sequence, space-separated.
std::string trace_to_string(const PtNet& net, const std::vector<std::uint32_t>& trace);

/// @brief Writes @p r as one JSON object: states, edges, deadlock, max_tokens_place, max_tokens_marking,
/// status, bounded, dead_trace (transition ids), unbounded pair, levels, seconds, peak_memory, threads.
void write_json(std::ostream& out, const PtNet& net, const ExploreResult& r);

/// @brief Writes a readable summary of @p r (several lines).
void write_summary(std::ostream& out, const PtNet& net, const ExploreResult& r);

}  // namespace vsd::analysis
