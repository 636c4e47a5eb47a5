/** @file
 *  @brief Participant: keeps one SimState in sync with the SimStates of other processes or machines over
 *  Cyclone DDS — bundles out and in, late joiners, ownership, faults.
 *
 *  A participant records its SimState; publish() sends what was recorded as one bundle (one DDS sample,
 *  reliable, keep-all, in order), poll() applies the bundles of the others in the order each one sent
 *  them. Only Distributed properties travel (vsd/dist/wire.hpp). Every bundle and ownership claim carries
 *  the sender's sequence number, so a receiver sees duplicates (dropped) and gaps (it resynchronises).
 *
 *  A participant that is not the seed starts unsynchronised: it asks for a snapshot until a synchronised
 *  participant answers with its state, the last sequence number it applied of every sender and the
 *  ownership table; bundles that arrive meanwhile are kept and applied after the snapshot, those the
 *  snapshot already holds dropped. A bundle that does not apply (a diverged state) and a gap make a
 *  participant resynchronise the same way; it says so in its log.
 *
 *  Threading: like its SimState, a participant belongs to one thread; DDS delivers into its own queue,
 *  read by poll(). Ids of instances are only unique across participants whose Environments have
 *  different sites (Environment(site)).
 *
 *  @code
 *  vsd::Environment env(1);                      // a site of its own
 *  vsd::dist::ParticipantOptions o;
 *  o.name = "ui";
 *  o.domain = 7;
 *  vsd::dist::Participant ui(env.main_state(), o);
 *  ui.wait_synced(std::chrono::seconds(5));
 *  robot_node.set_target(0.5);                   // recorded ...
 *  ui.poll();                                    // ... published, and the others' changes applied
 *  @endcode
 */
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "vsd/core/config.hpp"
#include "vsd/core/signal.hpp"

namespace vsd {
class SimState;
class SimStateInstance;
}  // namespace vsd

