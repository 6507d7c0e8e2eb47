// The wavefront priority queue of vertices (paper Section 5.2): an indexed binary min-heap keyed by
// (distance, vertex id), with decrease-key. Breaking ties by id keeps vertices with equal distances apart.
#pragma once

#include <cstdint>
#include <vector>

#include "surface_mesh.hpp"

namespace exactgeo::detail {

class VertexQueue {
 public:
  void reset(std::size_t vertex_count) {
    heap_.clear();
    position_.assign(vertex_count, kNone);
  }
  bool empty() const { return heap_.empty(); }
  bool contains(std::uint32_t v) const { return position_[v] != kNone; }

  // Inserts v with `key`, or lowers its key if it is queued with a larger one.
  void push_or_decrease(std::uint32_t v, double key) {
    std::uint32_t i = position_[v];
    if (i == kNone) {
      i = static_cast<std::uint32_t>(heap_.size());
      heap_.push_back({key, v});
    } else if (key < heap_[i].key) {
      heap_[i].key = key;
    } else {
      return;
    }
    sift_up(i);
  }
  std::uint32_t pop() {
    const std::uint32_t top = heap_.front().vertex;
    position_[top] = kNone;
    const Entry last = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) {
      heap_[0] = last;
      position_[last.vertex] = 0;
      sift_down(0);
    }
    return top;
  }

 private:
  struct Entry {
    double key;
    std::uint32_t vertex;
  };
  static bool before(const Entry& a, const Entry& b) {
    return a.key < b.key || (a.key == b.key && a.vertex < b.vertex);
  }
  void place(std::uint32_t i, const Entry& e) {
    heap_[i] = e;
    position_[e.vertex] = i;
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

  std::vector<Entry> heap_;
  std::vector<std::uint32_t> position_;
};

}  // namespace exactgeo::detail
