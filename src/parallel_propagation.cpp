// Parallel propagation of one run (GeodesicOptions::threads > 1, vertex-sorted variants; its state in
// parallel_propagation.hpp, its queues in band_queue.hpp and crossing_queues.hpp).
//
// The sequential engine takes one vertex at a time and crosses the lists it sets moving one at a time. Here
// the wavefront advances by a band instead: the queued vertices whose distances lie in the nearest slice of
// the band width (on a fixed grid) join the traversed area. Each thread takes a share of the band's vertices,
// those it reached itself in the bands before (which lie where it crossed lists, so their faces and lists
// are in its cache), emits from those that bend paths and enters their faces, then crosses the lists this
// sets moving and whatever they reach inside the traversed area, until no thread has a list left. A list is
// taken off its edge under the lock of the edge's face (one lock guards a face's three lists) before it is
// pruned and crossed, so windows keep arriving there meanwhile (and schedule it again); a vertex's distance
// and arrival change under the vertex's lock. A vertex reached from outside the traversed area is filed, by
// the thread that reached it, under the band of its distance: the bands' queue is a list per band and
// thread, so no heap is kept on one thread between the bands, and that list is the thread's share of the
// band when it comes.
//
// Exactness does not depend on the order of propagation (every window is propagated until pruned, and the
// pruning compares only with lengths of real paths: a distance read while another thread lowers it is
// still one); the order only decides how much is pruned early, and which of two windows that agree to
// within the pruning tolerance survives. So the distances agree with one thread's to that tolerance, and
// in practice to a few ulps, but which thread crosses what, and when, changes the last bits between runs.
// The earlier design of this engine was bit-reproducible: each band crossed its lists in rounds, with the
// distances a round read frozen at its start, and a step on one thread between the rounds. On two cores it
// gained 1.3x at best on 100K-face scans against 1.55-1.65x for this one (docs/performance.md).
//
// Work stays where it was made: a thread crosses the lists it scheduled, whose faces lie next to those it
// crossed before, and hands the older half of them to a thread that has run out (the next time it looks,
// after a crossing). There is no shared counter of work to be done: a band is over when every thread that
// joined it has run out, since only a thread with a list to cross makes new ones.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>

#include "assert.hpp"
#include "face_windows.hpp"
#include "parallel_propagation.hpp"
#include "phase_timer.hpp"
#include "spin_lock.hpp"
#include "vtp_engine.hpp"

