#include "vsd/analysis/token_game.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <optional>

#include "compiled_net.hpp"
#include "place_bounds.hpp"
#include "vsd/core/error.hpp"
#include "vsd/analysis/explorer.hpp"  // default_memory_limit

namespace vsd::analysis {

// Two representations of the marking; the constructor picks one and the game never mixes them. Both keep,
// per transition, the number of its arcs that the marking does not satisfy (input arcs short of tokens,
// inhibitor arcs with too many): a transition is enabled when that count is 0, and a firing changes the
// counts only of transitions reading a place it changes.
//
// Safe nets (the P-semiflow bounds prove that every place holds at most one token in every reachable
// marking): the counts are bit-sliced: slice s of word w holds bit s of the counts of transitions
// 64w..64w+63, so one word operation updates 64 counts. In a reachable marking where t is enabled, the
// places t empties hold one token and those it fills none (or the bound would be wrong), so the change of
// every count that firing t makes is known in advance: per word of transitions that t touches, the
// changes as S-bit two's-complement slices D, added to the count slices with a ripple-carry adder (mod 2^S,
// exact since no count exceeds its transition's arc count < 2^S). The enabled bits of that word are then
// the lanes whose count slices are all zero. On Dekker-PT-010, whose flags are read by ~20 transitions
// each, a firing costs two such word updates instead of ~60 arc-count adjustments or ~15 enabling tests.
// Transitions that can never fire in a safe net (an input arc of weight 2 or more) are masked out, as are
// the unused lanes of the last word; inhibitor arcs of weight 2 or more are always satisfied there.
//
// Other nets (unbounded, or bounds above one): the counts are plain integers, adjusted arc by arc for the
// arcs on the places a firing changes.
//
// Both keep the enabled set as the bitset E with a count per word of E and per block of kBlockWords words,
// so play() finds the index-th enabled transition by walking counts (no popcount: the default x86-64
// target has no popcnt instruction) and then selecting in one word (select_bit).
struct TokenGame::Net {
  struct Test {
    std::uint32_t transition;
    std::uint32_t weight;
    bool inhibitor;
  };
  struct WordFlip {  // m[word] ^= bits
    std::uint32_t word;
    std::uint64_t bits;
  };

  detail::Compiled c;
  std::vector<std::uint32_t> initial;
  std::vector<std::string> transition_ids;
  bool safe = false;

  // General nets.
  std::vector<std::uint32_t> tests_begin;  // per place, into tests
  std::vector<Test> tests;

  // Safe nets. *_begin: per transition, size transitions + 1.
  std::uint32_t words = 0;   // of a marking
  std::uint32_t twords = 0;  // of a transition bitset
  std::uint32_t slices = 0;  // S: bits of a count
  std::vector<std::uint32_t> flip_begin, update_begin;
  std::vector<WordFlip> flips;
  std::vector<std::uint32_t> update_word;  // per update: the word of transitions it changes
  std::vector<std::uint64_t> update_d;     // per update: S slices of the count changes
  std::vector<std::uint64_t> never;        // per word of transitions: lanes never enabled
  std::vector<std::uint64_t> initial_bits;
  // Per word of transitions, S slices: the counts in the initial marking.
  std::vector<std::uint64_t> initial_counts;

  explicit Net(const PtNet& net) : c(net), initial(net.initial_marking()) {
    for (const auto& t : net.transitions()) transition_ids.push_back(t.id);
    std::optional<std::vector<std::uint64_t>> bounds;
    if (c.places > 0) bounds = detail::place_bounds(net, default_memory_limit() / 4);
    safe = bounds && std::all_of(bounds->begin(), bounds->end(), [](std::uint64_t b) { return b <= 1; });
    if (safe)
      compile_safe(net);
    else
      compile_general(net);
  }

