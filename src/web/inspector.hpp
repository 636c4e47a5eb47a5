/** @file
 *  @brief Internal: what the inspector does on the simulation thread — it answers requests from the
 *  state (generated from the meta-information), applies edits through the setters, and turns what changed
 *  into batches for the event streams. Nothing here knows about HTTP or threads (server.cpp does), so the
 *  tests drive it directly too.
 */
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_set>
#include <utility>
#include <vector>

#include "debug_view.hpp"
#include "feed.hpp"
#include "timeline.hpp"
#include "vsd/core/watch.hpp"
#include "vsd/web/server.hpp"

namespace vsd::web::detail {

class JsonWriter;

/// @brief A request as the inspector sees it.
struct Request {
  std::string method;  // "GET" or "POST"
  std::string path;    // "/api/instance"
  std::vector<std::pair<std::string, std::string>> query;
  std::string body;
  bool writable = false;  // the request carried the right token
  /// @brief Query parameter @p name, or nullptr.
  [[nodiscard]] const std::string* param(std::string_view name) const noexcept;
};

/// @brief An answer: status and JSON body.
struct Reply {
  int status = 200;
  std::string body;
  static Reply error(int status, std::string_view message);
};

class Inspector {
 public:
  Inspector(Environment& env, SimState& state, const Options& options, Feed& feed);
  ~Inspector();
  Inspector(const Inspector&) = delete;
  Inspector& operator=(const Inspector&) = delete;

  /// @brief Answers @p request from the state (GET) or changes the state (POST). Never throws: bad
  /// requests get 4xx and change nothing.
  Reply handle(const Request& request);
  /// @brief End of a step (or of a serve_for() round): the recording becomes a timeline entry, and what
  /// changed goes out as a batch once the push interval has passed (@p force: now).
  void publish(bool force = false);
  /// @brief The `hello` event of a new client.
  [[nodiscard]] Event hello() const;

  [[nodiscard]] bool paused() const noexcept { return paused_; }
  void pause(bool on) noexcept { paused_ = on; }
  [[nodiscard]] std::uint64_t batches() const noexcept { return batches_; }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_; }
  [[nodiscard]] std::size_t timeline_size() const noexcept { return timeline_.size(); }
  /// @brief The SOML++ debugging (null when Options::debug is off).
  [[nodiscard]] Debugging* debugging() noexcept { return debug_.get(); }

 private:
  Reply get(const Request& r);
  Reply post(const Request& r);
  // GET
  void info(JsonWriter& out, const Request& r) const;
  void classes(JsonWriter& out) const;
  void children(JsonWriter& out, const Request& r) const;
  void table(JsonWriter& out, const Request& r) const;
  void instance(JsonWriter& out, const Request& r) const;
  // POST
  void set(JsonWriter& out, const Request& r);
  void call(JsonWriter& out, const Request& r);
  void fire(JsonWriter& out, const Request& r);
  void seek(JsonWriter& out, const Request& r);
  /// After a write: the loaded programs re-test what the edit touched, so /api/nets shows it at once.
  void refresh_nets();

  SimStateInstance& find(Id id) const;
  void write_batch(JsonWriter& out, std::vector<Watch::Report>& reports);
  void write_stats(double seconds);

  Environment& env_;
  SimState& state_;
  const Options& options_;
  Feed& feed_;
  Timeline timeline_;
  std::unique_ptr<Debugging> debug_;
  Watch watch_;  // every change of every instance, de-duplicated per (instance, property)
  std::atomic<bool> paused_{false};
  std::uint64_t seq_ = 0;
  std::uint64_t batches_ = 0;
  std::uint64_t dropped_ = 0;
  std::chrono::steady_clock::time_point last_push_{};
  std::chrono::steady_clock::time_point last_stats_{};
  std::uint64_t stats_steps_ = 0;     // at last_stats_
  std::uint64_t stats_changes_ = 0;   // changes published since last_stats_
  std::uint64_t stats_firings_ = 0;   // at last_stats_
};

}  // namespace vsd::web::detail
