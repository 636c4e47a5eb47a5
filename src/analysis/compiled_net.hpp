// The net as flat arrays for the inner loops of the explorer and the token game (internal).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "vsd/analysis/pt_net.hpp"

namespace vsd::analysis::detail {

struct Compiled {
  std::uint32_t places = 0;
  std::uint32_t transitions = 0;
  struct PW {
    std::uint32_t place;
    std::uint32_t weight;
  };
  struct PD {
    std::uint32_t place;
    std::int64_t delta;
  };
  std::vector<std::uint32_t> in_begin, inh_begin, delta_begin, aff_begin;  // size transitions + 1
  std::vector<PW> in, inh;
  std::vector<PD> delta;
  std::vector<std::uint32_t> aff;  // transitions to test again after firing t (unless aff_all)
  // aff would have passed the cap given to the constructor (it grows with the square of the transitions
  // that share a place): it is empty, and every transition is tested again after a firing.
  bool aff_all = false;
  std::vector<std::uint8_t> inhibitor_place;
  bool conserving = true;  // no transition adds tokens in total: every marking has <= initial tokens
  std::uint64_t initial_sum = 0;
  std::uint32_t initial_max = 0;

  /// @param max_aff_entries the most entries aff may hold (see aff_all).
  explicit Compiled(const PtNet& net, std::size_t max_aff_entries = SIZE_MAX) {
    places = static_cast<std::uint32_t>(net.place_count());
    transitions = static_cast<std::uint32_t>(net.transition_count());
    inhibitor_place.assign(places, 0);
    std::vector<std::vector<std::uint32_t>> readers(places);  // place -> transitions testing it
    for (std::uint32_t t = 0; t < transitions; ++t) {
      const Transition& tr = net.transitions()[t];
      for (const auto& a : tr.inputs) readers[a.place].push_back(t);
      for (const auto& a : tr.inhibitors) {
        readers[a.place].push_back(t);
        inhibitor_place[a.place] = 1;
      }
    }
    for (auto& r : readers) r.erase(std::unique(r.begin(), r.end()), r.end());
    std::vector<std::int64_t> d(places, 0);
    std::vector<std::uint8_t> mark(transitions, 0);
    for (std::uint32_t t = 0; t < transitions; ++t) {
      const Transition& tr = net.transitions()[t];
      in_begin.push_back(static_cast<std::uint32_t>(in.size()));
      inh_begin.push_back(static_cast<std::uint32_t>(inh.size()));
      delta_begin.push_back(static_cast<std::uint32_t>(delta.size()));
      aff_begin.push_back(static_cast<std::uint32_t>(aff.size()));
      std::int64_t sum = 0;
      for (const auto& a : tr.inputs) {
        in.push_back({a.place, a.weight});
        d[a.place] -= a.weight;
        sum -= a.weight;
      }
      for (const auto& a : tr.inhibitors) inh.push_back({a.place, a.weight});
      for (const auto& a : tr.outputs) {
        d[a.place] += a.weight;
        sum += a.weight;
      }
      if (sum > 0) conserving = false;
      std::vector<std::uint32_t> touched;
      for (const auto& a : tr.inputs) touched.push_back(a.place);
      for (const auto& a : tr.outputs) touched.push_back(a.place);
      std::sort(touched.begin(), touched.end());
      touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
      const auto aff_start = aff.size();
      for (std::uint32_t p : touched) {
        if (d[p] != 0) {
          delta.push_back({p, d[p]});
          if (!aff_all)
            for (std::uint32_t u : readers[p])
              if (!mark[u]) {
                mark[u] = 1;
                aff.push_back(u);
              }
        }
        d[p] = 0;
      }
      for (std::size_t i = aff_start; i < aff.size(); ++i) mark[aff[i]] = 0;
      std::sort(aff.begin() + static_cast<std::ptrdiff_t>(aff_start), aff.end());
      if (aff.size() > max_aff_entries) {  // no more: the begins stay, aff_all says not to use them
        aff_all = true;
        aff.clear();
        aff.shrink_to_fit();
      }
    }
    in_begin.push_back(static_cast<std::uint32_t>(in.size()));
    inh_begin.push_back(static_cast<std::uint32_t>(inh.size()));
    delta_begin.push_back(static_cast<std::uint32_t>(delta.size()));
    aff_begin.push_back(static_cast<std::uint32_t>(aff.size()));
    for (const auto& p : net.places()) {
      initial_sum += p.initial;
      initial_max = std::max(initial_max, p.initial);
    }
  }

  /// Bytes held (what the explorer counts against its memory limit).
  std::size_t bytes() const {
    return (in_begin.capacity() + inh_begin.capacity() + delta_begin.capacity() + aff_begin.capacity() +
            aff.capacity()) * sizeof(std::uint32_t) +
           (in.capacity() + inh.capacity()) * sizeof(PW) + delta.capacity() * sizeof(PD) +
           inhibitor_place.capacity();
  }

  bool enabled(std::uint32_t t, const std::uint32_t* m) const {
    for (std::uint32_t i = in_begin[t]; i < in_begin[t + 1]; ++i)
      if (m[in[i].place] < in[i].weight) return false;
    for (std::uint32_t i = inh_begin[t]; i < inh_begin[t + 1]; ++i)
      if (m[inh[i].place] >= inh[i].weight) return false;
    return true;
  }
};

}  // namespace vsd::analysis::detail
