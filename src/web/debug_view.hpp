/** @file
 *  @brief Internal: the SOML++ debugger and the token trace in the inspector. A soml::Debugger is attached
 *  to every program of the state as the programs appear (one stop handler, one firing trace each); the
 *  page sets breakpoints, reads the stack, the locals and print() at a stop, and resumes.
 *
 *  A stop happens inside the program's run, on the simulation thread. The stop handler hands control to
 *  `wait` (set by the server): it keeps answering requests — reads, debugger commands — until a resume
 *  command arrives or the server stops, and only then does the program go on. Everything that would run
 *  or change the state in the middle of a firing (edits, calls, firings, timeline moves) is refused while
 *  stopped (Inspector::handle).
 */
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vsd/core/fwd.hpp"
#include "vsd/soml/debugger.hpp"

namespace vsd::web::detail {

class JsonWriter;
class JsonObject;

class Debugging {
 public:
  /// @p trace_capacity: token-trace entries kept (the oldest go first).
  Debugging(Environment& env, SimState& state, std::size_t trace_capacity = 2000);
  ~Debugging();
  Debugging(const Debugging&) = delete;
  Debugging& operator=(const Debugging&) = delete;

  /// @brief Attaches to the programs loaded since the last call and forgets those that are gone.
  void sync();
  /// @brief Called at a stop, after the stop was published: serves requests until resume() or the end
  /// of the server. Empty: every stop continues at once (no one could resume it).
  std::function<void()> wait;
  /// @brief Called with a "debug" event's JSON when the program stops or goes on.
  std::function<void(const std::string&)> announce;

  /// @brief True while a program is stopped (inside wait()).
  [[nodiscard]] bool stopped() const noexcept { return stop_.has_value(); }
  /// @brief True once resume() was asked at the current stop (wait() returns then).
  [[nodiscard]] bool resuming() const noexcept { return resume_.has_value(); }

  // GET
  void write(JsonWriter& out);                                  // /api/debug
  void write_source(JsonWriter& out, std::uint64_t program);    // /api/debug/source
  void write_locals(JsonWriter& out, std::size_t frame) const;  // /api/debug/locals
  void write_print(JsonWriter& out, const std::string& path, std::size_t frame) const;  // /api/debug/print
  void write_trace(JsonWriter& out, std::uint64_t after, std::size_t limit) const;      // /api/trace
  /// @brief The trace entries since the last call, as a "trace" event's JSON; empty when there are none.
  [[nodiscard]] std::string take_trace_event(std::size_t limit);

  // POST
  void post(JsonWriter& out, const std::string& path, const JsonObject& body);  // /api/debug/*

 private:
  struct Entry;
  struct Traced {
    std::uint64_t seq;  // 1, 2, ... over all programs
    std::uint64_t program;
    std::uint64_t firing;  // the program's firing number
    Id transition, mark, from, to, invocation;
    soml::FiringKind kind;
    std::vector<std::pair<Id, std::int64_t>> taken, given;  // (place, tokens)
  };
  struct Stopped {
    Entry* entry;
    soml::Stop stop;
    std::string json;  // the stop as the "debug" event and /api/debug give it
  };

  Entry& entry(std::uint64_t key);
  Entry& only_or(const JsonObject& body);
  soml::Resume stopped_at(Entry& e, const soml::Stop& s);
  void write_entry(JsonWriter& out, const Traced& t) const;
  std::string stop_json(const Entry& e, const soml::Stop& s) const;

  Environment& env_;
  SimState& state_;
  std::vector<std::unique_ptr<Entry>> entries_;
  std::uint64_t next_key_ = 1;
  std::deque<Traced> trace_;
  std::size_t trace_capacity_;
  std::uint64_t trace_seq_ = 0;     // of the newest entry
  std::uint64_t trace_pushed_ = 0;  // the newest entry an event carried
  std::optional<Stopped> stop_;
  std::optional<soml::Resume> resume_;
};

}  // namespace vsd::web::detail
