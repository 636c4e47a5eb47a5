// Instance, SimStateInstance and the core node classes.
#include "vsd/core/instance.hpp"

#include <algorithm>

#include "vsd/core/database.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/extension.hpp"
#include "vsd/core/node.hpp"
#include "vsd/core/sim_state.hpp"

namespace vsd {

// ---- Instance ---------------------------------------------------------------------------------------------

const MetaInstance& Instance::static_meta() {
  // Class descriptors are never destroyed (see VSD_INSTANCE).
  static const MetaInstance& meta =
      *new MetaInstance("Instance", nullptr, sizeof(Instance), alignof(Instance), nullptr, nullptr);
  return meta;
}

Instance::~Instance() = default;

Value Instance::call(std::string_view name, std::span<const Value> args) {
  return meta_->call(*this, name, args);
}

// ---- SimStateInstance -------------------------------------------------------------------------------------

const MetaInstance& SimStateInstance::static_meta() {
  static const MetaInstance& meta = *new MetaInstance(
      "SimStateInstance", &Instance::static_meta(), sizeof(SimStateInstance), alignof(SimStateInstance),
      [](void* memory) -> SimStateInstance* { return ::new (memory) SimStateInstance(); }, nullptr);
  return meta;
}

SimStateInstance::~SimStateInstance() = default;

std::vector<SimStateInstance*> SimStateInstance::composite_holders() const {
  std::vector<SimStateInstance*> out;
  for (const detail::RefLink* l = composite_head_; l != nullptr; l = l->next)
    if (l->holder != nullptr && std::find(out.begin(), out.end(), l->holder) == out.end())
      out.push_back(l->holder);
  std::reverse(out.begin(), out.end());  // oldest first
  return out;
}

std::vector<std::pair<SimStateInstance*, const MetaProperty*>> SimStateInstance::referrers() const {
  std::vector<std::pair<SimStateInstance*, const MetaProperty*>> out;
  for (const detail::RefLink* head : {composite_head_, shared_head_}) {
    std::vector<std::pair<SimStateInstance*, const MetaProperty*>> part;
    for (const detail::RefLink* l = head; l != nullptr; l = l->next)
      if (l->holder != nullptr && l->prop != nullptr &&
          std::find(part.begin(), part.end(), std::make_pair(l->holder, l->prop)) == part.end())
        part.emplace_back(l->holder, l->prop);
    std::reverse(part.begin(), part.end());  // the lists are newest first
    for (auto& r : part)
      if (std::find(out.begin(), out.end(), r) == out.end()) out.push_back(r);
  }
  return out;
}

SimStateInstance* SimStateInstance::composite_holder(const MetaProperty& p) const noexcept {
  SimStateInstance* found = nullptr;
  for (const detail::RefLink* l = composite_head_; l != nullptr; l = l->next)
    if (l->prop == &p) found = l->holder;  // the list is newest first: keep the oldest
  return found;
}

Value SimStateInstance::get(std::string_view name) const { return meta().property(name).get_value(*this); }

void SimStateInstance::set(std::string_view name, const Value& v) {
  meta().property(name).set_value(*this, v);
}

namespace {
RefListBase& list_of(SimStateInstance& holder, const MetaProperty& p) {
  if (!holder.meta().is_a(p.owner()))
    detail::throw_error("property '" + p.owner().name() + "::" + p.name() + "' does not belong to class '" +
                        holder.meta().name() + "'");
  if (!p.type().is_ref_list())
    detail::throw_error("property '" + p.owner().name() + "::" + p.name() + "' is a " + p.type().name() +
                        ", not a reference list");
  return *static_cast<RefListBase*>(const_cast<void*>(p.address(holder)));
}

struct ListEdit : RefListBase {  // the SimState's access to a list's editing operations
  using RefListBase::erase_at;
  using RefListBase::insert_at;
};
}  // namespace

void SimStateInstance::list_insert(const MetaProperty& p, std::size_t index, SimStateInstance& target) {
  RefListBase& list = list_of(*this, p);
  if (!target.is_a(*p.type().target()))
    detail::throw_error("list '" + p.owner().name() + "::" + p.name() + "' holds " +
                        p.type().target()->name() + ", not '" + target.meta().name() + "'");
  if (index > list.size())
    detail::throw_error("index " + std::to_string(index) + " is past the end of '" + p.name() + "' (size " +
                        std::to_string(list.size()) + ")");
  static_cast<ListEdit&>(list).insert_at(index, &target);
  state_->list_changed(*this, p, index, target, true);
}

void SimStateInstance::list_erase(const MetaProperty& p, std::size_t index) {
  RefListBase& list = list_of(*this, p);
  if (index >= list.size())
    detail::throw_error("index " + std::to_string(index) + " is out of '" + p.name() + "' (size " +
                        std::to_string(list.size()) + ")");
  SimStateInstance& target = *list.at(index);
  // Hold the element while the change is recorded and announced; it may go when the guard does.
  detail::RefLink guard(true);
  if (list.is_composite() && !target.is_being_deleted()) guard.reset(&target);
  static_cast<ListEdit&>(list).erase_at(index);
  state_->list_changed(*this, p, index, target, false);
}

Sink<void(SimStateInstance&, const MetaProperty&)> SimStateInstance::on_changed() {
  auto& slot = state_->instance_signals_[this];
  if (!slot) {
    slot = std::make_unique<PropertySignal>();
    // Setters take the slow path from the moment the signal has a listener again.
    slot->on_first_listener([](void* self) { static_cast<SimStateInstance*>(self)->watch_ |= own_watch; },
                            this);
  }
  return Sink<void(SimStateInstance&, const MetaProperty&)>(*slot);
}

void SimStateInstance::notify_changed(const MetaProperty& p, const void* old_value) {
  state_->property_changed(*this, p, old_value);
}

void MetaProperty::assign_raw(SimStateInstance& obj, const void* v) const {
  void* field = const_cast<void*>(address(obj));
  if (obj.watch_ == 0) {
    type_->assign(field, v);
    return;
  }
  if (type_->equal(field, v)) return;
  Value old(*type_, field);
  type_->assign(field, v);
  obj.notify_changed(*this, old.data());
}

// ---- NamedModelInstance / Extension -----------------------------------------------------------------------

void NamedModelInstance::add_extension(Extension& e) {
  const MetaProperty& p = vsd_prop_extensions();
  NamedModelInstance* former = e.owner();
  if (former == this) return;
  list_insert(p, extensions_.size(), e);
  if (former != nullptr) former->list_erase(p, former->extensions_.index_of(&e));
}

void NamedModelInstance::remove_extension(Extension& e) {
  const std::size_t i = extensions_.index_of(&e);
  if (i == RefListBase::npos)
    detail::throw_error("extension #" + std::to_string(e.id()) + " is not attached to #" +
                        std::to_string(id()));
  list_erase(vsd_prop_extensions(), i);
}

NamedModelInstance* Extension::owner() const noexcept {
  return static_cast<NamedModelInstance*>(composite_holder(vsd_prop_extensions()));
}

// ---- Node -------------------------------------------------------------------------------------------------

Node* Node::parent() const noexcept { return static_cast<Node*>(composite_holder(vsd_prop_children())); }

Node& Node::add_child(Node& child) { return insert_child(children_.size(), child); }

Node& Node::insert_child(std::size_t index, Node& child) {
  Node* former = child.parent();
  const MetaProperty& p = vsd_prop_children();
  if (former == this) {  // a move within this node: erase first, the guard in list_erase keeps it alive
    const std::size_t at = children_.index_of(&child);
    detail::RefLink keep(true);
    keep.reset(&child);
    list_erase(p, at);
    list_insert(p, std::min(index, children_.size()), child);
    return child;
  }
  list_insert(p, index, child);  // attach first, so the child never drops to zero references
  if (former != nullptr) former->list_erase(p, former->children_.index_of(&child));
  return child;
}

void Node::remove_child(Node& child) {
  const std::size_t i = children_.index_of(&child);
  if (i == RefListBase::npos)
    detail::throw_error("node #" + std::to_string(child.id()) + " is not a child of #" +
                        std::to_string(id()));
  list_erase(vsd_prop_children(), i);
}

Node* Node::find_child(std::string_view name) const noexcept {
  for (Node* c : children_)
    if (c->name() == name) return c;
  return nullptr;
}

std::string Node::path() const {
  std::vector<const Node*> chain;
  for (const Node* n = this; n != nullptr; n = n->parent()) chain.push_back(n);
  std::string out;
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    if ((*it)->is_a<Database>()) continue;
    out += "/";
    out += (*it)->name();
  }
  return out.empty() ? "/" : out;
}

// ---- Database ---------------------------------------------------------------------------------------------

std::size_t Database::size() const {
  std::size_t n = 0;
  for_each([&](Node&) { ++n; });
  return n;
}

bool Database::contains(const Node& n) const {
  for (const Node* x = &n; x != nullptr; x = x->parent())
    if (x == this) return true;
  return false;
}

void Database::for_each(const std::function<void(Node&)>& fn) const {
  std::vector<Node*> todo{const_cast<Database*>(this)};
  while (!todo.empty()) {
    Node* n = todo.back();
    todo.pop_back();
    fn(*n);
    for (std::size_t i = n->children().size(); i-- > 0;) todo.push_back(n->children()[i]);
  }
}

void Database::notify_attached(Node& parent, Node& child) {
  if (added_.has_listeners() && contains(parent)) added_.emit(child);
}

void Database::notify_detached(Node& parent, Node& child) {
  if (removed_.has_listeners() && contains(parent)) removed_.emit(child);
}

}  // namespace vsd
