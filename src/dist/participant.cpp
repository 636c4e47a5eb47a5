// vsd::dist::Participant on Cyclone DDS's C API. All DDS types stay in this file (pimpl).
#include "vsd/dist/participant.hpp"

#include <dds/dds.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <deque>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include "sequence.hpp"
#include "vsd/core/bytes.hpp"
#include "vsd/core/detail/tx_codec.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/meta_instance.hpp"
#include "vsd/core/node.hpp"
#include "vsd/core/reference.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/dist/wire.hpp"
#include "vsd_dist.h"

namespace vsd::dist {

namespace {

// ---- the envelope --------------------------------------------------------------------------------------

enum class Kind : std::uint8_t { Bundle = 1, Claim = 2, Request = 3, Snapshot = 4, Report = 5 };
constexpr std::uint8_t envelope_magic[4] = {'V', 'S', 'D', 'D'};
constexpr std::uint8_t envelope_version = 2;  // 2: element-form list edits, list sequences in snapshots
constexpr std::size_t envelope_size = 5;

void write_envelope(std::vector<std::uint8_t>& out) {
  out.insert(out.end(), std::begin(envelope_magic), std::end(envelope_magic));
  out.push_back(envelope_version);
}

std::string hex(std::uint64_t id) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(id));
  return buf;
}

std::uint64_t random_id() {
  std::random_device rd;
  std::uint64_t id = 0;
  while (id == 0) id = (static_cast<std::uint64_t>(rd()) << 32) ^ rd();
  return id;
}

[[noreturn]] void dds_fail(const char* what, dds_return_t rc) {
  throw Error(std::string("dist: ") + what + " failed: " + dds_strretcode(rc));
}

// ---- one Cyclone domain per domain id and process, shared by the participants in it -------------------

struct Domains {
  std::mutex mutex;
  std::map<std::uint32_t, std::pair<dds_entity_t, int>> open;  // id -> (domain handle or 0, users)
};
Domains& domains() {
  static Domains* d = new Domains;  // never destroyed: participants may outlive static destruction order
  return *d;
}
void acquire_domain(std::uint32_t id, const std::string& config) {
  Domains& d = domains();
  std::lock_guard lock(d.mutex);
  auto& [handle, users] = d.open[id];
  if (users++ > 0 || config.empty()) return;
  const dds_entity_t h = dds_create_domain(id, config.c_str());
  if (h < 0) {
    --users;
    dds_fail("creating the DDS domain with the given configuration", h);
  }
  handle = h;
}
void release_domain(std::uint32_t id) {
  Domains& d = domains();
  std::lock_guard lock(d.mutex);
  auto it = d.open.find(id);
  if (it == d.open.end() || --it->second.second > 0) return;
  if (it->second.first > 0) dds_delete(it->second.first);
  d.open.erase(it);
}

// A received message, copied out of DDS's loan (it may wait in a buffer).
struct Message {
  std::uint64_t sender = 0;
  std::uint64_t seq = 0;
  std::uint64_t clock = 0;
  std::uint64_t target = 0;
  Kind kind{};
  std::vector<std::uint8_t> payload;  // after the envelope
};

using OwnerKey = std::pair<Id, std::string>;  // property "" is the instance itself
using ListKey = std::pair<Id, std::string>;   // (holder, list property)

// The newest entry of a node in a children list.
struct Top {
  ElementId element;
  Id holder = null_id;
};

// A node's children list: a node has one parent, so concurrent moves of one child are arbitrated.
bool is_children(std::string_view property) { return property == Node::vsd_prop_children().name(); }

// The ids in the reference list @p prop of @p holder (empty when either does not exist here).
std::vector<Id> list_ids(const SimState& state, Id holder, std::string_view prop) {
  std::vector<Id> ids;
  const SimStateInstance* x = state.find(holder);
  if (x == nullptr) return ids;
  const MetaProperty* p = x->meta().find_property(prop);
  if (p == nullptr || !p->type().is_ref_list()) return ids;
  const auto& list = *static_cast<const RefListBase*>(p->address(*x));
  ids.reserve(list.size());
  for (std::size_t i = 0; i < list.size(); ++i) ids.push_back(list.at(i)->id());
  return ids;
}

// The ids of a reference list's binary form (varint count, varint ids).
std::vector<Id> ids_of_list_value(std::span<const std::uint8_t> value) {
  ByteReader r(value.data(), value.size());
  std::vector<Id> ids(r.size_prefix(1));
  for (Id& i : ids) i = r.varint();
  return ids;
}

// The total order of bundles and claims: the sender's Lamport clock, then its id. Every replica compares
// the same two numbers, so every replica decides a race alike.
struct Stamp {
  std::uint64_t clock = 0;
  std::uint64_t who = 0;
  auto operator<=>(const Stamp&) const = default;
};
constexpr Stamp no_limit{~std::uint64_t{0}, ~std::uint64_t{0}};

// A change of another participant that lost here: to a later write, a deletion, a newer move.
struct Lost {
  Id instance;
  std::string property;
  Stamp winner;
  Id target;            // the instance a reference or list entry referred to (or null_id)
  std::uint64_t loser;  // the participant whose change lost
};

// The report of a lost change, made while applying the bundle m (the loser's sequence number is known
// only when m is the loser's own bundle).
Conflict conflict_of(const Lost& l, ConflictKind kind, const Message& m) {
  Conflict c;
  c.kind = kind;
  c.writer = l.loser;
  c.owner = l.winner.who;
  c.seq = l.loser == m.sender ? m.seq : 0;
  c.instance = l.instance;
  c.property = l.property;
  c.target = l.target;
  return c;
}

// One operation of a bundle, for the ownership check.
struct OpRef {
  Transaction::Op op;
  Id id;
  std::string_view name;
};

// The stamp of the last set of one property that was applied (a last-writer-wins register's stamp).
struct Written {
  std::string property;
  Stamp stamp;
};

// One claim or release of an ownership key, in stamp order.
struct OwnEvent {
  Stamp stamp;
  bool take = true;
  std::uint64_t seq = 0;  // the claimant's sequence number of the claim
  bool lost = false;      // a take that lost a race (reported once)
};

// Who owns a key after the events before @p limit: events apply in stamp order; a take succeeds when
// nobody (or the claimant) owns the key, a release when the releaser does.
std::uint64_t replay(const std::vector<OwnEvent>& history, const Stamp& limit) {
  std::uint64_t owner = 0;
  for (const OwnEvent& e : history) {
    if (!(e.stamp < limit)) break;
    if (e.take) {
      if (owner == 0) owner = e.stamp.who;
    } else if (owner == e.stamp.who) {
      owner = 0;
    }
  }
  return owner;
}

}  // namespace

struct Participant::Impl {
  SimState& state;
  ParticipantOptions opt;
  std::uint64_t id = random_id();
  bool synced = false;
  bool ever_synced = false;
  std::uint64_t seq = 0;                                     // my last sequence number
  std::uint64_t clock = 0;                                   // my Lamport clock
  std::unordered_map<std::uint64_t, std::uint64_t> applied;  // sender -> last seq handled
  std::unordered_map<Id, std::vector<Written>> written;      // instance -> its registers' stamps
  std::map<OwnerKey, std::vector<OwnEvent>> claims;          // every claim and release, per key
  // Instances deleted, with the stamp of the deletion: a change to one of them made concurrently with the
  // deletion is dropped by every replica (the deletion wins), whatever the arrival order.
  std::unordered_map<Id, Stamp> deleted;
  // When each tombstone was made here, oldest first: pruned after ParticipantOptions::tombstone_horizon.
  std::deque<std::pair<std::chrono::steady_clock::time_point, Id>> deletion_order;
  std::chrono::steady_clock::time_point last_prune{};
  // Every reference list edited through vsd::dist since it was created or joined: a replicated sequence
  // whose visible entries are the list here (docs/dist.md, "Reference lists"). Lists nobody edited have
  // none; their value is the same everywhere.
  std::map<ListKey, internal::Sequence> lists;
  // Per node: the newest entry of it in any children list (holder, entry). A node has one parent: of two
  // concurrent moves, the newer entry wins and the other is removed (docs/dist.md).
  std::unordered_map<Id, Top> top_child;
  std::uint64_t prefer = 0;  // the participant a resynchronisation asks first (0: anyone)
  std::unordered_map<std::uint64_t, std::string> names;
  std::deque<Message> buffer;  // bundles and claims received while unsynchronised
  // Bundles (and the ones after them, per sender) that edit a list entry made by a bundle of a third
  // participant that has not arrived yet: they wait for it (bundles are not delivered in causal order).
  std::map<std::uint64_t, std::deque<Message>> waiting;
  std::chrono::steady_clock::time_point waiting_since{};
  bool replaying = false;
  std::unordered_map<std::uint64_t, std::uint64_t> last_clock;  // sender -> clock of its last bundle applied
  std::uint64_t nonce = 0;                                      // of my pending snapshot request
  std::chrono::steady_clock::time_point last_request{};
  ParticipantStats stats;
  Signal<void(const Conflict&)> conflict_signal;
  Signal<void()> synced_signal;
  std::deque<Transaction> local;  // bundles of local changes not published yet (see hear_bundle)
  int ignoring = 0;               // > 0 while this participant cuts the recording to drop it
  bool owns_recording = false;    // recording was started by this participant (and is stopped by it)
  Connection bundle_listener;
  dds_entity_t participant = 0, topic = 0, writer = 0, reader = 0, waitset = 0, readcond = 0;
  bool domain_acquired = false;

