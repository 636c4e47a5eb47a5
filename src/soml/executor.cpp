// The SOML++ net executor (docs/soml.md, 5.2 and 5.3): transitions are re-tested only when something
// they read changed — an input place (known from the arrows) or a property their condition or arrow
// conditions read the last time they ran (recorded by the VM) — heard through a vsd::Watch that covers
// just the class properties some test read. Among the enabled transitions one is chosen with a seeded
// generator, so runs are reproducible. Every firing changes markings through the setters of the place nodes.
#include <algorithm>
#include <limits>
#include <utility>

#include "program_impl.hpp"
#include "vsd/core/error.hpp"
#include "vsd/soml/debugger.hpp"  // net_node_label

namespace vsd::soml {

void ProgramImpl::on_change(SimStateInstance& inst, const MetaProperty& p) {
  if (&p == tokens_property_ || &p == objects_property_) {
    auto it = place_watch_.find(inst.id());
    if (it != place_watch_.end())
      for (std::uint32_t ti : it->second) mark_dirty(ti);
  }
  if (deps_map_.empty()) return;
  if (const auto* watchers = deps_map_.find(DepKey{inst.id(), &p}))
    for (std::uint32_t ti : *watchers) mark_dirty(ti);
  if (!whole_instance_deps_) return;
  // Tests that called a C++ method of the instance.
  if (const auto* watchers = deps_map_.find(DepKey{inst.id(), nullptr}))
    for (std::uint32_t ti : *watchers) mark_dirty(ti);
}

// What the executor's Watch reports (connect_listeners), on_change inlined here: it runs for every change
// of a property some test read.
void ProgramImpl::heard(void* self, SimStateInstance& inst, const MetaProperty* p, Changes what) {
  auto* program = static_cast<ProgramImpl*>(self);
  if (p != nullptr) {
    program->on_change(inst, *p);
  } else if (what.has(Changes::deleted)) {
    program->on_deleted(inst);
  }
}

// A net whose owner, place or transition is deleted stops: its transitions leave the enabled set and
// are never tested again (their nodes, which the executor holds by pointer, are going away).
void ProgramImpl::on_deleted(SimStateInstance& inst) {
  if (&inst == exec_) exec_ = nullptr;  // someone deleted the executor's state: the run is no longer saved
  auto it = node_net_.find(inst.id());
  if (it == node_net_.end()) return;
  NetInst* n = it->second;
  if (n->dead) return;
  n->dead = true;
  dead_tis_ += n->transitions.size();
  for (std::size_t t = 0; t < n->transitions.size(); ++t) {
    const auto i = static_cast<std::uint32_t>(n->first_ti + t);
    set_enabled(i, false);
  }
  for (Place* p : n->places) {
    place_watch_.erase(p->id());
    node_net_.erase(p->id());
  }
  for (Transition* t : n->transitions) node_net_.erase(t->id());
  node_net_.erase(n->owner);
  if (guarding_) killed_.push_back(n);
}

void ProgramImpl::put_token(Place& p, SimStateInstance* obj, std::int64_t n) {
  if (obj == nullptr) {
    std::int64_t v;
    if (__builtin_add_overflow(p.tokens(), n, &v)) too_many_tokens(p, n);
    p.set_tokens(v);
    return;
  }
  Node* node = obj->as<Node>();
  if (node == nullptr) fail("only nodes can be tokens");
  p.edit_objects().push_back(*node);
}

void ProgramImpl::too_many_tokens(const Place& p, std::int64_t n, const ArrowDecl* arrow) {
  fail("place '" + net_node_label(&p) + "' would hold more than 9223372036854775807 (2^63-1) tokens: " +
       std::to_string(p.tokens()) + " + " + std::to_string(n) +
       (arrow != nullptr ? "\n  at the arrow (" + where(*this, arrow->loc) + ")" : std::string()));
}

void ProgramImpl::check_token_room(NetInst& net, const TransitionInfo& t) {
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  for (const ArrowInfo& a : t.out) {
    if (a.object) continue;
    Place* p = a.remote ? remote_place(a, net) : net.places[static_cast<std::size_t>(a.place)];
    if (p == nullptr || p->tokens() <= kMax - t.out_weight) continue;
    // Near the top: the place's count after the firing, exactly (its inputs take first, then every
    // output arrow to it gives).
    auto place_of = [&](const ArrowInfo& x) {
      return x.remote ? remote_place(x, net) : net.places[static_cast<std::size_t>(x.place)];
    };
    std::int64_t after = p->tokens();
    for (const ArrowInfo& i : t.in)
      if (!i.object && !i.inhibitor && place_of(i) == p) after -= std::min(after, i.weight);
    bool over = false;
    for (const ArrowInfo& o : t.out)
      if (!o.object && place_of(o) == p) over = over || __builtin_add_overflow(after, o.weight, &after);
    if (over) too_many_tokens(*p, a.weight, a.decl);
  }
}

void ProgramImpl::set_enabled(std::uint32_t i, bool on) {
  TI& ti = tis_[i];
  if (on == ti.enabled) return;
  ti.enabled = on;
  if (on) {
    ti.enabled_pos = static_cast<std::int32_t>(enabled_.size());
    enabled_.push_back(i);
  } else {
    const auto pos = static_cast<std::size_t>(ti.enabled_pos);
    const std::uint32_t last = enabled_.back();
    enabled_[pos] = last;
    tis_[last].enabled_pos = static_cast<std::int32_t>(pos);
    enabled_.pop_back();
    ti.enabled_pos = -1;
  }
}

std::uint64_t ProgramImpl::port_place_id(std::uint64_t copy, std::size_t k) const {
  auto it = node_net_.find(copy);
  if (it == node_net_.end() || it->second->dead || k >= image().port_places.size()) return 0;
  const NetInst& n = *it->second;
  for (std::size_t t = 0; t < n.transitions.size(); ++t) {
    if (n.transitions[t]->id() != copy) continue;
    const auto& sub = n.cls->transitions[t].sub_places;
    auto p = sub.find(image().port_places[k]);
    return p == sub.end() ? 0 : n.places[static_cast<std::size_t>(p->second)]->id();
  }
  return 0;
}

Place* ProgramImpl::remote_place(const ArrowInfo& a, const NetInst& net) {
  std::uint64_t id = arrow_self(net, a);
  for (const PathStep& st : a.path) {
    if (st.object != nullptr) {
      id = object_ids_.at(st.object);
      continue;
    }
    SimStateInstance* o = id == 0 ? nullptr : state_.find(id);
    if (o == nullptr || !o->meta().is_a(st.prop->owner())) return nullptr;
    if (deps_ != nullptr) deps_->emplace_back(id, st.prop);
    const SimStateInstance* t = static_cast<const RefBase*>(st.prop->address(*o))->get();
    id = t != nullptr ? t->id() : 0;
  }
  const NetInst* n = net_of(id);
  if (n == nullptr) return nullptr;
  for (std::size_t i = 0; i < n->cls->places.size(); ++i)
    if (n->cls->places[i] == a.remote_place) {
      Place* p = n->places[i];
      if (deps_ != nullptr)
        deps_->emplace_back(p->id(),
                            p->object_tokens() ? &Place::vsd_prop_objects() : &Place::vsd_prop_tokens());
      return p;
    }
  return nullptr;
}

bool ProgramImpl::test(TI& ti) {
  const NetInst& net = *ti.net;
  const TransitionInfo& t = net.cls->transitions[static_cast<std::size_t>(ti.t)];
  if (ti.counts_only) {
    // What the general way below does for such a transition, without its set-up: the counts of the
    // input places against the weights, nothing run, no dependency (ti.deps stays empty), no mark.
    bool enabled = true;
    for (std::size_t k = 0; k < t.in.size() && enabled; ++k) {
      const ArrowInfo& a = t.in[k];
      const std::int64_t n = net.places[static_cast<std::size_t>(a.place)]->count();
      enabled = a.inhibitor ? n < a.weight : n >= a.weight;
    }
    ti.mark = 0;
    return enabled;
  }
  const std::uint64_t tid = net.transitions[static_cast<std::size_t>(ti.t)]->id();
  dep_scratch_.clear();
  deps_ = &dep_scratch_;
  bool enabled = true;
  std::uint64_t mark = 0;
  auto truth = [&](int fn, std::uint64_t self, std::uint64_t m) {
    ++tests_;
    const bool yes = run(fn, self, m, nullptr, nullptr).i != 0;
    if (net.dead)
      throw Error("the net of instance " + std::to_string(net.owner) + " was deleted while it was tested");
    return yes;
  };
  try {
    for (std::size_t k = 0; k < t.in.size() && enabled; ++k) {
      if (static_cast<int>(k) == t.mark_in) continue;
      const ArrowInfo& a = t.in[k];
      // A communication arrow's remote place is found now; a null reference disables.
      const Place* rp = a.remote ? remote_place(a, net) : net.places[static_cast<std::size_t>(a.place)];
      if (rp == nullptr) {
        enabled = false;
        continue;
      }
      const Place& p = *rp;
      std::int64_t n = 0;
      if (a.cond < 0) {
        n = p.count();
      } else if (p.object_tokens()) {
        for (std::size_t j = 0; j < p.objects().size(); ++j) {
          const SimStateInstance* o = p.objects().at(j);
          if (o != nullptr && truth(a.cond, arrow_self(net, a), o->id())) ++n;
        }
      } else {
        n = truth(a.cond, arrow_self(net, a), 0) ? p.count() : 0;
      }
      enabled = a.inhibitor ? n < a.weight : n >= a.weight;
    }
    // A communication output arrow whose path meets a null reference disables too: its tokens would
    // have nowhere to go.
    for (std::size_t k = 0; k < t.out.size() && enabled; ++k)
      if (t.out[k].remote) enabled = remote_place(t.out[k], net) != nullptr;
    if (enabled && t.mark_in >= 0) {
      const ArrowInfo& a = t.in[static_cast<std::size_t>(t.mark_in)];
      // The mark comes from a place of this net, or over a communication arrow from another's (5.4).
      const Place* mp = a.remote ? remote_place(a, net) : net.places[static_cast<std::size_t>(a.place)];
      enabled = false;
      for (std::size_t j = 0; mp != nullptr && j < mp->objects().size() && !enabled; ++j) {
        const SimStateInstance* o = mp->objects().at(j);
        if (o == nullptr) continue;
        if (a.cond >= 0 && !truth(a.cond, arrow_self(net, a), o->id())) continue;
        if (t.cond >= 0 && !truth(t.cond, tid, o->id())) continue;
        enabled = true;
        mark = o->id();
      }
    } else if (enabled && t.cond >= 0) {
      enabled = truth(t.cond, tid, 0);
    }
  } catch (const Error& e) {
    enabled = false;
    if (condition_errors_.size() < 100) condition_errors_.emplace_back(e.what());
  }
  deps_ = nullptr;
  // Listen to what this test read, and stop listening to what it no longer reads (a token that left,
  // a deleted instance): the table holds only current dependencies.
  if (dep_scratch_.size() > 1) {  // most tests read one property (the mark's): sorted already
    std::sort(dep_scratch_.begin(), dep_scratch_.end());
    dep_scratch_.erase(std::unique(dep_scratch_.begin(), dep_scratch_.end()), dep_scratch_.end());
  }
  // (Sizes and elements are read through locals: the calls below could change any vector as far as
  // the compiler knows, and this runs for every test.)
  const std::size_t nn = dep_scratch_.size();
  const std::size_t no = ti.deps.size();
  const std::pair<std::uint64_t, const MetaProperty*>* now = dep_scratch_.data();
  const DepKey* old = ti.deps.data();
  auto equal = [](const DepKey& k, const std::pair<std::uint64_t, const MetaProperty*>& d) {
    return k.id == d.first && k.prop == d.second;
  };
  bool same = nn == no;
  for (std::size_t k = 0; same && k < nn; ++k) same = equal(old[k], now[k]);
  if (!same) {
    const auto index = static_cast<std::uint32_t>(&ti - tis_.data());
    // Both lists are sorted: walk them together and touch only the keys that differ (an object token
    // that moved on changes one key of a test's reads, not all of them). Each watcher list is kept in
    // transition order, not in the order of the tests that happened to run: a change then marks its
    // watchers dirty in the same order in a run that was saved and attached again (8.7), whose tests
    // ran at other times, as in the run that was never saved. The order of these adds and removes does
    // not matter: a watcher list is a sorted set.
    std::size_t o = 0;
    std::size_t n = 0;
    while (o < no || n < nn) {
      if (n == nn || (o < no && std::pair(old[o].id, old[o].prop) < now[n])) {
        deps_map_.remove(old[o++], index);  // no longer read (a token that left, a deleted instance)
      } else if (o < no && equal(old[o], now[n])) {
        ++o;  // read before and now
        ++n;
      } else {
        const auto& [id, prop] = now[n++];
        whole_instance_deps_ = whole_instance_deps_ || prop == nullptr;
        if (deps_map_.add(DepKey{id, prop}, index)) cover(id, prop);
      }
    }
    ti.deps.resize(nn);  // (old is not used after this)
    for (std::size_t k = 0; k < nn; ++k) ti.deps[k] = DepKey{now[k].first, now[k].second};
  }
  ti.mark = mark;
  return enabled;
}

bool ProgramImpl::refresh() {
  while (!dirty_.empty()) {
    const std::uint32_t i = dirty_.back();
    dirty_.pop_back();
    tis_[i].dirty = false;
    if (tis_[i].net->dead) continue;
    const bool on = test(tis_[i]);
    set_enabled(i, on);
  }
  return !enabled_.empty();
}

void ProgramImpl::fire(std::uint32_t i) {
  TI& ti = tis_[i];
  NetInst& net = *ti.net;
  const TransitionInfo& t = net.cls->transitions[static_cast<std::size_t>(ti.t)];
  Transition& tn = *net.transitions[static_cast<std::size_t>(ti.t)];
  if (debug_ != nullptr) debug_->on_fire(tn, ti.mark);  // a breakpoint on the transition (debugger.cpp)
  // A firing that runs SOML++ code (an action, an invocation's arguments, initialisers and constructors,
  // output arrow conditions) can fail half-way: it runs under a savepoint of the SimState, and an error
  // undoes every change it made — properties, markings, created and deleted instances — so a firing is
  // all or nothing. One without code cannot fail and runs without the recording that costs.
  if (!t.guarded) {
    // The one way it could fail, checked before anything changes; not needed when it gives no black
    // tokens (only object tokens move: no count can pass 2^63-1).
    if (t.out_weight != 0) check_token_room(net, t);
    fire_body(i);
  } else {
    const SimState::Savepoint sp = state_.savepoint();
    const std::uint64_t firings = firings_;
    const std::size_t killed = killed_.size();
    struct Guard {
      ProgramImpl& p;
      std::size_t killed;
      ~Guard() {
        p.guarding_ = false;
        p.killed_.resize(std::min(killed, p.killed_.size()));
      }
    } guard{*this, killed};
    guarding_ = true;
    try {
      fire_body(i);
    } catch (const Error& e) {
      pending_.clear();
      finished_instance_ = 0;
      firings_ = firings;
      guarding_ = false;
      roll_back(sp, killed, e.what());
      throw;
    } catch (...) {
      pending_.clear();
      finished_instance_ = 0;
      firings_ = firings;
      guarding_ = false;
      roll_back(sp, killed, "an exception");
      throw;
    }
    state_.release(sp);
  }
  // The trace once the firing stands; then a finished invocation goes (its transition, which a Finish
  // entry of the trace names, lived until now).
  const Id gone = std::exchange(finished_instance_, 0);
  struct Cleanup {
    ProgramImpl& p;
    Id gone;
    ~Cleanup() {
      p.pending_.clear();
      if (SimStateInstance* o = gone != 0 ? p.state_.find(gone) : nullptr; o != nullptr) p.state_.destroy(*o);
    }
  } cleanup{*this, gone};
  if (trace_)
    for (const Firing& f : pending_) trace_(f);
}

void ProgramImpl::roll_back(const SimState::Savepoint& sp, std::size_t killed, const std::string& why) {
  try {
    state_.roll_back(sp);
  } catch (const Error& e) {
    throw Error(why + "\nand undoing the failed firing failed too: " + e.what());
  }
  // Nets whose nodes the firing deleted are back (re-created with their ids): the executor takes them up
  // again. Nets the firing created are gone again with their nodes.
  for (std::size_t k = killed; k < killed_.size(); ++k) revive(killed_[k]);
  killed_.resize(killed);
}

void ProgramImpl::fire_body(std::uint32_t i) {
  TI& ti = tis_[i];
  NetInst& net = *ti.net;
  const TransitionInfo& t = net.cls->transitions[static_cast<std::size_t>(ti.t)];
  Transition& tn = *net.transitions[static_cast<std::size_t>(ti.t)];
  const std::uint64_t mark = ti.mark;
  SimStateInstance* m = mark != 0 ? state_.find(mark) : nullptr;
  Place* from = nullptr;
  std::vector<TokenMove> taken, given;  // black token moves, recorded only for the trace
  // Consume.
  for (std::size_t k = 0; k < t.in.size(); ++k) {
    const ArrowInfo& a = t.in[k];
    if (a.inhibitor) continue;
    Place* pp = a.remote ? remote_place(a, net) : net.places[static_cast<std::size_t>(a.place)];
    if (pp == nullptr) continue;  // a communication arrow whose path meets a null reference (not enabled)
    Place& p = *pp;
    if (static_cast<int>(k) == t.mark_in) {
      from = &p;
      const std::size_t at = p.objects().index_of(m);
      if (at != RefListBase::npos) p.edit_objects().erase(at);
    } else if (!a.object) {
      p.set_tokens(p.tokens() - a.weight);
      if (trace_) taken.push_back(TokenMove{&p, a.weight});
    }
  }
  // An invoking transition: a new net instance takes over; the mark waits in it (4.11).
  if (t.invoke != nullptr) {
    SimStateInstance& inv = start_invocation(t, tn, mark);
    tn.set_firings(tn.firings() + 1);
    ++firings_;
    mark_dirty(i);
    if (trace_)
      pending_.push_back(
          Firing{firings_, &tn, mark, from, nullptr, FiringKind::Invoke, inv.id(), std::move(taken), {}});
    return;
  }
  // Act.
  if (t.action >= 0) {
    run(t.action, tn.id(), mark, nullptr, nullptr);
    // `finish` ran: the invoking transition's action runs with the result now (its error undoes this
    // firing too), then the instance goes and the invoking transition produces its outputs.
    if (net.cls->invocable && !net.dead && finished(net)) {
      const std::pair<NetInst*, int> invoker = complete_action(net);
      const std::uint64_t instance = net.owner;
      ++firings_;
      if (trace_)
        pending_.push_back(
            Firing{firings_, &tn, mark, from, nullptr, FiringKind::Finish, instance, std::move(taken), {}});
      complete_outputs(*invoker.first, invoker.second, instance);
      return;
    }
    if (net.dead) {  // the action deleted its own net: nothing to produce into
      ++firings_;
      return;
    }
  }
  Place* to = produce(net, t, mark, trace_ ? &given : nullptr);
  tn.set_firings(tn.firings() + 1);
  ++firings_;
  mark_dirty(i);
  if (trace_)
    pending_.push_back(
        Firing{firings_, &tn, mark, from, to, FiringKind::Plain, 0, std::move(taken), std::move(given)});
}

// Produce: black tokens to every black output place, the mark to the first object place that takes it.
Place* ProgramImpl::produce(NetInst& net, const TransitionInfo& t, std::uint64_t mark,
                            std::vector<TokenMove>* given) {
  Place* to = nullptr;
  SimStateInstance* m = mark != 0 ? state_.find(mark) : nullptr;
  for (const ArrowInfo& a : t.out) {
    Place* pp = a.remote ? remote_place(a, net) : net.places[static_cast<std::size_t>(a.place)];
    if (pp == nullptr) continue;  // a communication arrow whose path meets a null reference
    Place& p = *pp;
    if (!a.object) {
      if (a.cond < 0 || run(a.cond, arrow_self(net, a), mark, nullptr, nullptr).i != 0) {
        std::int64_t v;
        if (__builtin_add_overflow(p.tokens(), a.weight, &v)) too_many_tokens(p, a.weight, a.decl);
        p.set_tokens(v);
        if (given != nullptr) given->push_back(TokenMove{&p, a.weight});
      }
    } else if (to == nullptr && m != nullptr && m->as<Node>() != nullptr) {
      if (a.cond >= 0 && run(a.cond, arrow_self(net, a), mark, nullptr, nullptr).i == 0) continue;
      p.edit_objects().push_back(*m->as<Node>());
      to = &p;
    }
  }
  return to;
}

void ProgramImpl::compact_nets() {
  constexpr std::uint32_t gone = ~std::uint32_t{0};
  std::vector<std::uint32_t> to(tis_.size(), gone);       // old index -> new index
  std::vector<std::uint32_t> before(tis_.size() + 1, 0);  // old index -> live entries before it
  std::vector<TI> kept;
  kept.reserve(tis_.size() - dead_tis_);
  for (std::uint32_t i = 0; i < tis_.size(); ++i) {
    before[i] = static_cast<std::uint32_t>(kept.size());
    if (!tis_[i].net->dead) {
      to[i] = static_cast<std::uint32_t>(kept.size());
      kept.push_back(std::move(tis_[i]));
    }
  }
  before[tis_.size()] = static_cast<std::uint32_t>(kept.size());
  // Every list of indices keeps its order (choice, re-test and watcher order stay as they were).
  auto remap = [&](std::vector<std::uint32_t>& v) {
    std::size_t n = 0;
    for (std::uint32_t i : v)
      if (to[i] != gone) v[n++] = to[i];
    v.resize(n);
  };
  remap(dirty_);
  remap(enabled_);
  for (std::size_t k = 0; k < enabled_.size(); ++k)
    kept[enabled_[k]].enabled_pos = static_cast<std::int32_t>(k);
  auto remap_all = [&](auto& table) {  // watcher tables: lists that end empty go
    for (auto it = table.begin(); it != table.end();) {
      remap(it->second);
      it = it->second.empty() ? table.erase(it) : std::next(it);
    }
  };
  remap_all(place_watch_);
  deps_map_.update_all([&](const DepKey&, DepTable::Watchers& w) { remap(w); });
  tis_ = std::move(kept);
  std::erase_if(net_order_, [](const NetInst* n) { return n->dead; });
  for (NetInst* n : net_order_) n->first_ti = before[n->first_ti];  // a net's entries are contiguous
  std::erase_if(nets_, [](const auto& entry) { return entry.second->dead; });
  dead_nets_.clear();
  dead_tis_ = 0;
}

std::uint64_t ProgramImpl::step(std::uint64_t n) {
  // Between firings (not from the program's own code): drop dead nets once they are most of the list.
  if (dead_tis_ > 64 && dead_tis_ * 2 > tis_.size() && frames_.empty() && !guarding_) compact_nets();
  std::uint64_t fired = 0;
  try {
    fired = step_loop(n);
  } catch (...) {
    sync_state();
    throw;
  }
  sync_state();
  return fired;
}

bool ProgramImpl::fire_chosen(const Transition& node) {
  bool fired = false;
  try {
    refresh();
    for (const std::uint32_t i : enabled_) {
      const TI& ti = tis_[i];
      if (ti.net->dead || ti.net->transitions[static_cast<std::size_t>(ti.t)] != &node) continue;
      fire(i);
      fired = true;
      break;
    }
  } catch (...) {
    sync_state();
    throw;
  }
  sync_state();
  return fired;
}

std::uint64_t ProgramImpl::step_loop(std::uint64_t n) {
  std::uint64_t fired = 0;
  while (fired < n) {
    if (!refresh()) break;
    // xorshift64*: a seeded, reproducible choice among the enabled transitions.
    rng_ ^= rng_ >> 12;
    rng_ ^= rng_ << 25;
    rng_ ^= rng_ >> 27;
    const std::uint64_t r = rng_ * 0x2545F4914F6CDD1DULL;
    const std::uint32_t pick = enabled_[static_cast<std::size_t>((r >> 32) % enabled_.size())];
    fire(pick);
    ++fired;
  }
  return fired;
}

}  // namespace vsd::soml
