// Data-parallel steps on the thread team of worker_pool.hpp, for the work that is one pass over flat arrays:
// building the mesh and reading files. Every step gives the same result whatever the thread count, so a
// mesh built on 16 threads is bit for bit the mesh built on one.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <span>
#include <stop_token>
#include <vector>

#include "stop.hpp"
#include "surface_mesh.hpp"
#include "worker_pool.hpp"

namespace exactgeo::detail {

// A team for data-parallel passes: the pool, and the stop request each chunk checks before it starts (a
// chunk is a few milliseconds of work at most, so a stop takes effect within that).
struct ParallelTeam {
  WorkerPool& pool;
  std::stop_token stop = {};
  // Items per range, when set, instead of each pass's own grain: the tests set 1 so that small inputs are
  // cut into ranges as large ones are.
  std::size_t grain_override = 0;

  unsigned threads() const { return pool.threads(); }

  // Calls body(begin, end) on disjoint ranges covering [0, count), spread over the threads. Ranges hold at
  // least `grain` items (a few microseconds of work), and there are a few per thread so that loads even
  // out. Bodies must write only to what their range owns.
  template <class Body>
  void for_ranges(std::size_t count, std::size_t grain, Body&& body) const {
    const std::size_t ranges = range_count(count, grain);
    if (ranges <= 1) {
      throw_if_stopped(stop);
      if (count > 0) body(std::size_t{0}, count);
      return;
    }
    pool.run(ranges, [&](std::size_t range, unsigned) {
      throw_if_stopped(stop);
      body(count * range / ranges, count * (range + 1) / ranges);
    });
  }

  // Calls body(item) for each item in [0, count), items grouped in ranges as in for_ranges.
  template <class Body>
  void for_each(std::size_t count, std::size_t grain, Body&& body) const {
    for_ranges(count, grain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) body(i);
    });
  }

  // Calls body(begin, end) on the ranges of for_ranges and folds what each returns into `value` in range
  // order. The ranges depend on the thread count: fold only where the order does not change the result
  // (counts, minima, maxima), so that it stays the same on any thread count.
  template <class T, class Body, class Fold>
  T reduce_ranges(std::size_t count, std::size_t grain, T value, Body&& body, Fold&& fold) const {
    const std::size_t ranges = range_count(count, grain);
    std::vector<T> partial(ranges, value);
    if (ranges == 1) {
      throw_if_stopped(stop);
      partial[0] = body(std::size_t{0}, count);
    } else if (ranges > 1) {
      pool.run(ranges, [&](std::size_t range, unsigned) {
        throw_if_stopped(stop);
        partial[range] = body(count * range / ranges, count * (range + 1) / ranges);
      });
    }
    for (const T& p : partial) value = fold(value, p);
    return value;
  }

  // How many items in [0, count) satisfy pred(item).
  template <class Pred>
  std::size_t count_if(std::size_t count, std::size_t grain, Pred&& pred) const {
    return reduce_ranges(
        count, grain, std::size_t{0},
        [&](std::size_t begin, std::size_t end) {
          std::size_t n = 0;
          for (std::size_t i = begin; i < end; ++i) n += pred(i) ? 1 : 0;
          return n;
        },
        [](std::size_t a, std::size_t b) { return a + b; });
  }

  // How many ranges for_ranges cuts `count` items into: one below two grains, else up to eight per thread.
  std::size_t range_count(std::size_t count, std::size_t grain) const {
    if (threads() == 1) return count > 0 ? 1 : 0;
    if (grain_override != 0) grain = grain_override;
    return std::clamp<std::size_t>(count / std::max<std::size_t>(grain, 1), 1, 8 * std::size_t{threads()});
  }
};

// Faults in the untouched range [p, p + bytes) for writing, parts of it on each of the team's threads, before
// one thread zeroes or copies into it (a std::vector does so on one thread). Where the system backs memory
// lazily, the first touch is most of that work: on the virtual machine we measure on, 0.5-0.8 GB/s for memory
// the process has not touched before against 7 GB/s after.
inline void populate_on_team(const ParallelTeam& team, void* p, std::size_t bytes) {
  constexpr std::size_t kPart = std::size_t{2} << 20;
  if (team.threads() == 1 || bytes < 2 * kPart) return;
  team.for_ranges((bytes + kPart - 1) / kPart, 1, [&](std::size_t first, std::size_t last) {
    populate_for_writing(static_cast<char*>(p) + first * kPart, std::min(bytes, last * kPart) - first * kPart);
  });
}

// Reserves room for `count` elements in an empty `values`, in huge pages faulted in on the team.
template <class T>
void reserve_on_team(const ParallelTeam& team, std::vector<T>& values, std::size_t count) {
  values.reserve(count);
  advise_huge_pages(values.data(), count * sizeof(T));
  populate_on_team(team, values.data(), count * sizeof(T));
}

