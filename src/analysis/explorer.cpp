// Breadth-first exploration of a PtNet's reachable markings. See explorer.hpp for the design; the
// comments here say why each piece is the way it is.
//
// A level of a net with structural bounds is either fused (one worker, small hash set) or shared (the
// workers insert into the hash set themselves: insert_shared). A level of another net, when not fused,
// runs in four phases:
//   A (parallel over chunks of the frontier): enabled sets (incrementally from the parent's), counts,
//     and the successor markings ("candidates") in per-chunk buffers, each with its hash;
//   B (parallel over hash-set shards): each candidate is looked up in, or inserted into, its shard;
//     a new marking is inserted as "pending" (a reference to its candidate), in candidate order;
//   C (sequential): new markings get consecutive state indices in candidate order and are copied into
//     the arena: numbering never depends on the thread count;
//   D (parallel over shards): pending entries are rewritten to state indices.
#include "vsd/analysis/explorer.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <ostream>
#include <sstream>
#include <thread>
#include <type_traits>

#include "compiled_net.hpp"
#include "place_bounds.hpp"
#include "vsd/core/error.hpp"

namespace vsd::analysis {

namespace {

using detail::Compiled;
using Clock = std::chrono::steady_clock;

constexpr std::uint32_t kNone = UINT32_MAX;
constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
constexpr std::uint64_t kPendingBit = std::uint64_t{1} << 63;
constexpr unsigned kShardBits = 6;
constexpr std::size_t kShards = std::size_t{1} << kShardBits;
constexpr std::size_t kChunkStates = 256;                       // frontier states per work item of phase A
constexpr unsigned kBlockBits = 12;                             // states per arena block = 2^12
constexpr std::uint64_t kMaxStates = UINT32_MAX - 1;            // indices are 32-bit; kNone is reserved
constexpr std::size_t kFusedTableBytes = std::size_t{1} << 20;  // see `fused` in attempt()

std::string format_bytes(std::size_t b) {
  char buf[32];
  if (b >= (std::size_t{1} << 30))
    std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(b) / (1 << 30));
  else if (b >= (std::size_t{1} << 20))
    std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(b) / (1 << 20));
  else
    std::snprintf(buf, sizeof buf, "%.1f KiB", static_cast<double>(b) / 1024);
  return buf;
}

unsigned bits_for(std::uint64_t max_value) {
  unsigned b = 1;
  while (b < 32 && (max_value >> b) != 0) b *= 2;
  return b;
}

// Packed marking layout: `bits` bits per place, 64/bits places per word, no field straddles words.
struct Layout {
  unsigned bits = 1;
  unsigned shift = 0;  // log2(places per word)
  std::uint64_t mask = 1;
  std::uint32_t words = 1;   // words of a marking
  std::uint32_t record = 2;  // words of an arena record: marking + (parent << 32 | transition)

  Layout(unsigned b, std::uint32_t places) : bits(b) {
    shift = static_cast<unsigned>(std::countr_zero(64u / b));
    mask = b == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << b) - 1;
    const std::uint32_t per_word = 64u / b;
    words = std::max<std::uint32_t>(1, (places + per_word - 1) / per_word);
    record = words + 1;
  }
  std::uint32_t get(const std::uint64_t* w, std::uint32_t p) const {
    const unsigned off = (p & ((1u << shift) - 1)) * bits;
    return static_cast<std::uint32_t>((w[p >> shift] >> off) & mask);
  }
  void set(std::uint64_t* w, std::uint32_t p, std::uint64_t v) const {
    const unsigned off = (p & ((1u << shift) - 1)) * bits;
    std::uint64_t& x = w[p >> shift];
    x = (x & ~(mask << off)) | (v << off);
  }
  void unpack(const std::uint64_t* w, std::uint32_t places, std::uint32_t* out) const {
    for (std::uint32_t p = 0; p < places; ++p) out[p] = get(w, p);
  }
};

// The net compiled against one Layout: what firing a transition does to the words of a packed marking,
// and, for one bit per place, its enabling test as word masks. Both skip unpacking the marking.
struct PackedNet {
  struct WordOp {  // word = word - sub + add: the transition's token changes in this word, all fields at once
    std::uint32_t word;
    std::uint64_t add, sub;
  };
  struct WordTest {  // one bit per place: enabled when (word & need) == need and (word & forbid) == 0
    std::uint32_t word;
    std::uint64_t need, forbid;
  };
  std::vector<std::uint32_t> op_begin, test_begin;  // size transitions + 1
  std::vector<WordOp> ops;
  std::vector<WordTest> tests;
  std::vector<std::uint8_t> never;  // one bit per place: needs two or more tokens from a place
  // Markings of at most kDenseWords words: the same, dense, `words` entries per transition, so that the
  // explorer's loops over a marking's words are unrolled and branch-free. diff = add - sub (mod 2^64):
  // firing adds it to each word. need/forbid: the WordTests (all ones in both for a `never` transition,
  // which no marking passes).
  static constexpr std::uint32_t kDenseWords = 4;
  std::vector<std::uint64_t> diff, need, forbid;

  PackedNet(const Compiled& c, const PtNet& net, const Layout& L) {
    const std::uint32_t per_word_mask = (1u << L.shift) - 1;
    auto word_of = [&](std::uint32_t p) { return p >> L.shift; };
    auto off_of = [&](std::uint32_t p) { return (p & per_word_mask) * L.bits; };
    never.assign(c.transitions, 0);
    // Per word of a marking: the index of its WordOp (WordTest) for the transition at hand, so that a
    // transition over n words costs O(n), not a search per place.
    std::vector<std::uint32_t> op_of(L.words, kNone), test_of(L.words, kNone);
    for (std::uint32_t t = 0; t < c.transitions; ++t) {
      op_begin.push_back(static_cast<std::uint32_t>(ops.size()));
      for (std::uint32_t i = c.delta_begin[t]; i < c.delta_begin[t + 1]; ++i) {
        const auto& d = c.delta[i];
        const std::uint32_t w = word_of(d.place);
        if (op_of[w] == kNone) {
          op_of[w] = static_cast<std::uint32_t>(ops.size());
          ops.push_back(WordOp{w, 0, 0});
        }
        WordOp& o = ops[op_of[w]];
        const auto magnitude = static_cast<std::uint64_t>(d.delta < 0 ? -d.delta : d.delta);
        (d.delta < 0 ? o.sub : o.add) += magnitude << off_of(d.place);
      }
      for (std::size_t i = op_begin[t]; i < ops.size(); ++i) op_of[ops[i].word] = kNone;
      test_begin.push_back(static_cast<std::uint32_t>(tests.size()));
      if (L.bits != 1) continue;
      auto test_for = [&](std::uint32_t p) -> WordTest& {
        const std::uint32_t w = word_of(p);
        if (test_of[w] == kNone) {
          test_of[w] = static_cast<std::uint32_t>(tests.size());
          tests.push_back(WordTest{w, 0, 0});
        }
        return tests[test_of[w]];
      };
      const Transition& tr = net.transitions()[t];
      for (const auto& a : tr.inputs) {
        if (a.weight > 1) never[t] = 1;  // a one-bit place never holds two tokens
        test_for(a.place).need |= std::uint64_t{1} << off_of(a.place);
      }
      for (const auto& a : tr.inhibitors)
        if (a.weight == 1) test_for(a.place).forbid |= std::uint64_t{1} << off_of(a.place);
      // (an inhibitor of weight 2 or more is always satisfied by a one-bit place)
      for (std::size_t i = test_begin[t]; i < tests.size(); ++i) test_of[tests[i].word] = kNone;
    }
    op_begin.push_back(static_cast<std::uint32_t>(ops.size()));
    test_begin.push_back(static_cast<std::uint32_t>(tests.size()));
    if (L.words > kDenseWords) return;
    const std::size_t W = L.words;
    diff.assign(c.transitions * W, 0);
    need.assign(c.transitions * W, 0);
    forbid.assign(c.transitions * W, 0);
    for (std::uint32_t t = 0; t < c.transitions; ++t) {
      for (std::uint32_t i = op_begin[t]; i < op_begin[t + 1]; ++i)
        diff[t * W + ops[i].word] = ops[i].add - ops[i].sub;
      for (std::uint32_t i = test_begin[t]; i < test_begin[t + 1]; ++i) {
        need[t * W + tests[i].word] = tests[i].need;
        forbid[t * W + tests[i].word] = tests[i].forbid;
      }
      if (never[t]) need[t * W] = forbid[t * W] = ~std::uint64_t{0};
    }
  }

  std::size_t bytes() const {
    return (op_begin.capacity() + test_begin.capacity()) * 4 + ops.capacity() * sizeof(WordOp) +
           tests.capacity() * sizeof(WordTest) + never.capacity() +
           (diff.capacity() + need.capacity() + forbid.capacity()) * 8;
  }

  bool enabled(std::uint32_t t, const std::uint64_t* m) const {
    if (never[t]) return false;
    for (std::uint32_t i = test_begin[t]; i < test_begin[t + 1]; ++i) {
      const WordTest& x = tests[i];
      if ((m[x.word] & x.need) != x.need || (m[x.word] & x.forbid) != 0) return false;
    }
    return true;
  }
  // Only where no field can overflow (the net's bounds fit the fields), and t is enabled (no underflow).
  void fire(std::uint32_t t, std::uint64_t* m) const {
    for (std::uint32_t i = op_begin[t]; i < op_begin[t + 1]; ++i) {
      const WordOp& o = ops[i];
      m[o.word] = m[o.word] - o.sub + o.add;
    }
  }
};

