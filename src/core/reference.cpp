// References: the intrusive holder lists, counting, cycle checks, and the ops of reference MetaTypes.
#include "vsd/core/reference.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <span>
#include <string>
#include <unordered_set>
#include <vector>

#include "vsd/core/bytes.hpp"
#include "vsd/core/detail/huge_pages.hpp"
#include "vsd/core/detail/instance_pool.hpp"  // VSD_POOL_POISON
#include "vsd/core/error.hpp"
#include "vsd/core/instance.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/core/text.hpp"

namespace vsd {

namespace detail {

struct RefAccess {
  static RefLink*& head(SimStateInstance& t, bool composite) noexcept {
    return composite ? t.composite_head_ : t.shared_head_;
  }

  static void unlink(RefLink& l) noexcept {
    if (l.prev != nullptr) {
      l.prev->next = l.next;
    } else {
      head(*l.target, l.composite) = l.next;
    }
    if (l.next != nullptr) l.next->prev = l.prev;
    l.prev = l.next = nullptr;
  }

  static void link(RefLink& l, SimStateInstance& t) noexcept {
    RefLink*& h = head(t, l.composite);
    l.prev = nullptr;
    l.next = h;
    if (h != nullptr) h->prev = &l;
    h = &l;
    l.target = &t;
  }

  // True when @p t holds @p h through a chain of composite references, or is @p h (so that a composite
  // reference h -> t would close a cycle). See CycleSearch below.
  static bool composite_ancestor(const SimStateInstance& t, const SimStateInstance& h);
  static void check(const RefLink& l, SimStateInstance& t) {
    // A free reference may still point at a dying instance (old values being recorded, a listener's
    // copy): the SimState drops such links before it frees the instance. A property may not.
    if (t.is_being_deleted() && l.holder != nullptr)
      throw_error("cannot reference instance #" + std::to_string(t.id()) + " of class '" + t.meta().name() +
                  "': it is being deleted");
    if (l.holder == nullptr) return;
    if (t.state_ != l.holder->state_)
      throw_error("instance #" + std::to_string(l.holder->id()) + " cannot reference instance #" +
                  std::to_string(t.id()) + ": they live in different SimStates");
    if (l.composite && composite_ancestor(t, *l.holder))
      throw_error("a composite reference from #" + std::to_string(l.holder->id()) + " to #" +
                  std::to_string(t.id()) + " would make an instance its own ancestor");
  }

  static void reset(RefLink& l, SimStateInstance* t) {
    SimStateInstance* old = l.target;
    if (t == old) return;
    if (t != nullptr) check(l, *t);  // throws before anything changes
    if (old != nullptr) unlink(l);
    l.adopted = false;
    if (t != nullptr) {
      link(l, *t);
      if (l.composite) {
        ++t->refs_;
        // A property adopts a floating instance; a free reference only keeps it alive.
        if (l.holder != nullptr && t->is_floating()) {
          t->life_ &= static_cast<std::uint8_t>(~SimStateInstance::floating_bit);
          l.adopted = true;
        }
      }
    } else {
      l.target = nullptr;
    }
    if (old != nullptr && l.composite && --old->refs_ == 0 && !old->is_floating())
      old->state_->released(*old);
  }

  static void drop(RefLink& l) noexcept {
    if (l.target == nullptr) return;
    unlink(l);
    if (l.composite) --l.target->refs_;
    l.target = nullptr;
    l.adopted = false;
  }

  static void revert(RefLink& l) noexcept {
    SimStateInstance* t = l.target;
    if (t == nullptr) return;
    const bool adopted = l.adopted;
    drop(l);
    if (adopted) t->life_ |= SimStateInstance::floating_bit;
  }

