// Windows and window lists (paper Section 2): each list lives on a halfedge, its windows contiguous.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "assert.hpp"
#include "cache_hint.hpp"
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

// The distance through window w to the point (qx, qy) of the face it enters (in w's frame), and where the ray
// to it crosses the edge; +inf if that ray misses the window. A point on the edge's line with the
// pseudo-source on it too is left to the paths through the face's corners.
inline double distance_through_window(const Window& w, double qx, double qy, double& crossing) {
  const double rise = qy - w.py;
  if (!(rise > 0)) return HUGE_VAL;
  crossing = w.px + (qx - w.px) * (-w.py / rise);
  if (crossing < w.b0 || crossing > w.b1) return HUGE_VAL;
  const double dx = qx - w.px, dy = qy - w.py;
  return w.sigma + std::sqrt(dx * dx + dy * dy);
}

// All window lists. Each list is one block of a power-of-two capacity, carved from large chunks that never
// move; freed blocks are reused by size class, so after the first vertices no more memory is asked for and a
// list is read as one run of memory rather than by chasing links.
//
// Every change takes the number of the thread making it: each thread allocates from its own chunks and keeps
// the blocks it frees, so the parallel bands can move lists concurrently, each thread changing only lists
// whose locks it holds (parallel_propagation.cpp). A block may be freed by another thread than the one that carved it; it
// then serves that thread's next allocations.
class WindowLists {
 public:
  // Makes every list empty, for a run on `threads` threads. for_parts(count, clear) is to call clear(begin,
  // end) on parts covering [0, count), on several threads if the run has them: a large mesh's records are
  // megabytes of fresh pages, and touching them is most of a run's set-up (half of it on two threads).
  template <class ForParts>
  void reset(std::size_t halfedge_count, unsigned threads, ForParts&& for_parts) {
    if (halfedge_count > lists_.get_deleter().count) {
      lists_.reset();  // the old block goes first: a larger one may take its place
      lists_ = {std::allocator<List>().allocate(halfedge_count), FreeRecords{halfedge_count}};
      advise_huge_pages(lists_.get(), halfedge_count * sizeof(List));
    }
    for_parts(halfedge_count, [this](std::size_t begin, std::size_t end) {
      std::uninitialized_fill(lists_.get() + begin, lists_.get() + end, List{});
    });
    start_run(threads);
  }
  // For a run on `threads` threads once every list is empty (after reset, or a run that crossed every list it
  // made): the last run's blocks go with their chunks.
  void start_run(unsigned threads) {
    allocators_.clear();
    allocators_.resize(threads);
    peak_sum_ = 0;
  }
  // Whether h's record is an empty list's with no marks, as reset leaves it.
  bool untouched(std::uint32_t h) const {
    const List& list = lists_[h];
    return list.data == nullptr && list.size == 0 && list.capacity_log2 == 0 && list.runs == 0 && list.scheduled == 0 &&
           list.depth == 0;
  }
  bool empty(std::uint32_t h) const { return lists_[h].size == 0; }

  // The windows of h's list, in order; valid until h's list is next changed.
  std::span<const Window> view(std::uint32_t h) const { return {lists_[h].data, lists_[h].size}; }
  // The same, for work in place; shrink_to gives back what that work removed.
  std::span<Window> edit(std::uint32_t h) { return {lists_[h].data, lists_[h].size}; }

  // Cache hints ahead of work on h's list: its record, or its windows (reading the record).
  void prefetch_record(std::uint32_t h) const { prefetch(&lists_[h]); }
  void prefetch_windows(std::uint32_t h) const { prefetch(lists_[h].data); }

  // A list's record, 16 bytes (one per halfedge: the largest per-run array): its block, the windows in use
  // at its start, how they came, and the engine's marks for its next crossing, kept here so that scheduling a
  // list reads no other record. Emptying the list clears the marks too.
  struct List {
    Window* data = nullptr;
    std::uint32_t size = 0;
    std::uint8_t capacity_log2 : 5 = 0;  // the block holds 1 << capacity_log2 windows; 0: no block
    // Runs of windows added since it was empty (each change that adds windows adds one: the windows of
    // one crossing, or of one pseudo-source), counted up to 2.
    std::uint8_t runs : 2 = 0;
    std::uint8_t scheduled : 1 = 0;  // waiting in a queue to cross
    std::uint16_t depth = 0;         // parallel bands: the longest chain of the band's crossings that reached it
    std::uint32_t capacity() const { return capacity_log2 == 0 ? 0 : std::uint32_t{1} << capacity_log2; }
  };
  static_assert(sizeof(List) == 16);
  List& record(std::uint32_t h) { return lists_[h]; }
  const List& record(std::uint32_t h) const { return lists_[h]; }
  // Takes h's list away, leaving h empty, for work on it while other windows join h (several threads);
  // give_back returns its block once done.
  List take(std::uint32_t h) { return std::exchange(lists_[h], List{}); }
  void give_back(const List& taken, unsigned thread) {
    Allocator& a = allocators_[thread];
    a.live -= taken.size;
    free_block(taken, a);
  }

