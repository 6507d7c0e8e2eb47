// Windows and window lists (paper Section 2): each list lives on a halfedge, its windows contiguous in one
// shared arena.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <span>
#include <vector>

#include "assert.hpp"
#include "surface_mesh.hpp"

namespace exactgeo::detail {

// A window on halfedge h, in h's frame (tail at the origin, the face it enters at y > 0): the interval
// [b0, b1] of the edge is reached straight from the unfolded pseudo-source (px, py), py <= 0, whose geodesic
// distance from the source is sigma. Distance at x in [b0, b1]: sigma + |(x, 0) - (px, py)|.
struct Window {
  double b0, b1;
  double px, py;
  double sigma;
  std::uint32_t pseudo_source;  // surface vertex the straight rays start from (a source or a bend vertex)
};

// All window lists. Each list is one block of the arena, of a power-of-two capacity; freed blocks are
// reused by size class, so after the first vertices the arena stops growing and a list is read as one run of
// memory rather than by chasing links.
class WindowLists {
 public:
  void reset(std::size_t halfedge_count) {
    lists_.assign(halfedge_count, List{});
    arena_.clear();
    for (auto& blocks : free_blocks_) blocks.clear();
    live_ = peak_live_ = 0;
  }
  bool empty(std::uint32_t h) const { return lists_[h].size == 0; }

  // The windows of h's list, in order; valid until the lists are next changed.
  std::span<const Window> view(std::uint32_t h) const {
    const List& list = lists_[h];
    return {arena_.data() + list.offset, list.size};
  }
  // The same, writable in place (for joins that fill space reserved with extend).
  std::span<Window> windows(std::uint32_t h) {
    const List& list = lists_[h];
    return {arena_.data() + list.offset, list.size};
  }
  // Empties h's list, giving its block back for reuse.
  void clear(std::uint32_t h) {
    live_ -= lists_[h].size;
    release(lists_[h]);
  }
  void append(std::uint32_t h, std::span<const Window> windows) {
    List& list = lists_[h];
    reserve(list, list.size + static_cast<std::uint32_t>(windows.size()));
    std::copy(windows.begin(), windows.end(), arena_.begin() + list.offset + list.size);
    grow_live(list, windows.size());
  }
  void prepend(std::uint32_t h, std::span<const Window> windows) {
    List& list = lists_[h];
    reserve(list, list.size + static_cast<std::uint32_t>(windows.size()));
    const auto begin = arena_.begin() + list.offset;
    std::copy_backward(begin, begin + list.size, begin + list.size + windows.size());
    std::copy(windows.begin(), windows.end(), begin);
    grow_live(list, windows.size());
  }

  // Grows h's list by `added` windows at its end (left for the caller to fill) and returns the whole list,
  // for work in place; shrink_to gives back what that work removed.
  std::span<Window> extend(std::uint32_t h, std::size_t added) {
    List& list = lists_[h];
    reserve(list, list.size + static_cast<std::uint32_t>(added));
    grow_live(list, added);
    return {arena_.data() + list.offset, list.size};
  }
  void shrink_to(std::uint32_t h, std::size_t size) {
    List& list = lists_[h];
    EXACTGEO_ASSERT(size <= list.size);
    live_ -= list.size - size;
    list.size = static_cast<std::uint32_t>(size);
  }

  std::uint64_t peak_live() const { return peak_live_; }
  std::uint64_t arena_bytes() const { return arena_.capacity() * sizeof(Window); }

 private:
  struct List {
    std::uint32_t offset = 0, size = 0, capacity = 0;
  };
  static constexpr std::uint32_t kSmallestBlock = 4;

  void reserve(List& list, std::uint32_t needed) {
    if (needed <= list.capacity) return;
    const std::uint32_t capacity = std::max(kSmallestBlock, std::bit_ceil(needed));
    const std::uint32_t offset = allocate(capacity);
    std::copy(arena_.begin() + list.offset, arena_.begin() + list.offset + list.size, arena_.begin() + offset);
    const std::uint32_t size = list.size;
    release(list);
    list = {offset, size, capacity};
  }
  std::uint32_t allocate(std::uint32_t capacity) {
    auto& blocks = free_blocks_[std::countr_zero(capacity)];
    if (!blocks.empty()) {
      const std::uint32_t offset = blocks.back();
      blocks.pop_back();
      return offset;
    }
    const auto offset = static_cast<std::uint32_t>(arena_.size());
    arena_.resize(arena_.size() + capacity);
    return offset;
  }
  void release(List& list) {
    if (list.capacity > 0) free_blocks_[std::countr_zero(list.capacity)].push_back(list.offset);
    list = List{};
  }
  void grow_live(List& list, std::size_t added) {
    list.size += static_cast<std::uint32_t>(added);
    live_ += added;
    peak_live_ = std::max(peak_live_, live_);
  }

  std::vector<List> lists_;
  std::vector<Window> arena_;
  std::vector<std::uint32_t> free_blocks_[32];
  std::uint64_t live_ = 0, peak_live_ = 0;
};

// Order-preserving merge: inserts each of the windows list[old_size, end) after the last window before it
// that starts no later, found by binary search, so that a list ordered by start stays ordered.
inline void insert_in_order(std::span<Window> list, std::size_t old_size) {
  for (auto end = list.begin() + static_cast<std::ptrdiff_t>(old_size); end != list.end(); ++end) {
    const Window w = *end;  // the next window to place; [begin, end) is ordered
    const auto at = std::upper_bound(list.begin(), end, w.b0, [](double b0, const Window& x) { return b0 < x.b0; });
    std::move_backward(at, end, end + 1);
    *at = w;
  }
}

}  // namespace exactgeo::detail
