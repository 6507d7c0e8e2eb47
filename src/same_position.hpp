// Points at the same position, found on the thread team: for each point, the first point at its position.
// The mesh build uses it for duplicate vertices (welding, the report), the STL reader to share the corners of
// its triangles. Positions are compared by value, so -0 and +0 are one position.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "parallel.hpp"

namespace exactgeo::detail {

namespace same_position_detail {

using Point = std::array<double, 3>;

inline std::uint64_t position_hash(const Point& p) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (double c : p) {
    const double normalized = c + 0.0;  // maps -0.0 to +0.0
    std::uint64_t bits;
    static_assert(sizeof bits == sizeof normalized);
    __builtin_memcpy(&bits, &normalized, sizeof bits);
    h = (h ^ bits) * 0xbf58476d1ce4e5b9ull;
    h ^= h >> 31;
  }
  return h * 0x94d049bb133111ebull;
}

inline bool position_less(const Point& a, const Point& b) {
  return a[0] != b[0] ? a[0] < b[0] : (a[1] != b[1] ? a[1] < b[1] : a[2] < b[2]);
}

}  // namespace same_position_detail

// first[i]: the smallest j with position_of(j) == position_of(i) (j == i for the first point at a position).
// Points are grouped by a hash of their position; groups of a few are compared pairwise, larger ones (many
// points at one position) sorted, so that no input is quadratic.
template <class PositionOf>
MeshArray<std::uint32_t> first_at_same_position(const ParallelTeam& team, std::size_t count, PositionOf&& position_of) {
  using namespace same_position_detail;
  MeshArray<std::uint32_t> first(count);
  const int bits = group_bits(count);
  const Groups groups = group_by_key(team, count, std::size_t{1} << bits, [&](std::size_t i) {
    return bits == 0 ? 0 : position_hash(position_of(i)) >> (64 - bits);
  });
  team.for_ranges(groups.offsets.size() - 1, 1 << 13, [&](std::size_t begin_group, std::size_t end_group) {
    std::vector<std::uint32_t> sorted;
    for (std::size_t g = begin_group; g < end_group; ++g) {
      const std::uint32_t* items = groups.begin(g);
      const std::size_t n = groups.size(g);
      if (n <= kPairwiseGroupSize) {
        // In increasing order: the first equal position met is the first point at it.
        for (std::size_t j = 0; j < n; ++j) {
          first[items[j]] = items[j];
          const Point p = position_of(items[j]);
          for (std::size_t i = 0; i < j; ++i)
            if (position_of(items[i]) == p) {
              first[items[j]] = items[i];
              break;
            }
        }
        continue;
      }
      sorted.assign(items, items + n);
      std::sort(sorted.begin(), sorted.end(), [&](std::uint32_t a, std::uint32_t b) {
        const Point pa = position_of(a), pb = position_of(b);
        return position_less(pa, pb) || (!position_less(pb, pa) && a < b);
      });
      for (std::size_t i = 0; i < n;) {
        std::size_t j = i;
        const Point p = position_of(sorted[i]);
        for (; j < n && position_of(sorted[j]) == p; ++j) first[sorted[j]] = sorted[i];
        i = j;
      }
    }
  });
  return first;
}

}  // namespace exactgeo::detail