inline std::uint64_t hash_words(const std::uint64_t* w, std::uint32_t n) {
  std::uint64_t h = 0x243F6A8885A308D3ull ^ n;
  for (std::uint32_t i = 0; i < n; ++i) {
    h ^= w[i];
    h *= 0x9E3779B97F4A7C15ull;
    h ^= h >> 29;
  }
  h ^= h >> 32;
  h *= 0xD6E8FEB86659FD93ull;
  h ^= h >> 32;
  return h;
}

// Markings are a few words: a plain loop beats a call to memcmp.
inline bool same(const std::uint64_t* a, const std::uint64_t* b, std::uint32_t words) {
  for (std::uint32_t i = 0; i < words; ++i)
    if (a[i] != b[i]) return false;
  return true;
}

// The explorer's helper threads, started once per explore() (at the first phase that wants more than one
// worker) and kept for all its phases and levels: starting and joining threads for every phase of every
// level cost more than small levels (Dekker-PT-010's) gain from a second thread. Idle helpers block on a
// condition variable, so a loaded machine loses no cycles to spinning. Worker 0 is the calling thread.
class WorkerPool {
 public:
  WorkerPool() = default;
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  ~WorkerPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
      ++generation_;
    }
    wake_.notify_all();
    for (auto& t : helpers_) t.join();
  }

  // Runs body(w) for w in [0, workers), body(0) on this thread, and returns when all have returned (the
  // pool grows to workers - 1 helpers). Work split: bodies take items from a shared counter of their own.
  template <class F>
  void run(unsigned workers, F&& body) {
    if (workers <= 1) {
      body(0u);
      return;
    }
    while (helpers_.size() + 1 < workers) {
      const auto w = static_cast<unsigned>(helpers_.size() + 1);
      std::uint64_t now = 0;  // a new helper waits for the next job, not the last one
      {
        std::lock_guard<std::mutex> lock(mutex_);
        now = generation_;
      }
      helpers_.emplace_back([this, w, now] { loop(w, now); });
    }
    using Body = std::remove_reference_t<F>;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = static_cast<void*>(&body);
      call_ = [](void* job, unsigned w) { (*static_cast<Body*>(job))(w); };
      active_ = workers;
      pending_ = workers - 1;
      ++generation_;
    }
    wake_.notify_all();
    std::exception_ptr error;
    try {
      body(0u);
    } catch (...) {
      error = std::current_exception();  // rethrown once the helpers no longer use `body`
    }
    {
      std::unique_lock<std::mutex> lock(mutex_);
      done_.wait(lock, [this] { return pending_ == 0; });
    }
    if (error) std::rethrow_exception(error);
  }

 private:
  void loop(unsigned w, std::uint64_t seen) {
    std::unique_lock<std::mutex> lock(mutex_);
    while (true) {
      wake_.wait(lock, [&] { return generation_ != seen; });
      seen = generation_;
      if (stop_) return;
      if (w >= active_) continue;  // a phase with fewer workers than the pool has threads
      void* const job = job_;
      void (*const call)(void*, unsigned) = call_;
      lock.unlock();
      call(job, w);
      lock.lock();
      if (--pending_ == 0) done_.notify_one();
    }
  }

  std::vector<std::thread> helpers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::uint64_t generation_ = 0;  // one per run(): a helper runs each job once
  bool stop_ = false;
  unsigned active_ = 0;   // workers of the current job
  unsigned pending_ = 0;  // helpers of the current job still running it
  void* job_ = nullptr;
  void (*call_)(void*, unsigned) = nullptr;
};

struct alignas(64) WorkerStats {
  std::uint64_t edges = 0;
  std::uint32_t max_place = 0;
  std::uint64_t max_sum = 0;
  std::uint32_t first_dead = kNone;
  std::uint32_t first_cover = kNone;  // smallest new state covering an ancestor
  std::uint32_t covered = kNone;      // ... and that ancestor
  bool overflow = false;
  std::vector<std::uint32_t> unpacked;
  std::vector<std::uint32_t> unpacked2;
  // Shared levels (see `shared` in attempt()): successors made but not yet inserted, kBatch at most, so
  // that their slots are prefetched while the next ones are made.
  std::vector<std::uint64_t> batch_markings;  // kBatch * words
  std::uint64_t batch_hashes[32];
  std::uint32_t batch_parents[32], batch_firings[32];
  std::uint32_t batched = 0;
  // Shared levels: entries taken in each shard's `used` and not yet filled, and the state indices taken
  // from next_id_ and not yet given out ([id_next, id_end)): both are taken kCredit at a time, so that
  // the workers do not write the same cache lines for every new state.
  std::uint32_t credits[kShards] = {};
  std::uint64_t id_next = 0, id_end = 0;
};
constexpr std::uint32_t kBatch = 32;
constexpr std::uint32_t kCredit = 64;

// A growable array of a trivial type whose growth does not fill the new elements (std::vector::resize
// would zero them, only to have them overwritten: a memset per frontier state).
template <class T>
class PodBuffer {
 public:
  std::size_t size() const { return n_; }
  std::size_t capacity() const { return cap_; }
  T* data() { return p_.get(); }
  const T* data() const { return p_.get(); }
  T& operator[](std::size_t i) { return p_[i]; }
  const T& operator[](std::size_t i) const { return p_[i]; }
  void clear() { n_ = 0; }
  void reserve(std::size_t c) {
    if (c <= cap_) return;
    std::unique_ptr<T[]> q(new T[c]);  // default-initialised: not filled
    if (n_ != 0) std::memcpy(q.get(), p_.get(), n_ * sizeof(T));
    p_ = std::move(q);
    cap_ = c;
  }
  // Capacity for at least c elements, doubling: amortised constant growth.
  void ensure(std::size_t c) {
    if (c > cap_) reserve(std::max(c, cap_ * 2));
  }
  // Only within the capacity; the new elements are not initialised.
  void set_size(std::size_t n) { n_ = n; }

 private:
  std::unique_ptr<T[]> p_;
  std::size_t n_ = 0, cap_ = 0;
};

// Calls f(std::integral_constant<std::uint32_t, W>) with W = words for the marking widths the explorer
// has unrolled loops for, W = 0 (the width known at run time only) for the others.
template <class F>
void with_words(std::uint32_t words, F&& f) {
  switch (words) {
    case 1:
      f(std::integral_constant<std::uint32_t, 1>{});
      break;
    case 2:
      f(std::integral_constant<std::uint32_t, 2>{});
      break;
    case 3:
      f(std::integral_constant<std::uint32_t, 3>{});
      break;
    case 4:
      f(std::integral_constant<std::uint32_t, 4>{});
      break;
    default:
      f(std::integral_constant<std::uint32_t, 0>{});
  }
}

// Successors of one chunk of the frontier.
struct Chunk {
  PodBuffer<std::uint64_t> markings;  // `words` per candidate
  PodBuffer<std::uint64_t> hashes;
  PodBuffer<std::uint32_t> parents;
  PodBuffer<std::uint32_t> firings;
  std::vector<std::uint8_t> fresh;  // phase B: first occurrence of a new marking
  std::vector<std::uint32_t> ids;   // phase C: its state index
  void clear() {
    markings.clear();
    hashes.clear();
    parents.clear();
    firings.clear();
  }
  std::size_t bytes() const {
    return markings.capacity() * 8 + hashes.capacity() * 8 + parents.capacity() * 4 + firings.capacity() * 4 +
           fresh.capacity() + ids.capacity() * 4;
  }
};

// One cache line apart: two threads inserting into neighbouring shards must not share a line.
struct alignas(64) Shard {
  std::vector<std::uint64_t> slots;
  std::size_t used = 0;
  std::vector<std::uint64_t> pending;  // (chunk << 32 | index) of the candidates inserted as pending
};

