#include "timeline.hpp"

#include <string>

#include "json.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"

namespace vsd::web::detail {

Timeline::Timeline(SimState& state, std::size_t max_bytes) : state_(state), max_bytes_(max_bytes) {
  bundles_ = state.on_bundle().connect([this](const Transaction& t) { heard(t); });
  if (!state.recording()) {
    state.start_recording();
    started_recording_ = true;
  }
}

Timeline::~Timeline() {
  bundles_.disconnect();
  // Stop only a recording we started; what was recorded since the last cut is dropped with us.
  if (started_recording_ && state_.recording()) (void)state_.stop_recording();
}

void Timeline::cut(std::uint64_t step, double time) {
  step_ = step;
  time_ = time;
  if (state_.recording()) (void)state_.take_recording();  // heard() receives it (and every other reader)
}

void Timeline::heard(const Transaction& t) {
  if (seeking_ || t.empty()) return;
  // A change made while scrubbed back forks the history: the undone entries are gone for good.
  while (position_ < end()) {
    bytes_ -= entries_.back().bundle.bytes().size();
    entries_.pop_back();
  }
  bytes_ += t.bytes().size();
  entries_.push_back(Entry{step_, time_, t});
  while (bytes_ > max_bytes_ && entries_.size() > 1) {
    bytes_ -= entries_.front().bundle.bytes().size();
    entries_.pop_front();
    ++first_;
  }
  position_ = end();
}

void Timeline::seek(std::uint64_t position, std::uint64_t step, double time) {
  if (position < first_ || position > end())
    throw Error("timeline: position " + std::to_string(position) + " is outside the entries kept [" +
                std::to_string(first_) + ", " + std::to_string(end()) + "]");
  cut(step, time);  // what happened since the last cut is an entry of its own (and may fork)
  seeking_ = true;
  struct Done {
    Timeline& t;
    ~Done() {
      // Our own applications are recorded too (a vsd::dist replica follows the seek); cut them away so
      // that they are not taken for an edit.
      if (t.state_.recording()) (void)t.state_.take_recording();
      t.seeking_ = false;
    }
  } done{*this};
  while (position_ > position) {
    state_.apply(entries_[position_ - 1 - first_].bundle.inverted());
    --position_;
  }
  while (position_ < position) {
    state_.apply(entries_[position_ - first_].bundle);
    ++position_;
  }
}

void Timeline::write(JsonWriter& out, std::size_t limit) const {
  out.begin_object();
  out.member("first", first_).member("position", position_).member("end", end()).member("live", live());
  out.key("entries").begin_array();
  const std::size_t from = entries_.size() > limit ? entries_.size() - limit : 0;
  for (std::size_t i = from; i < entries_.size(); ++i) {
    const Entry& e = entries_[i];
    out.begin_object()
        .member("index", first_ + i)
        .member("step", e.step)
        .member("time", e.time)
        .member("ops", static_cast<std::uint64_t>(e.bundle.size()))
        .end_object();
  }
  out.end_array();
  out.end_object();
}

}  // namespace vsd::web::detail
