// The parallel propagation of the engine (GeodesicOptions::threads > 1, vertex-sorted variants): the thread
// team, the bands and the concurrent twins of the sequential engine's steps, and what a run keeps besides the
// engine's state. parallel_propagation.cpp says how the threads share the work.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "band_queue.hpp"
#include "crossing_queues.hpp"
#include "engine_state.hpp"
#include "exactgeo/geodesic.hpp"
#include "windows.hpp"
#include "worker_pool.hpp"

namespace exactgeo::detail {

class VtpEngine;  // vtp_engine.hpp

// What a parallel run keeps besides the engine's state, from its first band to its last.
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

// The vertex-sorted run on several threads, by bands. It changes the engine's per-vertex and per-face state
// (EngineState) through the rules written there once, each step the twin of the engine's sequential one
// under the locks of what it changes (the ..._concurrently members); the steps that change nothing shared
// (crossing a list, handing windows over, the targets) are the engine's own.
class ParallelPropagation {
 public:
  // A team of `threads` threads (fewer if the system refuses some), kept from run to run of `engine`.
  ParallelPropagation(VtpEngine& engine, EngineState& state, unsigned threads)
      : engine_(engine), state_(state), mesh_(state.mesh), pool_(threads), threads_asked_(threads) {}

  unsigned threads() const { return pool_.threads(); }
  unsigned threads_asked() const { return threads_asked_; }
  // Calls work(begin, end) over [0, count) cut into one part per thread, on the threads.
  template <class Work>
  void for_parts(std::size_t count, Work&& work) {
    const unsigned parts = pool_.threads();
    pool_.run(parts, [&](std::size_t part, unsigned) { work(count * part / parts, count * (part + 1) / parts); });
  }
  // From the sources the engine queued until every vertex within the cut-off is inside the traversed area.
  void run();

 private:
  void propagate_band();
  void propagate_band_on(unsigned thread);
  bool take_concurrently(std::uint32_t v, unsigned thread);
  void enclose_concurrently(std::uint32_t v, unsigned thread);
  void cross_concurrently(std::uint32_t h, unsigned thread);
  void relax_concurrently(std::uint32_t v, double d, const Arrival& arrival, unsigned thread);
  void emit_concurrently(std::uint32_t v, unsigned thread);
  void place_concurrently(std::uint32_t g, const Window& w, unsigned thread);
  void deliver_concurrently(std::uint32_t side, std::span<Window> windows, std::uint32_t origin, bool prime,
                            unsigned thread);
  void schedule_locked(std::uint32_t h, unsigned thread);

  VtpEngine& engine_;
  EngineState& state_;
  const SurfaceMesh& mesh_;
  WorkerPool pool_;
  unsigned threads_asked_;              // pool_ may have fewer, if the system refused some
  std::unique_ptr<ParallelState> run_;  // of the run under way
};

}  // namespace exactgeo::detail
