/** @file
 *  @brief SimState: one state of the simulation — it owns its instances, the Database (spanning
 *  tree), the ElementIndex and the signals, and it records and applies transactions.
 *
 *  Threading rule: a SimState belongs to one thread at a time. Other threads never touch it; they
 *  build their own SimState and hand over a Transaction (bytes), which the owner applies.
 *
 *  Lifetime: instances live until deleted explicitly, until their last composite reference is
 *  released, or until the SimState is destroyed. Deleting an instance deletes the composite subtree that
 *  nothing else holds, nulls every shared reference to it (signalling the holders), and is recorded as
 *  the sequence of those steps, so that a replica applying the bundle ends equal to the source.
 *
 *  Memory: a SimState keeps the memory of its deleted instances and reuses it for its next instances of
 *  the same class (detail::InstancePool); it goes back to the system when the SimState is destroyed.
 *  An instance deleted while a signal is being dispatched stays allocated until the outermost dispatch
 *  ends. Ids are taken from the Environment in blocks (Environment::next_ids), so they are unique in the
 *  Environment but not consecutive across SimStates.
 */
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>  // instance_signals_
#include <vector>

#include "vsd/core/database.hpp"
#include "vsd/core/declare.hpp"
#include "vsd/core/detail/id_map.hpp"
#include "vsd/core/detail/instance_pool.hpp"
#include "vsd/core/element_index.hpp"
#include "vsd/core/state_context.hpp"
#include "vsd/core/transaction.hpp"

namespace vsd {

class Environment;
namespace detail {
class Applier;
class StateBuilder;
}  // namespace detail

class SimState : public Instance {
  VSD_ABSTRACT_INSTANCE(SimState, Instance)

 public:
  using InstanceSignal = Signal<void(SimStateInstance&)>;
  using ChildSignal = Signal<void(Node& parent, Node& child)>;
  using InstanceSink = Sink<void(SimStateInstance&)>;
  using PropertySink = Sink<void(SimStateInstance&, const MetaProperty&)>;
  using ChildSink = Sink<void(Node& parent, Node& child)>;
  using ExtensionSignal = Signal<void(NamedModelInstance& owner, Extension& extension)>;
  using ExtensionSink = Sink<void(NamedModelInstance& owner, Extension& extension)>;

  SimState(Environment& env, std::string name);
  ~SimState() override;

  [[nodiscard]] Environment& environment() const noexcept { return *env_; }
  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  /// @brief The root of the spanning tree (id 1).
  [[nodiscard]] Database& database() const noexcept { return *root_; }
  [[nodiscard]] ElementIndex& index() noexcept { return index_; }
  [[nodiscard]] const ElementIndex& index() const noexcept { return index_; }

  // ---- instances ----
  /// @brief Creates an instance of class T (built-in or a C++ class declared with VSD_INSTANCE).
  /// The new instance floats (see is_floating()) until a property attaches it. The on_created listeners
  /// run before this returns; should one of them delete the new instance, create() throws vsd::Error
  /// instead of returning a reference to a deleted instance (the creation and the deletion both happened
  /// and were recorded).
  template <class T>
  T& create() {
    return static_cast<T&>(create(T::static_meta()));
  }
  /// @brief Creates an instance of @p cls (built-in or run-time). @throws vsd::Error for abstract classes,
  /// and when an on_created listener deleted the new instance (see create<T>()).
  SimStateInstance& create(const MetaInstance& cls);
  /// @brief Creates an instance of the class named @p cls. @throws vsd::Error for unknown names.
  SimStateInstance& create(std::string_view cls);
  /// @brief Deletes @p inst now (see the file comment). @throws vsd::Error for the Database root or an
  /// instance of another SimState.
  void destroy(SimStateInstance& inst);
  /// @brief The instance with id @p id, or nullptr.
  [[nodiscard]] SimStateInstance* find(Id id) const noexcept;
  template <class T>
  [[nodiscard]] T* find(Id id) const noexcept {
    SimStateInstance* i = find(id);
    return i != nullptr ? i->template as<T>() : nullptr;
  }
  /// @brief Number of live instances, the Database included.
  [[nodiscard]] std::size_t size() const noexcept { return by_id_.size(); }
  /// @brief All live instances, ordered by id.
  [[nodiscard]] std::vector<SimStateInstance*> instances() const;