  Impl(SimState& s, ParticipantOptions o) : state(s), opt(std::move(o)) {}

  void log(const std::string& line) const {
    if (opt.log) {
      opt.log(line);
    } else {
      std::cerr << "vsd::dist[" << opt.name << "]: " << line << "\n";
    }
  }
  std::string who(std::uint64_t p) const {
    if (p == id) return "'" + opt.name + "'";
    if (auto it = names.find(p); it != names.end()) return "'" + it->second + "'";
    return hex(p);
  }

  // ---- DDS ----
  void open() {
    if (opt.domain > 230)
      throw Error("dist: domain id " + std::to_string(opt.domain) + " is out of range (0-230)");
    acquire_domain(opt.domain, opt.config);
    domain_acquired = true;
    // The lease decides how soon the others drop a participant that died without a goodbye; until then a
    // reliable writer waits for its acknowledgements.
    dds_qos_t* pqos = dds_create_qos();
    dds_qset_liveliness(pqos, DDS_LIVELINESS_AUTOMATIC, DDS_MSECS(opt.lease_duration.count()));
    participant = dds_create_participant(opt.domain, pqos, nullptr);
    dds_delete_qos(pqos);
    if (participant < 0) dds_fail("dds_create_participant", participant);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(opt.write_timeout.count()));
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
    dds_qset_destination_order(qos, DDS_DESTINATIONORDER_BY_RECEPTION_TIMESTAMP);
    dds_qset_ignorelocal(qos, DDS_IGNORELOCAL_PARTICIPANT);
    topic = dds_create_topic(participant, &vsd_dist_Message_desc, opt.topic.c_str(), qos, nullptr);
    if (topic < 0) {
      dds_delete_qos(qos);
      dds_fail("dds_create_topic", topic);
    }
    writer = dds_create_writer(participant, topic, qos, nullptr);
    reader = dds_create_reader(participant, topic, qos, nullptr);
    dds_delete_qos(qos);
    if (writer < 0) dds_fail("dds_create_writer", writer);
    if (reader < 0) dds_fail("dds_create_reader", reader);
    readcond = dds_create_readcondition(reader, DDS_ANY_STATE);
    waitset = dds_create_waitset(participant);
    if (readcond < 0 || waitset < 0) dds_fail("creating a wait set", readcond < 0 ? readcond : waitset);
    if (const dds_return_t rc = dds_waitset_attach(waitset, readcond, 0); rc < 0)
      dds_fail("dds_waitset_attach", rc);
  }
  void close() noexcept {
    if (participant > 0) dds_delete(participant);  // deletes its children
    participant = 0;
    if (domain_acquired) release_domain(opt.domain);
    domain_acquired = false;
  }

  void send(Kind kind, std::uint64_t msg_seq, std::uint64_t target, std::vector<std::uint8_t>& payload) {
    vsd_dist_Message m{};
    m.sender = id;
    m.seq = msg_seq;
    m.clock = clock;
    m.target = target;
    m.kind = static_cast<std::uint8_t>(kind);
    m.payload._buffer = payload.data();
    m.payload._length = static_cast<std::uint32_t>(payload.size());
    m.payload._maximum = m.payload._length;
    m.payload._release = false;
    const dds_return_t rc = dds_write(writer, &m);
    if (rc < 0) dds_fail("dds_write (is a participant stuck?)", rc);
  }

  // Sends what the writer holds back: with Cyclone's write batching (Internal/WriteBatch) samples wait in
  // the writer until a datagram is full or this is called; without it, this costs next to nothing.
  void flush() const noexcept {
    if (writer > 0) dds_write_flush(writer);
  }

  std::size_t peers() const {
    dds_publication_matched_status_t st{};
    if (dds_get_publication_matched_status(writer, &st) < 0) return 0;
    return st.current_count;
  }

  // ---- concurrent writes: a last-writer-wins register per property ----
  const Stamp* written_stamp(Id inst, std::string_view prop) const {
    auto it = written.find(inst);
    if (it == written.end()) return nullptr;
    for (const Written& w : it->second)
      if (w.property == prop) return &w.stamp;
    return nullptr;
  }
  void note_write(Id inst, std::string_view prop, const Stamp& stamp) {
    std::vector<Written>& ws = written[inst];
    for (Written& w : ws)
      if (w.property == prop) {
        w.stamp = stamp;
        return;
      }
    ws.push_back({std::string(prop), stamp});
  }

  // ---- ownership ----
  std::uint64_t key_owner(Id inst, std::string_view prop, const Stamp& limit) const {
    auto it = claims.find(OwnerKey(inst, std::string(prop)));
    return it == claims.end() ? 0 : replay(it->second, limit);
  }
  // The owner of @p prop of @p inst (or of the instance) as of the stamp @p limit.
  std::uint64_t owner_at(Id inst, std::string_view prop, const Stamp& limit) const {
    if (claims.empty()) return 0;
    if (!prop.empty())
      if (const std::uint64_t o = key_owner(inst, prop, limit); o != 0) return o;
    return key_owner(inst, {}, limit);
  }
  std::uint64_t owner_of(Id inst, std::string_view prop) const { return owner_at(inst, prop, no_limit); }
  // The operations of @p t, for find_conflict().
  static std::vector<OpRef> ops_of(const Transaction& t) {
    std::vector<OpRef> ops;
    detail::TxParser parser(t);
    for (detail::TxOp op; parser.next(op);) ops.push_back({op.op, op.id, op.name});
    return ops;
  }
  // The first of @p ops that touches what someone other than @p writer owns as of @p stamp.
  std::optional<Conflict> find_conflict(const std::vector<OpRef>& ops, std::uint64_t writer,
                                        const Stamp& stamp = no_limit) const {
    if (claims.empty()) return std::nullopt;
    for (const OpRef& op : ops) {
      Conflict c;
      c.writer = writer;
      c.instance = op.id;
      switch (op.op) {
        case Transaction::Op::Create:
          continue;
        case Transaction::Op::Delete:
          for (auto it = claims.lower_bound(OwnerKey(op.id, std::string()));
               it != claims.end() && it->first.first == op.id; ++it)
            if (const std::uint64_t o = replay(it->second, stamp); o != 0 && o != writer) {
              c.owner = o;
              c.property = it->first.second;
              break;
            }
          if (c.owner == 0) continue;
          break;
        default:
          c.owner = owner_at(op.id, op.name, stamp);
          if (c.owner == 0 || c.owner == writer) continue;
          c.property = std::string(op.name);
          break;
      }
      return c;
    }
    return std::nullopt;
  }
  void forget_deleted(const std::vector<Id>& ids, const Stamp& stamp) {
    for (const Id gone : ids) {
      if (deleted.emplace(gone, stamp).second)
        deletion_order.emplace_back(std::chrono::steady_clock::now(), gone);
      written.erase(gone);
      top_child.erase(gone);
      for (auto it = lists.lower_bound(ListKey(gone, std::string()));
           it != lists.end() && it->first.first == gone;)
        it = lists.erase(it);
      if (!claims.empty()) std::erase_if(claims, [&](const auto& e) { return e.first.first == gone; });
    }
  }
  std::string describe(const Conflict& c) const {
    std::string what = "#" + std::to_string(c.instance) + (c.property.empty() ? "" : "." + c.property);
    switch (c.kind) {
      case ConflictKind::ConcurrentWrite:
        return "concurrent writes to " + what + ": the set of " + who(c.writer) + " (bundle " +
               std::to_string(c.seq) + ") lost to the later stamped one of " + who(c.owner);
      case ConflictKind::ClaimRace:
        return "concurrent claims of " + what + ": the claim of " + who(c.writer) + " (claim " +
               std::to_string(c.seq) + ") lost to the earlier stamped one of " + who(c.owner) +
               "; rolled back";
      case ConflictKind::Deleted:
        if (c.target != null_id)
          return "reference by " + who(c.writer) + " from " + what + " to #" + std::to_string(c.target) +
                 (c.seq != 0 ? " (bundle " + std::to_string(c.seq) + ")" : std::string()) +
                 " dropped: " + who(c.owner) + " deleted #" + std::to_string(c.target) + " concurrently";
        return "write by " + who(c.writer) + " to " + what + " (bundle " + std::to_string(c.seq) +
               ") dropped: " + who(c.owner) + " deleted #" + std::to_string(c.instance) + " concurrently";
      case ConflictKind::ConcurrentMove:
        return "concurrent moves of #" + std::to_string(c.target) + ": the move of " + who(c.writer) +
               " to " + what + (c.seq != 0 ? " (bundle " + std::to_string(c.seq) + ")" : std::string()) +
               " lost to the newer one of " + who(c.owner);
      case ConflictKind::Owned:
        break;
    }
    return "write by " + who(c.writer) + " to " + what + ", owned by " + who(c.owner) + ", rejected" +
           (c.seq != 0 ? " (bundle " + std::to_string(c.seq) + ")" : " (undone before it was sent)");
  }
  void report(Conflict c, bool publish_it) {
    c.text = describe(c);
    ++stats.conflicts;
    log(c.text);
    if (publish_it) {
      std::vector<std::uint8_t> p;
      write_envelope(p);
      ByteWriter w(p);
      w.fixed(c.writer);
      w.varint(c.seq);
      w.fixed(c.owner);
      w.varint(c.instance);
      w.string(c.property);
      w.string(opt.name);
      w.u8(static_cast<std::uint8_t>(c.kind));
      w.varint(c.target);
      send(Kind::Report, 0, 0, p);
    }
    conflict_signal.emit(c);
  }

  // ---- sending ----
  // Replaces the whole-value sets of reference lists in @p t by erasures of the old entries and insertions
  // of the new ones: lists merge per entry (docs/dist.md, "Reference lists").
  void list_sets_as_edits(Transaction& t) const {
    const std::vector<std::uint8_t>& bytes = t.bytes();
    auto is_list_set = [&](const detail::TxOp& op) {
      if (op.op != Transaction::Op::Set) return false;
      const SimStateInstance* x = state.find(op.id);
      const MetaProperty* p = x != nullptr ? x->meta().find_property(op.name) : nullptr;
      return p != nullptr && p->type().is_ref_list();
    };
    bool any = false;  // most bundles have none: look without keeping the parse
    detail::TxParser parser(t);
    for (detail::TxOp op; !any && parser.next(op);) any = is_list_set(op);
    if (!any) return;
    std::vector<detail::TxOp> ops = detail::parse_tx(t);
    std::vector<std::uint8_t> out;
    detail::write_tx_header(out);
    std::size_t count = 0;
    for (std::size_t i = 0; i < ops.size(); ++i) {
      const detail::TxOp& op = ops[i];
      if (!is_list_set(op)) {
        const std::size_t end = i + 1 < ops.size() ? ops[i + 1].offset : bytes.size();
        out.insert(out.end(), bytes.begin() + static_cast<std::ptrdiff_t>(op.offset),
                   bytes.begin() + static_cast<std::ptrdiff_t>(end));
        ++count;
        continue;
      }
      const std::vector<Id> before = ids_of_list_value(op.old_value);
      const std::vector<Id> after = ids_of_list_value(op.new_value);
      for (std::size_t k = before.size(); k-- > 0; ++count)
        detail::write_list(out, Transaction::Op::Erase, op.id, op.name, k, before[k]);
      for (std::size_t k = 0; k < after.size(); ++k, ++count)
        detail::write_list(out, Transaction::Op::Insert, op.id, op.name, k, after[k]);
    }
    t = detail::make_transaction(std::move(out), count);
  }

  // The value each list edited by @p t (and without a sequence yet) had before @p t: the state holds the
  // value after it, so the edits are undone backwards.
  std::map<ListKey, std::vector<Id>> lists_before(const Transaction& t) const {
    struct Edit {
      bool insert;
      std::size_t index;
      Id target;
    };
    std::map<ListKey, std::vector<Edit>> edits;
    detail::TxParser parser(t);
    for (detail::TxOp op; parser.next(op);) {
      if (op.op != Transaction::Op::Insert && op.op != Transaction::Op::Erase) continue;
      ListKey key(op.id, std::string(op.name));
      if (lists.contains(key)) continue;
      edits[key].push_back({op.op == Transaction::Op::Insert, op.index, op.target});
    }
    std::map<ListKey, std::vector<Id>> out;
    for (const auto& [key, es] : edits) {
      std::vector<Id> v = list_ids(state, key.first, key.second);  // empty when the bundle deleted it
      for (auto e = es.rbegin(); e != es.rend(); ++e) {
        const auto at = v.begin() + static_cast<std::ptrdiff_t>(std::min(e->index, v.size()));
        if (e->insert) {
          if (at != v.end()) v.erase(at);
        } else {
          v.insert(at, e->target);
        }
      }
      out.emplace(key, std::move(v));
    }
    return out;
  }

  // The state's recording is shared through SimState::on_bundle(): whoever cuts it (this participant at
  // each poll, or another reader such as the web inspector at the end of a step), every bundle of local
  // changes reaches `local` once, in order. What this participant cuts itself to drop it (changes made by
  // applying others' bundles, an undone conflict) it ignores.
  void hear_bundle(const Transaction& t) {
    if (ignoring == 0) local.push_back(t);
  }
  void discard_recording() {
    ++ignoring;
    struct Leave {
      int& n;
      ~Leave() { --n; }
    } leave{ignoring};
    if (state.recording()) (void)state.take_recording();
  }

  bool publish() {
    if (state.recording()) (void)state.take_recording();  // the step's changes, to every reader
    bool any = false;
    while (!local.empty()) {
      Transaction t = std::move(local.front());
      local.pop_front();
      any = publish_one(std::move(t)) || any;
    }
    return any;
  }

  bool publish_one(Transaction t) {
    if (t.empty()) return false;
    if (!synced) {
      ++stats.dropped_unsynced;
      log("dropped " + std::to_string(t.size()) + " local changes made while not synchronised");
      return false;
    }
    if (std::optional<Conflict> c; !claims.empty() && (c = find_conflict(ops_of(t), id))) {
      // Undo the whole bundle here: a write to what another participant owns is never half-applied.
      state.apply(t.inverted());
      discard_recording();
      report(*c, true);
      return false;
    }
    list_sets_as_edits(t);
    // List edits travel in element form: each recorded index is turned into the entry it names here, and
    // the mirror sequences take the edits (the state holds them already).
    const Stamp next{clock + 1, id};
    std::uint64_t inserted = 0;
    std::optional<std::map<ListKey, std::vector<Id>>> before;
    const ListEncoder to_elements = [&](Transaction::Op op, Id holder, std::string_view prop,
                                        std::size_t index, Id target) {
      ListKey key(holder, std::string(prop));
      auto it = lists.find(key);
      if (it == lists.end()) {
        if (!before) before = lists_before(t);
        auto b = before->find(key);
        it = lists.emplace(key, internal::Sequence::base(b != before->end() ? b->second : std::vector<Id>{}))
                 .first;
      }
      internal::Sequence& seq_of_list = it->second;
      ElementEdit e;
      e.op = op;
      e.holder = holder;
      e.property = prop;
      e.target = target;
      auto out_of_sync = [&]() {
        return Error("dist: the entries of #" + std::to_string(holder) + "." + std::string(prop) +
                     " are out of step with the list (an edit at index " + std::to_string(index) + ")");
      };
      if (op == Transaction::Op::Insert) {
        if (index > 0) {
          const std::size_t pos = seq_of_list.position(index - 1);
          if (pos == internal::Sequence::npos) throw out_of_sync();
          e.origin = seq_of_list.elems[pos].id;
        }
        e.element = ElementId{next.clock, next.who, ++inserted};
        (void)seq_of_list.integrate(e.element, e.origin, target, false);
        if (is_children(prop)) top_child[target] = Top{e.element, holder};
      } else {
        const std::size_t pos = seq_of_list.position(index);
        if (pos == internal::Sequence::npos || seq_of_list.elems[pos].target != target) throw out_of_sync();
        e.element = seq_of_list.elems[pos].id;
        seq_of_list.remove(pos);
      }
      return e;
    };
    WireBundle wb = encode_bundle(t, state, to_elements);
    if (wb.ops == 0) {
      forget_deleted(wb.deleted, Stamp{clock, id});
      return false;
    }
    std::vector<std::uint8_t> p;
    p.reserve(envelope_size + wb.bytes.size());
    write_envelope(p);
    p.insert(p.end(), wb.bytes.begin(), wb.bytes.end());
    ++clock;
    send(Kind::Bundle, ++seq, 0, p);
    // My sets now hold the bundle's stamp here, as they will at every receiver that applies them.
    const Stamp stamp{clock, id};
    for (const auto& [inst, prop] : wb.sets) note_write(inst, prop, stamp);
    forget_deleted(wb.deleted, stamp);
    ++stats.bundles_sent;
    return true;
  }

  void request_snapshot() {
    std::vector<std::uint8_t> p;
    write_envelope(p);
    ByteWriter w(p);
    w.fixed(nonce);
    w.string(opt.name);
    w.fixed(prefer);
    send(Kind::Request, 0, 0, p);
    last_request = std::chrono::steady_clock::now();
  }

  void serve_snapshot(const Message& m) {
    ByteReader r(m.payload.data(), m.payload.size());
    const auto req_nonce = r.fixed<std::uint64_t>();
    names[m.sender] = r.string();
    if (const auto wanted = r.remaining() >= 8 ? r.fixed<std::uint64_t>() : 0; wanted != 0 && wanted != id)
      return;   // the joiner asks a particular participant (the owner whose state it must take)
    publish();  // my own changes go out first, so the snapshot's sequence number for me is exact
    WireBundle wb = encode_bundle(state.snapshot(), state);
    std::vector<std::uint8_t> p;
    write_envelope(p);
    ByteWriter w(p);
    w.fixed(req_nonce);
    w.string(opt.name);
    w.varint(applied.size() + 1);
    w.fixed(id);
    w.varint(seq);
    for (const auto& [sender, s] : applied) {
      w.fixed(sender);
      w.varint(s);
    }
    w.varint(claims.size());
    for (const auto& [key, history] : claims) {
      w.varint(key.first);
      w.string(key.second);
      w.varint(history.size());
      for (const OwnEvent& e : history) {
        w.varint(e.stamp.clock);
        w.fixed(e.stamp.who);
        w.u8(static_cast<std::uint8_t>((e.take ? 1 : 0) | (e.lost ? 2 : 0)));
        w.varint(e.seq);
      }
    }
    w.varint(names.size());
    for (const auto& [pid, n] : names) {
      w.fixed(pid);
      w.string(n);
    }
    w.varint(clock);
    w.varint(written.size());
    for (const auto& [inst, ws] : written) {
      w.varint(inst);
      w.varint(ws.size());
      for (const Written& x : ws) {
        w.string(x.property);
        w.varint(x.stamp.clock);
        w.fixed(x.stamp.who);
      }
    }
    w.varint(deleted.size());
    for (const auto& [inst, stamp] : deleted) {
      w.varint(inst);
      w.varint(stamp.clock);
      w.fixed(stamp.who);
    }
    w.varint(lists.size());
    for (const auto& [key, sq] : lists) {
      w.varint(key.first);
      w.string(key.second);
      w.varint(sq.elems.size());
      for (const internal::Element& e : sq.elems) {
        w.varint(e.id.clock);
        w.fixed(e.id.who);
        w.varint(e.id.n);
        w.varint(e.target);
        w.u8(e.removed ? 1 : 0);
      }
    }
    p.insert(p.end(), wb.bytes.begin(), wb.bytes.end());
    send(Kind::Snapshot, 0, m.sender, p);
    ++stats.snapshots_served;
  }

  // ---- receiving ----

  void resync(const std::string& reason, const Message* pending, std::uint64_t from = 0) {
    log(reason + "; resynchronising from a snapshot" + (from != 0 ? " of " + who(from) : std::string()));
    prefer = from;
    synced = false;
    buffer.clear();
    if (pending != nullptr) buffer.push_back(*pending);
    for (auto& [sender, q] : waiting)  // after the snapshot, in their senders' order
      for (Message& w : q)
        if (pending == nullptr || w.sender != pending->sender || w.seq != pending->seq)
          buffer.push_back(std::move(w));
    waiting.clear();
    waiting_since = {};
    nonce = random_id();
    resync_started = std::chrono::steady_clock::now();
    request_snapshot();
  }

  void clear_state() {
    std::vector<Id> ids;
    for (SimStateInstance* x : state.instances())
      if (x != &state.database()) ids.push_back(x->id());
    for (Id i : ids)
      if (SimStateInstance* x = state.find(i)) state.destroy(*x);
    Database& root = state.database();
    for (const MetaProperty* p : root.meta().properties())
      if (detail::carried_in_payload(*p) && p->has(Distributed))
        p->assign_raw(root, p->default_value().data());
  }

  void install_snapshot(const Message& m) {
    ByteReader r(m.payload.data(), m.payload.size());
    if (r.fixed<std::uint64_t>() != nonce || synced) return;  // an answer to an older request, or a late one
    const std::string from = r.string();
    names[m.sender] = from;
    std::unordered_map<std::uint64_t, std::uint64_t> seqs;
    for (std::size_t n = r.size_prefix(9); n > 0; --n) {
      const auto sender = r.fixed<std::uint64_t>();
      seqs[sender] = r.varint();
    }
    std::map<OwnerKey, std::vector<OwnEvent>> table;
    for (std::size_t n = r.size_prefix(3); n > 0; --n) {
      const Id inst = r.varint();
      auto& history = table[OwnerKey(inst, r.string())];
      for (std::size_t k = r.size_prefix(11); k > 0; --k) {
        OwnEvent e;
        e.stamp.clock = r.varint();
        e.stamp.who = r.fixed<std::uint64_t>();
        const std::uint8_t flags = r.u8();
        e.take = (flags & 1) != 0;
        e.lost = (flags & 2) != 0;
        e.seq = r.varint();
        history.push_back(e);
      }
    }
    for (std::size_t n = r.size_prefix(9); n > 0; --n) {
      const auto pid = r.fixed<std::uint64_t>();
      names[pid] = r.string();
    }
    const std::uint64_t their_clock = r.varint();
    std::unordered_map<Id, std::vector<Written>> registers;
    for (std::size_t n = r.size_prefix(2); n > 0; --n) {
      auto& ws = registers[r.varint()];
      for (std::size_t k = r.size_prefix(10); k > 0; --k) {
        Written x;
        x.property = r.string();
        x.stamp.clock = r.varint();
        x.stamp.who = r.fixed<std::uint64_t>();
        ws.push_back(std::move(x));
      }
    }
    std::unordered_map<Id, Stamp> tombstones;
    for (std::size_t n = r.size_prefix(10); n > 0; --n) {
      const Id inst = r.varint();
      Stamp& st = tombstones[inst];
      st.clock = r.varint();
      st.who = r.fixed<std::uint64_t>();
    }
    std::map<ListKey, internal::Sequence> sequences;
    for (std::size_t n = r.size_prefix(3); n > 0; --n) {
      const Id holder = r.varint();
      internal::Sequence& sq = sequences[ListKey(holder, r.string())];
      sq.elems.resize(r.size_prefix(12));
      for (internal::Element& e : sq.elems) {
        e.id.clock = r.varint();
        e.id.who = r.fixed<std::uint64_t>();
        e.id.n = r.varint();
        e.target = r.varint();
        e.removed = r.u8() != 0;
        if (e.removed) e.removed_at = std::chrono::steady_clock::now();
      }
    }
    if (seqs[id] < seq) {
      // The answering participant has not applied all my bundles yet: installing its state would lose
      // them here. Ask again later.
      return;
    }
    if (auto bad = invalid_write(table, registers)) {
      // The answer holds a write its own claims reject (its participant took the bundle before it knew the
      // claim, and has not noticed yet): ask the owner instead.
      log("ignored a snapshot of " + who(m.sender) + ": it holds a write of " + who(bad->writer) + " to #" +
          std::to_string(bad->instance) + "." + bad->property + " that the claim of " + who(bad->owner) +
          " came before");
      prefer = bad->owner;
      nonce = random_id();
      resync_started = std::chrono::steady_clock::now();
      request_snapshot();
      return;
    }
    const Transaction t = decode_bundle({m.payload.data() + r.position(), r.remaining()});
    clear_state();
    state.apply(t);
    discard_recording();
    seqs.erase(id);
    applied = std::move(seqs);
    // Claims that lost a race this participant had not seen yet (it may resynchronise because of the race):
    // counted and reported here too, so every participant reports every lost claim once.
    std::vector<Conflict> newly_lost;
    for (const auto& [key, history] : table)
      for (const OwnEvent& e : history) {
        if (!e.lost) continue;
        bool known = false;
        if (auto old = claims.find(key); old != claims.end())
          for (const OwnEvent& o : old->second) known = known || (o.stamp == e.stamp && o.lost);
        if (known) continue;
        Conflict c;
        c.kind = ConflictKind::ClaimRace;
        c.writer = e.stamp.who;
        c.owner = replay(history, e.stamp);
        c.seq = e.seq;
        c.instance = key.first;
        c.property = key.second;
        newly_lost.push_back(std::move(c));
      }
    claims = std::move(table);
    written = std::move(registers);
    deleted = std::move(tombstones);
    lists = std::move(sequences);
    deletion_order.clear();
    for (const auto& [gone, st] : deleted)
      deletion_order.emplace_back(std::chrono::steady_clock::now(), gone);
    top_child.clear();
    for (const auto& [key, sq] : lists)
      if (is_children(key.second))
        for (const internal::Element& e : sq.elems)
          if (auto [at, fresh] = top_child.try_emplace(e.target, Top{e.id, key.first});
              !fresh && at->second.element < e.id)
            at->second = Top{e.id, key.first};
    clock = std::max(clock, their_clock);
    prefer = 0;
    synced = true;
    self_diverged = false;
    if (ever_synced) ++stats.resyncs;
    ever_synced = true;
    log("synchronised from a snapshot of " + who(m.sender) + " (" + std::to_string(state.size()) +
        " instances)");
    synced_signal.emit();
    for (Conflict& c : newly_lost) {
      ++stats.claims_lost;
      report(std::move(c), false);
    }
    // Bundles and claims handled here before the resynchronisation that the answering participant had not
    // received yet: they will not come again, so they are taken from the history (in their senders' order,
    // before those that arrived since); should one be missing there, the next message of its sender shows
    // the gap.
    std::deque<Message> pending = std::move(buffer);
    buffer.clear();
    std::deque<Message> earlier = std::move(history);
    history.clear();
    for (const Message& b : earlier)
      if (auto a = applied.find(b.sender); a == applied.end() || a->second < b.seq) sequenced(b);
    for (const Message& b : pending) sequenced(b);
  }

  // Bundles and claims of others handled since the last snapshot was installed (at most history_limit):
  // a snapshot from a participant that has not received them yet is completed from here.
  static constexpr std::size_t history_limit = 1024;
  std::deque<Message> history;
  void handled(const Message& m) {
    history.push_back(m);
    if (history.size() > history_limit) history.pop_front();
  }

  std::size_t applied_now = 0;  // bundles applied during the current poll()
  bool accept_gaps = false;     // while give_up_resync() drains the buffer
  // The last bundle that did not apply: when it fails again after a snapshot, it is dropped.
  std::pair<std::uint64_t, std::uint64_t> last_failure{0, 0};
  // Set when this state holds a change of mine that the others rejected: it must not serve snapshots.
  bool self_diverged = false;
  std::chrono::steady_clock::time_point resync_started{};

  // True when entry @p e was made by a bundle of a participant other than @p sender that is not applied
  // here yet: its clock is past that participant's last bundle applied here.
  bool to_come(const ElementId& e, std::uint64_t sender) const {
    if (e.who == 0 || e.who == sender || e.who == id) return false;
    auto c = last_clock.find(e.who);
    return c == last_clock.end() || c->second < e.clock;
  }

  // Retries the waiting bundles, each sender's in order, until none moves on.
  void replay_waiting() {
    replaying = true;
    for (bool progress = true; progress && synced;) {
      progress = false;
      for (auto w = waiting.begin(); w != waiting.end() && synced;) {
        while (!w->second.empty() && synced) {
          const Message m = std::move(w->second.front());
          w->second.pop_front();
          const std::uint64_t before = applied[m.sender];
          sequenced(m);
          if (!synced) {  // it resynchronises: resync() moved the waiting bundles to the buffer
            replaying = false;
            return;
          }
          if (!w->second.empty() && w->second.front().seq == m.seq) break;  // waits again
          progress = progress || applied[m.sender] != before;
        }
        w = w->second.empty() ? waiting.erase(w) : std::next(w);
      }
    }
    if (waiting.empty()) waiting_since = {};
    replaying = false;
  }

  // A bundle or claim, in the sender's order.
  void sequenced(const Message& m) {
    if (!synced) {
      buffer.push_back(m);
      return;
    }
    if (!replaying)
      if (auto w = waiting.find(m.sender); w != waiting.end() && !w->second.empty()) {
        w->second.push_back(m);  // behind its sender's waiting bundle
        return;
      }
    publish();  // my changes first: the recording must hold only what this participant did
    const Stamp stamp{m.clock, m.sender};
    Transaction t;
    // The sets of this bundle that lost to a later stamped write applied here (last writer wins), and the
    // ones that take the register.
    std::vector<Lost> lost;
    std::vector<Lost> gone;      // changes to instances deleted concurrently (winner: the deletion's stamp)
    std::vector<Lost> dangling;  // references to, and list entries of, instances deleted concurrently
    std::vector<Lost> moved;     // children-list entries that lost a race of moves
    std::vector<std::pair<Id, std::string_view>> kept;
    std::vector<Id> deletes;
    std::vector<OpRef> own;  // the bundle's own kept operations (not those added here): for ownership
    // The list sequences and newest children entries as the bundle leaves them: committed once it applied.
    std::map<ListKey, internal::Sequence> touched;
    std::unordered_map<Id, Top> tops;
    std::unordered_map<Id, std::string_view> created;  // class names of the instances the bundle creates
    bool unknown_entry = false;   // an edit names a list entry this participant has not seen
    bool entry_to_come = false;   // ... one that a bundle not applied yet of a third participant makes
    bool target_unknown = false;  // a reference or list entry names an instance unknown here
    if (m.kind == Kind::Bundle) {
      auto existing = [&](const ListKey& key) -> internal::Sequence* {
        if (auto x = touched.find(key); x != touched.end()) return &x->second;
        if (auto l = lists.find(key); l != lists.end()) return &touched.emplace(key, l->second).first->second;
        return nullptr;
      };
      auto sequence = [&](Id holder, std::string_view prop) -> internal::Sequence& {
        ListKey key(holder, std::string(prop));
        if (internal::Sequence* x = existing(key)) return *x;
        // Nobody edited this list before: it holds the same value everywhere (docs/dist.md).
        return touched.emplace(key, internal::Sequence::base(list_ids(state, holder, prop))).first->second;
      };
      auto top_of = [&](Id child) -> std::optional<Top> {
        if (auto x = tops.find(child); x != tops.end()) return x->second;
        if (auto x = top_child.find(child); x != top_child.end()) return x->second;
        return std::nullopt;
      };
      // An instance that is neither here nor made by this bundle: a reference to it cannot apply yet.
      auto unknown_target = [&](Id target) {
        return target != null_id && state.find(target) == nullptr && !created.contains(target);
      };
      auto property_here = [&](Id inst, std::string_view prop) -> const MetaProperty* {
        const MetaInstance* cls = nullptr;
        if (const SimStateInstance* x = state.find(inst)) {
          cls = &x->meta();
        } else if (auto c = created.find(inst); c != created.end()) {
          cls = state.environment().registry().find_class_exact(c->second);
        }
        return cls != nullptr ? cls->find_property(prop) : nullptr;
      };
      DecodeHooks hooks;
      hooks.keep = [&](Transaction::Op op, Id inst, std::string_view prop) {
        if (auto d = deleted.find(inst); d != deleted.end()) {
          // The deletion wins, whatever the stamps: every replica ends without the instance. A second
          // deletion of it is no conflict.
          if (op != Transaction::Op::Delete &&
              std::none_of(gone.begin(), gone.end(), [&](const Lost& g) { return g.instance == inst; }))
            gone.push_back({inst, std::string(prop), d->second, null_id, m.sender});
          return false;
        }
        if (op == Transaction::Op::Delete) deletes.push_back(inst);
        if (op == Transaction::Op::Set) {
          if (const Stamp* s = written_stamp(inst, prop); s != nullptr && stamp < *s) {
            lost.push_back({inst, std::string(prop), *s, null_id, m.sender});
            return false;
          }
          kept.emplace_back(inst, prop);
        }
        if (!claims.empty()) own.push_back({op, inst, prop});
        return true;
      };
      hooks.created = [&](Id inst, std::string_view cls) { created.emplace(inst, cls); };
      // A reference set to an instance deleted concurrently becomes null: in stamp order the deletion
      // comes before or after the set, and either way the reference ends null (docs/dist.md).
      hooks.set_value = [&](Id inst, std::string_view prop,
                            std::span<const std::uint8_t> v) -> std::span<const std::uint8_t> {
        static constexpr std::uint8_t null_ref[1] = {0};
        const MetaProperty* p = property_here(inst, prop);
        if (p == nullptr || !p->type().is_reference() || p->type().is_ref_list()) return v;
        ByteReader r(v.data(), v.size());
        const Id target = r.varint();
        auto d = deleted.find(target);
        if (d == deleted.end()) {
          target_unknown = target_unknown || unknown_target(target);
          return v;
        }
        dangling.push_back({inst, std::string(prop), d->second, target, m.sender});
        return {null_ref, 1};
      };
      hooks.list = [&](const ElementEdit& e, std::vector<std::uint8_t>& out, std::size_t& ops) {
        internal::Sequence& sq = sequence(e.holder, e.property);
        if (e.op == Transaction::Op::Erase) {
          const std::size_t pos = sq.find(e.element);
          if (pos == internal::Sequence::npos || sq.elems[pos].target != e.target) {
            unknown_entry = true;
            entry_to_come =
                entry_to_come || (pos == internal::Sequence::npos && to_come(e.element, m.sender));
            return;
          }
          if (sq.elems[pos].removed) return;  // erased already: twice, a lost move, or its target deleted
          detail::write_list(out, Transaction::Op::Erase, e.holder, e.property, sq.index_of(pos), e.target);
          ++ops;
          sq.remove(pos);
          return;
        }
        const ElementId elem{stamp.clock, stamp.who, e.element.n};
        if (sq.find(elem) != internal::Sequence::npos) {
          unknown_entry = true;
          return;
        }
        bool hidden = false;
        if (auto d = deleted.find(e.target); d != deleted.end()) {
          hidden = true;  // the deletion wins: the entry is there, removed
          dangling.push_back({e.holder, std::string(e.property), d->second, e.target, m.sender});
        } else if (unknown_target(e.target)) {
          target_unknown = true;
        } else if (is_children(e.property)) {
          if (const auto top = top_of(e.target); top && elem < top->element) {
            hidden = true;  // a newer move of this child won
            moved.push_back({e.holder, std::string(e.property), Stamp{top->element.clock, top->element.who},
                             e.target, m.sender});
          } else {
            tops[e.target] = Top{elem, e.holder};
          }
        }
        const std::size_t pos = sq.integrate(elem, e.origin, e.target, hidden);
        if (pos == internal::Sequence::npos) {
          unknown_entry = true;
          entry_to_come = entry_to_come || to_come(e.origin, m.sender);
          return;
        }
        if (hidden) return;
        detail::write_list(out, Transaction::Op::Insert, e.holder, e.property, sq.index_of(pos), e.target);
        ++ops;
      };
      // Entries of a deleted instance that its deleter did not know of (inserted concurrently) go first.
      hooks.before_delete = [&](Id dead, std::vector<std::uint8_t>& out, std::size_t& ops) {
        auto sweep = [&](const ListKey& key) {
          if (key.first == dead) return;  // the instance's own lists go with it
          internal::Sequence* sq = existing(key);
          for (std::size_t pos = 0; sq != nullptr && pos < sq->elems.size(); ++pos) {
            internal::Element& x = sq->elems[pos];
            if (x.removed || x.target != dead) continue;
            detail::write_list(out, Transaction::Op::Erase, key.first, key.second, sq->index_of(pos), dead);
            ++ops;
            sq->remove(pos);
            // Its inserter learns it from the deleter, which sees the insertion arrive after its deletion.
            if (x.id.who != id) dangling.push_back({key.first, key.second, stamp, dead, x.id.who});
          }
        };
        auto holds = [&](const internal::Sequence& sq) {
          return std::any_of(sq.elems.begin(), sq.elems.end(),
                             [&](const internal::Element& x) { return !x.removed && x.target == dead; });
        };
        std::vector<ListKey> keys;
        for (const auto& [key, sq] : touched)
          if (holds(sq)) keys.push_back(key);
        for (const auto& [key, sq] : lists)
          if (!touched.contains(key) && holds(sq)) keys.push_back(key);
        for (const ListKey& key : keys) sweep(key);
      };
      // A child moved here whose entry elsewhere is older and still there: that entry lost a race of moves
      // (its mover had not seen this one) and goes, after the insertion, so the child never has no parent.
      hooks.finish = [&](std::vector<std::uint8_t>& out, std::size_t& ops) {
        for (const auto& [child, top] : tops) {
          auto old = top_child.find(child);
          if (old == top_child.end() || !(old->second.element < top.element)) continue;
          internal::Sequence* sq =
              existing(ListKey(old->second.holder, std::string(Node::vsd_prop_children().name())));
          const std::size_t pos = sq != nullptr ? sq->find(old->second.element) : internal::Sequence::npos;
          if (pos == internal::Sequence::npos || sq->elems[pos].removed) continue;
          detail::write_list(out, Transaction::Op::Erase, old->second.holder,
                             Node::vsd_prop_children().name(), sq->index_of(pos), child);
          ++ops;
          sq->remove(pos);
          moved.push_back({old->second.holder, std::string(Node::vsd_prop_children().name()), stamp, child,
                           old->second.element.who});
        }
      };
      // Decoded before its sequence number counts: a broken message must not make anyone resynchronise.
      try {
        t = decode_bundle(m.payload, hooks);
      } catch (const Error& e) {
        ++stats.malformed;
        log("rejected bundle " + std::to_string(m.seq) + " of " + who(m.sender) + ": " + e.what());
        if (auto it = applied.find(m.sender); it != applied.end() && it->second + 1 == m.seq) {
          it->second = m.seq;  // every participant drops it alike
          handled(m);
        }
        return;
      }
    }
    auto [it, fresh] = applied.try_emplace(m.sender, 0);
    const std::uint64_t expected = it->second + 1;
    if (m.seq < expected) {
      ++stats.duplicates;
      return;
    }
    if (m.seq > expected) {
      if (accept_gaps) {
        log("the messages of " + who(m.sender) + " continue at " + std::to_string(m.seq) +
            " here (expected " + std::to_string(expected) + ")");
      } else {
        resync("gap in the messages of " + who(m.sender) + ": expected " + std::to_string(expected) +
                   ", got " + std::to_string(m.seq),
               &m);
        return;
      }
    }
    clock = std::max(clock, m.clock);
    if (m.kind == Kind::Claim) {
      it->second = m.seq;
      handled(m);
      apply_claim(m);
      return;
    }
    if (auto c = find_conflict(own, m.sender, stamp)) {
      it->second = m.seq;
      handled(m);
      c->seq = m.seq;
      report(*c, c->owner == id);  // the owner tells the writer
      return;
    }
    if (((unknown_entry && entry_to_come) || target_unknown) &&
        (waiting_since == std::chrono::steady_clock::time_point{} ||
         std::chrono::steady_clock::now() - waiting_since < 10 * opt.request_interval)) {
      // Wait for the bundle that makes the entry or the instance (its sender's stream is behind this one's
      // here: bundles of different senders are not delivered in causal order). What is still missing
      // after 10 request intervals makes this participant resynchronise.
      if (waiting_since == std::chrono::steady_clock::time_point{})
        waiting_since = std::chrono::steady_clock::now();
      waiting[m.sender].push_front(m);
      if (!replaying) ++stats.bundles_waited;
      return;
    }
    try {
      if (unknown_entry) throw Error("it edits a list entry unknown here");
      state.apply(t);
    } catch (const Error& e) {
      discard_recording();
      if (last_failure == std::pair(m.sender, m.seq)) {
        // It failed on the snapshot too: the shared state cannot take it. Everyone drops it alike.
        ++stats.malformed;
        it->second = m.seq;
        handled(m);
        log("bundle " + std::to_string(m.seq) + " of " + who(m.sender) +
            " does not apply to the shared state either; dropped");
        return;
      }
      last_failure = {m.sender, m.seq};
      resync("bundle " + std::to_string(m.seq) + " of " + who(m.sender) + " does not apply here (" +
                 e.what() + ")",
             &m);
      return;
    }
    discard_recording();
    for (const auto& [inst, prop] : kept) note_write(inst, prop, stamp);
    for (auto& [key, sq] : touched) lists[key] = std::move(sq);
    for (const auto& [child, top] : tops) top_child[child] = top;
    forget_deleted(deletes, stamp);
    it->second = m.seq;
    last_clock[m.sender] = m.clock;
    handled(m);
    ++stats.bundles_applied;
    ++applied_now;
    if (!waiting.empty() && !replaying) replay_waiting();
    // The later stamped write won here, as it does everywhere: its writer tells the loser (who may see
    // nothing amiss: the winner's set simply overwrote its own). The deleter tells the writer of a change
    // to, a reference to or a list entry of an instance deleted concurrently (null, or removed). Both
    // movers and every other participant see both moves and decide alike: no report sample for those.
    stats.lost_writes += lost.size() + gone.size() + dangling.size() + moved.size();
    for (const Lost& l : lost) report(conflict_of(l, ConflictKind::ConcurrentWrite, m), l.winner.who == id);
    for (const Lost& g : gone) report(conflict_of(g, ConflictKind::Deleted, m), g.winner.who == id);
    for (const Lost& g : dangling)
      report(conflict_of(g, ConflictKind::Deleted, m), g.winner.who == id && g.loser == m.sender);
    for (const Lost& g : moved) report(conflict_of(g, ConflictKind::ConcurrentMove, m), false);
  }

  // Nobody answered a resynchronisation (every participant may have seen the same gap): go on with this
  // state and take every stream from where it is.
  void give_up_resync() {
    log("no snapshot arrived within " + std::to_string(opt.resync_give_up.count()) +
        " ms; continuing with this state");
    synced = true;
    accept_gaps = true;
    std::deque<Message> pending = std::move(buffer);
    buffer.clear();
    for (const Message& b : pending) sequenced(b);
    accept_gaps = false;
  }

  void apply_claim(const Message& m) {
    bool take = false;
    Id inst = null_id;
    std::string prop;
    try {
      ByteReader r(m.payload.data(), m.payload.size());
      take = r.u8() != 0;
      inst = r.varint();
      prop = r.string();
      names[m.sender] = r.string();
    } catch (const Error& e) {
      ++stats.malformed;
      log("rejected claim " + std::to_string(m.seq) + " of " + who(m.sender) + ": " + e.what());
      return;
    }
    add_claim_event(OwnerKey(inst, std::move(prop)), OwnEvent{Stamp{m.clock, m.sender}, take, m.seq, false});
  }

  // Puts a claim or release into its key's history in stamp order and settles what changed: takes that
  // lose now are reported (once) and rolled back; a write applied here that the new order makes a write
  // to what someone else owned means this state took a bundle the owner rejected: it resynchronises from
  // the owner.
  void add_claim_event(const OwnerKey& key, const OwnEvent& event) {
    std::vector<OwnEvent>& history = claims[key];
    history.insert(std::upper_bound(history.begin(), history.end(), event,
                                    [](const OwnEvent& a, const OwnEvent& b) { return a.stamp < b.stamp; }),
                   event);
    std::uint64_t owner = 0;
    for (OwnEvent& e : history) {
      if (!e.take) {
        if (owner == e.stamp.who) owner = 0;
        continue;
      }
      if (owner == 0 || owner == e.stamp.who) {
        owner = e.stamp.who;
        e.lost = false;
        continue;
      }
      if (e.lost) continue;
      e.lost = true;
      ++stats.claims_lost;
      Conflict c;
      c.kind = ConflictKind::ClaimRace;
      c.writer = e.stamp.who;
      c.owner = owner;
      c.seq = e.seq;
      c.instance = key.first;
      c.property = key.second;
      report(std::move(c), false);  // every participant sees both claims: nobody needs telling
    }
    if (!synced) return;
    if (auto bad = invalid_write(claims, written, key.first, key.second)) {
      // This state holds a change the others reject: it must not be served to anyone until replaced.
      self_diverged = true;
      resync("this state holds a write of " + who(bad->writer) + " to #" + std::to_string(bad->instance) +
                 "." + bad->property + " that the claim of " + who(bad->owner) + " came before",
             nullptr, bad->owner);
    }
  }

  // The first set held in @p registers (of instance @p only, and of property @p prop when not empty; all
  // instances when @p only is null_id) that @p table makes a write to what someone other than its writer
  // owned at its stamp: a state holding it took a bundle the owner rejected.
  std::optional<Conflict> invalid_write(const std::map<OwnerKey, std::vector<OwnEvent>>& table,
                                        const std::unordered_map<Id, std::vector<Written>>& registers,
                                        Id only = null_id, std::string_view prop = {}) const {
    if (table.empty()) return std::nullopt;
    auto owner_in = [&](Id inst, const std::string& p, const Stamp& limit) {
      auto key = table.find(OwnerKey(inst, p));
      std::uint64_t o = key == table.end() ? 0 : replay(key->second, limit);
      if (o == 0 && !p.empty())
        if (key = table.find(OwnerKey(inst, std::string())); key != table.end())
          o = replay(key->second, limit);
      return o;
    };
    auto check = [&](Id inst, const std::vector<Written>& ws) -> std::optional<Conflict> {
      for (const Written& w : ws) {
        if (!prop.empty() && w.property != prop) continue;
        const std::uint64_t o = owner_in(inst, w.property, w.stamp);
        if (o == 0 || o == w.stamp.who) continue;
        Conflict c;
        c.writer = w.stamp.who;
        c.owner = o;
        c.instance = inst;
        c.property = w.property;
        return c;
      }
      return std::nullopt;
    };
    if (only != null_id) {
      auto it = registers.find(only);
      return it == registers.end() ? std::nullopt : check(only, it->second);
    }
    for (const auto& [inst, ws] : registers)
      if (auto c = check(inst, ws)) return c;
    return std::nullopt;
  }

  void handle_report(const Message& m) {
    ByteReader r(m.payload.data(), m.payload.size());
    Conflict c;
    c.writer = r.fixed<std::uint64_t>();
    c.seq = r.varint();
    c.owner = r.fixed<std::uint64_t>();
    c.instance = r.varint();
    c.property = r.string();
    names[m.sender] = r.string();
    if (const std::uint8_t k = r.u8(); k <= static_cast<std::uint8_t>(ConflictKind::ConcurrentMove))
      c.kind = static_cast<ConflictKind>(k);
    else
      r.fail("unknown conflict kind " + std::to_string(k));
    c.target = r.varint();
    if (c.writer == id) {
      report(c, false);
      // My bundle was rejected by the others but applied here: this state has diverged. (A set that lost
      // to a concurrent one needs nothing: the winner's set overwrote it here too.)
      if (c.kind == ConflictKind::Owned && c.seq != 0 && synced) {
        self_diverged = true;
        resync("my bundle " + std::to_string(c.seq) + " was rejected", nullptr, c.owner);
      }
    } else if (c.owner == id) {
      report(c, false);
    }
  }

  void handle(Message&& m) {
    if (m.sender == id) return;
    try {
      switch (m.kind) {
        case Kind::Bundle:
        case Kind::Claim:
          if (m.seq == 0) throw Error("a bundle or claim without a sequence number");
          sequenced(m);
          break;
        case Kind::Request:
          // A participant resynchronising after a gap or a bundle that did not apply still holds a state
          // that matches its sequence numbers (bundles apply whole or not at all): it may answer too, so
          // that participants that all saw the same fault do not wait for each other.
          if (synced || (ever_synced && !self_diverged)) serve_snapshot(m);
          break;
        case Kind::Snapshot:
          if (m.target == id) install_snapshot(m);
          break;
        case Kind::Report:
          handle_report(m);
          break;
      }
    } catch (const Error& e) {
      ++stats.malformed;
      log("rejected message of " + who(m.sender) + ": " + e.what());
    }
  }

  // Checks the envelope of a DDS sample; a sample that is not ours is dropped with a log line.
  void receive(const vsd_dist_Message& s) {
    const std::uint8_t* b = s.payload._buffer;
    const std::size_t n = s.payload._length;
    const char* problem = nullptr;
    if (n < envelope_size || b == nullptr || std::memcmp(b, envelope_magic, 4) != 0)
      problem = "no VSDD envelope";
    else if (b[4] != envelope_version)
      problem = "unsupported envelope version";
    else if (s.kind < 1 || s.kind > 5)
      problem = "unknown message kind";
    if (problem != nullptr) {
      ++stats.foreign;
      log("rejected a foreign sample from " + hex(s.sender) + " (" + std::to_string(n) +
          " bytes): " + problem);
      return;
    }
    Message m;
    m.sender = s.sender;
    m.seq = s.seq;
    m.clock = s.clock;
    m.target = s.target;
    m.kind = static_cast<Kind>(s.kind);
    m.payload.assign(b + envelope_size, b + n);
    handle(std::move(m));
  }

  // Tombstones (ids of deleted instances, removed list entries) are there to recognise changes made
  // concurrently with the deletion or erasure. After the horizon no such change is expected any more: a
  // participant cut off that long has been dropped (its lease) and resynchronises (docs/dist.md).
  void prune_tombstones() {
    if (opt.tombstone_horizon.count() <= 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_prune <
        std::min<std::chrono::milliseconds>(opt.tombstone_horizon / 4, std::chrono::seconds(1)))
      return;
    last_prune = now;
    const auto before = now - opt.tombstone_horizon;
    while (!deletion_order.empty() && deletion_order.front().first < before) {
      stats.tombstones_pruned += deleted.erase(deletion_order.front().second);
      deletion_order.pop_front();
    }
    for (auto& [key, sq] : lists) stats.tombstones_pruned += sq.prune(before);
  }

  std::size_t poll() {
    applied_now = 0;
    publish();
    constexpr int batch = 64;
    for (;;) {
      std::array<void*, batch> samples{};
      std::array<dds_sample_info_t, batch> infos{};
      const int got = dds_take(reader, samples.data(), infos.data(), batch, batch);
      if (got < 0) dds_fail("dds_take", got);
      if (got == 0) break;
      for (std::size_t i = 0; i < static_cast<std::size_t>(got); ++i)
        if (infos[i].valid_data) receive(*static_cast<const vsd_dist_Message*>(samples[i]));
      dds_return_loan(reader, samples.data(), got);
      if (got < batch) break;
    }
    if (!synced) {
      const auto now = std::chrono::steady_clock::now();
      if (ever_synced && opt.resync_give_up.count() > 0 && now - resync_started >= opt.resync_give_up) {
        give_up_resync();
      } else if (now - last_request >= opt.request_interval) {
        // A resynchronisation asks one participant first (the owner whose state it must take); should it
        // not answer within ten requests, anyone may.
        if (prefer != 0 && now - resync_started >= 10 * opt.request_interval) prefer = 0;
        request_snapshot();
      }
    }
    if (!waiting.empty() && synced &&
        std::chrono::steady_clock::now() - waiting_since >= 10 * opt.request_interval)
      replay_waiting();  // waited long enough: what still does not apply makes this participant resynchronise
    prune_tombstones();
    flush();
    return applied_now;
  }

  void wait_data(std::chrono::milliseconds at_most) {
    dds_attach_t triggered = 0;
    (void)dds_waitset_wait(waitset, &triggered, 1, DDS_MSECS(std::max<std::int64_t>(0, at_most.count())));
  }

  void send_claim(bool take, Id inst, std::string_view prop) {
    std::vector<std::uint8_t> p;
    write_envelope(p);
    ByteWriter w(p);
    w.u8(take ? 1 : 0);
    w.varint(inst);
    w.string(prop);
    w.string(opt.name);
    publish();  // the claim comes after the changes made before it
    ++clock;
    send(Kind::Claim, ++seq, 0, p);
    ++stats.claims_sent;
    add_claim_event(OwnerKey(inst, std::string(prop)), OwnEvent{Stamp{clock, id}, take, seq, false});
  }
};

