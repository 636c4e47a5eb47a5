/** @file
 *  @brief Internal: the event streams of the connected pages. The simulation thread broadcasts each
 *  batch once (one shared, already formatted event); each client's HTTP thread waits for its queue and
 *  writes it out. A client that falls more than `backlog` events behind loses them (drop-oldest) and gets
 *  a `resync` event instead, so a slow page never holds memory or the simulation back.
 */
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace vsd::web::detail {

/// @brief One server-sent event, formatted: "event: NAME\ndata: JSON\n\n".
using Event = std::shared_ptr<const std::string>;
[[nodiscard]] Event make_event(std::string_view name, std::string_view json);

class Feed {
 public:
  struct Client {
    std::deque<Event> queue;
    bool resync = false;  // events were dropped: tell the page before anything else
    bool closed = false;
  };
  explicit Feed(std::size_t backlog) : backlog_(backlog) {}
  /// @brief A new client; @p first is queued for it alone (the `hello` event).
  std::shared_ptr<Client> open(Event first);
  void close(const std::shared_ptr<Client>& c);
  /// @brief Queues @p e for every client. @return how many clients lost events to it.
  std::size_t broadcast(const Event& e);
  /// @brief Waits until @p c has events (or @p timeout passes, or the feed shuts down) and moves them to
  /// @p out. @return false when the client or the feed is closed.
  bool wait(Client& c, std::vector<Event>& out, std::chrono::milliseconds timeout);
  /// @brief Closes every client and wakes their threads.
  void shutdown();
  [[nodiscard]] std::size_t clients() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::vector<std::shared_ptr<Client>> clients_;
  std::size_t backlog_;
  bool shut_ = false;
};

}  // namespace vsd::web::detail