class Explorer {
 public:
  // The list of transitions to test again after a firing (Compiled::aff) may take an eighth of the limit;
  // past that every transition is tested (it grows with the square of the transitions sharing a place).
  Explorer(const PtNet& net, const ExploreOptions& opt)
      : net_(net),
        limit_(opt.memory_limit == 0 ? default_memory_limit() : opt.memory_limit),
        c_(net, limit_ / 8 / sizeof(std::uint32_t)),
        opt_(opt) {
    threads_ = opt.threads == 0 ? std::max(1u, std::thread::hardware_concurrency()) : opt.threads;
    show_progress_ = opt.progress == ExploreOptions::Progress::always ||
                     (opt.progress == ExploreOptions::Progress::automatic && isatty(STDERR_FILENO) == 1);
    tw_ = std::max<std::uint32_t>(1, (c_.transitions + 63) / 64);
    // Which transitions a firing of t can enable and which it can disable. An input arc is satisfied
    // from `weight` tokens up, an inhibitor arc below `weight`: a place that gains tokens can only
    // satisfy its input arcs and break its inhibitor arcs, one that loses tokens the reverse. So after
    // firing t, a transition u that was enabled needs a test only if t can disable it (down), one that
    // was not only if t can enable it (up). Kept as bitsets over the transitions, tw_ words per t, for
    // nets with up to 64 * kDirWords transitions; larger nets test every transition in aff.
    if (tw_ <= kDirWords) {
      up_.assign(std::size_t{c_.transitions} * tw_, 0);
      down_.assign(std::size_t{c_.transitions} * tw_, 0);
      std::vector<std::vector<std::uint32_t>> inputs_of(c_.places), inhibitors_of(c_.places);
      for (std::uint32_t u = 0; u < c_.transitions; ++u) {
        for (const auto& a : net.transitions()[u].inputs) inputs_of[a.place].push_back(u);
        for (const auto& a : net.transitions()[u].inhibitors) inhibitors_of[a.place].push_back(u);
      }
      for (std::uint32_t t = 0; t < c_.transitions; ++t) {
        std::uint64_t* up = up_.data() + std::size_t{t} * tw_;
        std::uint64_t* down = down_.data() + std::size_t{t} * tw_;
        for (std::uint32_t i = c_.delta_begin[t]; i < c_.delta_begin[t + 1]; ++i) {
          const auto& d = c_.delta[i];
          // Named pointers, not `(d.delta > 0 ? up : down)[u >> 6] |= ...`: GCC 12.2 with -fsanitize=shift
          // (part of the ASan+UBSan build) at -O0 miscompiles a compound assignment through a subscript whose
          // base is a conditional expression and whose index is a shift; the write lands far outside the
          // array (SEGV in Pnml.RoundTripKeeps...). A 15-line program does it too; clang and -O1 do not.
          std::uint64_t* gains = d.delta > 0 ? up : down;  // input arcs on d.place
          std::uint64_t* loses = d.delta > 0 ? down : up;  // inhibitor arcs on d.place
          for (const std::uint32_t r : inputs_of[d.place]) gains[r >> 6] |= std::uint64_t{1} << (r & 63);
          for (const std::uint32_t r : inhibitors_of[d.place]) loses[r >> 6] |= std::uint64_t{1} << (r & 63);
        }
      }
    }
    fixed_ = c_.bytes() + (up_.capacity() + down_.capacity()) * 8;
  }

  ExploreResult run() {
    const auto start = Clock::now();
    start_ = start;
    ExploreResult r;
    if (fixed_ > limit_) {  // the compiled net alone
      over_limit(r, "while compiling the net", fixed_);
    } else {
      // Timed: part of the analysis. It may use what the compiled net leaves of the limit, and gives up
      // (no bounds) rather than pass it.
      if (c_.places > 0) bounds_ = detail::place_bounds(net_, limit_ - fixed_);
      if (bounds_) fixed_ += bounds_->capacity() * 8;
      // Conserving nets never hold more than the initial token count in a place: size fields for that.
      // A net with structural bounds gets fields that hold them, and needs no unboundedness check. Other
      // nets start as narrow as the initial marking allows and double the fields when a place outgrows
      // them.
      unsigned bits = bits_for(std::max<std::uint32_t>(c_.initial_max, 1));
      if (bounds_)
        bits = bits_for(std::max<std::uint64_t>(*std::max_element(bounds_->begin(), bounds_->end()), 1));
      while (true) {
        r = ExploreResult{};
        if (attempt(bits, r)) break;
        if (bits == 32)
          vsd::detail::throw_error("explore: a place of net '" + net_.id() +
                                   "' would hold more than 2^32-1 tokens");
        bits *= 2;  // a place outgrew the fields: start again with wider ones
      }
    }
    r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    r.threads = threads_;
    r.memory_limit = limit_;
    r.peak_memory = std::max(peak_, fixed_);
    if (progress_shown_) std::fputs("\n", stderr);
    return r;
  }

 private:
  const std::uint64_t* record(std::uint32_t id) const {
    return blocks_[id >> block_bits_].get() + std::size_t(id & ((1u << block_bits_) - 1)) * layout_.record;
  }
  std::uint64_t* record(std::uint32_t id) {
    return blocks_[id >> block_bits_].get() + std::size_t(id & ((1u << block_bits_) - 1)) * layout_.record;
  }
  std::uint32_t parent(std::uint32_t id) const {
    return static_cast<std::uint32_t>(record(id)[layout_.words] >> 32);
  }
  std::uint32_t firing(std::uint32_t id) const {
    return static_cast<std::uint32_t>(record(id)[layout_.words] & 0xFFFFFFFFu);
  }
  std::size_t block_bytes() const { return (std::size_t{1} << block_bits_) * layout_.record * 8; }

  // Everything the exploration holds, read between phases (not while workers run: they change it).
  std::size_t memory() const {
    std::size_t m = fixed_ + attempt_fixed_ + blocks_.size() * block_bytes() + blocks_.capacity() * 8;
    for (const auto& s : shards_) m += s.slots.capacity() * 8 + s.pending.capacity() * 8;
    for (const auto& ch : chunks_) m += ch.bytes();
    m += chunks_.capacity() * sizeof(Chunk);
    m += (prev_enabled_.capacity() + cur_enabled_.capacity()) * 8;
    return m;
  }

  // The limit holds before anything is allocated. Between phases memory() says what is held; within a
  // phase, whatever grows (an arena block, a hash shard, a successor buffer; on any thread) first takes
  // room for its new size here, and gives back the old size once that is freed. Without room the phase
  // stops (full_) and the exploration ends with Status::memory_limit.
  void begin_phase() {
    phase_base_ = memory();
    growth_.store(0, std::memory_order_relaxed);
    peak_ = std::max(peak_, phase_base_);
  }
  void end_phase() { peak_ = std::max(peak_, phase_base_ + peak_growth_.exchange(0)); }
  bool room(std::size_t bytes) {
    const std::size_t now = growth_.fetch_add(bytes, std::memory_order_relaxed) + bytes;
    if (phase_base_ + now > limit_) {
      growth_.fetch_sub(bytes, std::memory_order_relaxed);
      full_.store(true, std::memory_order_relaxed);
      return false;
    }
    std::size_t seen = peak_growth_.load(std::memory_order_relaxed);
    while (now > seen && !peak_growth_.compare_exchange_weak(seen, now, std::memory_order_relaxed)) {
    }
    return true;
  }
  void release(std::size_t bytes) { growth_.fetch_sub(bytes, std::memory_order_relaxed); }
  // Capacity for n elements in b (doubling), within the limit.
  template <class T>
  bool fit(PodBuffer<T>& b, std::size_t n) {
    if (n <= b.capacity()) return true;
    const std::size_t cap = std::max(n, b.capacity() * 2);
    if (!room(cap * sizeof(T))) return false;
    const std::size_t old = b.capacity() * sizeof(T);
    b.reserve(cap);
    release(old);
    return true;
  }
  template <class T>
  bool fit(std::vector<T>& v, std::size_t n) {
    if (n <= v.capacity()) return true;
    if (!room(n * sizeof(T))) return false;
    const std::size_t old = v.capacity() * sizeof(T);
    v.reserve(n);
    release(old);
    return true;
  }

  void over_limit(ExploreResult& r, const std::string& phase, std::size_t needed) {
    r.status = ExploreResult::Status::memory_limit;
    r.message = "memory limit of " + format_bytes(limit_) + " reached " + phase + " (it needs at least " +
                format_bytes(needed) + "). Raise it with --limit-mem.";
  }
  bool check_memory(ExploreResult& r) {
    const std::size_t m = memory();
    peak_ = std::max(peak_, m);
    if (m <= limit_ && !full_.load()) return true;
    r.status = ExploreResult::Status::memory_limit;
    r.message = "memory limit of " + format_bytes(limit_) + " reached in the exploration after " +
                std::to_string(states_) + " states (" + format_bytes(std::max(m, phase_base_ + growth_.load())) +
                " in use or asked for); the figures count the states visited so far. Raise it with --limit-mem.";
    return false;
  }

  // Stores a new state; false (nothing stored) when its arena block does not fit the limit.
  bool add_state(const std::uint64_t* marking, std::uint32_t par, std::uint32_t t, std::uint32_t& id) {
    id = static_cast<std::uint32_t>(states_);
    if ((id >> block_bits_) >= blocks_.size()) {
      const std::size_t list = blocks_.size() == blocks_.capacity() ? std::max<std::size_t>(8, blocks_.size() * 2) : 0;
      if (!room(block_bytes() + list * 8)) return false;
      if (list != 0) {
        const std::size_t old = blocks_.capacity() * 8;
        blocks_.reserve(list);
        release(old);
      }
      blocks_.emplace_back(new std::uint64_t[(std::size_t{1} << block_bits_) * layout_.record]);
    }
    std::uint64_t* rec = record(id);
    std::memcpy(rec, marking, layout_.words * 8);
    rec[layout_.words] = (std::uint64_t{par} << 32) | t;
    ++states_;
    return true;
  }

  std::vector<std::uint32_t> path_to(std::uint32_t id) const {
    std::vector<std::uint32_t> seq;
    while (id != 0) {
      seq.push_back(firing(id));
      id = parent(id);
    }
    std::reverse(seq.begin(), seq.end());
    return seq;
  }
  std::vector<std::uint32_t> unpack(std::uint32_t id) const {
    std::vector<std::uint32_t> m(c_.places);
    layout_.unpack(record(id), c_.places, m.data());
    return m;
  }