Participant::Participant(SimState& state, ParticipantOptions options)
    : impl_(std::make_unique<Impl>(state, std::move(options))) {
  impl_->open();
  impl_->names[impl_->id] = impl_->opt.name;
  // A state that records already (for another reader) shares its recording: what was changed before
  // joining is not this participant's to publish.
  if (state.recording()) {
    impl_->discard_recording();
  } else {
    state.start_recording();
    impl_->owns_recording = true;
  }
  Impl* impl = impl_.get();
  impl_->bundle_listener = state.on_bundle().connect([impl](const Transaction& t) { impl->hear_bundle(t); });
  if (impl_->opt.seed) {
    impl_->synced = impl_->ever_synced = true;
  } else {
    impl_->nonce = random_id();
    impl_->request_snapshot();
  }
}

Participant::~Participant() {
  impl_->flush();
  impl_->bundle_listener.disconnect();
  if (impl_->owns_recording && impl_->state.recording()) (void)impl_->state.stop_recording();
  impl_->close();
}

std::uint64_t Participant::id() const noexcept { return impl_->id; }
const std::string& Participant::name() const noexcept { return impl_->opt.name; }
SimState& Participant::state() const noexcept { return impl_->state; }
bool Participant::synced() const noexcept { return impl_->synced; }
std::size_t Participant::peers() const { return impl_->peers(); }
bool Participant::publish() { return impl_->publish(); }
void Participant::flush() { impl_->flush(); }
std::size_t Participant::poll() { return impl_->poll(); }

