#include "vsd/core/savepoint.hpp"

#include <vector>

#include "vsd/core/detail/tx_codec.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/sim_state.hpp"

namespace vsd {

Savepoint::Savepoint(SimState& state) : state_(state), was_recording_(state.recording_) {
  if (!was_recording_) state_.start_recording();
  mark_bytes_ = state_.recorded_.size();
  mark_ops_ = state_.recorded_ops_;
}

Savepoint::~Savepoint() {
  if (!open_) return;
  try {
    rollback();
  } catch (...) {  // NOLINT(bugprone-empty-catch): a destructor must not throw; rollback() says why
    close();
  }
}

void Savepoint::close() noexcept {
  open_ = false;
  if (!was_recording_) {
    // The recording was the savepoint's own: it ends with it, and so do its bytes.
    state_.recording_ = false;
    state_.recorded_.clear();
    state_.recorded_ops_ = 0;
  }
}

void Savepoint::commit() noexcept {
  if (open_) close();
}

void Savepoint::rollback() {
  if (!open_) return;
  std::vector<std::uint8_t>& rec = state_.recorded_;
  if (!state_.recording_ || rec.size() < mark_bytes_ || state_.recorded_ops_ < mark_ops_) {
    close();
    throw Error("Savepoint: the recording of SimState '" + state_.name() +
                "' was taken or stopped while the savepoint was open; nothing was undone");
  }
  if (state_.recorded_ops_ > mark_ops_) {
    std::vector<std::uint8_t> bytes;
    detail::write_tx_header(bytes);
    bytes.insert(bytes.end(), rec.begin() + static_cast<std::ptrdiff_t>(mark_bytes_), rec.end());
    const Transaction undo =
        detail::make_transaction(std::move(bytes), state_.recorded_ops_ - mark_ops_).inverted();
    // The undoing changes are not recorded: the recording loses the undone ones instead.
    state_.recording_ = false;
    // Instances that changed while nothing recorded dropped their watch bit: set it again.
    try {
      state_.apply(undo);
    } catch (...) {
      state_.recording_ = true;
      state_.enable_state_watch();
      throw;
    }
    state_.recording_ = true;
    state_.enable_state_watch();
    rec.resize(mark_bytes_);
    state_.recorded_ops_ = mark_ops_;
  }
  close();
}

}  // namespace vsd
