/** @file
 *  @brief Watch: one subscription to the changes of a SimState — classes × properties (by MetaProperty),
 *  creation, deletion and re-parenting — for modules that keep data derived from the database.
 *
 *  A module says once what its derived data depends on (Drake's dependency tracker): "the frame of every
 *  Node3D", "role and geometry of every Hull", "any property of a Geometry", "Hulls created or deleted",
 *  "Node3Ds that changed parent". The Watch then hears exactly those changes and nothing else, and hands
 *  them over in one of two ways:
 *
 *  - **queued** (the default): one report per instance (or per instance and property, when asked),
 *    de-duplicated, which the module drains at its step — `watch.drain([](const Watch::Report& r) {...})`.
 *    A hundred sets of one frame in a step are one report. on_pending() tells when the first report
 *    arrives after a drain (to trigger an event-driven scheduler task).
 *  - **at once**: a callback runs inside the change, for derived data that must never be seen stale (a
 *    world-frame cache is invalidated at once and recomputed lazily on the next read).
 *
 *  Cost: subscriptions are per class. Only the setters of instances of watched classes leave their
 *  one-branch fast path; an instance of a class nobody watches costs what it costs with no Watch at all.
 *  Properties are matched by MetaProperty pointer (a bit test), never by name.
 *
 *  Lifetime and threading: a Watch belongs to its SimState's thread and must not outlive the SimState
 *  (keep it in the state's context, see StateContext). Subscribing and destroying a Watch are safe at
 *  any time, inside a signal's dispatch too. Reports of deleted instances carry the id only: the
 *  instance is gone by the time the report is drained (SimState::find returns nullptr).
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <span>
#include <vector>

#include "vsd/core/fwd.hpp"
#include "vsd/core/signal.hpp"

namespace vsd {

/// @brief What happened to an instance: a set of bits (`Changes::created | Changes::property`).
class Changes {
 public:
  constexpr Changes() noexcept = default;
  constexpr explicit Changes(std::uint8_t bits) noexcept : bits_(bits) {}
  [[nodiscard]] constexpr std::uint8_t bits() const noexcept { return bits_; }
  [[nodiscard]] constexpr bool has(Changes c) const noexcept { return (bits_ & c.bits_) == c.bits_ && c.bits_ != 0; }
  [[nodiscard]] constexpr bool empty() const noexcept { return bits_ == 0; }
  constexpr Changes operator|(Changes o) const noexcept { return Changes{static_cast<std::uint8_t>(bits_ | o.bits_)}; }
  constexpr Changes& operator|=(Changes o) noexcept {
    bits_ = static_cast<std::uint8_t>(bits_ | o.bits_);
    return *this;
  }
  constexpr bool operator==(const Changes&) const noexcept = default;

  static const Changes created;   ///< the instance was created
  static const Changes deleted;   ///< the instance was deleted (it is gone when the report is drained)
  static const Changes property;  ///< a watched property changed
  static const Changes parent;    ///< the node was added to or removed from a parent's children

 private:
  std::uint8_t bits_ = 0;
};
inline constexpr Changes Changes::created{1};
inline constexpr Changes Changes::deleted{2};
inline constexpr Changes Changes::property{4};
inline constexpr Changes Changes::parent{8};

class Watch {
 public:
  /// @brief How queued reports are de-duplicated.
  enum class Granularity : std::uint8_t {
    instance,      ///< one report per instance; Report::property is null
    per_property,  ///< one report per instance and property (created, deleted, parent: property null)
  };
  /// @brief One de-duplicated report of a queued Watch.
  struct Report {
    Id id;                           ///< the instance (look it up with SimState::find)
    const MetaProperty* property;    ///< the changed property (Granularity::per_property), else null
    Changes changes;                 ///< everything that happened to it since the last drain
  };
  /// @brief The callback of a Watch that reports at once: the instance (whole, also when it is being
  /// deleted), the property for Changes::property (else null), and what happened.
  using Callback = std::function<void(SimStateInstance& instance, const MetaProperty* property, Changes what)>;

  /// @brief A queued Watch of @p state.
  explicit Watch(SimState& state, Granularity granularity = Granularity::instance);
  /// @brief A Watch of @p state that calls @p callback inside each change instead of queueing it.
  Watch(SimState& state, Callback callback);
  /// @brief The same with a plain function and its context (`fn(context, instance, property, what)`):
  /// one indirect call less per change, for a module on a hot path (the SOML++ executor).
  using Function = void (*)(void* context, SimStateInstance& instance, const MetaProperty* property, Changes what);
  Watch(SimState& state, Function function, void* context);
  Watch(const Watch&) = delete;
  Watch& operator=(const Watch&) = delete;
  ~Watch();

  [[nodiscard]] SimState& state() const noexcept { return *state_; }

  // ---- what to watch (adds to what is watched already; takes effect at once) ----
  /// @brief Changes of @p properties of instances of @p cls and its subclasses.
  /// @throws vsd::Error when a property is not one of @p cls (its own or inherited).
  Watch& properties(const MetaInstance& cls, std::span<const MetaProperty* const> properties);
  Watch& properties(const MetaInstance& cls, std::initializer_list<const MetaProperty*> properties) {
    return this->properties(cls, std::span<const MetaProperty* const>(properties.begin(), properties.size()));
  }
  /// @brief Changes of any property of instances of @p cls and its subclasses.
  Watch& all_properties(const MetaInstance& cls);
  /// @brief Creation of instances of @p cls and its subclasses.
  Watch& created(const MetaInstance& cls);
  /// @brief Deletion of instances of @p cls and its subclasses (reported while they are whole when at once).
  Watch& deleted(const MetaInstance& cls);
  /// @brief Nodes of @p cls (a Node class) and its subclasses added to or removed from a parent, or
  /// extensions of @p cls (an Extension class) attached to or detached from an owner. Watching this needs
  /// no watch of the parent's or owner's class: the change is reported whoever holds the instance.
  /// @throws vsd::Error when @p cls is neither a Node nor an Extension class.
  Watch& reparented(const MetaInstance& cls);

  // ---- queued delivery ----
  /// @brief True when no report waits.
  [[nodiscard]] bool empty() const noexcept { return pending_.empty(); }
  /// @brief Number of reports waiting.
  [[nodiscard]] std::size_t size() const noexcept { return pending_.size(); }
  /// @brief Hands every waiting report to @p fn, oldest first, and forgets them. Changes that @p fn
  /// makes (or that happen meanwhile) are reported by the next drain.
  template <class F>
  void drain(F&& fn) {
    std::vector<Report> batch = take();
    for (const Report& r : batch) fn(r);
  }
  /// @brief The waiting reports, oldest first; the queue is empty afterwards.
  [[nodiscard]] std::vector<Report> take();
  /// @brief Forgets every waiting report.
  void clear() noexcept;
  /// @brief Calls @p hook whenever a report arrives in an empty queue (e.g. to trigger a scheduler task).
  void on_pending(std::function<void()> hook) { on_pending_ = std::move(hook); }

 private:
  struct Filter;  // one subscription of property changes: a class and a bit set of its properties
  void report(SimStateInstance& inst, const MetaProperty* p, Changes what);
  void queue(Id id, const MetaProperty* p, Changes what);
  void grow();
  Filter& filter_of(const MetaInstance& cls);

  SimState* state_;
  Granularity granularity_ = Granularity::instance;
  Callback callback_;
  Function function_ = nullptr;  // at once: called with context_ (a Callback is called through it)
  void* context_ = nullptr;
  std::function<void()> on_pending_;
  std::vector<Report> pending_;
  std::vector<std::uint32_t> table_;  // open addressing: index + 1 into pending_, 0 = empty
  std::vector<std::unique_ptr<Filter>> filters_;
  std::vector<const MetaInstance*> parent_classes_;
  std::vector<Connection> connections_;
  bool child_connected_ = false;
  bool extension_connected_ = false;
};

}  // namespace vsd