bool Participant::poll_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    poll();
    if (done()) return true;
    const auto now = std::chrono::steady_clock::now();
    if (now >= end) return false;
    // Wake for data, and at least every 20 ms for snapshot requests and conditions on other threads. What
    // done() published leaves first.
    impl_->flush();
    impl_->wait_data(std::min(std::chrono::duration_cast<std::chrono::milliseconds>(end - now),
                              std::chrono::milliseconds(20)));
  }
}

bool Participant::wait_synced(std::chrono::milliseconds timeout) {
  return poll_until([this] { return impl_->synced; }, timeout);
}

bool Participant::wait_peers(std::size_t n, std::chrono::milliseconds timeout) {
  return poll_until([this, n] { return impl_->peers() >= n; }, timeout);
}

void Participant::claim(const SimStateInstance& inst) { claim(inst, {}); }

void Participant::claim(const SimStateInstance& inst, std::string_view property) {
  if (!property.empty() && inst.meta().find_property(property) == nullptr)
    throw Error("dist: class '" + inst.meta().name() + "' has no property '" + std::string(property) + "'");
  const std::uint64_t o = owner(inst.id(), property);
  if (o != 0 && o != impl_->id)
    throw Error("dist: #" + std::to_string(inst.id()) +
                (property.empty() ? "" : "." + std::string(property)) + " is owned by " + impl_->who(o));
  if (impl_->key_owner(inst.id(), property, no_limit) == impl_->id) return;  // mine already
  impl_->send_claim(true, inst.id(), property);
}

void Participant::release(const SimStateInstance& inst, std::string_view property) {
  if (impl_->key_owner(inst.id(), property, no_limit) != impl_->id) return;
  impl_->send_claim(false, inst.id(), property);
}

std::uint64_t Participant::owner(Id id, std::string_view property) const {
  return impl_->owner_of(id, property);
}
std::string Participant::participant_name(std::uint64_t id) const {
  if (auto it = impl_->names.find(id); it != impl_->names.end()) return it->second;
  return hex(id);
}
Sink<void(const Conflict&)> Participant::on_conflict() noexcept {
  return Sink<void(const Conflict&)>(impl_->conflict_signal);
}
Sink<void()> Participant::on_synced() noexcept { return Sink<void()>(impl_->synced_signal); }
const ParticipantStats& Participant::stats() const noexcept { return impl_->stats; }

}  // namespace vsd::dist