  // Room in shard s for one more entry: grown (doubled) when half full; false when that does not fit.
  bool ensure_slot(Shard& s) {
    if ((s.used + 1) * 2 <= s.slots.size()) return true;
    const std::size_t old = s.slots.size() * 8;
    if (!room(2 * old)) return false;
    grow(s);
    release(old);
    return true;
  }
  static void grow(Shard& s) {
    std::vector<std::uint64_t> old = std::move(s.slots);
    s.slots.assign(old.size() * 2, kEmpty);
    const std::size_t mask = s.slots.size() - 1;
    for (std::uint64_t v : old) {
      if (v == kEmpty) continue;
      std::size_t i = ((v >> 32) & 0x7FFFFFFFull) & mask;
      while (s.slots[i] != kEmpty) i = (i + 1) & mask;
      s.slots[i] = v;
    }
  }
  // After ensure_slot.
  static void put_slot(Shard& s, std::uint64_t h, std::uint64_t value) {
    const std::size_t mask = s.slots.size() - 1;
    std::size_t i = (h & 0x7FFFFFFFull) & mask;
    while (s.slots[i] != kEmpty) i = (i + 1) & mask;
    s.slots[i] = value;
    ++s.used;
  }

  // ---- shared levels: all workers insert into the hash set at once --------------------------------
  // A worker that finds no entry for a marking writes its record at the worker's next state index, then
  // claims the empty slot with a compare-and-swap to fragment and index (release: the record is there for
  // whoever finds the slot); if another worker got there first it looks at that entry instead and keeps
  // the index for its next new state. Shards cannot grow while workers probe them, nor can the list of
  // arena blocks move: both are sized before the level (reserve_slots, blocks_ capacity), and a successor
  // that finds its shard three quarters full or the list at its capacity is left in the worker's stash
  // for drain_stash().

  // Capacity in shard s for `extra` more entries at a load of at most one half; false without room.
  bool reserve_slots(Shard& s, std::size_t extra) {
    std::size_t size = s.slots.size();
    while ((s.used + extra) * 2 > size) size *= 2;
    if (size == s.slots.size()) return true;
    const std::size_t old = s.slots.size() * 8;
    if (!room(size * 8)) return false;
    while (s.slots.size() < size) grow(s);
    release(old);
    return true;
  }
  // The record of new state id (its arena block made if need be), or nullptr without room (full_ set) or
  // when blocks_ is at its capacity: it must not move while workers read it.
  std::uint64_t* new_record(std::uint32_t id) {
    const std::size_t b = id >> block_bits_;
    if (b >= blocks_ready_.load(std::memory_order_acquire)) {
      std::lock_guard<std::mutex> lock(blocks_mutex_);
      while (blocks_.size() <= b) {
        if (blocks_.size() == blocks_.capacity()) return nullptr;
        if (!room(block_bytes())) return nullptr;
        blocks_.emplace_back(new std::uint64_t[(std::size_t{1} << block_bits_) * layout_.record]);
      }
      blocks_ready_.store(blocks_.size(), std::memory_order_release);
    }
    return record(id);
  }
  enum class Insert { found, added, stashed, failed };
  // Looks mk up and adds it if new, concurrently with other workers (see above).
  Insert insert_shared(WorkerStats& st, const std::uint64_t* mk, std::uint32_t words, std::uint64_t h,
                       std::uint32_t par, std::uint32_t t) {
    const std::size_t si = h >> (64 - kShardBits);
    Shard& sh = shards_[si];
    const std::uint64_t frag = h & 0x7FFFFFFFull;
    std::uint64_t* const slots = sh.slots.data();
    const std::size_t mask = sh.slots.size() - 1;
    for (std::size_t pos = frag & mask;; pos = (pos + 1) & mask) {
      std::atomic_ref<std::uint64_t> slot(slots[pos]);
      std::uint64_t v = slot.load(std::memory_order_acquire);
      while (true) {
        if (v == kEmpty) {
          // Take room for the entry first: the shard must never fill up (the probes would not end).
          if (st.credits[si] == 0) {  // kCredit entries, or one when the shard is nearly full
            std::atomic_ref<std::size_t> used(sh.used);
            const std::size_t most = sh.slots.size() / 4 * 3;
            std::uint32_t take = kCredit;
            if (used.fetch_add(take, std::memory_order_relaxed) + take > most) {
              used.fetch_sub(take, std::memory_order_relaxed);
              take = 1;
              if (used.fetch_add(take, std::memory_order_relaxed) + take > most) {
                used.fetch_sub(take, std::memory_order_relaxed);
                return Insert::stashed;
              }
            }
            st.credits[si] = take;
          }
          // The record first, at the worker's next index, then the slot (release): whoever finds the slot
          // finds the record. If another worker takes the slot first, the index stays for the next one.
          if (st.id_next == st.id_end) {
            st.id_next = next_id_.fetch_add(kCredit, std::memory_order_relaxed);
            st.id_end = st.id_next + kCredit;
          }
          const std::uint64_t id = st.id_next;
          if (id >= kMaxStates) {
            too_many_.store(true, std::memory_order_relaxed);
            return Insert::failed;
          }
          std::uint64_t* rec = new_record(static_cast<std::uint32_t>(id));
          if (rec == nullptr)  // no room (the run stops), or blocks_ is at its capacity: after the level
            return full_.load(std::memory_order_relaxed) ? Insert::failed : Insert::stashed;
          std::memcpy(rec, mk, words * 8);
          rec[words] = (std::uint64_t{par} << 32) | t;
          if (!slot.compare_exchange_strong(v, frag << 32 | id, std::memory_order_acq_rel,
                                            std::memory_order_acquire))
            continue;  // v is what another worker put there: look at it
          --st.credits[si];
          ++st.id_next;
          return Insert::added;
        }
        if (((v >> 32) & 0x7FFFFFFFull) != frag) break;
        if (same(record(static_cast<std::uint32_t>(v & 0xFFFFFFFFull)), mk, words)) return Insert::found;
        break;
      }
    }
  }
  // After a shared level: the credits not used go back to the shards, and the indices taken but not given
  // out (the rest of each worker's last range) are holes below next_id_: the states with the highest
  // indices move into them (their records copied, their hash entries rewritten; nothing refers to a
  // state of the newest level yet), so that the level's states are numbered without gaps. Without
  // `compact` (the run stops) only the count is made right.
  void close_shared_level(std::vector<WorkerStats>& ws, unsigned workers, const Layout& L, bool compact) {
    const std::uint64_t end = next_id_.load();
    std::vector<std::uint64_t> holes;
    for (unsigned wi = 0; wi < workers; ++wi) {
      WorkerStats& st = ws[wi];
      for (std::size_t si = 0; si < kShards; ++si) {
        shards_[si].used -= st.credits[si];
        st.credits[si] = 0;
      }
      for (std::uint64_t id = st.id_next; id < st.id_end; ++id) holes.push_back(id);
      st.id_next = st.id_end = 0;
    }
    const std::uint64_t count = end - holes.size();
    states_ = count;
    if (!compact) return;
    std::sort(holes.begin(), holes.end());
    std::size_t next_hole = 0;
    for (std::uint64_t src = count; src < end; ++src) {
      if (std::binary_search(holes.begin(), holes.end(), src)) continue;
      const auto from = static_cast<std::uint32_t>(src);
      const auto to = static_cast<std::uint32_t>(holes[next_hole++]);  // below count: as many as these
      std::memcpy(record(to), record(from), std::size_t{L.record} * 8);
      const std::uint64_t h = hash_words(record(to), L.words);
      Shard& sh = shards_[h >> (64 - kShardBits)];
      const std::uint64_t frag = h & 0x7FFFFFFFull;
      const std::size_t mask = sh.slots.size() - 1;
      std::size_t pos = frag & mask;
      while (sh.slots[pos] != (frag << 32 | from)) pos = (pos + 1) & mask;
      sh.slots[pos] = frag << 32 | to;
    }
  }
  // After a shared level: the successors left in the workers' stashes (chunks_[0..workers)), added one by
  // one, with the shards growing as they must. False when something found no room.
  bool drain_stash(unsigned workers, const Layout& L) {
    for (unsigned wi = 0; wi < workers; ++wi) {
      Chunk& ch = chunks_[wi];
      for (std::size_t i = 0; i < ch.hashes.size(); ++i) {
        const std::uint64_t h = ch.hashes[i];
        Shard& sh = shards_[h >> (64 - kShardBits)];
        const std::uint64_t frag = h & 0x7FFFFFFFull;
        const std::uint64_t* mk = ch.markings.data() + i * L.words;
        if (contains<0>(sh, frag, mk, L.words)) continue;
        if (states_ >= kMaxStates)
          vsd::detail::throw_error("explore: more than 2^32-2 states; not supported");
        std::uint32_t id = 0;
        if (!ensure_slot(sh) || !add_state(mk, ch.parents[i], ch.firings[i], id)) return false;
        put_slot(sh, h, frag << 32 | id);
      }
      ch.clear();
    }
    return true;
  }

