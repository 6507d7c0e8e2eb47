// The bands' queue of the parallel propagation (parallel_propagation.cpp): where the sequential engine keeps a heap of
// wavefront vertices, the threads file the vertices they reach by the band of their distance, band k holding
// distances in [k - 1, k) band widths, and the wavefront advances one band at a time. Each thread files into
// lists of its own, so filing takes no shared write but the vertex's entry, written under the vertex's lock.
// A band's vertices are taken by the threads too, a thread's own list first (its share): it reached those
// vertices from the lists it crossed, so their faces and lists lie where it worked, in its cache.
//
// Lowering a queued vertex's distance files it anew and leaves a stale entry behind, told apart by the
// vertex's band: only the last filing counts. A vertex whose band is behind goes into the next band; one of
// the band under way stays there, to be taken in it; one kSlots - 1 bands ahead or more goes into the last
// slot, and is filed again when its turn comes.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "surface_mesh.hpp"

namespace exactgeo::detail {

class BandQueue {
 public:
  static constexpr std::uint64_t kSlots = 1024;

  // An empty queue for a run of `threads` filing threads over `vertex_count` vertices, bands `width` wide
  // (engine lengths, > 0). The vertices' entries are left as they are: clear_vertices clears them, in parts
  // on the run's threads.
  void start(std::size_t vertex_count, unsigned threads, double width) {
    width_ = width;
    band_under_way_ = 0;  // band 0 is never under way: distance 0 falls in band 1
    band_of_.resize(vertex_count);
    filed_.assign(threads, ThreadLists{});
    for (ThreadLists& lists : filed_) lists.by_slot.resize(kSlots);
  }
  void clear_vertices(std::size_t begin, std::size_t end) {
    std::fill(band_of_.begin() + static_cast<std::ptrdiff_t>(begin), band_of_.begin() + static_cast<std::ptrdiff_t>(end),
              std::uint64_t{0});
  }

  double width() const { return width_; }
  std::uint64_t band_under_way() const { return band_under_way_; }
  // The band a distance falls in, as a double: distances far ahead lie beyond any band index.
  double band_of_distance(double d) const { return std::floor(d / width_) + 1; }

  // Files vertex v, at distance d, in its band (the nearest one the queue takes), on `thread`'s lists. The
  // caller holds v (its lock, or the only thread). A vertex filed last in the band under way is left there,
  // however much nearer: the thread that takes its share takes it in this band (as the sequential engine
  // would pop it next), and every vertex it holds was taken when the band ends.
  void file(std::uint32_t v, double d, unsigned thread) {
    if (band_under_way_ != 0 && band_of_[v] == band_under_way_) return;
    file_ahead(v, d, thread);
  }

  // Between bands, on one thread: makes the nearest band that holds a vertex to take (one filed there last,
  // still queued (is_queued(v)), whose distance (distance_of(v)) lies in it) the band under way; its vertices
  // are then taken a share at a time (take_share). A band with none to take is passed over: those filed there
  // last that lie farther are filed again, on thread 0's lists. False, with no band under way, once no band
  // holds a vertex. Looks no further into the band's lists than its first vertex to take.
  template <class IsQueued, class DistanceOf>
  bool next_band(IsQueued&& is_queued, DistanceOf&& distance_of) {
    for (std::uint64_t empty_slots = 0;;) {
      const std::uint64_t band = ++band_under_way_;
      bool any_filed = false;
      for (ThreadLists& lists : filed_) {
        const std::vector<std::uint32_t>& slot = lists.by_slot[band % kSlots];
        any_filed = any_filed || !slot.empty();
        for (const std::uint32_t v : slot)
          if (band_of_[v] == band && is_queued(v) && !beyond_band_under_way(distance_of(v))) return true;
      }
      for (ThreadLists& lists : filed_) {
        std::vector<std::uint32_t>& slot = lists.by_slot[band % kSlots];
        for (const std::uint32_t v : slot)
          if (band_of_[v] == band && is_queued(v)) file_ahead(v, distance_of(v), 0);  // into a later slot
        slot.clear();
      }
      empty_slots = any_filed ? 0 : empty_slots + 1;
      if (empty_slots == kSlots - 1) return false;  // every slot a vertex can be filed in is empty
    }
  }

  // During a band, on the one thread that claimed share `share`: calls visit(v) for each vertex that thread
  // `share` filed in the band under way, then empties that list. visit(v) holds v and asks take whether to
  // take it. No thread files into the band under way's slot meanwhile (file leaves its vertices where they
  // are; every band ahead lies in another slot).
  template <class Visit>
  void take_share(unsigned share, Visit&& visit) {
    std::vector<std::uint32_t>& slot = filed_[share].by_slot[band_under_way_ % kSlots];
    for (const std::uint32_t v : slot) visit(v);
    slot.clear();
  }

  // For take_share's visit(v), which holds v: whether to take v, at distance d, still queued or not, in the
  // band under way. Not an entry left behind when v was filed again; not one that lies beyond the band (one
  // filed in the last slot), which is filed again now, on `thread`'s lists.
  bool take(std::uint32_t v, bool queued, double d, unsigned thread) {
    if (band_of_[v] != band_under_way_ || !queued) return false;
    if (!beyond_band_under_way(d)) return true;
    file_ahead(v, d, thread);
    return false;
  }

 private:
  bool beyond_band_under_way(double d) const { return band_of_distance(d) > static_cast<double>(band_under_way_); }

  // file, for a vertex filed last in the band under way (or, between bands, in the band passed over) whose
  // distance lies beyond it: into a band ahead.
  void file_ahead(std::uint32_t v, double d, unsigned thread) {
    const std::uint64_t first = band_under_way_ + 1, last = band_under_way_ + kSlots - 1;
    const double at = band_of_distance(d);
    const std::uint64_t band = at <= static_cast<double>(first)  ? first
                               : at >= static_cast<double>(last) ? last
                                                                 : static_cast<std::uint64_t>(at);
    if (band_of_[v] == band) return;
    band_of_[v] = band;
    filed_[thread].by_slot[band % kSlots].push_back(v);
  }

  struct alignas(64) ThreadLists {  // a cache line of its own: each thread files into its own often
    std::vector<std::vector<std::uint32_t>> by_slot;  // band k's vertices in slot k % kSlots
  };

  double width_ = 1;
  std::uint64_t band_under_way_ = 0;
  MeshArray<std::uint64_t> band_of_;  // per vertex: the band it was last filed in, 0 if never
  std::vector<ThreadLists> filed_;
};

}  // namespace exactgeo::detail