// `values`, empty, sized to `count` value-initialised elements in huge pages faulted in on the team.
template <class T>
void resize_on_team(const ParallelTeam& team, std::vector<T>& values, std::size_t count) {
  reserve_on_team(team, values, count);
  values.resize(count);
}

// A copy of `values` in huge pages faulted in on the team.
template <class T>
std::vector<T> copy_on_team(const ParallelTeam& team, std::span<const T> values) {
  std::vector<T> copy;
  reserve_on_team(team, copy, values.size());
  copy.assign(values.begin(), values.end());
  return copy;
}

// Turns counts into offsets in place: values[i] becomes the sum of the values before it; returns the total.
// Summed by ranges on the team, then the ranges' totals once in order.
template <class Array>
std::uint64_t exclusive_prefix_sum(const ParallelTeam& team, Array& values) {
  constexpr std::size_t kGrain = 1 << 16;
  const std::size_t ranges = std::max<std::size_t>(team.range_count(values.size(), kGrain), 1);
  std::vector<std::uint64_t> range_total(ranges + 1, 0);
  const auto range_of = [&](std::size_t r) { return std::pair{values.size() * r / ranges, values.size() * (r + 1) / ranges}; };
  team.pool.run(ranges, [&](std::size_t r, unsigned) {
    const auto [begin, end] = range_of(r);
    range_total[r + 1] = std::accumulate(values.begin() + begin, values.begin() + end, std::uint64_t{0});
  });
  std::partial_sum(range_total.begin(), range_total.end(), range_total.begin());
  team.pool.run(ranges, [&](std::size_t r, unsigned) {
    const auto [begin, end] = range_of(r);
    std::uint64_t running = range_total[r];
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t value = values[i];
      values[i] = static_cast<std::uint32_t>(running);
      running += value;
    }
  });
  return range_total.back();
}

// The number of bits that index about `count` groups, one item each on average (at most 2^30 groups): the
// groups of a hash or of a sort key's high bits.
inline int group_bits(std::size_t count) {
  int bits = 0;
  while (bits < 30 && (std::size_t{1} << bits) < count) ++bits;
  return bits;
}

// Groups this small are searched pairwise; larger ones are sorted first, so that no input is quadratic.
inline constexpr std::size_t kPairwiseGroupSize = 16;

// Items grouped by key, in compressed form: group k holds items[offsets[k] .. offsets[k + 1]), in increasing
// item order (a stable counting sort).
struct Groups {
  MeshArray<std::uint32_t> offsets;  // group_count + 1
  MeshArray<std::uint32_t> items;

  std::size_t size(std::size_t group) const { return offsets[group + 1] - offsets[group]; }
  const std::uint32_t* begin(std::size_t group) const { return items.data() + offsets[group]; }
  const std::uint32_t* end(std::size_t group) const { return items.data() + offsets[group + 1]; }
};