  void progress(std::uint32_t level, bool force) {
    if (!show_progress_) return;
    const auto now = Clock::now();
    if (!force && now - last_progress_ < std::chrono::seconds(1)) return;
    if (!progress_shown_ && now - start_ < std::chrono::seconds(1)) return;
    last_progress_ = now;
    progress_shown_ = true;
    const double secs = std::chrono::duration<double>(now - start_).count();
    std::fprintf(stderr, "\rvsd-soml: level %u, %llu states, %llu edges, %.0f states/s, %zu MiB   ", level,
                 static_cast<unsigned long long>(states_), static_cast<unsigned long long>(edges_),
                 secs > 0 ? static_cast<double>(states_) / secs : 0.0, memory() >> 20);
    std::fflush(stderr);
  }

  // One exploration with `bits` per place; false when a place outgrew them.
  bool attempt(unsigned bits, ExploreResult& r);
  // False when a hash shard or an arena block found no room (the level is then incomplete).
  bool phases_b_to_d(std::size_t nchunks, const Layout& L);

  // Whether the hash set holds marking mk (fragment frag of its hash), committed or pending. W: the
  // marking's words if the loop over them is unrolled, else 0.
  template <std::uint32_t W>
  bool contains(const Shard& sh, std::uint64_t frag, const std::uint64_t* mk, std::uint32_t words) const {
    const std::uint64_t* slots = sh.slots.data();
    const std::size_t mask = sh.slots.size() - 1;
    for (std::size_t pos = frag & mask;; pos = (pos + 1) & mask) {
      const std::uint64_t v = slots[pos];
      if (v == kEmpty) return false;
      if (((v >> 32) & 0x7FFFFFFFull) != frag) continue;
      const std::uint64_t* other;
      if (v & kPendingBit) {
        const std::uint64_t ref = sh.pending[v & 0xFFFFFFFFull];
        other = chunks_[ref >> 32].markings.data() + (ref & 0xFFFFFFFFull) * words;
      } else {
        other = record(static_cast<std::uint32_t>(v & 0xFFFFFFFFull));
      }
      if (same(other, mk, W != 0 ? W : words)) return true;
    }
  }

  const PtNet& net_;
  std::size_t limit_ = 0;  // before c_, whose constructor uses it
  Compiled c_;
  std::optional<std::vector<std::uint64_t>> bounds_;  // structural place bounds, when the net proves them
  ExploreOptions opt_;
  unsigned threads_ = 1;
  std::size_t peak_ = 0;
  std::size_t fixed_ = 0;          // the compiled net (and bounds) for the whole run
  std::size_t attempt_fixed_ = 0;  // the net compiled for the layout, workers' scratch, the result's markings
  std::size_t phase_base_ = 0;     // memory() when the phase under way began
  std::atomic<std::size_t> growth_{0};       // room taken since
  std::atomic<std::size_t> peak_growth_{0};  // the most of it at once
  std::atomic<bool> full_{false};            // some growth found no room: the run stops
  unsigned block_bits_ = kBlockBits;         // states per arena block = 2^block_bits_
  bool show_progress_ = false;
  bool progress_shown_ = false;
  Clock::time_point start_, last_progress_;
  std::uint32_t tw_ = 1;  // words of an enabled-transition bitset
  static constexpr std::uint32_t kDirWords = 8;
  std::vector<std::uint64_t> up_, down_;  // per transition, tw_ words each (when tw_ <= kDirWords)
  Layout layout_{1, 0};
  std::vector<std::unique_ptr<std::uint64_t[]>> blocks_;
  std::vector<Shard> shards_;
  std::vector<Chunk> chunks_;
  std::vector<std::uint64_t> prev_enabled_, cur_enabled_;
  std::uint64_t states_ = 0;
  std::uint64_t edges_ = 0;
  // Shared levels (insert_shared): the next state index, 2^32-2 passed; blocks_ entries made (new_record
  // makes more under blocks_mutex_).
  std::atomic<std::uint64_t> next_id_{0};
  std::atomic<bool> too_many_{false};
  std::atomic<std::size_t> blocks_ready_{0};
  std::mutex blocks_mutex_;
  WorkerPool pool_;  // last: its helpers stop before anything they could touch goes away
};