  // ---- signals (sinks: anyone may listen, only the SimState emits) ----
  /// @brief Emitted after an instance is created and has its initial values.
  [[nodiscard]] InstanceSink on_created() noexcept { return InstanceSink(created_); }
  /// @brief Emitted when an instance starts being deleted, while it is still whole.
  [[nodiscard]] InstanceSink on_deleted() noexcept { return InstanceSink(deleted_); }
  /// @brief Emitted for every property change of every instance (reference lists included). A listener
  /// here sends every setter of the state down its slow path; prefer a per-class signal or a Watch.
  [[nodiscard]] PropertySink on_property_changed() noexcept { return PropertySink(property_changed_); }
  /// @brief Emitted for property changes of instances of @p type (and subclasses, when asked). Only the
  /// setters of instances of those classes leave their fast path while the signal has listeners.
  [[nodiscard]] PropertySink on_property_changed(const MetaInstance& type, bool include_subtypes = true);
  [[nodiscard]] ChildSink on_child_added() noexcept { return ChildSink(child_added_); }
  [[nodiscard]] ChildSink on_child_removed() noexcept { return ChildSink(child_removed_); }
  /// @brief Emitted when an extension is attached to a node or another extension (its owner's
  /// `extensions` list gains it), whether or not anybody watches the owner.
  [[nodiscard]] ExtensionSink on_extension_added() noexcept { return ExtensionSink(extension_added_); }
  /// @brief Emitted when an extension is detached from its owner (also when either is deleted).
  [[nodiscard]] ExtensionSink on_extension_removed() noexcept { return ExtensionSink(extension_removed_); }

  // ---- per-state data of modules ----
  /// @brief Typed slots for data that belongs to this state alone (a module's collision world, ODE world,
  /// compiled models, executors): created by the module when it starts to serve the state, destroyed
  /// before the state's instances (see StateContext).
  [[nodiscard]] StateContext& context() noexcept { return context_; }
  [[nodiscard]] const StateContext& context() const noexcept { return context_; }
  /// @brief True for the main state of its Environment.
  [[nodiscard]] bool is_main() const noexcept { return main_; }