// Groups the items [0, keys.size()) by their keys, each in [0, group_count). Two stable passes: first by the
// key's high bits into at most kCoarseGroups ranges of keys (each range of items counted into its own row of
// counters, so no counter is shared), then each range on its own by the whole key. Linear in count +
// group_count however the keys are distributed, and the same result on any thread count.
inline Groups group_by_keys(const ParallelTeam& team, std::span<const std::uint32_t> keys, std::size_t group_count) {
  constexpr std::size_t kGrain = 1 << 14;
  constexpr std::size_t kCoarseGroups = 1 << 12;
  const std::size_t count = keys.size();
  Groups groups;
  groups.offsets.resize(group_count + 1);
  groups.items.resize(count);
  if (count == 0) {
    std::fill(groups.offsets.begin(), groups.offsets.end(), 0u);
    return groups;
  }
  int shift = 0;
  while (((group_count - 1) >> shift) >= kCoarseGroups) ++shift;
  const std::size_t coarse_count = ((group_count - 1) >> shift) + 1;

  // Pass 1: by the key's high bits, one row of counters per range of items.
  const std::size_t ranges = std::max<std::size_t>(team.range_count(count, kGrain), 1);
  std::vector<std::uint32_t> counters(ranges * coarse_count, 0);
  const auto range_of = [&](std::size_t r) { return std::pair{count * r / ranges, count * (r + 1) / ranges}; };
  team.pool.run(ranges, [&](std::size_t r, unsigned) {
    throw_if_stopped(team.stop);
    const auto [begin, end] = range_of(r);
    std::uint32_t* row = counters.data() + r * coarse_count;
    for (std::size_t i = begin; i < end; ++i) ++row[keys[i] >> shift];
  });
  std::vector<std::uint32_t> coarse_offsets(coarse_count + 1, 0);
  std::uint32_t running = 0;
  for (std::size_t g = 0; g < coarse_count; ++g) {
    coarse_offsets[g] = running;
    for (std::size_t r = 0; r < ranges; ++r) {
      const std::uint32_t n = counters[r * coarse_count + g];
      counters[r * coarse_count + g] = running;
      running += n;
    }
  }
  coarse_offsets[coarse_count] = running;
  MeshArray<std::uint32_t> by_coarse(count);
  team.pool.run(ranges, [&](std::size_t r, unsigned) {
    const auto [begin, end] = range_of(r);
    std::uint32_t* row = counters.data() + r * coarse_count;
    for (std::size_t i = begin; i < end; ++i) by_coarse[row[keys[i] >> shift]++] = static_cast<std::uint32_t>(i);
  });

  // Pass 2: each coarse group by the whole key, on its own (the groups' counters are disjoint slices).
  team.for_ranges(coarse_count, 1, [&](std::size_t first, std::size_t last) {
    for (std::size_t g = first; g < last; ++g) {
      const std::size_t low = g << shift, high = std::min(group_count, (g + 1) << shift);
      std::uint32_t* offsets = groups.offsets.data() + low;
      std::fill(offsets, offsets + (high - low), 0u);
      for (std::uint32_t j = coarse_offsets[g]; j < coarse_offsets[g + 1]; ++j) ++offsets[keys[by_coarse[j]] - low];
      std::uint32_t at = coarse_offsets[g];
      for (std::size_t k = 0; k < high - low; ++k) {
        const std::uint32_t n = offsets[k];
        offsets[k] = at;
        at += n;
      }
      // offsets[k] now runs as each group's fill cursor; it ends at the next group's start and is rebuilt below.
      for (std::uint32_t j = coarse_offsets[g]; j < coarse_offsets[g + 1]; ++j) {
        const std::uint32_t item = by_coarse[j];
        groups.items[offsets[keys[item] - low]++] = item;
      }
      for (std::size_t k = high - low; k-- > 1;) offsets[k] = offsets[k - 1];
      if (high > low) offsets[0] = coarse_offsets[g];
    }
  });
  groups.offsets[group_count] = static_cast<std::uint32_t>(count);
  return groups;
}

// Groups the items [0, count) by key_of(item) in [0, group_count), as group_by_keys does (the keys computed
// once, on the team).
template <class KeyOf>
Groups group_by_key(const ParallelTeam& team, std::size_t count, std::size_t group_count, KeyOf&& key_of) {
  constexpr std::size_t kGrain = 1 << 14;
  MeshArray<std::uint32_t> keys(count);
  team.for_ranges(count, kGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) keys[i] = static_cast<std::uint32_t>(key_of(i));
  });
  return group_by_keys(team, keys, group_count);
}

// Union-find whose unions may run on several threads at once: a root is linked below a smaller root with a
// compare-and-swap, so each set ends with its smallest element as root whatever the order of the unions.
class ConcurrentUnionFind {
 public:
  // `count` singletons, set up on the team (one thread writing every parent first would fault the array in alone).
  ConcurrentUnionFind(const ParallelTeam& team, std::size_t count) : parent_(count) {
    team.for_ranges(count, 1 << 16, [&](std::size_t begin, std::size_t end) {
      std::iota(parent_.begin() + static_cast<std::ptrdiff_t>(begin),
                parent_.begin() + static_cast<std::ptrdiff_t>(end), static_cast<std::uint32_t>(begin));
    });
  }

  std::uint32_t find(std::uint32_t x) {
    for (;;) {
      std::uint32_t p = load(x);
      if (p == x) return x;
      const std::uint32_t grandparent = load(p);
      // Path halving: x skips a level. Links only ever point to smaller roots, so a grandparent stays an
      // ancestor, and a failed swap just means another thread moved x up already.
      if (p != grandparent)
        std::atomic_ref(parent_[x]).compare_exchange_weak(p, grandparent, std::memory_order_relaxed);
      x = grandparent;
    }
  }

  void unite(std::uint32_t a, std::uint32_t b) {
    for (;;) {
      a = find(a);
      b = find(b);
      if (a == b) return;
      if (a < b) std::swap(a, b);
      std::uint32_t expected = a;  // a is still a root: link it under the smaller root b
      if (std::atomic_ref(parent_[a]).compare_exchange_strong(expected, b, std::memory_order_relaxed)) return;
    }
  }

  // Whether x is the root of its set; only meaningful once every union is done.
  bool is_root(std::uint32_t x) const { return parent_[x] == x; }

 private:
  std::uint32_t load(std::uint32_t x) { return std::atomic_ref(parent_[x]).load(std::memory_order_relaxed); }
  MeshArray<std::uint32_t> parent_;
};

}  // namespace exactgeo::detail
