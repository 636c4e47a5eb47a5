#include "vsd/core/element_index.hpp"

#include <algorithm>
#include <array>

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

ElementIndex::InstanceSink ElementIndex::on_created(const MetaInstance& m, bool include_subtypes) {
  auto& slot = include_subtypes ? bucket(m).created_tree : bucket(m).created_exact;
  if (!slot) {
    slot = std::make_unique<InstanceSignal>();
    ++signals_;
  }
  return InstanceSink(*slot);
}

ElementIndex::InstanceSink ElementIndex::on_deleted(const MetaInstance& m, bool include_subtypes) {
  auto& slot = include_subtypes ? bucket(m).deleted_tree : bucket(m).deleted_exact;
  if (!slot) {
    slot = std::make_unique<InstanceSignal>();
    ++signals_;
  }
  return InstanceSink(*slot);
}

template <class F>
void ElementIndex::for_each_listener(const SimStateInstance& i, bool created, F&& fn) {
  // Collected before emitting: a listener may define a class and grow the bucket table. A small array
  // holds the signals of the usual class depth; deeper hierarchies with more listening classes spill.
  std::array<InstanceSignal*, 8> small{};
  std::vector<InstanceSignal*> more;
  std::size_t n = 0;
  auto add = [&](const std::unique_ptr<InstanceSignal>& s) {
    if (!s || !s->has_listeners()) return;
    if (n < small.size()) {
      small[n++] = s.get();
    } else {
      more.push_back(s.get());
    }
  };
  for (const MetaInstance* m = &i.meta(); m != nullptr; m = m->base()) {
    if (m->index() >= buckets_.size()) continue;
    Bucket& b = buckets_[m->index()];
    if (m == &i.meta()) add(created ? b.created_exact : b.deleted_exact);
    add(created ? b.created_tree : b.deleted_tree);
  }
  for (std::size_t k = 0; k < n; ++k) fn(*small[k]);
  for (InstanceSignal* s : more) fn(*s);
}

void ElementIndex::emit_created(SimStateInstance& i) {
  if (signals_ == 0) return;
  for_each_listener(i, true, [&](InstanceSignal& s) { s.emit(i); });
}

void ElementIndex::emit_deleted(SimStateInstance& i) {
  if (signals_ == 0) return;
  for_each_listener(i, false, [&](InstanceSignal& s) { s.emit(i); });
}

}  // namespace vsd