bool Explorer::attempt(unsigned bits, ExploreResult& r) {
  layout_ = Layout(bits, c_.places);
  r.bits_per_place = bits;
  blocks_.clear();
  shards_.assign(kShards, Shard{});
  for (auto& s : shards_) s.slots.assign(16, kEmpty);
  chunks_.clear();
  prev_enabled_.clear();
  cur_enabled_.clear();
  attempt_fixed_ = 0;
  full_.store(false);
  states_ = 0;
  edges_ = 0;
  const std::uint32_t P = c_.places;
  const Layout L = layout_;
  // Arena blocks of 2^12 states, fewer for large markings: a block stays near 1 MiB (at least one
  // record), so that the first state does not take gigabytes at once (a record of 200,000 places of 32 bits
  // is 800 KB).
  block_bits_ = kBlockBits;
  while (block_bits_ > 0 && block_bytes() > (std::size_t{1} << 20)) --block_bits_;
  const bool check_cover = !bounds_.has_value();
  // Fast paths on the packed words: enabling by masks with one bit per place; firing by word arithmetic
  // when the structural bounds fit the fields (no field can overflow into its neighbour). Where both
  // hold, a frontier state is never unpacked.
  const PackedNet pk(c_, net_, L);
  const bool use_masks = L.bits == 1;
  const bool use_ops = !check_cover;
  const bool unpack_states = !(use_masks && use_ops);
  // For the whole attempt: the net compiled for the layout, each worker's two unpacked markings, and the
  // result's markings (a dead one, an unbounded pair).
  attempt_fixed_ =
      pk.bytes() + std::size_t{threads_} * (P * 8 + kBatch * L.words * 8) + std::size_t{3} * P * 4;
  if (fixed_ + attempt_fixed_ > limit_) {
    over_limit(r,
               "while preparing the exploration (the net compiled for " + std::to_string(bits) +
                   " bit(s) per place, " + std::to_string(threads_) + " worker(s))",
               fixed_ + attempt_fixed_);
    return true;
  }
  std::vector<WorkerStats> ws(threads_);
  for (auto& w : ws) {
    w.unpacked.assign(P, 0);
    w.unpacked2.assign(P, 0);
    w.batch_markings.assign(std::size_t{kBatch} * L.words, 0);
  }

  begin_phase();
  {  // the initial marking
    std::vector<std::uint64_t> m0(L.words, 0);
    for (std::uint32_t p = 0; p < P; ++p) {
      const std::uint32_t v = net_.places()[p].initial;
      if (v > L.mask) return false;
      L.set(m0.data(), p, v);
    }
    const std::uint64_t h = hash_words(m0.data(), L.words);
    Shard& s = shards_[h >> (64 - kShardBits)];
    std::uint32_t id = 0;
    if (!ensure_slot(s) || !add_state(m0.data(), kNone, kNone, id)) {
      end_phase();
      over_limit(r, "storing the initial marking", phase_base_ + block_bytes());
      return true;
    }
    put_slot(s, h, (h & 0x7FFFFFFFull) << 32 | id);
  }
  end_phase();

  std::uint32_t first_dead = kNone;
  std::uint64_t lo = 0, hi = 1, prev_lo = 0, prev_n = 0;
  std::uint32_t level = 0;
  for (; lo < hi; ++level) {
    const std::uint64_t n = hi - lo;
    const std::size_t nchunks = (n + kChunkStates - 1) / kChunkStates;
    // One worker and a small hash set: each successor is looked up (and a new one numbered) as soon as it is
    // made, in the order phases B and C would have used, so the numbering is the same; no successor buffers,
    // and phases B to D fall away. Chunk 0 serves as scratch. Only while the hash set is small enough to stay
    // in cache: on a larger one the lookups are cache misses, which shared levels and phase B hide by
    // prefetching a few candidates ahead (the ring of 490 314 states ran 25 % slower fused than phased).
    std::size_t table_bytes = 0;
    for (const auto& sh : shards_) table_bytes += sh.slots.size() * 8;
    const bool small_table = table_bytes <= kFusedTableBytes;
    // While the hash set is small, one worker (fused) also beats several (phased) in wall time: the
    // phases cost ~5x the CPU per successor (Dekker-PT-010: 2.4 M states/s on one thread, 0.45 M per
    // core on two). So the threads share only the levels of larger state spaces, unless told otherwise.
    const unsigned workers = small_table && !opt_.split_small_levels
                                 ? 1u
                                 : static_cast<unsigned>(std::min<std::size_t>(threads_, nchunks));
    const bool fused = workers == 1 && small_table;
    // Shared: the workers look their successors up and add the new ones to the hash set and the arena
    // themselves, all at once (insert_shared), with no phases B to D. New states are numbered in the order
    // the workers add them, which depends on the timing: the states, edges, levels and token bounds do
    // not, nor does the length of the firing sequence to a dead marking (a shortest one either way), but
    // which dead marking and which sequence may. The unboundedness check reads parents on the
    // breadth-first tree, so nets that need it keep the phases, whose numbering is fixed.
    const bool shared = !fused && !check_cover;
    const std::uint64_t new_lo = states_;
    begin_phase();
    if (shared) {  // room for the level's new states: arena block list, hash shards (see insert_shared)
      // Expected new states: the frontier grew by n / prev_n last level; half as much again for the
      // variation among shards. More goes to the stashes.
      const double grow = prev_n == 0 ? 1.0 : static_cast<double>(n) / static_cast<double>(prev_n);
      const auto per_shard = static_cast<std::size_t>(static_cast<double>(n) * std::max(1.0, grow) * 1.5 /
                                                      static_cast<double>(kShards)) + 16;
      // Arena blocks for as many, and the workers' unused index ranges (kCredit each).
      const std::size_t list = static_cast<std::size_t>(
          (states_ + per_shard * kShards + std::uint64_t{workers} * kCredit) >> block_bits_) + 2;
      bool ok = blocks_.capacity() >= list || fit(blocks_, list);
      for (auto& sh : shards_) ok = ok && reserve_slots(sh, per_shard);
      if (!ok) {
        end_phase();
        check_memory(r);
        break;
      }
      blocks_ready_.store(blocks_.size());
      next_id_.store(states_);
      too_many_.store(false);
    }
    {  // the chunks and the level's enabled sets, within the limit
      const std::size_t want = fused ? 1 : shared ? workers : nchunks;
      const bool chunks_fit = chunks_.size() >= want || fit(chunks_, want);
      if (!chunks_fit || !fit(cur_enabled_, n * tw_)) {
        end_phase();
        check_memory(r);
        break;
      }
      if (chunks_.size() < want) chunks_.resize(want);
      if (shared)
        for (unsigned wi = 0; wi < workers; ++wi) chunks_[wi].clear();
      cur_enabled_.assign(n * tw_, 0);
    }
    std::atomic<std::size_t> next_chunk{0};
    std::atomic<bool> stop{false};
    const double successors_per_state = lo == 0 ? 1.0 : static_cast<double>(edges_) / static_cast<double>(lo);

    // ---- phase A: expand the frontier -------------------------------------------------------------
    // W: the marking's words when the loops over them are unrolled (1..4), else 0 (L.words at run time).
    with_words(L.words, [&](auto wc) {
      constexpr std::uint32_t W = decltype(wc)::value;
      const std::uint32_t words = W != 0 ? W : L.words;
      pool_.run(workers, [&](unsigned wi) {
        WorkerStats& st = ws[wi];
        std::uint32_t* m = st.unpacked.data();
        while (!stop.load(std::memory_order_relaxed)) {
          const std::size_t ci = next_chunk.fetch_add(1);
          if (ci >= nchunks) break;
          Chunk& ch = chunks_[fused ? 0 : shared ? wi : ci];  // shared: the worker's stash
          if (!shared) ch.clear();
          const std::uint64_t first = lo + ci * kChunkStates;
          const std::uint64_t last = std::min(hi, first + kChunkStates);
          // Size the buffers from the successors per state so far: few reallocations while filling them.
          if (!fused && !shared) {
            const auto expect =
                static_cast<std::size_t>(static_cast<double>(last - first) * successors_per_state * 1.25) + 16;
            if (!fit(ch.markings, expect * words) || !fit(ch.hashes, expect) || !fit(ch.parents, expect) ||
                !fit(ch.firings, expect)) {
              stop.store(true, std::memory_order_relaxed);
              break;
            }
          }
          bool no_room = false;  // an arena block or a hash shard found no room (fused, shared)
          // Shared: inserts the batched successors, whose slots were prefetched as they were made.
          auto flush = [&] {
            for (std::uint32_t j = 0; j < st.batched && !no_room; ++j) {
              const std::uint64_t* mk = st.batch_markings.data() + std::size_t{j} * words;
              const Insert in = insert_shared(st, mk, words, st.batch_hashes[j], st.batch_parents[j],
                                              st.batch_firings[j]);
              if (in == Insert::stashed) {
                const std::size_t at = ch.hashes.size();
                if (fit(ch.markings, (at + 1) * words) && fit(ch.hashes, at + 1) && fit(ch.parents, at + 1) &&
                    fit(ch.firings, at + 1)) {
                  std::memcpy(ch.markings.data() + at * words, mk, words * 8);
                  ch.markings.set_size((at + 1) * words);
                  ch.hashes[at] = st.batch_hashes[j];
                  ch.parents[at] = st.batch_parents[j];
                  ch.firings[at] = st.batch_firings[j];
                  ch.hashes.set_size(at + 1);
                  ch.parents.set_size(at + 1);
                  ch.firings.set_size(at + 1);
                  continue;
                }
              } else if (in != Insert::failed) {
                continue;
              }
              if (!too_many_.load(std::memory_order_relaxed)) full_.store(true, std::memory_order_relaxed);
              no_room = true;
              stop.store(true, std::memory_order_relaxed);
            }
            st.batched = 0;
          };
          for (std::uint64_t s64 = first; s64 < last && !no_room; ++s64) {
            const auto s = static_cast<std::uint32_t>(s64);
            const std::uint64_t* rec = record(s);
            if (unpack_states) {
              L.unpack(rec, P, m);
              std::uint64_t sum = 0;
              for (std::uint32_t p = 0; p < P; ++p) {
                sum += m[p];
                st.max_place = std::max(st.max_place, m[p]);
              }
              st.max_sum = std::max(st.max_sum, sum);
            } else {  // one bit per place: the tokens are the set bits
              std::uint64_t sum = 0;
              for (std::uint32_t w = 0; w < words; ++w)
                sum += static_cast<std::uint64_t>(std::popcount(rec[w]));
              st.max_sum = std::max(st.max_sum, sum);
              if (sum != 0) st.max_place = std::max(st.max_place, 1u);
            }
            auto enabled = [&](std::uint32_t t) -> bool {
              if constexpr (W != 0) {
                if (use_masks) {  // branch-free over the W words
                  const std::uint64_t* need = pk.need.data() + std::size_t{t} * W;
                  const std::uint64_t* forbid = pk.forbid.data() + std::size_t{t} * W;
                  std::uint64_t bad = 0;
                  for (std::uint32_t w = 0; w < W; ++w)
                    bad |= ((rec[w] & need[w]) ^ need[w]) | (rec[w] & forbid[w]);
                  return bad == 0;
                }
              }
              return use_masks ? pk.enabled(t, rec) : c_.enabled(t, m);
            };
            std::uint64_t* en = cur_enabled_.data() + (s64 - lo) * tw_;
            if (s == 0) {
              for (std::uint32_t t = 0; t < c_.transitions; ++t)
                if (enabled(t)) en[t >> 6] |= std::uint64_t{1} << (t & 63);
            } else {
              // Incremental enabling: the parent's set, with the transitions reading a changed place
              // retested.
              const std::uint32_t par = static_cast<std::uint32_t>(rec[L.words] >> 32);
              const std::uint32_t ft = static_cast<std::uint32_t>(rec[L.words] & 0xFFFFFFFFu);
              const std::uint64_t* pen = prev_enabled_.data() + (par - prev_lo) * tw_;
              for (std::uint32_t wd = 0; wd < tw_; ++wd) en[wd] = pen[wd];
              if (!up_.empty()) {  // only those that the firing can switch, in the direction it can
                const std::uint64_t* up = up_.data() + std::size_t{ft} * tw_;
                const std::uint64_t* down = down_.data() + std::size_t{ft} * tw_;
                for (std::uint32_t wd = 0; wd < tw_; ++wd) {
                  std::uint64_t retest = (up[wd] & ~en[wd]) | (down[wd] & en[wd]);
                  while (retest != 0) {
                    const unsigned b = static_cast<unsigned>(std::countr_zero(retest));
                    retest &= retest - 1;
                    const std::uint64_t e = enabled(wd * 64 + b) ? 1 : 0;
                    en[wd] = (en[wd] & ~(std::uint64_t{1} << b)) | (e << b);
                  }
                }
              } else if (c_.aff_all) {  // no list of them (it would not fit the limit): all
                for (std::uint32_t u = 0; u < c_.transitions; ++u) {
                  const std::uint64_t e = enabled(u) ? 1 : 0;
                  en[u >> 6] = (en[u >> 6] & ~(std::uint64_t{1} << (u & 63))) | (e << (u & 63));
                }
              } else {
                for (std::uint32_t i = c_.aff_begin[ft]; i < c_.aff_begin[ft + 1]; ++i) {
                  const std::uint32_t u = c_.aff[i];
                  const std::uint64_t e = enabled(u) ? 1 : 0;
                  en[u >> 6] = (en[u >> 6] & ~(std::uint64_t{1} << (u & 63))) | (e << (u & 63));
                }
              }
            }
            // Room for the successor of every enabled transition (fused: one at a time), within the limit: no
            // per-successor growth checks in the loop below. (Room for every transition was 5 GB for one
            // state of a net of 200,000 places and transitions.)
            const std::size_t k0 = shared ? 0 : ch.hashes.size();
            std::size_t need = 1;
            if (!fused) {
              need = k0;
              for (std::uint32_t wd = 0; wd < tw_; ++wd)
                need += static_cast<std::size_t>(std::popcount(en[wd]));
            }
            if (!shared && (!fit(ch.markings, need * words) || !fit(ch.hashes, need) ||
                            !fit(ch.parents, need) || !fit(ch.firings, need))) {
              stop.store(true, std::memory_order_relaxed);
              break;
            }
            std::uint64_t* const out_markings = ch.markings.data();
            std::uint64_t* const out_hashes = ch.hashes.data();
            std::uint32_t* const out_parents = ch.parents.data();
            std::uint32_t* const out_firings = ch.firings.data();
            std::size_t k = k0;
            for (std::uint32_t wd = 0; wd < tw_ && !no_room; ++wd) {
              std::uint64_t bitsw = en[wd];
              while (bitsw != 0) {
                const std::uint32_t t = wd * 64 + static_cast<std::uint32_t>(std::countr_zero(bitsw));
                bitsw &= bitsw - 1;
                std::uint64_t* out = shared ? st.batch_markings.data() + std::size_t{st.batched} * words
                                            : out_markings + (fused ? k0 : k) * words;
                if constexpr (W != 0) {
                  if (use_ops) {  // firing adds each word's difference: no carries cross fields here
                    const std::uint64_t* d = pk.diff.data() + std::size_t{t} * W;
                    for (std::uint32_t w = 0; w < W; ++w) out[w] = rec[w] + d[w];
                  }
                }
                if (W == 0 || !use_ops) {
                  for (std::uint32_t w = 0; w < words; ++w) out[w] = rec[w];
                  if (use_ops) {
                    pk.fire(t, out);
                  } else {
                    for (std::uint32_t i = c_.delta_begin[t]; i < c_.delta_begin[t + 1]; ++i) {
                      const auto& d = c_.delta[i];
                      const std::int64_t v = static_cast<std::int64_t>(m[d.place]) + d.delta;
                      if (static_cast<std::uint64_t>(v) > L.mask) {
                        st.overflow = true;
                        stop.store(true, std::memory_order_relaxed);
                      }
                      L.set(out, d.place, static_cast<std::uint64_t>(v) & L.mask);
                    }
                  }
                }
                const std::uint64_t h = hash_words(out, words);
                if (fused) {
                  Shard& sh = shards_[h >> (64 - kShardBits)];
                  const std::uint64_t frag = h & 0x7FFFFFFFull;
                  if (!contains<W>(sh, frag, out, words)) {
                    if (states_ >= kMaxStates)
                      vsd::detail::throw_error("explore: more than 2^32-2 states; not supported");
                    std::uint32_t id = 0;
                    if (!ensure_slot(sh) || !add_state(out, s, t, id)) {
                      no_room = true;
                      stop.store(true, std::memory_order_relaxed);
                      break;
                    }
                    put_slot(sh, h, frag << 32 | id);
                  }
                } else if (shared) {
                  const Shard& sh = shards_[h >> (64 - kShardBits)];
                  __builtin_prefetch(sh.slots.data() + ((h & 0x7FFFFFFFull) & (sh.slots.size() - 1)));
                  st.batch_hashes[st.batched] = h;
                  st.batch_parents[st.batched] = s;
                  st.batch_firings[st.batched] = t;
                  if (++st.batched == kBatch) flush();
                } else {
                  out_hashes[k] = h;
                  out_parents[k] = s;
                  out_firings[k] = t;
                }
                ++k;
              }
            }
            if (!fused && !shared) {
              ch.markings.set_size(k * words);
              ch.hashes.set_size(k);
              ch.parents.set_size(k);
              ch.firings.set_size(k);
            }
            const std::uint64_t count = k - k0;
            st.edges += count;
            if (count == 0 && !no_room && s < st.first_dead) st.first_dead = s;
          }
          if (shared) flush();
          if (fused || shared) continue;  // the new states went straight into the arena and the hash set
          if (!fit(ch.fresh, ch.hashes.size()) || !fit(ch.ids, ch.hashes.size())) {
            stop.store(true, std::memory_order_relaxed);
            break;
          }
          ch.fresh.assign(ch.hashes.size(), 0);
          ch.ids.resize(ch.hashes.size());
        }
      });
    });
    for (auto& w : ws) {
      if (w.overflow) return false;
      edges_ += w.edges;
      w.edges = 0;
      r.max_tokens_place = std::max(r.max_tokens_place, w.max_place);
      r.max_tokens_marking = std::max(r.max_tokens_marking, w.max_sum);
      first_dead = std::min(first_dead, w.first_dead);
    }
    std::swap(prev_enabled_, cur_enabled_);
    prev_lo = lo;
    prev_n = n;
    r.levels = level + 1;
    if (shared) {
      if (too_many_.load()) vsd::detail::throw_error("explore: more than 2^32-2 states; not supported");
      close_shared_level(ws, workers, L, !stop.load());
    }
    // No room (the only other stop, an overflow, returned above):
    if (stop.load() || (!fused && !(shared ? drain_stash(workers, L) : phases_b_to_d(nchunks, L)))) {
      end_phase();
      check_memory(r);
      break;
    }

    // ---- unboundedness: does a new marking strictly cover an ancestor? -------------------------------
    if (check_cover && states_ > new_lo) {
      std::atomic<std::uint64_t> next{new_lo};
      const unsigned cworkers =
          static_cast<unsigned>(std::min<std::uint64_t>(threads_, (states_ - new_lo) / 64 + 1));
      pool_.run(cworkers, [&](unsigned wi) {
        WorkerStats& st = ws[wi];
        std::uint32_t* m = st.unpacked.data();
        while (true) {
          const std::uint64_t from = next.fetch_add(256);
          if (from >= states_) break;
          const std::uint64_t to = std::min<std::uint64_t>(states_, from + 256);
          for (std::uint64_t s64 = from; s64 < to; ++s64) {
            const auto s = static_cast<std::uint32_t>(s64);
            if (s >= st.first_cover) break;
            L.unpack(record(s), P, m);
            for (std::uint32_t a = parent(s);; a = parent(a)) {
              const std::uint64_t* am = record(a);
              bool ge = true, gt = false;
              for (std::uint32_t p = 0; p < P && ge; ++p) {
                const std::uint32_t v = L.get(am, p);
                if (m[p] < v || (m[p] != v && c_.inhibitor_place[p])) ge = false;
                gt = gt || m[p] > v;
              }
              if (ge && gt) {
                st.first_cover = s;
                st.covered = a;
                break;
              }
              if (a == 0) break;
            }
            if (st.first_cover == s) break;
          }
        }
      });
      std::uint32_t cover = kNone, covered = kNone;
      for (auto& w : ws)
        if (w.first_cover < cover) {
          cover = w.first_cover;
          covered = w.covered;
        }
      if (cover != kNone) {
        r.status = ExploreResult::Status::unbounded;
        r.unbounded_prefix = path_to(covered);
        const auto full = path_to(cover);
        r.unbounded_cycle.assign(full.begin() + static_cast<std::ptrdiff_t>(r.unbounded_prefix.size()),
                                 full.end());
        r.unbounded_covered = unpack(covered);
        r.unbounded_covering = unpack(cover);
        r.message = "the net is unbounded: firing " + trace_to_string(net_, r.unbounded_cycle) +
                    " from the marking reached by [" + trace_to_string(net_, r.unbounded_prefix) +
                    "] gives a marking that strictly covers it, and the sequence can be repeated forever";
        break;
      }
    }
    lo = hi;
    hi = states_;
    end_phase();
    if (!check_memory(r)) break;
    progress(level, false);
  }
  progress(level, true);
  r.states = states_;
  r.edges = edges_;
  if (first_dead != kNone) {
    r.deadlock = true;
    r.dead_trace = path_to(first_dead);
    r.dead_marking = unpack(first_dead);
  }
  return true;
}

