/** @file
 *  @brief Savepoint: undo every change made to a SimState since a point, as if they never happened.
 *
 *  @code
 *  vsd::Savepoint sp(state);
 *  try {
 *    change_many_things(state);   // may throw half way
 *    sp.commit();
 *  } catch (...) {
 *    sp.rollback();               // the state is as before (ids, values, references)
 *    throw;
 *  }
 *  @endcode
 *
 *  A scope around SimState::savepoint(), roll_back() and release(). A savepoint records the changes made
 *  after it (through the state's recording, which it starts when the state does not record yet) and rolls
 * them back by applying their inverse (Transaction::inverted). Rolled back changes vanish from the state's
 * recording too, so a replica fed from it never sees them; committed ones stay in it when the state was
 * recording and are dropped from it otherwise. Instances deleted after the savepoint come back with their ids
 * and values, but at other addresses: pointers to them are invalid. Do not take the state's recording
 * (SimState::take_recording) while a savepoint is open; rollback() then throws. Savepoints nest (the inner
 * one is closed first).
 */
#pragma once

#include "vsd/core/sim_state.hpp"

namespace vsd {

/// @brief A scope around SimState::savepoint(): rolled back unless committed.
class Savepoint {
 public:
  /// @brief Starts recording the changes to @p state.
  explicit Savepoint(SimState& state);
  /// @brief Rolls back when neither commit() nor rollback() was called (errors are swallowed).
  ~Savepoint();
  Savepoint(const Savepoint&) = delete;
  Savepoint& operator=(const Savepoint&) = delete;

  /// @brief Keeps the changes and closes the savepoint.
  void commit() noexcept;
  /// @brief Undoes the changes since the savepoint was made and closes it; listeners hear the undoing
  /// changes. @throws vsd::Error when the state's recording was taken meanwhile, or when the inverse
  /// bundle does not apply (then nothing was undone).
  void rollback();
  /// @brief True until commit() or rollback().
  [[nodiscard]] bool open() const noexcept { return open_; }

 private:
  SimState& state_;
  SimState::Savepoint point_;
  bool open_ = true;
};

}  // namespace vsd
