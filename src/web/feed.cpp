#include "feed.hpp"

#include <algorithm>

namespace vsd::web::detail {

Event make_event(std::string_view name, std::string_view json) {
  std::string s;
  s.reserve(json.size() + name.size() + 16);
  s += "event: ";
  s += name;
  s += "\ndata: ";
  s += json;  // JSON as we write it has no raw newline (strings escape them), so one data line suffices
  s += "\n\n";
  return std::make_shared<const std::string>(std::move(s));
}

std::shared_ptr<Feed::Client> Feed::open(Event first) {
  auto c = std::make_shared<Client>();
  c->queue.push_back(std::move(first));
  std::lock_guard lock(mutex_);
  if (shut_) c->closed = true;
  clients_.push_back(c);
  return c;
}

void Feed::close(const std::shared_ptr<Client>& c) {
  std::lock_guard lock(mutex_);
  c->closed = true;
  c->queue.clear();
  clients_.erase(std::remove(clients_.begin(), clients_.end(), c), clients_.end());
}

std::size_t Feed::broadcast(const Event& e) {
  std::size_t dropped = 0;
  {
    std::lock_guard lock(mutex_);
    for (const auto& c : clients_) {
      if (c->queue.size() >= backlog_) {
        c->queue.clear();  // drop-oldest, all of it: the page starts again from a snapshot
        c->resync = true;
        ++dropped;
      }
      c->queue.push_back(e);
    }
  }
  ready_.notify_all();
  return dropped;
}

bool Feed::wait(Client& c, std::vector<Event>& out, std::chrono::milliseconds timeout) {
  out.clear();
  std::unique_lock lock(mutex_);
  ready_.wait_for(lock, timeout, [&] { return c.closed || shut_ || c.resync || !c.queue.empty(); });
  if (c.closed || shut_) return false;
  if (c.resync) {
    c.resync = false;
    out.push_back(make_event("resync", R"({"reason":"the page fell behind; events were dropped"})"));
    // Events queued after the drop are newer than the snapshot the page fetches, but the page refetches
    // everything anyway: drop them too and let it start clean.
    c.queue.clear();
    return true;
  }
  out.assign(c.queue.begin(), c.queue.end());
  c.queue.clear();
  return true;
}

void Feed::shutdown() {
  {
    std::lock_guard lock(mutex_);
    shut_ = true;
    for (const auto& c : clients_) c->closed = true;
    clients_.clear();
  }
  ready_.notify_all();
}

std::size_t Feed::clients() const {
  std::lock_guard lock(mutex_);
  return clients_.size();
}

}  // namespace vsd::web::detail