// Phases B to D of a level expanded by several workers (see the file comment).
bool Explorer::phases_b_to_d(std::size_t nchunks, const Layout& L) {
  // ---- phase B: look up / insert into the shards ----------------------------------------------------
  std::size_t candidates = 0;
  for (std::size_t ci = 0; ci < nchunks; ++ci) candidates += chunks_[ci].hashes.size();
  const unsigned bworkers = candidates > 4096 ? std::min<unsigned>(threads_, kShards) : 1u;
  // Worker w owns the shards s with owner(s) == w: a range of shards each, found by a multiply and a
  // shift (a division per candidate would cost more than the rest of a probe).
  auto owner = [bworkers](std::size_t shard) {
    return static_cast<unsigned>((shard * bworkers) >> kShardBits);
  };
  with_words(L.words, [&](auto wc) {
    constexpr std::uint32_t W = decltype(wc)::value;
    const std::uint32_t words = W != 0 ? W : L.words;
    const bool all_mine = bworkers == 1;
    pool_.run(bworkers, [&](unsigned wi) {
      // Worker wi reads every candidate's hash in order and takes those of its shards.
      constexpr std::size_t kAhead = 8;  // the table probes are cache misses: prefetch a few candidates ahead
      for (std::size_t ci = 0; ci < nchunks; ++ci) {
        Chunk& ch = chunks_[ci];
        const std::size_t count = ch.hashes.size();
        const std::uint64_t* hashes = ch.hashes.data();
        const std::uint64_t* markings = ch.markings.data();
        for (std::size_t i = 0; i < count; ++i) {
          if (i + kAhead < count) {
            const std::uint64_t ha = hashes[i + kAhead];
            const Shard& sa = shards_[ha >> (64 - kShardBits)];
            if (all_mine || owner(ha >> (64 - kShardBits)) == wi)
              __builtin_prefetch(sa.slots.data() + ((ha & 0x7FFFFFFFull) & (sa.slots.size() - 1)));
          }
          const std::uint64_t h = hashes[i];
          const std::size_t si = h >> (64 - kShardBits);
          if (!all_mine && owner(si) != wi) continue;
          Shard& sh = shards_[si];
          const std::uint64_t frag = h & 0x7FFFFFFFull;
          const std::uint64_t* mk = markings + i * words;
          const bool found = contains<W>(sh, frag, mk, words);
          if (found) continue;
          // Room for its pending entry and its slot first: a pending entry without a slot would never
          // be found by phase D.
          if (sh.pending.size() == sh.pending.capacity() &&
              !fit(sh.pending, std::max<std::size_t>(16, sh.pending.capacity() * 2)))
            continue;
          if (!ensure_slot(sh)) continue;
          ch.fresh[i] = 1;
          const std::uint64_t pidx = sh.pending.size();
          sh.pending.push_back((std::uint64_t{ci} << 32) | i);
          put_slot(sh, h, kPendingBit | frag << 32 | pidx);
        }
      }
    });
  });

  // ---- phase C: number the new markings in candidate order ----------------------------------------
  bool too_many = false;
  for (std::size_t ci = 0; ci < nchunks && !too_many; ++ci) {
    Chunk& ch = chunks_[ci];
    for (std::size_t i = 0; i < ch.fresh.size(); ++i) {
      if (!ch.fresh[i]) continue;
      if (states_ >= kMaxStates) {
        too_many = true;
        break;
      }
      if (!add_state(ch.markings.data() + i * L.words, ch.parents[i], ch.firings[i], ch.ids[i]))
        return false;  // (phase D would give the unnumbered ones made-up indices; the run stops here)
    }
  }
  if (too_many) vsd::detail::throw_error("explore: more than 2^32-2 states; not supported");

  // ---- phase D: pending entries become state indices ----------------------------------------------
  pool_.run(bworkers, [&](unsigned wi) {
    for (std::size_t si = 0; si < kShards; ++si) {
      if (owner(si) != wi) continue;
      Shard& sh = shards_[si];
      const std::size_t mask = sh.slots.size() - 1;
      for (std::size_t k = 0; k < sh.pending.size(); ++k) {
        const std::uint64_t ref = sh.pending[k];
        const Chunk& ch = chunks_[ref >> 32];
        const std::size_t i = ref & 0xFFFFFFFFull;
        const std::uint64_t h = ch.hashes[i];
        const std::uint64_t frag = h & 0x7FFFFFFFull;
        const std::uint64_t want = kPendingBit | frag << 32 | k;
        std::size_t pos = frag & mask;
        while (sh.slots[pos] != want) pos = (pos + 1) & mask;
        sh.slots[pos] = frag << 32 | ch.ids[i];
      }
      sh.pending.clear();
    }
  });
  return !full_.load();
}

}  // namespace