  // ---- transactions ----
  /// @brief Starts recording every change into a bundle (continues an ongoing recording).
  void start_recording();
  /// @brief True while recording.
  [[nodiscard]] bool recording() const noexcept { return recording_; }
  /// @brief True while a bundle is being applied (or the state torn down): listeners that derive
  /// changes of their own from what they hear (e.g. vsd::scene::SpatialView) hold back, since the
  /// bundle carries those changes already.
  [[nodiscard]] bool applying() const noexcept { return applying_ > 0; }
  /// @brief The changes recorded so far; recording goes on with an empty bundle. A bundle that is not
  /// empty is also handed to the on_bundle() listeners.
  Transaction take_recording();
  /// @brief take_recording() into @p into: the bundle replaces what @p into held, and the state records
  /// on into @p into's old buffer (emptied, its capacity kept). A reader that takes a bundle every step
  /// and keeps a copy or nothing (the web inspector's timeline) so records into the same warm memory every
  /// step instead of into a fresh allocation. The on_bundle() listeners hear the bundle as with
  /// take_recording().
  void take_recording(Transaction& into);
  /// @brief Listeners of every bundle the recording hands out (take_recording(), stop_recording()),
  /// whoever takes it: one reader cuts the recording (vsd::dist at each poll, or the web inspector at
  /// the end of a step), and every other reader still sees every recorded change once, in order.
  /// Listeners must not change the state.
  [[nodiscard]] Sink<void(const Transaction&)> on_bundle() noexcept {
    return Sink<void(const Transaction&)>(bundle_);
  }
  /// @brief Stops recording and returns what was recorded.
  Transaction stop_recording();
  /// @brief A point in the changes of this state that roll_back() returns to (see savepoint()).
  struct Savepoint {
    std::size_t bytes = 0;       ///< size of the recording at the savepoint
    std::size_t ops = 0;         ///< operations recorded at the savepoint
    bool was_recording = false;  ///< whether the state recorded before the savepoint
  };
  /// @brief Marks the present state so that every later change can be undone with roll_back(); records
  /// from now on if the state did not record yet. End it with release() or roll_back(), innermost first.
  Savepoint savepoint();
  /// @brief Keeps the changes since @p sp. When the state did not record before @p sp, recording stops
  /// again and the changes since @p sp are dropped from the buffer (they stay in the state).
  void release(const Savepoint& sp) noexcept;
  /// @brief Undoes every change since @p sp — property values, reference lists, created and deleted
  /// instances (re-created with their ids and last values) — by applying their inverse, which emits the
  /// ordinary signals, and removes them from the recording; then release(sp). Transient properties are
  /// not recorded, so they are not undone. @throws vsd::Error when the inverse does not apply (the
  /// state then records as before @p sp).
  void roll_back(const Savepoint& sp);
  /// @brief Marks the changes that the code in its scope makes to the state as *derived*: they are
  /// signalled like any change but not recorded, because every state derives them itself from what is
  /// recorded (a link's frame from its joint value, a mimic joint's value from its master's). A bundle then
  /// carries the cause once, and a replica or an undo re-derives the rest through the same module. What
  /// listeners change in reaction to a derived change is recorded as usual (a box carried by a moving link
  /// is a recorded move). Only property and list changes can be derived; creations and deletions are
  /// always recorded. Scopes nest.
  class Deriving {
   public:
    explicit Deriving(SimState& state) noexcept : state_(state), previous_(state.derive_depth_) {
      state.derive_depth_ = state.dispatching_ + 1;  // the depth of the changes made right here
    }
    ~Deriving() { state_.derive_depth_ = previous_; }
    Deriving(const Deriving&) = delete;
    Deriving& operator=(const Deriving&) = delete;

   private:
    SimState& state_;
    int previous_;
  };
  /// @brief Applies a bundle. Everything is checked first (ids, classes, properties, values, list
  /// positions): a bundle that does not fit this state throws vsd::Error and changes nothing.
  void apply(const Transaction& t);
  /// @brief The whole state as a bundle that rebuilds it in an empty SimState.
  [[nodiscard]] Transaction snapshot() const;
  /// @brief Makes this (empty) state a copy of @p other. @throws vsd::Error when this state is not empty.
  void copy_from(const SimState& other);
  /// @brief Deep comparison: same ids, classes and property values (references by id).
  /// @param difference receives a description of the first difference found.
  [[nodiscard]] bool equals(const SimState& other, std::string* difference = nullptr) const;

 private:
  friend class SimStateInstance;
  friend class Node;
  friend class Database;
  friend struct detail::RefAccess;
  friend class detail::Applier;
  friend class detail::StateBuilder;

