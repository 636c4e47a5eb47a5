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

#include "vsd/core/bytes.hpp"
#include "vsd/core/detail/tx_codec.hpp"
#include "vsd/core/environment.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/meta_instance.hpp"
#include "vsd/core/sim_state.hpp"
#include "vsd/dist/wire.hpp"
#include "vsd_dist.h"

namespace vsd::dist {

namespace {

// ---- the envelope --------------------------------------------------------------------------------------

enum class Kind : std::uint8_t { Bundle = 1, Claim = 2, Request = 3, Snapshot = 4, Report = 5 };
constexpr std::uint8_t envelope_magic[4] = {'V', 'S', 'D', 'D'};
constexpr std::uint8_t envelope_version = 1;
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
  std::uint64_t target = 0;
  Kind kind{};
  std::vector<std::uint8_t> payload;  // after the envelope
};

using OwnerKey = std::pair<Id, std::string>;  // property "" is the instance itself

}  // namespace

struct Participant::Impl {
  SimState& state;
  ParticipantOptions opt;
  std::uint64_t id = random_id();
  bool synced = false;
  bool ever_synced = false;
  std::uint64_t seq = 0;                                     // my last sequence number
  std::unordered_map<std::uint64_t, std::uint64_t> applied;  // sender -> last seq handled
  std::map<OwnerKey, std::uint64_t> owners;
  std::unordered_map<std::uint64_t, std::string> names;
  std::deque<Message> buffer;  // bundles and claims received while unsynchronised
  std::uint64_t nonce = 0;     // of my pending snapshot request
  std::chrono::steady_clock::time_point last_request{};
  ParticipantStats stats;
  Signal<void(const Conflict&)> conflict_signal;
  Signal<void()> synced_signal;
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
    m.target = target;
    m.kind = static_cast<std::uint8_t>(kind);
    m.payload._buffer = payload.data();
    m.payload._length = static_cast<std::uint32_t>(payload.size());
    m.payload._maximum = m.payload._length;
    m.payload._release = false;
    const dds_return_t rc = dds_write(writer, &m);
    if (rc < 0) dds_fail("dds_write (is a participant stuck?)", rc);
  }

  std::size_t peers() const {
    dds_publication_matched_status_t st{};
    if (dds_get_publication_matched_status(writer, &st) < 0) return 0;
    return st.current_count;
  }

  // ---- ownership ----
  std::uint64_t owner_of(Id inst, std::string_view prop) const {
    if (!prop.empty())
      if (auto it = owners.find(OwnerKey(inst, std::string(prop))); it != owners.end()) return it->second;
    if (auto it = owners.find(OwnerKey(inst, std::string())); it != owners.end()) return it->second;
    return 0;
  }
  // The first operation of @p t that touches what someone other than @p writer owns.
  std::optional<Conflict> find_conflict(const Transaction& t, std::uint64_t writer) const {
    if (owners.empty()) return std::nullopt;
    detail::TxParser parser(t);
    for (detail::TxOp op; parser.next(op);) {
      Conflict c;
      c.writer = writer;
      c.instance = op.id;
      switch (op.op) {
        case Transaction::Op::Create:
          continue;
        case Transaction::Op::Delete:
          for (auto it = owners.lower_bound(OwnerKey(op.id, std::string()));
               it != owners.end() && it->first.first == op.id; ++it)
            if (it->second != writer) {
              c.owner = it->second;
              c.property = it->first.second;
              break;
            }
          if (c.owner == 0) continue;
          break;
        default:
          c.owner = owner_of(op.id, op.name);
          if (c.owner == 0 || c.owner == writer) continue;
          c.property = std::string(op.name);
          break;
      }
      return c;
    }
    return std::nullopt;
  }
  void forget_deleted(const Transaction& t) {
    if (owners.empty()) return;
    detail::TxParser parser(t);
    for (detail::TxOp op; parser.next(op);)
      if (op.op == Transaction::Op::Delete)
        std::erase_if(owners, [&](const auto& e) { return e.first.first == op.id; });
  }
  std::string describe(const Conflict& c) const {
    std::string what = "#" + std::to_string(c.instance) + (c.property.empty() ? "" : "." + c.property);
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
      send(Kind::Report, 0, 0, p);
    }
    conflict_signal.emit(c);
  }

  // ---- sending ----
  bool publish() {
    if (!state.recording()) return false;
    Transaction t = state.take_recording();
    if (t.empty()) return false;
    if (!synced) {
      ++stats.dropped_unsynced;
      log("dropped " + std::to_string(t.size()) + " local changes made while not synchronised");
      return false;
    }
    if (auto c = find_conflict(t, id)) {
      // Undo the whole bundle here: a write to what another participant owns is never half-applied.
      state.apply(t.inverted());
      (void)state.take_recording();
      report(*c, true);
      return false;
    }
    WireBundle wb = encode_bundle(t, state);
    forget_deleted(t);
    if (wb.ops == 0) return false;
    std::vector<std::uint8_t> p;
    p.reserve(envelope_size + wb.bytes.size());
    write_envelope(p);
    p.insert(p.end(), wb.bytes.begin(), wb.bytes.end());
    send(Kind::Bundle, ++seq, 0, p);
    ++stats.bundles_sent;
    return true;
  }

  void request_snapshot() {
    std::vector<std::uint8_t> p;
    write_envelope(p);
    ByteWriter w(p);
    w.fixed(nonce);
    w.string(opt.name);
    send(Kind::Request, 0, 0, p);
    last_request = std::chrono::steady_clock::now();
  }

  void serve_snapshot(const Message& m) {
    ByteReader r(m.payload.data(), m.payload.size());
    const auto req_nonce = r.fixed<std::uint64_t>();
    names[m.sender] = r.string();
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
    w.varint(owners.size());
    for (const auto& [key, who_owns] : owners) {
      w.fixed(who_owns);
      w.varint(key.first);
      w.string(key.second);
    }
    w.varint(names.size());
    for (const auto& [pid, n] : names) {
      w.fixed(pid);
      w.string(n);
    }
    p.insert(p.end(), wb.bytes.begin(), wb.bytes.end());
    send(Kind::Snapshot, 0, m.sender, p);
    ++stats.snapshots_served;
  }

  // ---- receiving ----
  void discard_recording() {
    if (state.recording()) (void)state.take_recording();
  }

  void resync(const std::string& reason, const Message* pending) {
    log(reason + "; resynchronising from a snapshot");
    synced = false;
    buffer.clear();
    if (pending != nullptr) buffer.push_back(*pending);
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
    std::map<OwnerKey, std::uint64_t> table;
    for (std::size_t n = r.size_prefix(10); n > 0; --n) {
      const auto who_owns = r.fixed<std::uint64_t>();
      const Id inst = r.varint();
      table[OwnerKey(inst, r.string())] = who_owns;
    }
    for (std::size_t n = r.size_prefix(9); n > 0; --n) {
      const auto pid = r.fixed<std::uint64_t>();
      names[pid] = r.string();
    }
    if (seqs[id] < seq) {
      // The answering participant has not applied all my bundles yet: installing its state would lose
      // them here. Ask again later.
      return;
    }
    const Transaction t = decode_bundle({m.payload.data() + r.position(), r.remaining()});
    clear_state();
    state.apply(t);
    discard_recording();
    seqs.erase(id);
    applied = std::move(seqs);
    owners = std::move(table);
    synced = true;
    self_diverged = false;
    if (ever_synced) ++stats.resyncs;
    ever_synced = true;
    log("synchronised from a snapshot of " + who(m.sender) + " (" + std::to_string(state.size()) +
        " instances)");
    synced_signal.emit();
    std::deque<Message> pending = std::move(buffer);
    buffer.clear();
    for (const Message& b : pending) sequenced(b);
  }

  std::size_t applied_now = 0;  // bundles applied during the current poll()
  bool accept_gaps = false;     // while give_up_resync() drains the buffer
  // The last bundle that did not apply: when it fails again after a snapshot, it is dropped.
  std::pair<std::uint64_t, std::uint64_t> last_failure{0, 0};
  // Set when this state holds a change of mine that the others rejected: it must not serve snapshots.
  bool self_diverged = false;
  std::chrono::steady_clock::time_point resync_started{};

  // A bundle or claim, in the sender's order.
  void sequenced(const Message& m) {
    if (!synced) {
      buffer.push_back(m);
      return;
    }
    Transaction t;
    if (m.kind == Kind::Bundle) {
      // Decoded before its sequence number counts: a broken message must not make anyone resynchronise.
      try {
        t = decode_bundle(m.payload);
      } catch (const Error& e) {
        ++stats.malformed;
        log("rejected bundle " + std::to_string(m.seq) + " of " + who(m.sender) + ": " + e.what());
        if (auto it = applied.find(m.sender); it != applied.end() && it->second + 1 == m.seq)
          it->second = m.seq;  // every participant drops it alike
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
    if (m.kind == Kind::Claim) {
      apply_claim(m);
      it->second = m.seq;
      return;
    }
    if (auto c = find_conflict(t, m.sender)) {
      it->second = m.seq;
      c->seq = m.seq;
      report(*c, c->owner == id);  // the owner tells the writer
      return;
    }
    publish();  // my changes first: the recording must hold only what this participant did
    try {
      state.apply(t);
    } catch (const Error& e) {
      discard_recording();
      if (last_failure == std::pair(m.sender, m.seq)) {
        // It failed on the snapshot too: the shared state cannot take it. Everyone drops it alike.
        ++stats.malformed;
        it->second = m.seq;
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
    forget_deleted(t);
    it->second = m.seq;
    ++stats.bundles_applied;
    ++applied_now;
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
    try {
      ByteReader r(m.payload.data(), m.payload.size());
      const bool take = r.u8() != 0;
      const Id inst = r.varint();
      std::string prop = r.string();
      names[m.sender] = r.string();
      OwnerKey key(inst, std::move(prop));
      if (take) {
        auto [at, fresh] = owners.try_emplace(key, m.sender);
        if (!fresh && at->second != m.sender)
          log("claim of " + who(m.sender) + " on #" + std::to_string(inst) + " ignored: owned by " +
              who(at->second));
      } else if (auto at = owners.find(key); at != owners.end() && at->second == m.sender) {
        owners.erase(at);
      }
    } catch (const Error& e) {
      ++stats.malformed;
      log("rejected claim " + std::to_string(m.seq) + " of " + who(m.sender) + ": " + e.what());
    }
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
    if (c.writer == id) {
      report(c, false);
      // My bundle was rejected by the others but applied here: this state has diverged.
      if (c.seq != 0 && synced) {
        self_diverged = true;
        resync("my bundle " + std::to_string(c.seq) + " was rejected", nullptr);
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
    m.target = s.target;
    m.kind = static_cast<Kind>(s.kind);
    m.payload.assign(b + envelope_size, b + n);
    handle(std::move(m));
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
    if (!synced && std::chrono::steady_clock::now() - last_request >= opt.request_interval)
      request_snapshot();
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
    send(Kind::Claim, ++seq, 0, p);
  }
};

Participant::Participant(SimState& state, ParticipantOptions options)
    : impl_(std::make_unique<Impl>(state, std::move(options))) {
  if (state.recording()) throw Error("dist: SimState '" + state.name() + "' is already recording");
  impl_->open();
  impl_->names[impl_->id] = impl_->opt.name;
  state.start_recording();
  if (impl_->opt.seed) {
    impl_->synced = impl_->ever_synced = true;
  } else {
    impl_->nonce = random_id();
    impl_->request_snapshot();
  }
}

Participant::~Participant() {
  if (impl_->state.recording()) (void)impl_->state.stop_recording();
  impl_->close();
}

std::uint64_t Participant::id() const noexcept { return impl_->id; }
const std::string& Participant::name() const noexcept { return impl_->opt.name; }
SimState& Participant::state() const noexcept { return impl_->state; }
bool Participant::synced() const noexcept { return impl_->synced; }
std::size_t Participant::peers() const { return impl_->peers(); }
bool Participant::publish() { return impl_->publish(); }
std::size_t Participant::poll() { return impl_->poll(); }

bool Participant::poll_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    poll();
    if (done()) return true;
    const auto now = std::chrono::steady_clock::now();
    if (now >= end) return false;
    // Wake for data, and at least every 20 ms for snapshot requests and conditions on other threads.
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
  impl_->owners[OwnerKey(inst.id(), std::string(property))] = impl_->id;
  impl_->send_claim(true, inst.id(), property);
}

void Participant::release(const SimStateInstance& inst, std::string_view property) {
  auto it = impl_->owners.find(OwnerKey(inst.id(), std::string(property)));
  if (it == impl_->owners.end() || it->second != impl_->id) return;
  impl_->owners.erase(it);
  impl_->send_claim(false, inst.id(), property);
}

std::uint64_t Participant::owner(Id id, std::string_view property) const {
  return impl_->owner_of(id, property);
}
std::string Participant::participant_name(std::uint64_t id) const {
  if (auto it = impl_->names.find(id); it != impl_->names.end()) return it->second;
  return hex(id);
}
Signal<void(const Conflict&)>& Participant::on_conflict() noexcept { return impl_->conflict_signal; }
Signal<void()>& Participant::on_synced() noexcept { return impl_->synced_signal; }
const ParticipantStats& Participant::stats() const noexcept { return impl_->stats; }

}  // namespace vsd::dist