ExploreResult explore(const PtNet& net, const ExploreOptions& options) {
  return Explorer(net, options).run();
}

std::size_t default_memory_limit() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  std::size_t kib = 0;
  std::string unit;
  while (in >> key >> kib >> unit)
    if (key == "MemAvailable:") return std::max<std::size_t>(kib * 1024 / 4 * 3, std::size_t{64} << 20);
  return std::size_t{4} << 30;  // no /proc: a cautious guess
}

std::size_t parse_size(const std::string& text) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    vsd::detail::throw_error("size '" + text + "' is not a number with an optional unit (K, M, G, T)");
  }
  std::string unit = text.substr(used);
  for (auto& ch : unit) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  double scale = 1;
  if (unit.empty() || unit == "B")
    scale = 1;
  else if (unit == "K" || unit == "KB" || unit == "KIB")
    scale = 1024.0;
  else if (unit == "M" || unit == "MB" || unit == "MIB")
    scale = 1024.0 * 1024;
  else if (unit == "G" || unit == "GB" || unit == "GIB")
    scale = 1024.0 * 1024 * 1024;
  else if (unit == "T" || unit == "TB" || unit == "TIB")
    scale = 1024.0 * 1024 * 1024 * 1024;
  else
    vsd::detail::throw_error("size '" + text + "': unknown unit '" + unit + "' (use K, M, G or T)");
  if (!(v > 0) || !std::isfinite(v) || v * scale > 1.8e19)
    vsd::detail::throw_error("size '" + text + "' must be positive and finite");
  return static_cast<std::size_t>(v * scale);
}

std::string trace_to_string(const PtNet& net, const std::vector<std::uint32_t>& trace) {
  std::string s;
  for (std::uint32_t t : trace) {
    if (!s.empty()) s += ' ';
    s += net.transitions().at(t).id;
  }
  return s;
}

namespace {
void json_string(std::ostream& out, std::string_view s) {
  out << '"';
  for (char ch : s) {
    switch (ch) {
      case '"':
        out << "\\\"";
        break;
      case '\\':
        out << "\\\\";
        break;
      case '\n':
        out << "\\n";
        break;
      case '\t':
        out << "\\t";
        break;
      case '\r':
        out << "\\r";
        break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(ch)));
          out << buf;
        } else {
          out << ch;
        }
    }
  }
  out << '"';
}
void json_trace(std::ostream& out, const PtNet& net, const std::vector<std::uint32_t>& trace) {
  out << '[';
  for (std::size_t i = 0; i < trace.size(); ++i) {
    if (i) out << ", ";
    json_string(out, net.transitions().at(trace[i]).id);
  }
  out << ']';
}
void json_marking(std::ostream& out, const PtNet& net, const std::vector<std::uint32_t>& m) {
  // Sparse: only marked places, by id.
  out << '{';
  bool first = true;
  for (std::size_t p = 0; p < m.size(); ++p) {
    if (m[p] == 0) continue;
    if (!first) out << ", ";
    first = false;
    json_string(out, net.places()[p].id);
    out << ": " << m[p];
  }
  out << '}';
}
const char* status_name(ExploreResult::Status s) {
  switch (s) {
    case ExploreResult::Status::complete:
      return "complete";
    case ExploreResult::Status::unbounded:
      return "unbounded";
    case ExploreResult::Status::memory_limit:
      return "memory_limit";
  }
  return "?";
}
}  // namespace

void write_json(std::ostream& out, const PtNet& net, const ExploreResult& r) {
  out << "{\"net\": ";
  json_string(out, net.id());
  out << ", \"status\": \"" << status_name(r.status) << "\", \"states\": " << r.states
      << ", \"edges\": " << r.edges << ", \"deadlock\": " << (r.deadlock ? "true" : "false")
      << ", \"max_tokens_place\": " << r.max_tokens_place
      << ", \"max_tokens_marking\": " << r.max_tokens_marking << ", \"bounded\": ";
  if (r.status == ExploreResult::Status::complete)
    out << "true";
  else if (r.status == ExploreResult::Status::unbounded)
    out << "false";
  else
    out << "null";
  if (r.deadlock) {
    out << ", \"dead_trace\": ";
    json_trace(out, net, r.dead_trace);
    out << ", \"dead_marking\": ";
    json_marking(out, net, r.dead_marking);
  }
  if (r.status == ExploreResult::Status::unbounded) {
    out << ", \"unbounded_prefix\": ";
    json_trace(out, net, r.unbounded_prefix);
    out << ", \"unbounded_cycle\": ";
    json_trace(out, net, r.unbounded_cycle);
  }
  if (!r.message.empty()) {
    out << ", \"message\": ";
    json_string(out, r.message);
  }
  char secs[32];
  std::snprintf(secs, sizeof secs, "%.6f", r.seconds);
  out << ", \"levels\": " << r.levels << ", \"bits_per_place\": " << r.bits_per_place
      << ", \"threads\": " << r.threads << ", \"seconds\": " << secs << ", \"peak_memory\": " << r.peak_memory
      << "}\n";
}

void write_summary(std::ostream& out, const PtNet& net, const ExploreResult& r) {
  out << "net " << net.id() << ": " << net.place_count() << " places, " << net.transition_count()
      << " transitions, " << net.arc_count() << " arcs\n";
  switch (r.status) {
    case ExploreResult::Status::complete:
      out << "state space complete\n";
      break;
    case ExploreResult::Status::unbounded:
      out << "UNBOUNDED (exploration stopped)\n";
      break;
    case ExploreResult::Status::memory_limit:
      out << "INCOMPLETE: memory limit reached\n";
      break;
  }
  const char* prefix = r.complete() ? "" : "at least ";
  out << "  states (reachable markings): " << prefix << r.states << "\n"
      << "  edges (firings):             " << prefix << r.edges << "\n"
      << "  max tokens in one place:     " << prefix << r.max_tokens_place << "\n"
      << "  max tokens in one marking:   " << prefix << r.max_tokens_marking << "\n"
      << "  deadlock:                    " << (r.deadlock ? "yes" : (r.complete() ? "no" : "none found"))
      << "\n";
  if (r.deadlock)
    out << "  shortest firing sequence to a dead marking (" << r.dead_trace.size() << " firings): "
        << (r.dead_trace.empty() ? "(the initial marking is dead)" : trace_to_string(net, r.dead_trace))
        << "\n";
  if (!r.message.empty()) out << "  " << r.message << "\n";
  char buf[160];
  std::snprintf(buf, sizeof buf, "  %u levels, %u bits per place, %u thread(s), %.3f s, peak %.1f MiB\n",
                r.levels, r.bits_per_place, r.threads, r.seconds,
                static_cast<double>(r.peak_memory) / (1 << 20));
  out << buf;
}

}  // namespace vsd::analysis
