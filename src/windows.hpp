// Windows and window lists (paper Section 2): each list lives on a halfedge, its windows in one pool.
#pragma once

#include <cstdint>
#include <vector>

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
  std::uint32_t next;           // next window of the same list in the pool, or kNone
};

// All window lists, as singly linked lists threaded through one pool with a free list: no allocation per
// window once the pool has grown to the run's peak.
class WindowLists {
 public:
  void reset(std::size_t halfedge_count) {
    head_.assign(halfedge_count, kNone);
    tail_.assign(halfedge_count, kNone);
    pool_.clear();
    free_ = kNone;
    live_ = peak_live_ = 0;
  }
  bool empty(std::uint32_t h) const { return head_[h] == kNone; }

  // Moves the windows of h's list, in order, to the end of `out`, leaving h's list empty.
  void take(std::uint32_t h, std::vector<Window>& out) {
    for (std::uint32_t i = head_[h]; i != kNone;) {
      const std::uint32_t next = pool_[i].next;
      out.push_back(pool_[i]);
      release(i);
      i = next;
    }
    head_[h] = tail_[h] = kNone;
  }
  void append(std::uint32_t h, const Window& w) {
    const std::uint32_t i = allocate(w);
    if (tail_[h] == kNone) head_[h] = i; else pool_[tail_[h]].next = i;
    tail_[h] = i;
  }
  void prepend(std::uint32_t h, const Window& w) {
    const std::uint32_t i = allocate(w);
    pool_[i].next = head_[h];
    head_[h] = i;
    if (tail_[h] == kNone) tail_[h] = i;
  }

  std::uint64_t live() const { return live_; }
  std::uint64_t peak_live() const { return peak_live_; }

 private:
  std::uint32_t allocate(const Window& w) {
    std::uint32_t i;
    if (free_ != kNone) {
      i = free_;
      free_ = pool_[i].next;
      pool_[i] = w;
    } else {
      i = static_cast<std::uint32_t>(pool_.size());
      pool_.push_back(w);
    }
    pool_[i].next = kNone;
    if (++live_ > peak_live_) peak_live_ = live_;
    return i;
  }
  void release(std::uint32_t i) {
    pool_[i].next = free_;
    free_ = i;
    --live_;
  }

  std::vector<std::uint32_t> head_, tail_;
  std::vector<Window> pool_;
  std::uint32_t free_ = kNone;
  std::uint64_t live_ = 0, peak_live_ = 0;
};

}  // namespace exactgeo::detail
