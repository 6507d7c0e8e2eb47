// The wavefront priority queue: an indexed binary min-heap of element ids (vertices for the vertex-sorted
// variants, paper Section 5.2; faces for the face-sorted ones, Section 5.1) keyed by (distance, id), with
// decrease-key. Breaking ties by id keeps elements with equal distances apart.
#pragma once

#include <cstdint>
#include <vector>

#include "assert.hpp"
#include "surface_mesh.hpp"

namespace exactgeo::detail {

class WavefrontQueue {
 public:
  // Empties the queue for ids [0, id_count). Only the ids still queued have a position to forget, so a run
  // that stopped early on a large mesh leaves the next one a reset as small as its wavefront.
  void reset(std::size_t id_count) {
    if (position_.size() == id_count) {
      for (const Entry& e : heap_) position_[e.id] = kNone;
    } else {
      position_.assign(id_count, kNone);
    }
    heap_.clear();
  }
  bool empty() const { return heap_.empty(); }
  bool contains(std::uint32_t id) const { return position_[id] != kNone; }

  // Inserts `id` with `key`, or lowers its key if it is queued with a larger one.
  void push_or_decrease(std::uint32_t id, double key) {
    EXACTGEO_ASSERT(id < position_.size() && key >= 0);  // a NaN key would break the heap order
    std::uint32_t i = position_[id];
    if (i == kNone) {
      i = static_cast<std::uint32_t>(heap_.size());
      heap_.push_back({key, id});
    } else if (key < heap_[i].key) {
      heap_[i].key = key;
    } else {
      return;
    }
    sift_up(i);
  }
  std::uint32_t pop() {
    EXACTGEO_ASSERT(!heap_.empty() && is_heap());
    const std::uint32_t top = heap_.front().id;
    position_[top] = kNone;
    const Entry last = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) {
      heap_[0] = last;
      position_[last.id] = 0;
      sift_down(0);
    }
    return top;
  }

 private:
  struct Entry {
    double key;
    std::uint32_t id;
  };
  static bool before(const Entry& a, const Entry& b) {
    return a.key < b.key || (a.key == b.key && a.id < b.id);
  }
  void place(std::uint32_t i, const Entry& e) {
    heap_[i] = e;
    position_[e.id] = i;
  }
  void sift_up(std::uint32_t i) {
    const Entry e = heap_[i];
    while (i > 0) {
      const std::uint32_t parent = (i - 1) / 2;
      if (!before(e, heap_[parent])) break;
      place(i, heap_[parent]);
      i = parent;
    }
    place(i, e);
  }
  void sift_down(std::uint32_t i) {
    const Entry e = heap_[i];
    const auto n = static_cast<std::uint32_t>(heap_.size());
    while (true) {
      std::uint32_t child = 2 * i + 1;
      if (child >= n) break;
      if (child + 1 < n && before(heap_[child + 1], heap_[child])) ++child;
      if (!before(heap_[child], e)) break;
      place(i, heap_[child]);
      i = child;
    }
    place(i, e);
  }

  // Every entry comes after its parent and is where position_ says: O(size), checked at each pop where
  // assertions are on (the queue holds the wavefront, a small part of the mesh).
  bool is_heap() const {
    for (std::uint32_t i = 0; i < heap_.size(); ++i)
      if (position_[heap_[i].id] != i || (i > 0 && before(heap_[i], heap_[(i - 1) / 2]))) return false;
    return true;
  }

  std::vector<Entry> heap_;
  std::vector<std::uint32_t> position_;
};

}  // namespace exactgeo::detail