  static std::vector<RefLink*>& links(RefListBase& r) noexcept { return r.links_; }
};

// ---- the composite cycle check ---------------------------------------------------------------------------
//
// Is there a path of composite references from t down to h? Both ends are searched at once, one reference
// per side and round: upwards from h through the holders of each instance, downwards from t through what
// each instance holds. Either search running out without meeting its goal proves there is no path, so a
// check costs about twice the smaller of the two searches:
//  - O(1) for the usual edits: a new leaf or a fresh subtree attached at any depth (nothing below t), a
//    deep tree attached under a new root (nothing above h);
//  - at most O(depth of h) for moving a subtree within a tree (the upward search is a chain);
//  - building any forest reference by reference, in any order, O(n log n) in all: each reference joins
//    two trees, and the check costs at most the size of the smaller one.
// Instances held by several holders (a DAG) are visited once per search.

namespace {

bool holds_anything(const SimStateInstance& x) noexcept {
  for (const MetaProperty* p : x.meta().reference_properties()) {
    if (!p->type().is_composite()) continue;
    const void* at = p->address(x);
    if (p->type().is_ref_list() ? !static_cast<const RefListBase*>(at)->empty()
                                : static_cast<const RefBase*>(at)->get() != nullptr)
      return true;
  }
  return false;
}

bool has_holder(const RefLink* head) noexcept {
  for (const RefLink* l = head; l != nullptr; l = l->next)
    if (l->holder != nullptr) return true;
  return false;
}

enum class Step : std::uint8_t { more, found, exhausted };

// One side of the search: visits instances from a start, one reference per step.
class Side {
 public:
  explicit Side(const SimStateInstance& start) : at_(&start) { seen_.insert(&start); }

 protected:
  // Records @p x as reached; true when it is new (to be expanded later).
  bool reach(const SimStateInstance* x) {
    if (!seen_.insert(x).second) return false;
    todo_.push_back(x);
    return true;
  }
  // The next instance to expand, or nullptr when there is none.
  const SimStateInstance* next() {
    if (todo_.empty()) return nullptr;
    const SimStateInstance* x = todo_.back();
    todo_.pop_back();
    return x;
  }

  const SimStateInstance* at_;  // the instance being expanded, or nullptr when done
  std::vector<const SimStateInstance*> todo_;
  std::unordered_set<const SimStateInstance*> seen_;
};

// Upwards: the composite holders of each instance (property links only; free references hold nothing).
class Up : public Side {
 public:
  explicit Up(const SimStateInstance& start, const RefLink* head) : Side(start), link_(head) {}

  Step step(const SimStateInstance& goal, const RefLink* (*head_of)(const SimStateInstance&)) {
    while (link_ == nullptr) {
      at_ = next();
      if (at_ == nullptr) return Step::exhausted;
      link_ = head_of(*at_);
    }
    const RefLink* l = link_;
    link_ = l->next;
    if (l->holder == nullptr) return Step::more;
    if (l->holder == &goal) return Step::found;
    reach(l->holder);
    return Step::more;
  }

 private:
  const RefLink* link_;
};

// Downwards: the targets of each instance's composite reference properties, element by element.
class Down : public Side {
 public:
  explicit Down(const SimStateInstance& start) : Side(start) { open(); }

  Step step(const SimStateInstance& goal) {
    while (true) {
      if (at_ == nullptr) return Step::exhausted;
      if (prop_ == props_.size()) {
        at_ = next();
        open();
        continue;
      }
      const MetaProperty& p = *props_[prop_];
      if (!p.type().is_composite()) {
        ++prop_;
        continue;
      }
      const void* address = p.address(*at_);
      const SimStateInstance* target = nullptr;
      if (p.type().is_ref_list()) {
        const auto& list = *static_cast<const RefListBase*>(address);
        if (element_ == list.size()) {
          ++prop_;
          element_ = 0;
          continue;
        }
        target = list.at(element_++);
      } else {
        target = static_cast<const RefBase*>(address)->get();
        ++prop_;
        if (target == nullptr) continue;
      }
      if (target == &goal) return Step::found;
      reach(target);
      return Step::more;
    }
  }

