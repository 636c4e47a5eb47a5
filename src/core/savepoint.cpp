#include "vsd/core/savepoint.hpp"

#include "vsd/core/sim_state.hpp"

namespace vsd {

// The mechanism is SimState's (savepoint, roll_back, release); this class only ties it to a scope.
Savepoint::Savepoint(SimState& state) : state_(state), point_(state.savepoint()) {}

Savepoint::~Savepoint() {
  if (!open_) return;
  try {
    rollback();
  } catch (...) {  // NOLINT(bugprone-empty-catch): a destructor must not throw; rollback() says why
  }
}

void Savepoint::commit() noexcept {
  if (!open_) return;
  open_ = false;
  state_.release(point_);
}

void Savepoint::rollback() {
  if (!open_) return;
  open_ = false;  // roll_back() releases the savepoint also when it throws
  state_.roll_back(point_);
}

}  // namespace vsd