  void compile_general(const PtNet& net) {
    std::vector<std::vector<Test>> by_place(net.place_count());
    for (std::uint32_t t = 0; t < net.transition_count(); ++t) {
      for (const auto& a : net.transitions()[t].inputs) by_place[a.place].push_back({t, a.weight, false});
      for (const auto& a : net.transitions()[t].inhibitors) by_place[a.place].push_back({t, a.weight, true});
    }
    for (const auto& v : by_place) {
      tests_begin.push_back(static_cast<std::uint32_t>(tests.size()));
      tests.insert(tests.end(), v.begin(), v.end());
    }
    tests_begin.push_back(static_cast<std::uint32_t>(tests.size()));
  }

  void compile_safe(const PtNet& net) {
    words = (c.places + 63) / 64;
    twords = (c.transitions + 63) / 64;
    auto bit = [](std::uint32_t i) { return std::uint64_t{1} << (i & 63); };
    std::vector<std::vector<std::uint32_t>> inputs_of(c.places), inhibitors_of(c.places);
    never.assign(twords, 0);
    std::uint32_t max_arcs = 0;
    for (std::uint32_t u = 0; u < c.transitions; ++u) {
      const Transition& tr = net.transitions()[u];
      std::uint32_t arcs = 0;
      for (const auto& a : tr.inputs) {
        inputs_of[a.place].push_back(u);
        ++arcs;
        if (a.weight > 1) never[u >> 6] |= bit(u);  // a place of a safe net never holds two tokens
      }
      for (const auto& a : tr.inhibitors)
        if (a.weight == 1) {  // (weight >= 2: always satisfied)
          inhibitors_of[a.place].push_back(u);
          ++arcs;
        }
      max_arcs = std::max(max_arcs, arcs);
    }
    if (c.transitions % 64 != 0) never.back() |= ~std::uint64_t{0} << (c.transitions % 64);
    slices = 1;
    while (slices < 32 && (max_arcs >> slices) != 0) ++slices;
    initial_bits.assign(words, 0);
    for (std::uint32_t p = 0; p < c.places; ++p)
      if (initial[p] != 0) initial_bits[p >> 6] |= bit(p);
    initial_counts.assign(std::size_t{twords} * slices, 0);
    for (std::uint32_t u = 0; u < c.transitions; ++u) {
      std::uint32_t k = 0;
      for (const auto& a : net.transitions()[u].inputs) k += initial[a.place] == 0 ? 1 : 0;
      for (const auto& a : net.transitions()[u].inhibitors)
        k += a.weight == 1 && initial[a.place] != 0 ? 1 : 0;
      for (std::uint32_t j = 0; j < slices; ++j)
        if ((k >> j) & 1) initial_counts[std::size_t{u >> 6} * slices + j] |= bit(u);
    }

    std::vector<std::int32_t> change(c.transitions, 0);
    std::vector<std::uint32_t> touched;
    std::vector<std::uint64_t> fl(words);
    for (std::uint32_t t = 0; t < c.transitions; ++t) {
      std::fill(fl.begin(), fl.end(), 0);
      touched.clear();
      for (std::uint32_t i = c.delta_begin[t]; i < c.delta_begin[t + 1]; ++i) {
        const auto& d = c.delta[i];
        fl[d.place >> 6] |= bit(d.place);
        // d.delta is +1 or -1 for a transition that can fire at all. A place that gains its token satisfies
        // its input arcs and breaks its inhibitor arcs; one that loses it the reverse.
        const std::int32_t sign = d.delta > 0 ? -1 : 1;
        for (const std::uint32_t u : inputs_of[d.place]) {
          change[u] += sign;
          touched.push_back(u >> 6);
        }
        for (const std::uint32_t u : inhibitors_of[d.place]) {
          change[u] -= sign;
          touched.push_back(u >> 6);
        }
      }
      flip_begin.push_back(static_cast<std::uint32_t>(flips.size()));
      for (std::uint32_t w = 0; w < words; ++w)
        if (fl[w]) flips.push_back({w, fl[w]});
      std::sort(touched.begin(), touched.end());
      touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
      update_begin.push_back(static_cast<std::uint32_t>(update_word.size()));
      for (const std::uint32_t w : touched) {
        std::vector<std::uint64_t> d(slices, 0);
        bool any = false;
        for (std::uint32_t u = w * 64; u < std::min(c.transitions, w * 64 + 64); ++u) {
          // Two's complement in S bits: adding it mod 2^S adds change[u].
          const auto v = static_cast<std::uint32_t>(change[u]);
          for (std::uint32_t k = 0; k < slices; ++k)
            if ((v >> k) & 1) d[k] |= bit(u);
          any |= change[u] != 0;
          change[u] = 0;
        }
        if (!any) continue;  // the changes of this word cancel out
        update_word.push_back(w);
        update_d.insert(update_d.end(), d.begin(), d.end());
      }
    }
    flip_begin.push_back(static_cast<std::uint32_t>(flips.size()));
    update_begin.push_back(static_cast<std::uint32_t>(update_word.size()));
  }
};

namespace {
constexpr std::uint32_t kBlockWords = 8;  // words of the enabled bitset per block count

// kSelectInByte[b][i]: the position of the i-th set bit of byte b (i below the byte's bit count).
constexpr auto kSelectInByte = [] {
  std::array<std::array<std::uint8_t, 8>, 256> table{};
  for (unsigned b = 0; b < 256; ++b) {
    unsigned i = 0;
    for (unsigned bit = 0; bit < 8; ++bit)
      if ((b >> bit) & 1) table[b][i++] = static_cast<std::uint8_t>(bit);
  }
  return table;
}();

// The position of the index-th set bit of w (index < the bit count of w), without branches and without
// a popcount instruction: byte counts by SWAR, their prefix sums by one multiplication, the byte by a
// bytewise comparison, the bit in the byte from a table. (A loop clearing `index` low bits mispredicts
// its exit on every pick.)
inline unsigned select_bit(std::uint64_t w, unsigned index) {
  constexpr std::uint64_t kOnes = 0x0101010101010101ull;
  std::uint64_t c = w - ((w >> 1) & 0x5555555555555555ull);
  c = (c & 0x3333333333333333ull) + ((c >> 2) & 0x3333333333333333ull);
  c = (c + (c >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  const std::uint64_t prefix = c * kOnes;  // byte k: set bits in bytes 0..k (at most 64: no carries)
  // High bit of byte k set where prefix_k <= index: bytes wholly before the wanted bit.
  const std::uint64_t before = ((index * kOnes | 0x8080808080808080ull) - prefix) & 0x8080808080808080ull;
  const auto byte = static_cast<unsigned>(((before >> 7) * kOnes) >> 56);
  const unsigned skipped = static_cast<unsigned>((prefix << 8) >> (8 * byte)) & 0xFF;  // bits in bytes < byte
  return 8 * byte + kSelectInByte[(w >> (8 * byte)) & 0xFF][index - skipped];
}
}  // namespace

TokenGame::TokenGame(const PtNet& net) : net_(std::make_unique<Net>(net)) { reset(); }
TokenGame::~TokenGame() = default;
TokenGame::TokenGame(TokenGame&&) noexcept = default;
TokenGame& TokenGame::operator=(TokenGame&&) noexcept = default;

void TokenGame::reset() {
  const Net& n = *net_;
  const std::uint32_t twords = (n.c.transitions + 63) / 64;
  enabled_bits_.assign(twords, 0);
  word_count_.assign(twords, 0);
  block_count_.assign((twords + kBlockWords - 1) / kBlockWords, 0);
  count_ = 0;
  if (n.safe) {
    bits_ = n.initial_bits;
    counts_ = n.initial_counts;
    for (std::uint32_t w = 0; w < n.twords; ++w) {
      std::uint64_t any = 0;
      for (std::uint32_t j = 0; j < n.slices; ++j) any |= counts_[std::size_t{w} * n.slices + j];
      for (std::uint64_t e = ~any & ~n.never[w]; e != 0; e &= e - 1)
        add(w * 64 + static_cast<std::uint32_t>(std::countr_zero(e)));
    }
    return;
  }
  marking_ = n.initial;
  unsatisfied_.assign(n.c.transitions, 0);
  for (std::uint32_t p = 0; p < marking_.size(); ++p)
    for (std::uint32_t i = n.tests_begin[p]; i < n.tests_begin[p + 1]; ++i) {
      const auto& test = n.tests[i];
      if ((marking_[p] >= test.weight) == test.inhibitor) ++unsatisfied_[test.transition];
    }
  for (std::uint32_t t = 0; t < n.c.transitions; ++t)
    if (unsatisfied_[t] == 0) add(t);
}

std::vector<std::uint32_t> TokenGame::marking() const {
  if (!net_->safe) return marking_;
  std::vector<std::uint32_t> m(net_->c.places);
  for (std::uint32_t p = 0; p < m.size(); ++p)
    m[p] = static_cast<std::uint32_t>((bits_[p >> 6] >> (p & 63)) & 1);
  return m;
}

std::vector<std::uint32_t> TokenGame::enabled() const {
  std::vector<std::uint32_t> e;
  e.reserve(count_);
  for (std::uint32_t w = 0; w < enabled_bits_.size(); ++w)
    for (std::uint64_t b = enabled_bits_[w]; b != 0; b &= b - 1)
      e.push_back(w * 64 + static_cast<std::uint32_t>(std::countr_zero(b)));
  return e;
}

bool TokenGame::is_enabled(std::uint32_t t) const noexcept {
  return t < net_->c.transitions && ((enabled_bits_[t >> 6] >> (t & 63)) & 1) != 0;
}

bool TokenGame::safe() const noexcept { return net_->safe; }

void TokenGame::add(std::uint32_t t) {
  enabled_bits_[t >> 6] |= std::uint64_t{1} << (t & 63);
  ++word_count_[t >> 6];
  ++block_count_[(t >> 6) / kBlockWords];
  ++count_;
}

void TokenGame::remove(std::uint32_t t) {
  enabled_bits_[t >> 6] &= ~(std::uint64_t{1} << (t & 63));
  --word_count_[t >> 6];
  --block_count_[(t >> 6) / kBlockWords];
  --count_;
}

std::uint32_t TokenGame::nth_enabled(std::uint32_t index) const noexcept {
  std::uint32_t b = 0;
  while (index >= block_count_[b]) index -= block_count_[b++];
  std::uint32_t w = b * kBlockWords;
  while (index >= word_count_[w]) index -= word_count_[w++];
  return w * 64 + select_bit(enabled_bits_[w], index);
}

template <std::uint32_t S>
void TokenGame::fire_safe(std::uint32_t t) {
  const Net& n = *net_;
  const std::uint32_t slices = S > 0 ? S : n.slices;
  std::uint64_t* m = bits_.data();
  for (std::uint32_t i = n.flip_begin[t]; i < n.flip_begin[t + 1]; ++i) m[n.flips[i].word] ^= n.flips[i].bits;
  std::int32_t total = 0;
  for (std::uint32_t i = n.update_begin[t]; i < n.update_begin[t + 1]; ++i) {
    const std::uint32_t w = n.update_word[i];
    const std::uint64_t* d = n.update_d.data() + std::size_t{i} * slices;
    std::uint64_t* k = counts_.data() + std::size_t{w} * slices;
    // k += d, 64 lanes of S-bit counts at once.
    std::uint64_t carry = 0, any = 0;
    for (std::uint32_t j = 0; j < slices; ++j) {
      const std::uint64_t a = k[j], b = d[j], x = a ^ b;
      const std::uint64_t sum = x ^ carry;
      carry = (a & b) | (carry & x);
      k[j] = sum;
      any |= sum;
    }
    const std::uint64_t before = enabled_bits_[w];
    const std::uint64_t after = ~any & ~n.never[w];
    enabled_bits_[w] = after;
    // Count change without popcount (few bits change per firing).
    std::int32_t delta = 0;
    for (std::uint64_t g = after & ~before; g != 0; g &= g - 1) ++delta;
    for (std::uint64_t l = before & ~after; l != 0; l &= l - 1) --delta;
    word_count_[w] = static_cast<std::uint8_t>(word_count_[w] + delta);
    block_count_[w / kBlockWords] += static_cast<std::uint32_t>(delta);
    total += delta;
  }
  count_ += static_cast<std::uint32_t>(total);
}

void TokenGame::fire_general(std::uint32_t t) {
  const Net& n = *net_;
  const detail::Compiled& c = n.c;
  for (std::uint32_t i = c.delta_begin[t]; i < c.delta_begin[t + 1]; ++i) {
    const auto& d = c.delta[i];
    const std::uint32_t before = marking_[d.place];
    const std::int64_t v = static_cast<std::int64_t>(before) + d.delta;
    if (v > static_cast<std::int64_t>(UINT32_MAX))
      vsd::detail::throw_error("TokenGame::fire: a place would exceed 2^32-1 tokens firing '" +
                               n.transition_ids[t] + "'");
    const auto after = static_cast<std::uint32_t>(v);
    marking_[d.place] = after;
    for (std::uint32_t k = n.tests_begin[d.place]; k < n.tests_begin[d.place + 1]; ++k) {
      const auto& test = n.tests[k];
      // An input arc is satisfied at >= weight, an inhibitor arc below it.
      const bool was = (before >= test.weight) != test.inhibitor;
      const bool is = (after >= test.weight) != test.inhibitor;
      if (was == is) continue;
      std::uint32_t& u = unsatisfied_[test.transition];
      if (is) {
        if (--u == 0) add(test.transition);
      } else {
        if (u++ == 0) remove(test.transition);
      }
    }
  }
}

void TokenGame::fire(std::uint32_t t) {
  if (!is_enabled(t))
    vsd::detail::throw_error("TokenGame::fire: transition " +
                             (t < net_->transition_ids.size() ? "'" + net_->transition_ids[t] + "'"
                                                              : "index " + std::to_string(t)) +
                             " is not enabled");
  if (!net_->safe) return fire_general(t);
  switch (net_->slices) {
    case 1:
      return fire_safe<1>(t);
    case 2:
      return fire_safe<2>(t);
    case 3:
      return fire_safe<3>(t);
    case 4:
      return fire_safe<4>(t);
    default:
      return fire_safe<0>(t);
  }
}

template <std::uint32_t W>
std::uint64_t TokenGame::play_loop(std::uint64_t steps, std::uint64_t seed) {
  std::uint64_t x = seed * 0x9E3779B97F4A7C15ull + 1;  // xorshift64*: cheap and good enough to pick
  std::uint64_t done = 0;
  while (done < steps) {
    if (count_ == 0) {
      reset();
      if (count_ == 0) return done;  // the initial marking is dead
    }
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    const std::uint64_t r = x * 0x2545F4914F6CDD1Dull;
    // Multiply-shift maps the high 32 bits of r onto [0, count_) without a division.
    const auto t = nth_enabled(static_cast<std::uint32_t>(((r >> 32) * count_) >> 32));
    if constexpr (W == kGeneral)
      fire_general(t);
    else
      fire_safe<W>(t);
    ++done;
  }
  return done;
}

std::uint64_t TokenGame::play(std::uint64_t steps, std::uint64_t seed) {
  if (!net_->safe) return play_loop<kGeneral>(steps, seed);
  switch (net_->slices) {
    case 1:
      return play_loop<1>(steps, seed);
    case 2:
      return play_loop<2>(steps, seed);
    case 3:
      return play_loop<3>(steps, seed);
    case 4:
      return play_loop<4>(steps, seed);
    default:
      return play_loop<0>(steps, seed);
  }
}

}  // namespace vsd::analysis
