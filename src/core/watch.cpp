// Watch: class × property subscriptions over the SimState's per-class signals, with a de-duplicating queue.
#include "vsd/core/watch.hpp"

#include <algorithm>
#include <bit>

#include "vsd/core/error.hpp"
#include "vsd/core/extension.hpp"
#include "vsd/core/node.hpp"
#include "vsd/core/sim_state.hpp"

namespace vsd {

// The properties of one class that a Watch follows: a bit per property index. A class's properties keep
// their indexes in every subclass (inherited ones come first), so one bit set serves the whole subtree.
struct Watch::Filter {
  Watch* watch = nullptr;
  const MetaInstance* cls = nullptr;
  std::vector<std::uint64_t> bits;
  bool all = false;

  [[nodiscard]] bool matches(const MetaProperty& p) const noexcept {
    if (all) return true;
    const std::size_t i = p.index();
    return i / 64 < bits.size() && ((bits[i / 64] >> (i % 64)) & 1U) != 0;
  }
  // Connected as a member (no allocation, one load less per change than a capturing lambda).
  void heard(SimStateInstance& inst, const MetaProperty& p) {
    if (matches(p)) watch->report(inst, &p, Changes::property);
  }
};

Watch::Watch(SimState& state, Granularity granularity) : state_(&state), granularity_(granularity) {}

Watch::Watch(SimState& state, Callback callback) : state_(&state), callback_(std::move(callback)) {
  if (!callback_) detail::throw_error("a Watch that reports at once needs a callback");
  function_ = [](void* self, SimStateInstance& inst, const MetaProperty* p, Changes what) {
    static_cast<Watch*>(self)->callback_(inst, p, what);
  };
  context_ = this;
}

Watch::Watch(SimState& state, Function function, void* context)
    : state_(&state), function_(function), context_(context) {
  if (function_ == nullptr) detail::throw_error("a Watch that reports at once needs a callback");
}

Watch::~Watch() = default;  // the connections go first (declared last), then the filters they point at

Watch::Filter& Watch::filter_of(const MetaInstance& cls) {
  for (auto& f : filters_)
    if (f->cls == &cls) return *f;
  filters_.push_back(std::make_unique<Filter>());
  Filter* f = filters_.back().get();
  f->watch = this;
  f->cls = &cls;
  f->bits.assign((cls.properties().size() + 63) / 64, 0);
  connections_.push_back(state_->on_property_changed(cls, true).connect<&Filter::heard>(*f));
  return *f;
}

Watch& Watch::properties(const MetaInstance& cls, std::span<const MetaProperty* const> properties) {
  const auto own = cls.properties();
  for (const MetaProperty* p : properties)  // all checked before anything is subscribed
    if (p == nullptr || p->index() >= own.size() || own[p->index()] != p)
      detail::throw_error("class '" + cls.name() + "' has no property '" + (p != nullptr ? p->name() : "(null)") +
                          "' to watch");
  Filter& f = filter_of(cls);
  for (const MetaProperty* p : properties) f.bits[p->index() / 64] |= std::uint64_t{1} << (p->index() % 64);
  return *this;
}

Watch& Watch::all_properties(const MetaInstance& cls) {
  filter_of(cls).all = true;
  return *this;
}

Watch& Watch::created(const MetaInstance& cls) {
  connections_.push_back(state_->index().on_created(cls, true).connect(
      [this](SimStateInstance& inst) { report(inst, nullptr, Changes::created); }));
  return *this;
}

Watch& Watch::deleted(const MetaInstance& cls) {
  connections_.push_back(state_->index().on_deleted(cls, true).connect(
      [this](SimStateInstance& inst) { report(inst, nullptr, Changes::deleted); }));
  return *this;
}

Watch& Watch::reparented(const MetaInstance& cls) {
  const bool node = cls.is_a(Node::static_meta());
  if (!node && !cls.is_a(Extension::static_meta()))
    detail::throw_error("class '" + cls.name() +
                        "' is neither a Node nor an Extension class: its instances have no parent to watch");
  if (std::find(parent_classes_.begin(), parent_classes_.end(), &cls) == parent_classes_.end())
    parent_classes_.push_back(&cls);
  auto moved = [this](SimStateInstance& x) {
    for (const MetaInstance* c : parent_classes_)
      if (x.is_a(*c)) {
        report(x, nullptr, Changes::parent);
        return;
      }
  };
  if (node && !child_connected_) {
    child_connected_ = true;
    auto child = [moved](Node&, Node& c) { moved(c); };
    connections_.push_back(state_->on_child_added().connect(child));
    connections_.push_back(state_->on_child_removed().connect(child));
  }
  if (!node && !extension_connected_) {
    extension_connected_ = true;
    auto ext = [moved](NamedModelInstance&, Extension& e) { moved(e); };
    connections_.push_back(state_->on_extension_added().connect(ext));
    connections_.push_back(state_->on_extension_removed().connect(ext));
  }
  return *this;
}

void Watch::report(SimStateInstance& inst, const MetaProperty* p, Changes what) {
  if (function_ != nullptr) {
    function_(context_, inst, p, what);
  } else {
    queue(inst.id(), p, what);
  }
}

namespace {
inline std::size_t slot_hash(Id id, const MetaProperty* p) noexcept {
  std::uint64_t h = id ^ (reinterpret_cast<std::uintptr_t>(p) * 0x9E3779B97F4A7C15ULL);
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ULL;
  return static_cast<std::size_t>(h ^ (h >> 32));
}
}  // namespace

void Watch::grow() {
  std::vector<std::uint32_t> table(std::max<std::size_t>(16, table_.size() * 2), 0);
  const std::size_t mask = table.size() - 1;
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    std::size_t i = slot_hash(pending_[k].id, pending_[k].property) & mask;
    while (table[i] != 0) i = (i + 1) & mask;
    table[i] = static_cast<std::uint32_t>(k + 1);
  }
  table_ = std::move(table);
}

void Watch::queue(Id id, const MetaProperty* p, Changes what) {
  if (granularity_ == Granularity::instance || what != Changes::property) p = nullptr;
  if (table_.size() < 2 * (pending_.size() + 1)) grow();
  const std::size_t mask = table_.size() - 1;
  for (std::size_t i = slot_hash(id, p) & mask;; i = (i + 1) & mask) {
    const std::uint32_t at = table_[i];
    if (at == 0) {
      pending_.push_back(Report{id, p, what});
      table_[i] = static_cast<std::uint32_t>(pending_.size());
      if (pending_.size() == 1 && on_pending_) on_pending_();
      return;
    }
    Report& r = pending_[at - 1];
    if (r.id == id && r.property == p) {
      r.changes |= what;
      return;
    }
  }
}

std::vector<Watch::Report> Watch::take() {
  std::vector<Report> out;
  out.swap(pending_);
  // A table much larger than this batch (left from a burst) is rebuilt small instead of cleared.
  if (table_.size() > 1024 && table_.size() > 8 * out.size()) {
    table_.clear();
  } else {
    std::fill(table_.begin(), table_.end(), 0U);
  }
  return out;
}

void Watch::clear() noexcept {
  pending_.clear();
  std::fill(table_.begin(), table_.end(), 0U);
}

}  // namespace vsd