namespace exactgeo::detail {
namespace {

// Width of a band in mean edge lengths. Narrower bands mean more of them, each ending with the threads
// waiting for the last list; wider ones cross lists before the nearer windows that would prune them have
// arrived (one edge on 16 threads: 3% more window propagations and a third more list crossings than half
// an edge on nefertiti). With few threads the waits are short and half an edge measured best on the scans
// (docs/performance.md); from four threads on a band of half an edge gives each thread only a few dozen
// crossings, and one edge measured 9% faster on nefertiti at 4 threads and 16-22% faster on nefertiti and its
// 400K-face subdivision at 16 threads (two edges: slower again on both).
constexpr double kBandEdgesFewThreads = 0.5, kBandEdgesManyThreads = 1.0;
constexpr unsigned kManyThreads = 4;

}  // namespace

void VtpEngine::run_vertex_sorted_in_bands(unsigned threads) {
  EXACTGEO_ASSERT(pool_ && pool_->threads() == threads);  // made by run, which clears the lists with it
  parallel_ = std::make_unique<ParallelState>(threads, mesh_.vertex_count, mesh_.face_count());
  ParallelState& parallel = *parallel_;
  // With more threads than cores, a hungry thread holds a core that one with lists could use. (Asked of the
  // team, which asked hardware_concurrency once: it reads a file.)
  parallel.hungry_spins = pool_->oversubscribed() ? 0 : 1024;
  double band_width = (threads < kManyThreads ? kBandEdgesFewThreads : kBandEdgesManyThreads) * mesh_.mean_edge_length;
  if (!(band_width > 0)) band_width = 1;  // every edge of length 0: every distance is 0
  parallel.bands.start(mesh_.vertex_count, threads, band_width);
  for_parts(mesh_.vertex_count, [&](std::size_t begin, std::size_t end) { parallel.bands.clear_vertices(begin, end); });

  while (true) {
    update_cutoff();
    // Vertices queued on this thread alone (by the sources, and by emissions of sources in the first band).
    while (!vertex_queue_.empty()) {
      const std::uint32_t v = vertex_queue_.pop();
      parallel.bands.file(v, distance_[v], 0);
    }
    {
      const PhaseTimer timer(options_.collect_timings, stats_.queue_seconds);
      const bool more = parallel.bands.next_band([&](std::uint32_t v) { return state_[v] == VertexState::queued; },
                                                 [&](std::uint32_t v) { return distance_[v]; });
      if (!more) break;
    }
    ++stats_.parallel_bands;
    ++iteration_;  // one iteration per band: all its faces are new to the traversed area
    const std::uint64_t pops_before = stats_.vertex_pops;
    propagate_band();
    // Progress and a stop asked for, as often as the sequential engine's (it looks at every multiple of the
    // interval).
    if (stats_.vertex_pops / kProgressInterval != pops_before / kProgressInterval)
      checkpoint(stats_.vertex_pops / kProgressInterval * kProgressInterval,
                 static_cast<double>(stats_.vertex_pops) / mesh_.vertex_count);
  }
  for (const ParallelState::ThreadScratch& s : parallel.scratch) {
    stats_.pruning_seconds += s.stats.pruning_seconds;
    stats_.prime_propagations += s.stats.prime_propagations;
    stats_.secondary_propagations += s.stats.secondary_propagations;
    stats_.prime_merges += s.stats.prime_merges;
    stats_.secondary_merges += s.stats.secondary_merges;
    stats_.pseudo_source_emissions += s.stats.pseudo_source_emissions;
    stats_.list_crossings += s.stats.list_crossings;
    stats_.parallel_lock_waits += s.stats.parallel_lock_waits;
    stats_.parallel_busy_seconds += s.stats.parallel_busy_seconds;
    stats_.parallel_busiest_thread_seconds =
        std::max(stats_.parallel_busiest_thread_seconds, s.stats.parallel_busy_seconds);
    stats_.parallel_start_seconds += s.stats.parallel_start_seconds;
    stats_.parallel_starved_seconds += s.stats.parallel_starved_seconds;
    stats_.parallel_lock_wait_seconds += s.stats.parallel_lock_wait_seconds;
  }
  parallel_.reset();
}

// One band: the threads share its vertices and the crossings they set off (and file the vertices they reach
// from outside the traversed area in the bands' queue).
void VtpEngine::propagate_band() {
  // Lists scheduled before the first band (by a source inside a face), and emissions of sources, on one
  // thread as the sequential engine would.
  while (!emit_queue_.empty()) emit_lowered_pseudo_source();
  ParallelState& parallel = *parallel_;
  const unsigned threads = pool_->threads();
  parallel.crossings.start_band(pending_);
  pending_.clear();
  const bool timed = options_.collect_timings;
  if (timed) parallel.band_start = std::chrono::steady_clock::now();
  pool_->run(threads, [this](std::size_t, unsigned thread) { propagate_band_on(thread); });
  const double seconds =
      timed ? std::chrono::duration<double>(std::chrono::steady_clock::now() - parallel.band_start).count() : 0.0;
  stats_.parallel_seconds += seconds;
  std::uint16_t deepest = 0;
  std::uint64_t crossings = 0, vertices = 0;
  double busy_seconds = 0;
  for (ParallelState::ThreadScratch& s : parallel.scratch) {
    targets_changed_ = targets_changed_ || s.targets_changed;
    s.targets_changed = false;
    deepest = std::max(deepest, s.deepest);
    s.deepest = 0;
    vertices += s.vertices_taken;
    s.vertices_taken = 0;
    crossings += s.stats.list_crossings;
    busy_seconds += s.stats.parallel_busy_seconds;
  }
  stats_.parallel_critical_path += deepest;
  stats_.vertex_pops += vertices;
  if (timed) {  // the threads' counts so far, less those of the bands before
    stats_.band_timeline.push_back({static_cast<std::uint32_t>(vertices),
                                    static_cast<std::uint32_t>(crossings - parallel.timeline_crossings), deepest,
                                    seconds, busy_seconds - parallel.timeline_busy_seconds});
    parallel.timeline_crossings = crossings;
    parallel.timeline_busy_seconds = busy_seconds;
  }
  lists_.note_peak();
}

// One thread's part of a band, if it comes before the band is over: it takes shares of the band's vertices
// while there are any (its own first), then crosses lists until every thread that joined has run out.
void VtpEngine::propagate_band_on(unsigned thread) {
  ParallelState& parallel = *parallel_;
  CrossingQueues& crossings = parallel.crossings;
  if (!crossings.join()) return;
  const unsigned threads = crossings.threads();
  ParallelState::ThreadScratch& scratch = parallel.scratch[thread];
  auto emit_lowered = [&] {
    while (!scratch.to_emit.empty()) {
      const std::uint32_t v = scratch.to_emit.back();
      scratch.to_emit.pop_back();
      emit_concurrently(v, thread);
    }
  };
  // With collect_timings, `mark` is when the thread last started working or waiting.
  const bool timed = options_.collect_timings;
  auto mark = timed ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
  auto time_since_mark = [&](double& bucket) {
    const auto now = std::chrono::steady_clock::now();
    bucket += std::chrono::duration<double>(now - mark).count();
    mark = now;
  };
  LockWaits& lock_waits_here = lock_waits;
  const LockWaits lock_waits_before = lock_waits_here;
  lock_waits_here.timed = timed;
  if (timed) scratch.stats.parallel_start_seconds += std::chrono::duration<double>(mark - parallel.band_start).count();
  auto leave = [&] {  // the thread's part of the band is over
    if (timed && mark != std::chrono::steady_clock::time_point::max())
      time_since_mark(scratch.stats.parallel_busy_seconds);
    scratch.stats.parallel_lock_waits += lock_waits_here.count - lock_waits_before.count;
    scratch.stats.parallel_lock_wait_seconds += lock_waits_here.seconds - lock_waits_before.seconds;
  };
  try {
    scratch.depth = 0;
    // Its own share first: the vertices it reached in the bands before, whose lists it has in its cache. A
    // share can be much larger than the others (the sources' is all of the first band): the lists it sets
    // moving are handed to hungry threads as they come.
    for (unsigned k = 0; k < threads; ++k) {
      const unsigned share = (thread + k) % threads;
      if (!crossings.claim_share(share, thread)) continue;
      parallel.bands.take_share(share, [&](std::uint32_t v) {
        if (!take_concurrently(v, thread)) return;
        enclose_concurrently(v, thread);
        emit_lowered();
        if (crossings.anyone_hungry()) crossings.feed_hungry(thread);
      });
    }
    while (!crossings.aborted()) {
      std::uint32_t h;
      if (crossings.pop(thread, h)) {
        cross_concurrently(h, thread);
        emit_lowered();
        if (crossings.anyone_hungry()) crossings.feed_hungry(thread);
        continue;
      }
      if (timed) time_since_mark(scratch.stats.parallel_busy_seconds);
      if (!crossings.wait_for_lists(thread, parallel.hungry_spins)) {
        mark = std::chrono::steady_clock::time_point::max();  // waits at the band's end are what is left
        break;
      }
      if (timed) time_since_mark(scratch.stats.parallel_starved_seconds);
    }
  } catch (...) {
    crossings.abort();  // the others stop too: the lists they wait for will not come
    leave();
    throw;
  }
  leave();
}

// move_inside, with other threads running, for a vertex of the band under way's share that `thread` took:
// whether v is still to be taken (false for an entry left behind when v was filed again, or one that lies
// beyond the band, which is filed again now). v's lock orders this with lowering v: a path that lowers v
// before it moves inside files nothing (v stays in the band), one after it makes v emit again.
bool VtpEngine::take_concurrently(std::uint32_t v, unsigned thread) {
  const SpinGuard guard(parallel_->vertex_locks[v]);
  if (!parallel_->bands.take(v, state_[v] == VertexState::queued, distance_[v], thread)) return false;
  state_[v] = VertexState::inside;
  ++parallel_->scratch[thread].vertices_taken;
  return true;
}

// enclose_vertex, with other threads running. A face joins the traversed area under its lock, which its
// lists' windows arrive under too: a window placed or delivered there either comes first and is found here,
// or finds the face inside and is scheduled by whoever brought it.
void VtpEngine::enclose_concurrently(std::uint32_t v, unsigned thread) {
  if (bends_paths(v)) parallel_->scratch[thread].to_emit.push_back(v);
  prefetch_faces_of(v);
  for (std::uint32_t i = mesh_.vertex_corner_offsets[v]; i < mesh_.vertex_corner_offsets[v + 1]; ++i) {
    const std::uint32_t f = face_of(mesh_.vertex_corners[i]);
    if (face_inside(f)) continue;  // most are: a plain load spares taking the lock, a locked instruction
    const SpinGuard guard(parallel_->face_locks[f]);
    if (face_inside(f)) continue;  // another thread's vertex of the same band entered it meanwhile
    std::atomic_ref<std::uint32_t>(face_visited_at_[f]).store(iteration_, std::memory_order_relaxed);
    for (std::uint32_t h = 3 * f; h < 3 * f + 3; ++h)
      if (!lists_.empty(h)) schedule_locked(h, thread);
  }
}

// cross, with other threads running: the list is taken off h first, so that windows can join h meanwhile
// (they schedule it again).
void VtpEngine::cross_concurrently(std::uint32_t h, unsigned thread) {
  ParallelState::ThreadScratch& scratch = parallel_->scratch[thread];
  WindowLists::List taken;
  {
    const SpinGuard guard(parallel_->face_locks[face_of(h)]);
    taken = lists_.take(h);  // no longer scheduled, its depth back to 0
    scratch.depth = std::max<std::uint16_t>(taken.depth, 1);
  }
  if (taken.size == 0) return;
  prefetch_destinations(h);
  ++scratch.stats.list_crossings;
  scratch.deepest = std::max(scratch.deepest, scratch.depth);
  std::span<Window> incoming(taken.data, taken.size);
  if (worth_pruning(taken)) {
    const PhaseTimer timer(options_.collect_timings, scratch.stats.pruning_seconds);
    incoming = incoming.first(prune_list(incoming, tolerances_));
  }
  if (kept_windows_) {
    const SpinGuard guard(parallel_->face_locks[face_of(h)]);  // h may be crossing on another thread too
    keep_entering(h, incoming, thread);
  }
  // The face entered in this band or before: no thread changes its visit any more.
  const bool prime = std::atomic_ref<std::uint32_t>(face_visited_at_[face_of(h)]).load(std::memory_order_relaxed) == iteration_;
  ApexReach reach;
  Arrival at_apex;
  for (std::vector<Window>& crossed : scratch.crossed) crossed.clear();
  const std::uint64_t propagations =
      cross_list(h, incoming, scratch.splits, scratch.crossed[0], scratch.crossed[1], reach, at_apex);
  (prime ? scratch.stats.prime_propagations : scratch.stats.secondary_propagations) += propagations;
  if (targets_.in_faces()) {
    const std::lock_guard lock(parallel_->targets_mutex);
    evaluate_targets(h, incoming);
  }
  lists_.give_back(taken, thread);
  relax_concurrently(mesh_.apex(h), reach.distance, at_apex, thread);
  deliver_concurrently(prev_halfedge(h), scratch.crossed[0], mesh_.tail(h), prime, thread);
  deliver_concurrently(next_halfedge(h), scratch.crossed[1], mesh_.head(h), prime, thread);
}

// relax, with other threads running: v's distance and arrival change under its lock; v is filed in the
// bands' queue by this thread, and a pseudo-source inside emits again once this thread's crossing is done.
void VtpEngine::relax_concurrently(std::uint32_t v, double d, const Arrival& arrival, unsigned thread) {
  if (!(d < distance_now(v))) return;
  ParallelState::ThreadScratch& scratch = parallel_->scratch[thread];
  const SpinGuard guard(parallel_->vertex_locks[v]);
  if (!(d < distance_[v])) return;
  lower(
      v, d, arrival, scratch.targets_changed, [&] { parallel_->bands.file(v, d, thread); },
      [&] { scratch.to_emit.push_back(v); });
}

// place_new_window, with other threads running.
void VtpEngine::place_concurrently(std::uint32_t g, const Window& w, unsigned thread) {
  if (beyond_cutoff(w, goal_across(g))) return;
  const SpinGuard guard(parallel_->face_locks[face_of(g)]);
  if (face_inside(face_of(g))) {
    lists_.append(g, {&w, 1}, thread);
    schedule_locked(g, thread);
  } else {
    lists_.prepend(g, {&w, 1}, thread);
  }
}

// deliver, with other threads running. The edge's face may have joined the traversed area since hand_over
// looked: the windows then join as inside, and the list is scheduled.
void VtpEngine::deliver_concurrently(std::uint32_t side, std::span<Window> windows, std::uint32_t origin,
                                     bool prime, unsigned thread) {
  if (windows.empty()) return;
  Handover to = hand_over(side, windows, origin, prime);
  if (to.edge == kNone || to.count == 0) return;
  GeodesicStats& stats = parallel_->scratch[thread].stats;
  const SpinGuard guard(parallel_->face_locks[face_of(to.edge)]);
  if (face_inside(face_of(to.edge))) to.joining = Joining::inside;
  if (to.joining != Joining::inside && !lists_.empty(to.edge)) ++(prime ? stats.prime_merges : stats.secondary_merges);
  const std::span<Window> list = lists_.extend(to.edge, to.count, thread);
  std::copy(windows.begin(), windows.begin() + to.count, list.end() - static_cast<std::ptrdiff_t>(to.count));
  join(list, to.count, to.joining);
  if (to.joining == Joining::inside) schedule_locked(to.edge, thread);
}

// schedule, with the lock of h's face held: into this thread's queue. The list's depth is one more than the
// crossing's that reached it (saturating: only a statistic).
void VtpEngine::schedule_locked(std::uint32_t h, unsigned thread) {
  WindowLists::List& edge = lists_.record(h);
  const std::uint16_t depth = parallel_->scratch[thread].depth;
  edge.depth = std::max<std::uint16_t>(edge.depth, depth == UINT16_MAX ? depth : static_cast<std::uint16_t>(depth + 1));
  if (edge.scheduled) return;
  edge.scheduled = 1;
  parallel_->crossings.push(thread, h);
}

}  // namespace exactgeo::detail