namespace vsd::dist {

/// @brief How a participant joins.
struct ParticipantOptions {
  /// @brief Shown in log lines and conflict reports ("ui", "robot").
  std::string name = "participant";
  /// @brief The DDS domain id (0–230). Participants meet only in the same domain and topic.
  std::uint32_t domain = 0;
  /// @brief The DDS topic: one shared model per topic.
  std::string topic = "vsd";
  /// @brief Cyclone DDS configuration for the domain: XML text or "file://..." (the same forms as
  /// CYCLONEDDS_URI). Empty: CYCLONEDDS_URI, else Cyclone's defaults. The repository ships
  /// src/dist/cyclonedds-loopback.xml (loopback, no multicast). The first participant of a domain in a
  /// process decides the configuration for all of that process's participants in that domain.
  std::string config;
  /// @brief True for the participant whose state is the model to start from: it is synchronised at once.
  /// Others ask for a snapshot first.
  bool seed = false;
  /// @brief How often an unsynchronised participant repeats its snapshot request.
  std::chrono::milliseconds request_interval{200};
  /// @brief How long a participant that was synchronised before waits for a snapshot when it
  /// resynchronises; then it goes on with its own state and logs so (every participant may have seen the
  /// same gap, and an unsynchronised participant answers no requests). 0: wait forever.
  std::chrono::milliseconds resync_give_up{5000};
  /// @brief How long publish() may block on a full DDS writer queue before it throws.
  std::chrono::milliseconds write_timeout{10000};
  /// @brief The participant's DDS lease: a participant that died without leaving is dropped by the others
  /// after this long (their writers wait for it until then). Keep write_timeout above it.
  std::chrono::milliseconds lease_duration{3000};
  /// @brief How long a participant keeps the tombstones of deleted instances and erased list entries (to
  /// recognise changes made concurrently with the deletion); then they are pruned. A change older than
  /// this that arrives later (a participant cut off that long) does not apply, and its receiver
  /// resynchronises. Keep it well above lease_duration. 0: keep them for the life of the domain.
  std::chrono::milliseconds tombstone_horizon{60000};
  /// @brief Receives one line per noteworthy event (rejections, resynchronisation, conflicts). Default:
  /// standard error, prefixed "vsd::dist[name]: ".
  std::function<void(std::string_view line)> log;
};

/// @brief What a Conflict is about.
enum class ConflictKind : std::uint8_t {
  /// A write to what another participant owns: the whole bundle was rejected (undone at the writer).
  Owned = 0,
  /// Two participants set the same unowned property concurrently: the set with the lower stamp
  /// (Lamport clock, participant id) lost everywhere; the rest of its bundle stands (docs/dist.md).
  ConcurrentWrite = 1,
  /// Two participants claimed the same instance or property concurrently: the claim with the lower stamp
  /// won everywhere; the other one was rolled back.
  ClaimRace = 2,
  /// A change to an instance (a set or a list edit) was made while another participant deleted it: the
  /// deletion won everywhere, the change was dropped; the deleter tells the writer (docs/dist.md). Also a
  /// reference set to, or a list entry of, an instance deleted concurrently (Conflict::target): the
  /// reference ends null, the entry removed, everywhere.
  Deleted = 3,
  /// Two participants moved the same node to different parents concurrently: the newer move (the larger
  /// stamp) won everywhere, the other entry was removed from its children list (docs/dist.md).
  ConcurrentMove = 4,
};

/// @brief A write or claim that lost: reported to the loser and the winner (and logged by receivers).
struct Conflict {
  ConflictKind kind = ConflictKind::Owned;  ///< what happened
  std::uint64_t writer = 0;  ///< participant id of the loser: the writer, or the claimant whose claim lost
  std::uint64_t owner =
      0;  ///< participant id of the winner: the owner, the winning writer or claimant, the deleter
  std::uint64_t seq = 0;  ///< the loser's sequence number of its bundle or claim (0: never sent)
  Id instance = null_id;  ///< the instance touched
  std::string property;   ///< the property touched (empty: the instance itself, a deletion)
  /// Deleted: the deleted instance a reference or list entry referred to (null_id: @p instance itself was
  /// deleted); ConcurrentMove: the node moved (@p instance, @p property: the children list it lost)
  Id target = null_id;
  std::string text;  ///< one line for logs: who, what, whose
};

/// @brief Counters, for tests, tools and monitoring.
struct ParticipantStats {
  std::uint64_t bundles_sent = 0;  ///< bundles published
  /// claims and releases sent (bundles_sent + claims_sent is the sequence number of the last one sent,
  /// the number a Conflict's seq names)
  std::uint64_t claims_sent = 0;
  std::uint64_t bundles_applied = 0;   ///< bundles of others applied
  std::uint64_t duplicates = 0;        ///< bundles and claims dropped as already applied
  std::uint64_t foreign = 0;           ///< samples that are not vsd::dist messages (dropped)
  std::uint64_t malformed = 0;         ///< vsd::dist messages whose content is broken (dropped)
  std::uint64_t conflicts = 0;         ///< conflicts reported here (as writer, owner or receiver)
  std::uint64_t resyncs = 0;           ///< snapshots installed after the first synchronisation
  std::uint64_t snapshots_served = 0;  ///< snapshot requests answered
  std::uint64_t dropped_unsynced = 0;  ///< local bundles dropped because they were made while unsynchronised
  /// sets and list edits of others dropped here: a concurrent write with a later stamp, a concurrent
  /// deletion or a newer move won
  std::uint64_t lost_writes = 0;
  std::uint64_t claims_lost = 0;  ///< claims (anyone's) that lost a race here, this one's included
  /// bundles that waited for a bundle of a third participant that made a list entry they edit
  std::uint64_t bundles_waited = 0;
  std::uint64_t tombstones_pruned = 0;  ///< tombstones dropped after ParticipantOptions::tombstone_horizon
};

/// @brief One SimState's membership in a distributed model (see the file comment).
class Participant {
 public:
  /// @brief Joins @p options.domain and starts recording @p state.
  /// @throws vsd::Error when DDS cannot create the participant, topic, reader or writer (bad configuration,
  /// domain id out of range), or when @p state is already recording.
  Participant(SimState& state, ParticipantOptions options);
  /// @brief Stops recording (unpublished changes are dropped) and leaves the domain.
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  /// @brief This participant's random 64-bit id (never 0).
  [[nodiscard]] std::uint64_t id() const noexcept;
  [[nodiscard]] const std::string& name() const noexcept;
  [[nodiscard]] SimState& state() const noexcept;
  /// @brief True once the state is the shared model (seed, or a snapshot installed) and no resync is on.
  [[nodiscard]] bool synced() const noexcept;
  /// @brief Number of other participants' readers DDS has matched with this participant's writer.
  [[nodiscard]] std::size_t peers() const;

