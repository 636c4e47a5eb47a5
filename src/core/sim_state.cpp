// SimState: instance lifetime, signals and transaction recording.
#include "vsd/core/sim_state.hpp"

#include <algorithm>
#include <array>

#include "vsd/core/detail/state_builder.hpp"
#include "vsd/core/detail/tx_codec.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"

namespace vsd {

/// Marks a dispatch in progress: instances deleted meanwhile stay allocated until the outermost one
/// ends, so a listener that deletes an instance never pulls it from under the code that notifies.
struct SimState::Dispatch {
  explicit Dispatch(SimState& s) noexcept : s_(s) { ++s_.dispatching_; }
  ~Dispatch() {
    if (--s_.dispatching_ == 0 && !s_.graveyard_.empty()) s_.free_graveyard();
  }
  Dispatch(const Dispatch&) = delete;
  Dispatch& operator=(const Dispatch&) = delete;
  SimState& s_;
};

SimState::SimState(Environment& env, std::string name) : env_(&env), name_(std::move(name)) {
  set_meta(static_meta());
  property_changed_.on_first_listener(&SimState::watch_hook, this);
  root_ = static_cast<Database*>(&make(Database::static_meta(), 1));
}

/// A per-class property signal, with what its first listener needs to switch on the class's watch bits.
struct SimState::TypeSignal {
  PropertySignal signal;
  SimState* state;
  const MetaInstance* cls;
  bool subtypes;
  static void hook(void* self) {
    auto* t = static_cast<TypeSignal*>(self);
    t->state->enable_class_watch(*t->cls, t->subtypes);
  }
};

SimState::~SimState() {
  // Modules' per-state data first, while every instance and signal it may touch is whole.
  context_.clear();
  ++applying_;  // no cascades while tearing down
  // First cut every reference to every instance (free references outside become null), so that the
  // instances can then be freed in any order.
  by_id_.for_each([](Id, SimStateInstance* x) {
    while (x->composite_head_ != nullptr) x->composite_head_->drop();
    while (x->shared_head_ != nullptr) x->shared_head_->drop();
  });
  by_id_.for_each([](Id, SimStateInstance* x) { x->meta().destruct(x); });
  by_id_.clear();
  free_graveyard();
  // pool_ frees the memory of them all when it dies.
}

void SimState::free_graveyard() noexcept {
  while (!graveyard_.empty()) {
    SimStateInstance* x = graveyard_.back();
    graveyard_.pop_back();
    while (x->composite_head_ != nullptr) x->composite_head_->drop();  // free references still held
    while (x->shared_head_ != nullptr) x->shared_head_->drop();
    free_instance(*x);
  }
}

inline Id SimState::fresh_id() noexcept {
  if (VSD_UNLIKELY(id_next_ == id_end_ || id_generation_ != env_->id_generation())) take_ids();
  return id_next_++;
}

void SimState::take_ids() noexcept {
  // The generation is read before the block is taken: a reservation in between only makes the next
  // create take yet another block.
  id_generation_ = env_->id_generation();
  id_next_ = env_->next_ids(id_block);
  id_end_ = id_next_ + id_block;
}

void SimState::check_class(const MetaInstance& cls) {
  if (!cls.is_a(SimStateInstance::static_meta()))
    detail::throw_error("class '" + cls.name() + "' is not a SimStateInstance and cannot live in a SimState");
  if (cls.is_abstract())
    detail::throw_error("class '" + cls.name() + "' is abstract and cannot be instantiated");
  if (root_ != nullptr && cls.is_a(Database::static_meta()))
    detail::throw_error("SimState '" + name_ + "' already has its Database");
  // The answer depends on the class alone once the Database exists; class indexes are never reused.
  if (root_ != nullptr) checked_class_ = cls.index();
}

SimStateInstance& SimState::make(const MetaInstance& cls, Id id) {
  if (cls.index() != checked_class_) check_class(cls);
  SimStateInstance** slot = by_id_.try_insert(id);
  if (slot == nullptr)
    detail::throw_error("SimState '" + name_ + "' already has an instance #" + std::to_string(id));
  SimStateInstance* obj = nullptr;
  try {
    void* memory = pool_.allocate(cls);
    try {
      obj = cls.construct(memory);
    } catch (...) {
      pool_.deallocate(cls, memory);
      throw;
    }
  } catch (...) {
    by_id_.erase(id);
    throw;
  }
  *slot = obj;
  obj->state_ = this;
  obj->id_ = id;
  obj->life_ = SimStateInstance::floating_bit;
  obj->watch_ = static_cast<std::uint8_t>((state_watch_ ? SimStateInstance::state_watch : 0) |
                                          (type_signals_ != 0 && class_watched(cls) ? SimStateInstance::class_watch : 0));
  index_.add(*obj);
  return *obj;
}

void SimState::finish_create(SimStateInstance& inst) {
  // Nobody to tell and nothing to record: no dispatch either (nothing can be deleted meanwhile).
  if (!recording_ && !created_.has_listeners() && !index_.has_signals()) return;
  Dispatch d(*this);
  if (recording_) {
    detail::write_lifecycle(recorded_, Transaction::Op::Create, inst);
    ++recorded_ops_;
  }
  created_.emit(inst);
  index_.emit_created(inst);
}

SimStateInstance& SimState::create(const MetaInstance& cls) {
  SimStateInstance& inst = make(cls, fresh_id());
  if (recording_ || created_.has_listeners() || index_.has_signals()) {
    Dispatch d(*this);  // an instance deleted by a creation listener stays allocated until the check below
    finish_create(inst);
    if (VSD_UNLIKELY(inst.is_being_deleted()))
      detail::throw_error("the new instance #" + std::to_string(inst.id()) + " of class '" + cls.name() +
                          "' was deleted by a listener of its creation");
  }
  return inst;
}

// ---- StateBuilder (loaders) -------------------------------------------------------------------------------

namespace detail {

StateBuilder::StateBuilder(SimState& state) noexcept : state_(state) {
  ++state_.applying_;
  ++state_.dispatching_;  // one dispatch for the whole build: see the header
}

StateBuilder::~StateBuilder() {
  delete links_;  // gives up the block's unused rest; its links keep the block
  --state_.applying_;
  if (--state_.dispatching_ == 0 && !state_.graveyard_.empty()) state_.free_graveyard();
}

void StateBuilder::check_class(SimState& state, const MetaInstance& cls) { state.check_class(cls); }

void StateBuilder::reserve(const MetaInstance& cls, std::size_t count) {
  state_.reserve_instances(cls, count);
}

void StateBuilder::reserve_ids(std::size_t count) { state_.by_id_.reserve(state_.by_id_.size() + count); }

void StateBuilder::reserve_links(std::size_t count) {
  auto* block = new LinkBlock(count);
  delete links_;
  links_ = block;
}

SimStateInstance& StateBuilder::make(const MetaInstance& cls, Id id) { return state_.make(cls, id); }

void StateBuilder::finish_create(SimStateInstance& x) { state_.finish_create(x); }

namespace {
struct ListAppend : RefListBase {  // the builder's access to a list's editing operation
  using RefListBase::insert_at;
  using RefListBase::insert_link;
};
}  // namespace

void StateBuilder::append(SimStateInstance& holder, const MetaProperty& p, SimStateInstance& target) {
  auto& list = *static_cast<RefListBase*>(const_cast<void*>(p.address(holder)));
  const std::size_t index = list.size();
  if (links_ != nullptr)
    static_cast<ListAppend&>(list).insert_link(index, &target, links_->make(list.is_composite()));
  else
    static_cast<ListAppend&>(list).insert_at(index, &target);
  state_.list_changed(holder, p, index, target, true);
}

}  // namespace detail

SimStateInstance& SimState::create(std::string_view cls) { return create(env_->registry().get_class(cls)); }

SimStateInstance* SimState::find(Id id) const noexcept {
  SimStateInstance* x = by_id_.find(id);
  return x == nullptr || x->is_being_deleted() ? nullptr : x;
}

std::vector<SimStateInstance*> SimState::instances() const {
  std::vector<SimStateInstance*> out;
  out.reserve(by_id_.size());
  by_id_.for_each([&](Id, SimStateInstance* x) { out.push_back(x); });
  std::sort(out.begin(), out.end(), [](auto* a, auto* b) { return a->id() < b->id(); });
  return out;
}

void SimState::released(SimStateInstance& inst) {
  // While a bundle is applied, deletions come from the bundle itself; the Database is never released.
  if (applying_ != 0 || inst.is_being_deleted() || &inst == root_) return;
  // Deleting releases what the instance held, which may delete more: a cascade as deep as the tree. The
  // outermost release runs it as a loop (depth first, each instance's released targets in the order they
  // were released), so a chain of a million levels takes no million stack frames.
  if (cascade_ != nullptr) {
    cascade_->push_back(&inst);
    return;
  }
  if (dispatching_ == 0 && stands_alone(inst)) {  // a leaf nobody watches: nothing can follow
    destroy(inst);
    return;
  }
  Dispatch d(*this);  // what a listener deletes meanwhile stays allocated: the pending list may name it
  std::vector<SimStateInstance*> pending{&inst};
  cascade_ = &pending;
  struct Done {
    SimState& s;
    ~Done() { s.cascade_ = nullptr; }
  } done{*this};
  while (!pending.empty()) {
    SimStateInstance& x = *pending.back();
    pending.pop_back();
    const std::size_t before = pending.size();
    if (!x.is_being_deleted() && x.refs_ == 0 && !x.is_floating()) destroy(x);
    std::reverse(pending.begin() + static_cast<std::ptrdiff_t>(before), pending.end());
  }
}

void SimState::destroy(SimStateInstance& x) {
  if (x.state_ != this)
    detail::throw_error("instance #" + std::to_string(x.id()) + " belongs to SimState '" + x.state_->name_ +
                        "', not '" + name_ + "'");
  if (&x == root_) detail::throw_error("the Database of SimState '" + name_ + "' cannot be deleted");
  if (x.is_being_deleted()) return;
  if (dispatching_ == 0 && stands_alone(x)) {
    // No step of the deletion can call out (nobody listens, nothing is recorded, x holds and is held by
    // nothing) and no dispatch is running: x goes at once, without a dispatch and the graveyard.
    x.life_ |= SimStateInstance::dying_bit;
    by_id_.erase(x.id_);
    index_.remove(x);
    if (!instance_signals_.empty()) instance_signals_.erase(&x);
    free_instance(x);
    return;
  }
  Dispatch d(*this);
  x.life_ |= SimStateInstance::dying_bit;
  deleted_.emit(x);
  index_.emit_deleted(x);
  // 1. Leave every composite holder (a parent's children list, ...): each step is a recorded change.
  while (x.composite_head_ != nullptr) detach_link(*x.composite_head_);
  // 2. Release what x holds; composite targets that nothing else holds go with it.
  const auto refs = x.meta().reference_properties();
  for (auto it = refs.rbegin(); it != refs.rend(); ++it)
    if (!holds_nothing(x, **it)) clear_reference(x, **it);
  // 3. Null shared references to x; their holders are told through their change signals.
  while (x.shared_head_ != nullptr) detach_link(*x.shared_head_);
  if (recording_) {
    detail::write_lifecycle(recorded_, Transaction::Op::Delete, x);
    ++recorded_ops_;
  }
  by_id_.erase(x.id_);
  index_.remove(x);
  if (!instance_signals_.empty()) instance_signals_.erase(&x);
  graveyard_.push_back(&x);
}

bool SimState::stands_alone(const SimStateInstance& x) const noexcept {
  if (recording_ || deleted_.has_listeners() || index_.has_signals()) return false;
  if (x.composite_head_ != nullptr || x.shared_head_ != nullptr) return false;
  for (const MetaProperty* p : x.meta().reference_properties())
    if (!holds_nothing(x, *p)) return false;
  return true;
}

void SimState::free_instance(SimStateInstance& x) noexcept {
  const MetaInstance& cls = x.meta();
  cls.destruct(&x);
  pool_.deallocate(cls, &x);
}

bool SimState::holds_nothing(const SimStateInstance& inst, const MetaProperty& p) noexcept {
  const void* at = p.address(inst);
  return p.type().is_ref_list() ? static_cast<const RefListBase*>(at)->empty()
                                : static_cast<const RefBase*>(at)->get() == nullptr;
}

void SimState::detach_link(detail::RefLink& link) {
  SimStateInstance* holder = link.holder;
  if (holder == nullptr) {  // a free reference: it just becomes null
    link.drop();
    return;
  }
  const MetaProperty& p = *link.prop;
  if (p.type().is_ref_list()) {
    const auto& list = *static_cast<const RefListBase*>(p.address(*holder));
    holder->list_erase(p, list.index_of(link.target));
  } else {
    const Value null(p.type());
    p.assign_raw(*holder, null.data());
  }
}

void SimState::clear_reference(SimStateInstance& inst, const MetaProperty& p) {
  if (p.type().is_ref_list()) {
    const auto& list = *static_cast<const RefListBase*>(p.address(inst));
    while (!list.empty()) inst.list_erase(p, list.size() - 1);
  } else if (static_cast<const RefBase*>(p.address(inst))->get() != nullptr) {
    const Value null(p.type());
    p.assign_raw(inst, null.data());
  }
}

// ---- signals ----------------------------------------------------------------------------------------------

// Watching: an instance's watch_ byte sends its setters down the slow path. The state-wide bit is switched
// on for every instance when the SimState starts recording or its state-wide property signal gains a first
// listener; the class bit only for the instances of the classes that a per-class signal covers (so an
// instance of a class nobody watches keeps its one-branch setter). Both are switched off lazily, per
// instance, when a change finds nobody interested.

void SimState::enable_state_watch() {
  state_watch_ = true;
  by_id_.for_each([](Id, SimStateInstance* x) { x->watch_ |= SimStateInstance::state_watch; });
}

void SimState::watch_hook(void* state) { static_cast<SimState*>(state)->enable_state_watch(); }

bool SimState::state_watch_wanted() const noexcept { return recording_ || property_changed_.has_listeners(); }

void SimState::enable_class_watch(const MetaInstance& cls, bool subtypes) {
  std::fill(class_watch_.begin(), class_watch_.end(), std::uint8_t{0});  // new instances ask again
  index_.for_each(cls, subtypes, [](SimStateInstance& x) { x.watch_ |= SimStateInstance::class_watch; });
}

bool SimState::class_watched(const MetaInstance& cls) noexcept {
  const std::size_t k = cls.index();
  if (k < class_watch_.size() && class_watch_[k] != 0) return class_watch_[k] == 2;
  const bool watched = class_watched_slow(cls);
  if (class_watch_.size() <= k) class_watch_.resize(k + 1, 0);
  class_watch_[k] = watched ? 2 : 1;
  return watched;
}

bool SimState::class_watched_slow(const MetaInstance& cls) const noexcept {
  if (type_signal(cls, false) != nullptr) return true;
  for (const MetaInstance* m = &cls; m != nullptr; m = m->base())
    if (type_signal(*m, true) != nullptr) return true;
  return false;
}

SimState::PropertySink SimState::on_property_changed(const MetaInstance& type, bool include_subtypes) {
  auto& table = include_subtypes ? type_tree_ : type_exact_;
  if (table.size() <= type.index()) table.resize(type.index() + 1);
  auto& slot = table[type.index()];
  if (!slot) {
    slot = std::make_unique<TypeSignal>();
    slot->state = this;
    slot->cls = &type;
    slot->subtypes = include_subtypes;
    slot->signal.on_first_listener(&TypeSignal::hook, slot.get());
    ++type_signals_;
    class_signals_.clear();  // a class's list may gain this one
  }
  return PropertySink(slot->signal);
}

PropertySignal* SimState::type_signal(const MetaInstance& m, bool tree) const noexcept {
  const auto& table = tree ? type_tree_ : type_exact_;
  if (m.index() >= table.size()) return nullptr;
  TypeSignal* s = table[m.index()].get();
  return s != nullptr && s->signal.has_listeners() ? &s->signal : nullptr;
}

const SimState::ClassSignals& SimState::signals_of_slow(const MetaInstance& cls) {
  const std::size_t k = cls.index();
  if (k >= class_signals_.size()) class_signals_.resize(k + 1);
  ClassSignals& c = class_signals_[k];
  auto add = [&](const std::vector<std::unique_ptr<TypeSignal>>& table, const MetaInstance& m) {
    if (m.index() >= table.size() || !table[m.index()]) return;
    if (c.count == c.signals.size()) {
      c.deep = true;
    } else {
      c.signals[c.count++] = &table[m.index()]->signal;
    }
  };
  add(type_exact_, cls);
  for (const MetaInstance* m = &cls; m != nullptr; m = m->base()) add(type_tree_, *m);
  c.known = true;
  return c;
}

// The subtree signals of @p cls's chain past the eight that signals_of() keeps, in chain order.
std::vector<PropertySignal*> SimState::deeper_signals(const MetaInstance& cls) const {
  std::vector<PropertySignal*> out;  // only those with listeners
  std::size_t seen = cls.index() < type_exact_.size() && type_exact_[cls.index()] ? 1 : 0;
  for (const MetaInstance* m = &cls; m != nullptr; m = m->base())
    if (m->index() < type_tree_.size() && type_tree_[m->index()] && ++seen > ClassSignals{}.signals.size())
      if (PropertySignal* s = type_signal(*m, true)) out.push_back(s);
  return out;
}

void SimState::emit_property(SimStateInstance& inst, const MetaProperty& p) {
  // Collect first, emit after: a listener may delete the instance or disconnect anyone.
  PropertySignal* own = nullptr;
  if ((inst.watch_ & SimStateInstance::own_watch) != 0) {
    auto it = instance_signals_.find(&inst);
    if (it != instance_signals_.end() && it->second->has_listeners()) {
      own = it->second.get();
    } else {
      inst.watch_ &= static_cast<std::uint8_t>(~SimStateInstance::own_watch);
    }
  }
  PropertySignal* typed[8];  // the class's exact signal, then subtree ones, that have listeners
  std::size_t n = 0;
  bool deep = false;  // more per-class signals in the chain than those eight (emit_deeper)
  if (type_signals_ != 0) {
    const ClassSignals& c = signals_of(inst.meta());
    for (std::size_t i = 0; i < c.count; ++i)
      if (c.signals[i]->has_listeners()) typed[n++] = c.signals[i];
    deep = c.deep;
  }
  const bool state_wide = property_changed_.has_listeners();
  if (own == nullptr && n == 0 && !state_wide && !recording_ && (!deep || deeper_signals(inst.meta()).empty())) {
    // Nobody is interested in this instance: back to the fast path until a signal gains a listener.
    inst.watch_ &= static_cast<std::uint8_t>(~(SimStateInstance::state_watch | SimStateInstance::class_watch));
    if (state_watch_ && !state_watch_wanted()) state_watch_ = false;
    return;
  }
  if (own != nullptr) own->emit(inst, p);
  for (std::size_t i = 0; i < n; ++i) typed[i]->emit(inst, p);
  if (VSD_UNLIKELY(deep))
    for (PropertySignal* s : deeper_signals(inst.meta())) s->emit(inst, p);  // collected before emitting
  if (state_wide) property_changed_.emit(inst, p);
}

void SimState::property_changed(SimStateInstance& inst, const MetaProperty& p, const void* old_value) {
  Dispatch d(*this);
  if (recording_ && !p.has(Transient) && derive_depth_ != dispatching_) {
    detail::write_set(recorded_, inst, p, old_value, p.address(inst));
    ++recorded_ops_;
  }
  emit_property(inst, p);
}

void SimState::list_changed(SimStateInstance& holder, const MetaProperty& p, std::size_t index,
                            SimStateInstance& target, bool inserted) {
  Dispatch d(*this);
  if (recording_ && !p.has(Transient) && derive_depth_ != dispatching_) {
    detail::write_list(recorded_, inserted ? Transaction::Op::Insert : Transaction::Op::Erase, holder.id(), p,
                       index, target.id());
    ++recorded_ops_;
  }
  if (&p == &Node::vsd_prop_children()) {
    auto& parent = static_cast<Node&>(holder);
    auto& child = static_cast<Node&>(target);
    if (inserted) {
      child_added_.emit(parent, child);
      root_->notify_attached(parent, child);
    } else {
      child_removed_.emit(parent, child);
      root_->notify_detached(parent, child);
    }
  } else if (&p == &NamedModelInstance::vsd_prop_extensions()) {
    auto& owner = static_cast<NamedModelInstance&>(holder);
    auto& ext = static_cast<Extension&>(target);
    (inserted ? extension_added_ : extension_removed_).emit(owner, ext);
  }
  if (holder.watch_ != 0) emit_property(holder, p);
}

// ---- transactions -----------------------------------------------------------------------------------------

void SimState::start_recording() {
  if (recorded_.empty()) detail::write_tx_header(recorded_);
  recording_ = true;
  enable_state_watch();
}

Transaction SimState::take_recording() {
  Transaction t;
  take_recording(t);
  return t;
}

void SimState::take_recording(Transaction& into) {
  into.bytes_.clear();
  std::swap(into.bytes_, recorded_);
  into.ops_ = recorded_ops_;
  if (into.bytes_.empty()) detail::write_tx_header(into.bytes_);  // nothing was recorded: an empty bundle
  recorded_ops_ = 0;
  if (recording_) {
    // A stepped state records about as much each step: room for half as much again as the last bundle
    // spares the buffer its doublings (no copies); it follows the bundles' size, so one large bundle
    // costs memory for one step only. A buffer handed back through take_recording(into) has the room
    // already after a step or two.
    recorded_.reserve(into.bytes_.size() + into.bytes_.size() / 2);
    detail::write_tx_header(recorded_);
  } else {
    recorded_ = std::vector<std::uint8_t>();  // stopped: hold no buffer
  }
  if (into.ops_ != 0) bundle_.emit(into);
}

SimState::Savepoint SimState::savepoint() {
  Savepoint sp{recorded_.size(), recorded_ops_, recording_};
  if (!recording_) {
    // Not start_recording(): it would visit every instance when the state watch is on already (a
    // state-wide listener turned it on), and a savepoint is taken per net firing.
    if (recorded_.empty()) detail::write_tx_header(recorded_);
    recording_ = true;
    if (!state_watch_) enable_state_watch();
  }
  return sp;
}

void SimState::release(const Savepoint& sp) noexcept {
  if (sp.was_recording) return;
  recording_ = false;
  recorded_.resize(sp.bytes);  // keeps the capacity for the next savepoint
  recorded_ops_ = sp.ops;
}

void SimState::roll_back(const Savepoint& sp) {
  if (!recording_ || recorded_.size() < sp.bytes || recorded_ops_ < sp.ops) {
    release(sp);
    throw Error("savepoint: the recording of SimState '" + name() +
                "' was taken or stopped while the savepoint was open; nothing was undone");
  }
  // The changes since sp as a bundle of their own (a header, then their operations), inverted.
  const std::size_t from = std::max(sp.bytes, detail::tx_header_size);
  std::vector<std::uint8_t> bytes;
  detail::write_tx_header(bytes);
  if (recorded_.size() > from)
    bytes.insert(bytes.end(), recorded_.begin() + static_cast<std::ptrdiff_t>(from), recorded_.end());
  const Transaction undo = detail::make_transaction(std::move(bytes), recorded_ops_ - sp.ops).inverted();
  // The undo itself is not recorded: the changes it reverses are dropped from the recording instead.
  recording_ = false;
  auto resume = [&] {
    recording_ = true;
    // An instance changed while nothing recorded or listened drops its watch bit (emit_property's fast
    // path): set them again, or the changes after the savepoint would go unrecorded.
    if (sp.was_recording) enable_state_watch();
    release(sp);
  };
  try {
    apply(undo);
  } catch (...) {  // nothing was undone (apply is all or nothing): the recording keeps the changes
    resume();
    throw;
  }
  recorded_.resize(std::max(sp.bytes, from));
  recorded_ops_ = sp.ops;
  resume();
}

Transaction SimState::stop_recording() {
  recording_ = false;
  Transaction t = take_recording();
  return t;
}

Transaction SimState::snapshot() const {
  Transaction t;  // starts with the header
  std::vector<std::uint8_t>& out = t.bytes_;
  const auto all = instances();
  for (SimStateInstance* x : all) {
    if (x == root_) {
      for (const MetaProperty* p : x->meta().properties()) {
        if (!detail::carried_in_payload(*p) || p->type().equal(p->address(*x), p->default_value().data()))
          continue;
        detail::write_set(out, *x, *p, p->default_value().data(), p->address(*x));
        ++t.ops_;
      }
      continue;
    }
    detail::write_lifecycle(out, Transaction::Op::Create, *x);
    ++t.ops_;
  }
  for (SimStateInstance* x : all) {
    for (const MetaProperty* p : x->meta().reference_properties()) {
      if (p->has(Transient)) continue;
      if (p->type().is_ref_list()) {
        const auto& list = *static_cast<const RefListBase*>(p->address(*x));
        for (std::size_t i = 0; i < list.size(); ++i) {
          detail::write_list(out, Transaction::Op::Insert, x->id(), *p, i, list.at(i)->id());
          ++t.ops_;
        }
      } else if (static_cast<const RefBase*>(p->address(*x))->get() != nullptr) {
        const Value null(p->type());
        detail::write_set(out, *x, *p, null.data(), p->address(*x));
        ++t.ops_;
      }
    }
  }
  return t;
}

void SimState::copy_from(const SimState& other) {
  if (size() != 1 || !root_->children().empty())
    detail::throw_error("copy_from needs an empty SimState, but '" + name_ + "' holds " +
                        std::to_string(size()) + " instances");
  apply(other.snapshot());
}

bool SimState::equals(const SimState& other, std::string* difference) const {
  auto differ = [&](std::string what) {
    if (difference != nullptr) *difference = std::move(what);
    return false;
  };
  if (size() != other.size())
    return differ("instance count " + std::to_string(size()) + " vs " + std::to_string(other.size()));
  for (SimStateInstance* x : instances()) {
    const SimStateInstance* y = other.find(x->id());
    if (y == nullptr) return differ("#" + std::to_string(x->id()) + " missing");
    if (&x->meta() != &y->meta())
      return differ("#" + std::to_string(x->id()) + " is a " + x->meta().name() + " vs a " +
                    y->meta().name());
    for (const MetaProperty* p : x->meta().properties()) {
      if (p->has(Transient)) continue;
      if (!p->type().equal(p->address(*x), p->address(*y)))
        return differ("#" + std::to_string(x->id()) + "." + p->name() + ": " +
                      p->type().to_text(p->address(*x)) + " vs " + p->type().to_text(p->address(*y)));
    }
  }
  return true;
}

}  // namespace vsd
