#include "vsd/core/element_index.hpp"

#include <algorithm>

namespace vsd {

ElementIndex::Bucket& ElementIndex::bucket(const MetaInstance& m) {
  if (buckets_.size() <= m.index()) buckets_.resize(m.index() + 1);
  return buckets_[m.index()];
}

std::span<SimStateInstance* const> ElementIndex::exact(const MetaInstance& m) const noexcept {
  if (m.index() >= buckets_.size()) return {};
  return buckets_[m.index()].items;
}

std::size_t ElementIndex::count(const MetaInstance& m, bool include_subtypes) const {
  std::size_t n = exact(m).size();
  if (include_subtypes)
    for (const MetaInstance* d : m.derived()) n += count(*d, true);
  return n;
}

ElementIndex::InstanceSignal& ElementIndex::on_created(const MetaInstance& m, bool include_subtypes) {
  auto& slot = include_subtypes ? bucket(m).created_tree : bucket(m).created_exact;
  if (!slot) {
    slot = std::make_unique<InstanceSignal>();
    ++signals_;
  }
  return *slot;
}

ElementIndex::InstanceSignal& ElementIndex::on_deleted(const MetaInstance& m, bool include_subtypes) {
  auto& slot = include_subtypes ? bucket(m).deleted_tree : bucket(m).deleted_exact;
  if (!slot) {
    slot = std::make_unique<InstanceSignal>();
    ++signals_;
  }
  return *slot;
}

std::vector<ElementIndex::InstanceSignal*> ElementIndex::listeners(const SimStateInstance& i, bool created) {
  // Collected before emitting: a listener may define a class and grow the bucket table.
  std::vector<InstanceSignal*> out;
  auto live = [](const std::unique_ptr<InstanceSignal>& s) {
    return s && s->has_listeners() ? s.get() : nullptr;
  };
  for (const MetaInstance* m = &i.meta(); m != nullptr; m = m->base()) {
    if (m->index() >= buckets_.size()) continue;
    Bucket& b = buckets_[m->index()];
    if (m == &i.meta())
      if (InstanceSignal* s = live(created ? b.created_exact : b.deleted_exact)) out.push_back(s);
    if (InstanceSignal* s = live(created ? b.created_tree : b.deleted_tree)) out.push_back(s);
  }
  return out;
}

void ElementIndex::emit_created(SimStateInstance& i) {
  if (signals_ == 0) return;
  for (InstanceSignal* s : listeners(i, true)) s->emit(i);
}

void ElementIndex::emit_deleted(SimStateInstance& i) {
  if (signals_ == 0) return;
  for (InstanceSignal* s : listeners(i, false)) s->emit(i);
}

}  // namespace vsd