  /// @brief Sends the changes recorded since the last publish as one bundle, if any Distributed change is
  /// among them. A change to what another participant owns is undone here instead (the whole bundle) and
  /// reported (on_conflict, log, and to the owner). While unsynchronised, changes are dropped (counted).
  /// With Cyclone's write batching (Internal/WriteBatch, on in the shipped loopback configuration) the
  /// sample waits in the writer until the next poll(), poll_until() or flush() (docs/dist.md).
  /// @return true when a bundle was sent. @throws vsd::Error when the writer stays blocked past
  /// write_timeout.
  bool publish();
  /// @brief Hands everything published so far to the network now (poll() and poll_until() do it too).
  void flush();
  /// @brief publish(), then handles everything that arrived: applies bundles and claims in order, answers
  /// snapshot requests, installs a snapshot; then flush(). Never blocks. @return the number of bundles
  /// applied.
  std::size_t poll();
  /// @brief Polls until @p done returns true or @p timeout passes, sleeping on DDS data in between.
  /// @return the last value of @p done.
  bool poll_until(const std::function<bool()>& done, std::chrono::milliseconds timeout);
  /// @brief poll_until(synced()).
  bool wait_synced(std::chrono::milliseconds timeout);
  /// @brief Polls until at least @p n peers are matched (discovery done) or @p timeout passes.
  bool wait_peers(std::size_t n, std::chrono::milliseconds timeout);

  // ---- ownership ----
  /// @brief Makes this participant the owner of @p inst (every property, and its deletion). Sent to the
  /// others in order with the bundles. Two claims made at the same time by two participants both succeed
  /// locally at first; everywhere, the one with the lower stamp (Lamport clock, participant id) wins and
  /// the other is rolled back and reported (on_conflict, ConflictKind::ClaimRace).
  /// @throws vsd::Error when another participant owns it already (as far as this one knows).
  void claim(const SimStateInstance& inst);
  /// @brief Makes this participant the owner of one property of @p inst.
  /// @throws vsd::Error when the property does not exist or another participant owns it.
  void claim(const SimStateInstance& inst, std::string_view property);
  /// @brief Gives up what claim() took (no effect when this participant does not own it).
  void release(const SimStateInstance& inst, std::string_view property = {});
  /// @brief The owner of @p property of instance @p id (or of the instance itself when @p property is
  /// empty or has no owner of its own); 0 when nobody owns it.
  [[nodiscard]] std::uint64_t owner(Id id, std::string_view property = {}) const;
  /// @brief The name a participant id announced (its ParticipantOptions::name), or its id in hex.
  [[nodiscard]] std::string participant_name(std::uint64_t id) const;

  /// @brief Emitted for every conflict this participant takes part in (writer, owner), and for conflicts
  /// it rejected as a receiver.
  [[nodiscard]] Sink<void(const Conflict&)> on_conflict() noexcept;
  /// @brief Emitted after a snapshot was installed (the first synchronisation and every resync).
  [[nodiscard]] Sink<void()> on_synced() noexcept;
  [[nodiscard]] const ParticipantStats& stats() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vsd::dist