  SimStateInstance& make(const MetaInstance& cls, Id id);
  void check_class(const MetaInstance& cls);  // may cls live here? (throws when not)
  void reserve_instances(const MetaInstance& cls, std::size_t count) {  // room for count more of cls
    index_.reserve(cls, count);
    pool_.reserve(cls, count);
  }
  /// The next id of the block this state took from its Environment (see Environment::next_ids).
  Id fresh_id() noexcept;
  void take_ids() noexcept;
  static constexpr std::size_t id_block = 64;
  void finish_create(SimStateInstance& inst);
  void released(SimStateInstance& inst);  // last composite reference went away
  void detach_link(detail::RefLink& link);
  void clear_reference(SimStateInstance& inst, const MetaProperty& p);
  static bool holds_nothing(const SimStateInstance& inst, const MetaProperty& p) noexcept;
  bool stands_alone(const SimStateInstance& x) const noexcept;  // can x be freed without telling anyone?
  void free_instance(SimStateInstance& x) noexcept;             // destructors, then back to the pool
  void enable_state_watch();
  static void watch_hook(void* state);
  bool state_watch_wanted() const noexcept;
  struct TypeSignal;  // a per-class property signal and what its first listener switches on
  void enable_class_watch(const MetaInstance& cls, bool subtypes);
  bool class_watched(const MetaInstance& cls) noexcept;
  [[nodiscard]] bool class_watched_slow(const MetaInstance& cls) const noexcept;
  void property_changed(SimStateInstance& inst, const MetaProperty& p, const void* old_value);
  void list_changed(SimStateInstance& holder, const MetaProperty& p, std::size_t index,
                    SimStateInstance& target, bool inserted);
  PropertySignal* type_signal(const MetaInstance& m, bool tree) const noexcept;
  friend class Environment;
  StateContext context_;  // cleared first thing in ~SimState, while every instance and signal is whole
  bool main_ = false;
  void emit_property(SimStateInstance& inst, const MetaProperty& p);
  void free_graveyard() noexcept;
  struct Dispatch;

  Environment* env_;
  std::string name_;
  detail::InstancePool pool_;  // the memory of the instances; declared first, so it dies last
  Database* root_ = nullptr;
  detail::IdMap by_id_;
  ElementIndex index_;
  InstanceSignal created_;
  InstanceSignal deleted_;
  PropertySignal property_changed_;
  ChildSignal child_added_;
  ChildSignal child_removed_;
  ExtensionSignal extension_added_;
  ExtensionSignal extension_removed_;
  Signal<void(const Transaction&)> bundle_;
  std::unordered_map<const SimStateInstance*, std::unique_ptr<PropertySignal>> instance_signals_;
  std::vector<std::unique_ptr<TypeSignal>> type_exact_, type_tree_;
  std::vector<std::uint8_t> class_watch_;  // per class index: 0 not known yet, 1 unwatched, 2 watched
  // Per class index: the per-class signals a property change of its instances goes to (its exact one,
  // then the subtree ones of it and its bases, most derived first), so a set does not walk the class
  // chain. Made on first use; forgotten when a per-class signal is made (signals are never destroyed
  // before the state, so the pointers stay valid).
  struct ClassSignals {
    bool known = false;
    bool deep = false;  // more than fit: emit_property walks the chain
    std::uint8_t count = 0;
    std::array<PropertySignal*, 8> signals{};
  };
  std::vector<ClassSignals> class_signals_;
  const ClassSignals& signals_of(const MetaInstance& cls) {
    const std::size_t k = cls.index();
    if (VSD_LIKELY(k < class_signals_.size() && class_signals_[k].known)) return class_signals_[k];
    return signals_of_slow(cls);
  }
  const ClassSignals& signals_of_slow(const MetaInstance& cls);
  [[nodiscard]] std::vector<PropertySignal*> deeper_signals(const MetaInstance& cls) const;
  std::vector<SimStateInstance*> graveyard_;  // deleted during a dispatch, freed when it ends
  std::vector<SimStateInstance*>* cascade_ = nullptr;  // released instances still to delete (released())
  int dispatching_ = 0;
  int derive_depth_ = -1;  // dispatch depth of derived changes (see Deriving), -1 when none
  std::size_t type_signals_ = 0;
  std::vector<std::uint8_t> recorded_;
  std::size_t recorded_ops_ = 0;
  int applying_ = 0;
  bool recording_ = false;
  bool state_watch_ = false;
  Id id_next_ = null_id;  // ids of the current block: [id_next_, id_end_)
  Id id_end_ = null_id;
  std::uint64_t id_generation_ = 0;
  std::size_t checked_class_ = static_cast<std::size_t>(-1);  // index of the last class make() accepted
};

}  // namespace vsd