  // Empties h's list, giving its block back for reuse.
  void clear(std::uint32_t h, unsigned thread) {
    Allocator& a = allocators_[thread];
    a.live -= lists_[h].size;
    release(lists_[h], a);
  }
  void append(std::uint32_t h, std::span<const Window> windows, unsigned thread) {
    const std::span<Window> list = extend(h, windows.size(), thread);
    std::copy(windows.begin(), windows.end(), list.end() - static_cast<std::ptrdiff_t>(windows.size()));
  }
  void prepend(std::uint32_t h, std::span<const Window> windows, unsigned thread) {
    const std::span<Window> list = extend(h, windows.size(), thread);
    std::copy_backward(list.begin(), list.end() - static_cast<std::ptrdiff_t>(windows.size()), list.end());
    std::copy(windows.begin(), windows.end(), list.begin());
  }

  // Grows h's list by `added` windows at its end (left for the caller to fill) and returns the whole list,
  // for work in place; shrink_to gives back what that work removed.
  std::span<Window> extend(std::uint32_t h, std::size_t added, unsigned thread) {
    Allocator& a = allocators_[thread];
    List& list = lists_[h];
    reserve(list, list.size + static_cast<std::uint32_t>(added), a);
    if (added > 0) list.runs = list.size == 0 ? 1 : 2;
    list.size += static_cast<std::uint32_t>(added);
    a.live += static_cast<std::int64_t>(added);
    a.peak = std::max(a.peak, a.live);
    return {list.data, list.size};
  }
  void shrink_to(std::uint32_t h, std::size_t size, unsigned thread) {
    List& list = lists_[h];
    EXACTGEO_ASSERT(size <= list.size);
    allocators_[thread].live -= static_cast<std::int64_t>(list.size - size);
    list.size = static_cast<std::uint32_t>(size);
  }

  // With several threads, the count of live windows is known only where they all stand still: the caller
  // says when (each count is added to the peak as taken).
  void note_peak() {
    std::int64_t live = 0;
    for (const Allocator& a : allocators_) live += a.live;
    peak_sum_ = std::max(peak_sum_, live);
  }
  std::uint64_t peak_live() const {
    const std::int64_t one_thread = allocators_.size() == 1 ? allocators_[0].peak : 0;
    return static_cast<std::uint64_t>(std::max(peak_sum_, one_thread));
  }
  std::uint64_t arena_bytes() const {
    std::uint64_t bytes = 0;
    for (const Allocator& a : allocators_) bytes += a.chunk_windows * sizeof(Window);
    return bytes;
  }

 private:
  static constexpr std::uint32_t kSmallestBlock = 4;
  // Chunks start small (a small mesh needs little) and double up to a few megabytes.
  static constexpr std::size_t kFirstChunk = 1024, kLargestChunk = std::size_t{1} << 16;

  struct alignas(64) Allocator {  // a cache line of its own: each thread changes its own often
    std::vector<Window*> free_blocks[32];
    std::vector<std::unique_ptr<Window[]>> chunks;
    Window* rest = nullptr;  // the unused end of the newest chunk
    std::size_t rest_size = 0;
    std::size_t next_chunk = kFirstChunk;
    std::uint64_t chunk_windows = 0;
    std::int64_t live = 0, peak = 0;  // windows in lists: allocated less freed by this thread
  };

  void reserve(List& list, std::uint32_t needed, Allocator& a) {
    if (needed <= list.capacity()) return;
    const std::uint32_t capacity = std::max(kSmallestBlock, std::bit_ceil(needed));
    Window* data = allocate(capacity, a);
    std::copy(list.data, list.data + list.size, data);
    free_block(list, a);
    list.data = data;
    list.capacity_log2 = static_cast<std::uint8_t>(std::countr_zero(capacity)) & 31;
  }
  static Window* allocate(std::uint32_t capacity, Allocator& a) {
    auto& blocks = a.free_blocks[std::countr_zero(capacity)];
    if (!blocks.empty()) {
      Window* block = blocks.back();
      blocks.pop_back();
      return block;
    }
    if (a.rest_size < capacity) add_chunk(capacity, a);
    Window* block = a.rest;
    a.rest += capacity;
    a.rest_size -= capacity;
    return block;
  }
  static void add_chunk(std::size_t at_least, Allocator& a) {
    // The old chunk's unused end becomes free blocks: every block size is a multiple of the smallest, so
    // the rest splits into powers of two.
    while (a.rest_size >= kSmallestBlock) {
      const std::size_t piece = std::bit_floor(a.rest_size);
      a.free_blocks[std::countr_zero(piece)].push_back(a.rest);
      a.rest += piece;
      a.rest_size -= piece;
    }
    const std::size_t size = std::max(at_least, a.next_chunk);
    a.next_chunk = std::min(2 * a.next_chunk, kLargestChunk);
    a.chunks.push_back(std::make_unique_for_overwrite<Window[]>(size));
    a.rest = a.chunks.back().get();
    a.rest_size = size;
    a.chunk_windows += size;
  }
  static void free_block(const List& list, Allocator& a) {
    if (list.capacity_log2 > 0) a.free_blocks[list.capacity_log2].push_back(list.data);
  }
  static void release(List& list, Allocator& a) {
    free_block(list, a);
    list = List{};
  }

  // The records, allocated untouched for reset to fill in parts (filling the storage starts the records'
  // lifetimes; they are trivially destructible). Kept across runs, and replaced only by a larger mesh's:
  // the deleter's count is the capacity.
  struct FreeRecords {
    std::size_t count;  // without a default initialiser, so that unique_ptr can default-construct it here
    void operator()(List* records) const { std::allocator<List>().deallocate(records, count); }
  };
  std::unique_ptr<List[], FreeRecords> lists_;
  std::vector<Allocator> allocators_;
  std::int64_t peak_sum_ = 0;
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
