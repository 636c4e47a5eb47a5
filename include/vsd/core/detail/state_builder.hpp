/** @file
 *  @brief Internal: StateBuilder, how a loader (vsd::io) fills a SimState with many new instances at
 *  once, the way applying a bundle of creates, sets and list inserts would, without encoding one.
 *
 *  A load used to become a Transaction bundle that the SimState then parsed twice (a dry run, then the
 *  real run). A loader checks everything a dry run would on its own model, before it changes anything;
 *  the builder then only does what the real run did: make each instance with its id, write its initial
 *  values, announce and record its creation, and fill its references through the ordinary editing
 *  paths (each recorded and signalled as before). While the builder lives, the state counts as applying
 *  (SimState::applying(): no cascades, listeners hold back their derived changes) and one dispatch spans
 *  the build, so that an instance a listener deletes stays allocated, and detectable, until it ends.
 */
#pragma once

#include <cstddef>

#include "vsd/core/fwd.hpp"

namespace vsd::detail {

class LinkBlock;

class StateBuilder {
 public:
  /// @brief Starts building into @p state (it counts as applying until the builder dies).
  explicit StateBuilder(SimState& state) noexcept;
  ~StateBuilder();
  StateBuilder(const StateBuilder&) = delete;
  StateBuilder& operator=(const StateBuilder&) = delete;

  /// @brief Checks that instances of @p cls may live in the state, changing nothing.
  /// @throws vsd::Error saying why not (abstract, not a SimStateInstance, a second Database).
  static void check_class(SimState& state, const MetaInstance& cls);
  /// @brief Makes room for @p count more instances of @p cls (id map, element index, instance memory).
  void reserve(const MetaInstance& cls, std::size_t count);
  /// @brief Makes room in the id map for @p count more instances.
  void reserve_ids(std::size_t count);
  /// @brief Makes the links of the next @p count list elements appended in one block (a LinkBlock:
  /// freed when its last link is freed) instead of one allocation each.
  void reserve_links(std::size_t count);
  /// @brief A new instance of @p cls with id @p id and its default values; it is neither announced nor
  /// recorded before finish_create(). @throws vsd::Error when the id is taken.
  SimStateInstance& make(const MetaInstance& cls, Id id);
  /// @brief Announces and records the creation of @p x, once its initial values are written.
  void finish_create(SimStateInstance& x);
  /// @brief Appends @p target to the reference list @p p of @p holder, recorded and signalled like
  /// SimStateInstance::list_insert(). The caller vouches that @p p is a list property of @p holder's
  /// class and that @p target is of its target class; the link's own checks (cycles, SimStates) still run.
  void append(SimStateInstance& holder, const MetaProperty& p, SimStateInstance& target);

 private:
  SimState& state_;
  LinkBlock* links_ = nullptr;
};

}  // namespace vsd::detail