 private:
  void open() {
    props_ = at_ != nullptr ? at_->meta().reference_properties() : std::span<const MetaProperty* const>{};
    prop_ = 0;
    element_ = 0;
  }
  std::span<const MetaProperty* const> props_;
  std::size_t prop_ = 0;
  std::size_t element_ = 0;
};

}  // namespace

bool RefAccess::composite_ancestor(const SimStateInstance& t, const SimStateInstance& h) {
  if (&t == &h) return true;
  // No allocation for the common cases: nothing below t, or nothing above h.
  if (!holds_anything(t) || !has_holder(h.composite_head_)) return false;
  auto head_of = [](const SimStateInstance& x) -> const RefLink* { return x.composite_head_; };
  Up up(h, h.composite_head_);
  Down down(t);
  while (true) {
    const Step u = up.step(t, head_of);
    if (u != Step::more) return u == Step::found;
    const Step d = down.step(h);
    if (d != Step::more) return d == Step::found;
  }
}

// ---- LinkBlock: a header, then the links -----------------------------------------------------------------

struct LinkBlockHeader {
  // Links still alive or still to be made, plus one while the maker lives. Atomic: a link in a free
  // Value may be freed on another thread than the one still building or editing the state.
  std::atomic<std::size_t> shares;
  std::size_t bytes;
};

namespace {
constexpr std::size_t link_header =
    (sizeof(LinkBlockHeader) + alignof(RefLink) - 1) / alignof(RefLink) * alignof(RefLink);
RefLink* links_of(void* header) noexcept {
  return reinterpret_cast<RefLink*>(static_cast<char*>(header) + link_header);
}
void give_up(LinkBlockHeader* h, std::size_t n) noexcept {
  if (h->shares.fetch_sub(n, std::memory_order_acq_rel) != n) return;
  const std::size_t bytes = h->bytes;
  h->~LinkBlockHeader();
  VSD_POOL_UNPOISON(h, bytes);
  free_big(h, bytes, alignof(LinkBlockHeader));
}
}  // namespace

LinkBlock::LinkBlock(std::size_t count) {
  count = std::min<std::size_t>(count, UINT32_MAX - 1);
  if (count == 0) return;
  const std::size_t bytes = link_header + count * sizeof(RefLink);
  void* memory = allocate_big(bytes, alignof(LinkBlockHeader));
  block_ = ::new (memory) LinkBlockHeader{{count + 1}, bytes};
  count_ = static_cast<std::uint32_t>(count);
}

LinkBlock::~LinkBlock() {
  if (block_ != nullptr) give_up(block_, count_ - next_ + 1);  // the unused rest and the maker's share
}

RefLink* LinkBlock::make(bool composite) {
  if (next_ == count_) return new RefLink(composite);
  RefLink* l = ::new (links_of(block_) + next_) RefLink(composite);
  l->block_slot = ++next_;
  return l;
}

void free_link(RefLink* l) noexcept {
  if (l->block_slot == 0) {
    delete l;
    return;
  }
  auto* h =
      reinterpret_cast<LinkBlockHeader*>(reinterpret_cast<char*>(l - (l->block_slot - 1)) - link_header);
  l->~RefLink();  // may release a subtree, freeing other links of the block: its own share goes last
  VSD_POOL_POISON(l, sizeof(RefLink));
  give_up(h, 1);
}

void RefLink::reset(SimStateInstance* t) { RefAccess::reset(*this, t); }
void RefLink::drop() noexcept { RefAccess::drop(*this); }
void RefLink::revert() noexcept { RefAccess::revert(*this); }

}  // namespace detail

Id RefBase::id() const noexcept { return link_.target != nullptr ? link_.target->id() : null_id; }

// ---- RefListBase ------------------------------------------------------------------------------------------

RefListBase::RefListBase(const RefListBase& o) : composite_(o.composite_) {
  links_.reserve(o.links_.size());
  for (const detail::RefLink* l : o.links_) insert_at(links_.size(), l->target);
}

RefListBase& RefListBase::operator=(const RefListBase& o) {
  if (this == &o) return *this;
  // Link the new targets before releasing the old ones, so an element in both never hits zero.
  std::vector<detail::RefLink*> old;
  old.swap(links_);
  try {
    for (const detail::RefLink* l : o.links_) insert_at(links_.size(), l->target);
  } catch (...) {
    for (auto* l : links_) {  // undo, not release: instances this list adopted float again
      l->revert();
      detail::free_link(l);
    }
    links_ = std::move(old);
    throw;
  }
  for (auto* l : old) detail::free_link(l);
  return *this;
}

RefListBase::RefListBase(RefListBase&& o) noexcept : links_(std::move(o.links_)), composite_(o.composite_) {
  o.links_.clear();
  for (auto* l : links_) {  // a moved-to list is free
    l->holder = nullptr;
    l->prop = nullptr;
  }
}

RefListBase& RefListBase::operator=(RefListBase&& o) {
  if (this != &o) {
    *this = static_cast<const RefListBase&>(o);
    o.clear_all();
  }
  return *this;
}

std::size_t RefListBase::index_of(const SimStateInstance* p) const noexcept {
  for (std::size_t i = 0; i < links_.size(); ++i)
    if (links_[i]->target == p) return i;
  return npos;
}

bool operator==(const RefListBase& a, const RefListBase& b) noexcept {
  if (a.links_.size() != b.links_.size()) return false;
  for (std::size_t i = 0; i < a.links_.size(); ++i)
    if (a.links_[i]->target != b.links_[i]->target) return false;
  return true;
}

namespace {
// Throws what inserting @p p at @p i into a list of @p size elements is wrong about, if anything.
void check_insert(std::size_t i, const SimStateInstance* p, std::size_t size) {
  if (p == nullptr) detail::throw_error("a reference list cannot hold null");
  if (i > size)
    detail::throw_error("index " + std::to_string(i) + " is past the end of a list of " +
                        std::to_string(size));
}
}  // namespace

void RefListBase::insert_at(std::size_t i, SimStateInstance* p) {
  check_insert(i, p, links_.size());
  insert_link(i, p, new detail::RefLink(composite_));
}

void RefListBase::insert_link(std::size_t i, SimStateInstance* p, detail::RefLink* l) {
  try {
    check_insert(i, p, links_.size());
  } catch (...) {
    detail::free_link(l);
    throw;
  }
  l->holder = holder_;
  l->prop = prop_;
  try {
    links_.insert(links_.begin() + static_cast<std::ptrdiff_t>(i), l);
  } catch (...) {
    detail::free_link(l);
    throw;
  }
  try {
    l->reset(p);
  } catch (...) {
    links_.erase(links_.begin() + static_cast<std::ptrdiff_t>(i));
    detail::free_link(l);
    throw;
  }
}

void RefListBase::erase_at(std::size_t i) {
  if (i >= links_.size())
    detail::throw_error("index " + std::to_string(i) + " is out of a list of " +
                        std::to_string(links_.size()));
  detail::RefLink* l = links_[i];
  links_.erase(links_.begin() + static_cast<std::ptrdiff_t>(i));
  detail::free_link(l);  // releases last: a cascade sees the list already updated
}

void RefListBase::clear_all() {
  while (!links_.empty()) erase_at(links_.size() - 1);
}

// ---- ops of reference MetaTypes ---------------------------------------------------------------------------

namespace detail {
namespace {

bool is_composite_kind(const MetaType& t) {
  return t.kind() == TypeKind::Ref || t.kind() == TypeKind::RefList;
}

SimStateInstance* resolve(const MetaType& t, Id id, const RefResolver* refs, const auto& fail) {
  if (id == null_id) return nullptr;
  if (refs == nullptr) fail("cannot resolve reference @" + std::to_string(id) + " here");
  SimStateInstance* p = refs->resolve(id);
  if (p == nullptr) fail("dangling reference: no instance @" + std::to_string(id));
  if (t.target() != nullptr && !p->is_a(*t.target()))
    fail("@" + std::to_string(id) + " is a '" + p->meta().name() + "', not a '" + t.target()->name() + "'");
  return p;
}

struct RefCore : RefBase {  // gives the ops access to RefBase's protected constructor and reset
  RefCore(bool composite, SimStateInstance* t) : RefBase(composite, t) {}
  using RefBase::reset_target;
};
struct ListCore : RefListBase {
  explicit ListCore(bool composite) : RefListBase(composite) {}
  using RefListBase::clear_all;
  using RefListBase::insert_at;
};

void ref_construct(const MetaType& t, void* dst) { ::new (dst) RefCore(is_composite_kind(t), nullptr); }
void ref_copy(const MetaType&, void* dst, const void* src) {
  ::new (dst) RefBase(*static_cast<const RefBase*>(src));
}
void ref_move(const MetaType&, void* dst, void* src) noexcept {
  // Copying a link cannot fail for a valid source (same target), so this is safe as noexcept.
  ::new (dst) RefBase(*static_cast<const RefBase*>(src));
}
void ref_destroy(const MetaType&, void* p) noexcept { static_cast<RefBase*>(p)->~RefBase(); }
void ref_assign(const MetaType&, void* dst, const void* src) {
  static_cast<RefCore*>(dst)->reset_target(static_cast<const RefBase*>(src)->get());
}
bool ref_equal(const MetaType&, const void* a, const void* b) {
  return static_cast<const RefBase*>(a)->id() == static_cast<const RefBase*>(b)->id();
}
std::size_t ref_hash(const MetaType&, const void* p) {
  return std::hash<Id>{}(static_cast<const RefBase*>(p)->id());
}
// A reference is the JSON string "@42" or null; the older bare @42 reads too.
void write_id(std::string& out, Id id) {
  if (id == null_id) {
    out += "null";
  } else {
    out += "\"@" + std::to_string(id) + "\"";
  }
}
Id read_id(TextReader& in) {
  const std::size_t at = in.token_start();
  const bool quoted = in.accept('"');
  if (quoted || in.peek() == '@') {
    if (!in.accept('@')) in.fail_at(at, "expected a reference (\"@id\" or null)");
    const Id id = in.unsigned_integer();
    if (quoted) in.expect('"');
    return id;
  }
  if (std::isalpha(static_cast<unsigned char>(in.peek())) == 0)
    in.fail_at(at, "expected a reference (\"@id\" or null)");
  const auto word = in.identifier();
  if (word != "null")
    in.fail_at(at, "expected a reference (\"@id\" or null), found '" + std::string(word) + "'");
  return null_id;
}
void ref_write_text(const MetaType&, const void* p, std::string& out) {
  write_id(out, static_cast<const RefBase*>(p)->id());
}
void ref_read_text(const MetaType& t, void* p, TextReader& in, const RefResolver* refs) {
  const std::size_t at = in.token_start();
  const Id id = read_id(in);
  SimStateInstance* target = resolve(t, id, refs, [&](const std::string& m) { in.fail_at(at, m); });
  static_cast<RefCore*>(p)->reset_target(target);
}
void ref_write_bytes(const MetaType&, const void* p, ByteWriter& out) {
  out.varint(static_cast<const RefBase*>(p)->id());
}
void ref_read_bytes(const MetaType& t, void* p, ByteReader& in, const RefResolver* refs) {
  const Id id = in.varint();
  SimStateInstance* target = resolve(t, id, refs, [&](const std::string& m) { in.fail(m); });
  static_cast<RefCore*>(p)->reset_target(target);
}
void ref_bind(const MetaType&, void* p, SimStateInstance* holder, const MetaProperty* prop) {
  RefBinding::bind(p, false, holder, prop);
}

void list_construct(const MetaType& t, void* dst) { ::new (dst) ListCore(is_composite_kind(t)); }
void list_copy(const MetaType&, void* dst, const void* src) {
  ::new (dst) RefListBase(*static_cast<const RefListBase*>(src));
}
void list_move(const MetaType&, void* dst, void* src) noexcept {
  ::new (dst) RefListBase(std::move(*static_cast<RefListBase*>(src)));
}
void list_destroy(const MetaType&, void* p) noexcept { static_cast<RefListBase*>(p)->~RefListBase(); }
void list_assign(const MetaType&, void* dst, const void* src) {
  *static_cast<RefListBase*>(dst) = *static_cast<const RefListBase*>(src);
}
bool list_equal(const MetaType&, const void* a, const void* b) {
  const auto& x = *static_cast<const RefListBase*>(a);
  const auto& y = *static_cast<const RefListBase*>(b);
  if (x.size() != y.size()) return false;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (x.at(i)->id() != y.at(i)->id()) return false;  // by id: equal across replicas
  return true;
}
std::size_t list_hash(const MetaType&, const void* p) {
  const auto& x = *static_cast<const RefListBase*>(p);
  std::size_t h = x.size();
  for (std::size_t i = 0; i < x.size(); ++i) h = hash_combine(h, std::hash<Id>{}(x.at(i)->id()));
  return h;
}
void list_write_text(const MetaType&, const void* p, std::string& out) {
  const auto& x = *static_cast<const RefListBase*>(p);
  out.push_back('[');
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (i != 0) out += ", ";
    write_id(out, x.at(i)->id());
  }
  out.push_back(']');
}
void list_read_text(const MetaType& t, void* p, TextReader& in, const RefResolver* refs) {
  ListCore fresh(is_composite_kind(t));
  for (bool first = true; vector_read_text_next(in, first); first = false) {
    const std::size_t at = in.token_start();
    const Id id = read_id(in);
    if (id == null_id) in.fail_at(at, "a reference list cannot hold null");
    fresh.insert_at(fresh.size(), resolve(t, id, refs, [&](const std::string& m) { in.fail_at(at, m); }));
  }
  *static_cast<RefListBase*>(p) = fresh;
}
void list_write_bytes(const MetaType&, const void* p, ByteWriter& out) {
  const auto& x = *static_cast<const RefListBase*>(p);
  out.varint(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) out.varint(x.at(i)->id());
}
void list_read_bytes(const MetaType& t, void* p, ByteReader& in, const RefResolver* refs) {
  ListCore fresh(is_composite_kind(t));
  const std::size_t n = in.size_prefix(1);
  for (std::size_t i = 0; i < n; ++i) {
    const Id id = in.varint();
    if (id == null_id) in.fail("a reference list cannot hold null");
    fresh.insert_at(fresh.size(), resolve(t, id, refs, [&](const std::string& m) { in.fail(m); }));
  }
  *static_cast<RefListBase*>(p) = fresh;
}
void list_bind(const MetaType&, void* p, SimStateInstance* holder, const MetaProperty* prop) {
  RefBinding::bind(p, true, holder, prop);
}

}  // namespace

const TypeOps ref_ops{&ref_construct, &ref_copy,        &ref_move,       &ref_destroy,
                      &ref_assign,    &ref_equal,       &ref_hash,       &ref_write_text,
                      &ref_read_text, &ref_write_bytes, &ref_read_bytes, &ref_bind};
const TypeOps ref_list_ops{&list_construct, &list_copy,        &list_move,       &list_destroy,
                           &list_assign,    &list_equal,       &list_hash,       &list_write_text,
                           &list_read_text, &list_write_bytes, &list_read_bytes, &list_bind};

}  // namespace detail

}  // namespace vsd
