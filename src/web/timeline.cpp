#include "timeline.hpp"

#include <algorithm>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "json.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"

namespace vsd::web::detail {

Timeline::Timeline(SimState& state, std::size_t max_bytes)
    : state_(state),
      max_bytes_(max_bytes),
      block_bytes_(std::clamp<std::size_t>(max_bytes / 16, std::size_t{64} << 10, std::size_t{1} << 20)) {
  if (max_bytes == 0) return;  // off: no recording for us, no entries
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
  if (max_bytes_ == 0 || !state_.recording()) return;
  // Every other reader hears the bundle (on_bundle). The state records the next step into scratch_'s
  // old buffer, which is warm; the entry is a copy of exactly the bundle's size. Keeping the recording's
  // own buffer instead (moved, no copy) made every step record into fresh, uncached memory: on the work
  // cell that cost more than the copy (benchmarks/README.md, "On the two-robot work cell").
  cutting_ = true;
  state_.take_recording(scratch_);
  cutting_ = false;
  if (!seeking_) add(scratch_);
}

void Timeline::heard(const Transaction& t) {
  if (cutting_ || seeking_) return;
  add(t);  // a bundle another reader cut (vsd::dist at its poll): ours to keep too
}

void Timeline::add(const Transaction& bundle) {
  if (bundle.empty()) return;
  // A change made while scrubbed back forks the history: the undone entries are gone for good.
  while (position_ < end()) drop_back();
  const std::span<const std::uint8_t> bytes(bundle.bytes());
  if (blocks_.empty() || blocks_.back().capacity - blocks_.back().used < bytes.size()) {
    Block b;
    if (spare_.data && spare_.capacity >= bytes.size()) {
      b = std::move(spare_);
      spare_ = Block{};
    } else {
      // A bundle larger than a block gets one of its own size.
      b.capacity = std::max(block_bytes_, bytes.size());
      b.data = std::make_unique_for_overwrite<std::uint8_t[]>(b.capacity);
    }
    b.used = 0;
    b.entries = 0;
    blocks_.push_back(std::move(b));
  }
  Block& b = blocks_.back();
  std::uint8_t* at = b.data.get() + b.used;
  std::memcpy(at, bytes.data(), bytes.size());
  b.used += bytes.size();
  ++b.entries;
  bytes_ += bytes.size();
  entries_.push_back(Entry{step_, time_, bundle.size(), at, bytes.size(), &b});
  while (bytes_ > max_bytes_ && entries_.size() > 1) drop_front();
  position_ = end();
}

void Timeline::drop_back() {
  const Entry e = entries_.back();
  entries_.pop_back();
  bytes_ -= e.size;
  // Entries are added at the end of the last block, so the newest one's bytes are the last used there.
  e.block->used = static_cast<std::size_t>(e.bytes - e.block->data.get());
  if (--e.block->entries == 0) {
    retire(std::move(blocks_.back()));
    blocks_.pop_back();
  }
}

void Timeline::drop_front() {
  const Entry e = entries_.front();
  entries_.pop_front();
  ++first_;
  bytes_ -= e.size;
  if (--e.block->entries == 0) {
    retire(std::move(blocks_.front()));
    blocks_.pop_front();
  }
}

void Timeline::retire(Block&& block) {
  // One spare of the usual size is kept; a bundle's block of its own is given back at once.
  if (block.capacity == block_bytes_ && !spare_.data) spare_ = std::move(block);
}

Transaction Timeline::bundle(const Entry& e) const {
  return vsd::detail::make_transaction(std::vector<std::uint8_t>(e.bytes, e.bytes + e.size), e.ops);
}

Transaction Timeline::entry(std::uint64_t index) const {
  if (index < first_ || index >= end())
    throw Error("timeline: entry " + std::to_string(index) + " is not kept (entries [" + std::to_string(first_) +
                ", " + std::to_string(end()) + "))");
  return bundle(entries_[index - first_]);
}

void Timeline::seek(std::uint64_t position, std::uint64_t step, double time) {
  if (max_bytes_ == 0) throw Error("timeline: it is off (Options::timeline_bytes is 0)");
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
    state_.apply(bundle(entries_[position_ - 1 - first_]).inverted());
    --position_;
  }
  while (position_ < position) {
    state_.apply(bundle(entries_[position_ - first_]));
    ++position_;
  }
}

void Timeline::write(JsonWriter& out, std::size_t limit) const {
  out.begin_object();
  out.member("enabled", max_bytes_ != 0).member("first", first_).member("position", position_).member("end", end()).member("live", live());
  out.key("entries").begin_array();
  const std::size_t from = entries_.size() > limit ? entries_.size() - limit : 0;
  for (std::size_t i = from; i < entries_.size(); ++i) {
    const Entry& e = entries_[i];
    out.begin_object()
        .member("index", first_ + i)
        .member("step", e.step)
        .member("time", e.time)
        .member("ops", static_cast<std::uint64_t>(e.ops))
        .end_object();
  }
  out.end_array();
  out.end_object();
}

}  // namespace vsd::web::detail
