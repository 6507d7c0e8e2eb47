// What a parallel run of the engine (GeodesicOptions::threads > 1, vertex-sorted variants) keeps besides the
// sequential engine's state: parallel_propagation.cpp says how the threads share the work.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "band_queue.hpp"
#include "crossing_queues.hpp"
#include "exactgeo/geodesic.hpp"
#include "windows.hpp"

namespace exactgeo::detail {

struct ParallelState {
  ParallelState(unsigned threads, std::size_t vertex_count, std::size_t face_count)
      : scratch(threads),
        crossings(threads),
        face_locks(std::make_unique<std::atomic<std::uint8_t>[]>(face_count)),
        vertex_locks(std::make_unique<std::atomic<std::uint8_t>[]>(vertex_count)) {}

  struct alignas(64) ThreadScratch {  // a cache line of its own: each thread writes its own often
    std::vector<double> splits;
    std::array<std::vector<Window>, 2> crossed;
    std::vector<std::uint32_t> to_emit;  // pseudo-sources inside that it lowered: they emit again
    std::uint16_t depth = 0;             // of the crossing under way (0: enclosing a vertex)
    std::uint16_t deepest = 0;           // of the band's crossings so far
    bool targets_changed = false;
    std::uint32_t vertices_taken = 0;  // in the band under way
    GeodesicStats stats;  // its propagations, merges, emissions, crossings and pruning time
  };
  std::vector<ThreadScratch> scratch;
  BandQueue bands;
  CrossingQueues crossings;
  // One lock per face guards the lists of its three halfedges (entering a face takes one lock, not three).
  std::unique_ptr<std::atomic<std::uint8_t>[]> face_locks;
  std::unique_ptr<std::atomic<std::uint8_t>[]> vertex_locks;
  std::mutex targets_mutex;  // the targets' distances, evaluated as lists cross their faces
  int hungry_spins = 0;      // how long a hungry thread spins before it yields the core
  // With collect_timings: when the band under way started, and the threads' crossings and busy time at the
  // end of the last band (GeodesicStats::band_timeline).
  std::chrono::steady_clock::time_point band_start{};
  std::uint64_t timeline_crossings = 0;
  double timeline_busy_seconds = 0;
};

}  // namespace exactgeo::detail
