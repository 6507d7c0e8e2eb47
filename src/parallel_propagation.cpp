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
#include "shadow_cone.hpp"
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

void ParallelPropagation::run() {
  const auto started = std::chrono::steady_clock::now();
  const unsigned threads = pool_.threads();
  run_ = std::make_unique<ParallelState>(threads, mesh_.vertex_count, mesh_.face_count());
  ParallelState& parallel = *run_;
  GeodesicStats& stats = engine_.stats_;
  // With more threads than cores, a hungry thread holds a core that one with lists could use. (Asked of the
  // team, which compared its threads with the cores as it started.)
  parallel.hungry_spins = pool_.oversubscribed() ? 0 : 1024;
  double band_width = (threads < kManyThreads ? kBandEdgesFewThreads : kBandEdgesManyThreads) * mesh_.mean_edge_length;
  if (!(band_width > 0)) band_width = 1;  // every edge of length 0: every distance is 0
  parallel.bands.start(mesh_.vertex_count, threads, band_width);
  for_parts(mesh_.vertex_count, [&](std::size_t begin, std::size_t end) { parallel.bands.clear_vertices(begin, end); });
  stats.setup_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  while (true) {
    engine_.update_cutoff();
    // Vertices queued on this thread alone (by the sources, and by emissions of sources in the first band).
    while (!engine_.vertex_queue_.empty()) {
      const std::uint32_t v = engine_.vertex_queue_.pop();
      parallel.bands.file(v, state_.distance[v], 0);
    }
    {
      const PhaseTimer timer(engine_.options_.collect_timings, stats.queue_seconds);
      const bool more =
          parallel.bands.next_band([&](std::uint32_t v) { return state_.vertex_state[v] == VertexState::queued; },
                                   [&](std::uint32_t v) { return state_.distance[v]; });
      if (!more) break;
    }
    ++stats.parallel_bands;
    ++engine_.iteration_;  // one iteration per band: all its faces are new to the traversed area
    const std::uint64_t pops_before = stats.vertex_pops;
    propagate_band();
    // Progress and a stop asked for, as often as the sequential engine's (it looks at every multiple of the
    // interval).
    if (stats.vertex_pops / VtpEngine::kProgressInterval != pops_before / VtpEngine::kProgressInterval)
      engine_.checkpoint(stats.vertex_pops / VtpEngine::kProgressInterval * VtpEngine::kProgressInterval,
                         static_cast<double>(stats.vertex_pops) / mesh_.vertex_count);
  }
  for (const ParallelState::ThreadScratch& s : parallel.scratch) {
    stats.pruning_seconds += s.stats.pruning_seconds;
    stats.prime_propagations += s.stats.prime_propagations;
    stats.secondary_propagations += s.stats.secondary_propagations;
    stats.prime_merges += s.stats.prime_merges;
    stats.secondary_merges += s.stats.secondary_merges;
    stats.pseudo_source_emissions += s.stats.pseudo_source_emissions;
    stats.list_crossings += s.stats.list_crossings;
    stats.parallel_lock_waits += s.stats.parallel_lock_waits;
    stats.parallel_busy_seconds += s.stats.parallel_busy_seconds;
    stats.parallel_busiest_thread_seconds =
        std::max(stats.parallel_busiest_thread_seconds, s.stats.parallel_busy_seconds);
    stats.parallel_start_seconds += s.stats.parallel_start_seconds;
    stats.parallel_starved_seconds += s.stats.parallel_starved_seconds;
    stats.parallel_lock_wait_seconds += s.stats.parallel_lock_wait_seconds;
  }
  run_.reset();
}

// One band: the threads share its vertices and the crossings they set off (and file the vertices they reach
// from outside the traversed area in the bands' queue).
void ParallelPropagation::propagate_band() {
  // Lists scheduled before the first band (by a source inside a face), and emissions of sources, on one
  // thread as the sequential engine would.
  while (!engine_.emit_queue_.empty()) engine_.emit_lowered_pseudo_source();
  ParallelState& parallel = *run_;
  GeodesicStats& stats = engine_.stats_;
  const unsigned threads = pool_.threads();
  parallel.crossings.start_band(engine_.pending_);
  engine_.pending_.clear();
  const bool timed = engine_.options_.collect_timings;
  if (timed) parallel.band_start = std::chrono::steady_clock::now();
  pool_.run(threads, [this](std::size_t, unsigned thread) { propagate_band_on(thread); });
  const double seconds =
      timed ? std::chrono::duration<double>(std::chrono::steady_clock::now() - parallel.band_start).count() : 0.0;
  stats.parallel_seconds += seconds;
  std::uint16_t deepest = 0;
  std::uint64_t crossings = 0, vertices = 0;
  double busy_seconds = 0;
  for (ParallelState::ThreadScratch& s : parallel.scratch) {
    engine_.targets_changed_ = engine_.targets_changed_ || s.targets_changed;
    s.targets_changed = false;
    deepest = std::max(deepest, s.deepest);
    s.deepest = 0;
    vertices += s.vertices_taken;
    s.vertices_taken = 0;
    crossings += s.stats.list_crossings;
    busy_seconds += s.stats.parallel_busy_seconds;
  }
  stats.parallel_critical_path += deepest;
  stats.vertex_pops += vertices;
  if (timed) {  // the threads' counts so far, less those of the bands before
    stats.band_timeline.push_back({static_cast<std::uint32_t>(vertices),
                                   static_cast<std::uint32_t>(crossings - parallel.timeline_crossings), deepest,
                                   seconds, busy_seconds - parallel.timeline_busy_seconds});
    parallel.timeline_crossings = crossings;
    parallel.timeline_busy_seconds = busy_seconds;
  }
  state_.lists.note_peak();
}

// One thread's part of a band, if it comes before the band is over: it takes shares of the band's vertices
// while there are any (its own first), then crosses lists until every thread that joined has run out.
void ParallelPropagation::propagate_band_on(unsigned thread) {
  ParallelState& parallel = *run_;
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
  const bool timed = engine_.options_.collect_timings;
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

// VtpEngine::move_inside, with other threads running, for a vertex of the band under way's share that `thread` took:
// whether v is still to be taken (false for an entry left behind when v was filed again, or one that lies
// beyond the band, which is filed again now). v's lock orders this with lowering v: a path that lowers v
// before it moves inside files nothing (v stays in the band), one after it makes v emit again.
bool ParallelPropagation::take_concurrently(std::uint32_t v, unsigned thread) {
  const SpinGuard guard(run_->vertex_locks[v]);
  if (!run_->bands.take(v, state_.vertex_state[v] == VertexState::queued, state_.distance[v], thread)) return false;
  state_.vertex_state[v] = VertexState::inside;
  ++run_->scratch[thread].vertices_taken;
  return true;
}

// VtpEngine::enclose_vertex, with other threads running. A face joins the traversed area under its lock, which its
// lists' windows arrive under too: a window placed or delivered there either comes first and is found here,
// or finds the face inside and is scheduled by whoever brought it.
void ParallelPropagation::enclose_concurrently(std::uint32_t v, unsigned thread) {
  if (state_.bends_paths(v)) run_->scratch[thread].to_emit.push_back(v);
  state_.prefetch_faces_of(v);
  for (std::uint32_t i = mesh_.vertex_corner_offsets[v]; i < mesh_.vertex_corner_offsets[v + 1]; ++i) {
    const std::uint32_t f = face_of(mesh_.vertex_corners[i]);
    if (state_.face_inside(f)) continue;  // most are: a plain load spares taking the lock, a locked instruction
    const SpinGuard guard(run_->face_locks[f]);
    if (state_.face_inside(f)) continue;  // another thread's vertex of the same band entered it meanwhile
    std::atomic_ref<std::uint32_t>(state_.face_visited_at[f]).store(engine_.iteration_, std::memory_order_relaxed);
    for (std::uint32_t h = 3 * f; h < 3 * f + 3; ++h)
      if (!state_.lists.empty(h)) schedule_locked(h, thread);
  }
}

// VtpEngine::cross, with other threads running: the list is taken off h first, so that windows can join h meanwhile
// (they schedule it again).
void ParallelPropagation::cross_concurrently(std::uint32_t h, unsigned thread) {
  ParallelState::ThreadScratch& scratch = run_->scratch[thread];
  WindowLists::List taken;
  {
    const SpinGuard guard(run_->face_locks[face_of(h)]);
    taken = state_.lists.take(h);  // no longer scheduled, its depth back to 0
    scratch.depth = std::max<std::uint16_t>(taken.depth, 1);
  }
  if (taken.size == 0) return;
  state_.prefetch_destinations(h);
  ++scratch.stats.list_crossings;
  scratch.deepest = std::max(scratch.deepest, scratch.depth);
  std::span<Window> incoming(taken.data, taken.size);
  if (engine_.worth_pruning(taken)) {
    const PhaseTimer timer(engine_.options_.collect_timings, scratch.stats.pruning_seconds);
    incoming = incoming.first(prune_list(incoming, state_.tolerances));
  }
  if (engine_.kept_windows_) {
    const SpinGuard guard(run_->face_locks[face_of(h)]);  // h may be crossing on another thread too
    engine_.keep_entering(h, incoming, thread);
  }
  // The face entered in this band or before: no thread changes its visit any more.
  const bool prime =
      std::atomic_ref<std::uint32_t>(state_.face_visited_at[face_of(h)]).load(std::memory_order_relaxed) ==
      engine_.iteration_;
  ApexReach reach;
  Arrival at_apex;
  for (std::vector<Window>& crossed : scratch.crossed) crossed.clear();
  const std::uint64_t propagations =
      engine_.cross_list(h, incoming, scratch.splits, scratch.crossed[0], scratch.crossed[1], reach, at_apex);
  (prime ? scratch.stats.prime_propagations : scratch.stats.secondary_propagations) += propagations;
  if (state_.targets.in_faces()) {
    const std::lock_guard lock(run_->targets_mutex);
    engine_.evaluate_targets(h, incoming);
  }
  state_.lists.give_back(taken, thread);
  relax_concurrently(mesh_.apex(h), reach.distance, at_apex, thread);
  deliver_concurrently(prev_halfedge(h), scratch.crossed[0], mesh_.tail(h), prime, thread);
  deliver_concurrently(next_halfedge(h), scratch.crossed[1], mesh_.head(h), prime, thread);
}

// VtpEngine::relax, with other threads running: v's distance and arrival change under its lock; v is filed in the
// bands' queue by this thread, and a pseudo-source inside emits again once this thread's crossing is done.
void ParallelPropagation::relax_concurrently(std::uint32_t v, double d, const Arrival& arrival, unsigned thread) {
  if (!(d < state_.distance_now(v))) return;
  ParallelState::ThreadScratch& scratch = run_->scratch[thread];
  const SpinGuard guard(run_->vertex_locks[v]);
  if (!(d < state_.distance[v])) return;
  state_.lower(
      v, d, arrival, scratch.targets_changed, [&] { run_->bands.file(v, d, thread); },
      [&] { scratch.to_emit.push_back(v); });
}

// VtpEngine::emit, with other threads running:
// v's distance and arrival are read under its lock, the distances it offers and the windows it places go in
// under theirs.
void ParallelPropagation::emit_concurrently(std::uint32_t v, unsigned thread) {
  double d;
  Arrival arrival;
  bool everywhere;
  {
    const SpinGuard guard(run_->vertex_locks[v]);
    state_.emit_scheduled[v] = 0;
    d = state_.distance[v];
    arrival = state_.arrival[v];
    everywhere = state_.emits_everywhere[v];
    if (!state_.lowered_since_emission(v, d) || state_.emission_beyond_cutoff(v, d)) return;
    state_.emitted_at[v] = d;
  }
  ++run_->scratch[thread].stats.pseudo_source_emissions;
  for_each_emission_part(
      mesh_, v, d, arrival, everywhere, state_.tolerances.min_width,
      [&](std::uint32_t u, double du, const Arrival& a) { relax_concurrently(u, du, a, thread); },
      [&](std::uint32_t g, const Window& w) { place_concurrently(g, w, thread); },
      [&](std::uint32_t u) {
        const SpinGuard guard(run_->vertex_locks[u]);
        if (state_.emit_everywhere(u)) run_->scratch[thread].to_emit.push_back(u);
      });
}

// VtpEngine::place_new_window, with other threads running.
void ParallelPropagation::place_concurrently(std::uint32_t g, const Window& w, unsigned thread) {
  if (state_.beyond_cutoff(w, state_.goal_across(g))) return;
  const SpinGuard guard(run_->face_locks[face_of(g)]);
  if (state_.face_inside(face_of(g))) {
    state_.lists.append(g, {&w, 1}, thread);
    schedule_locked(g, thread);
  } else {
    state_.lists.prepend(g, {&w, 1}, thread);
  }
}

// VtpEngine::deliver, with other threads running. The edge's face may have joined the traversed area since hand_over
// looked: the windows then join as inside, and the list is scheduled.
void ParallelPropagation::deliver_concurrently(std::uint32_t side, std::span<Window> windows, std::uint32_t origin,
                                               bool prime, unsigned thread) {
  if (windows.empty()) return;
  Handover to = engine_.hand_over(side, windows, origin, prime);
  if (to.edge == kNone || to.count == 0) return;
  GeodesicStats& stats = run_->scratch[thread].stats;
  const SpinGuard guard(run_->face_locks[face_of(to.edge)]);
  if (state_.face_inside(face_of(to.edge))) to.joining = Joining::inside;
  if (to.joining != Joining::inside && !state_.lists.empty(to.edge))
    ++(prime ? stats.prime_merges : stats.secondary_merges);
  const std::span<Window> list = state_.lists.extend(to.edge, to.count, thread);
  std::copy(windows.begin(), windows.begin() + to.count, list.end() - static_cast<std::ptrdiff_t>(to.count));
  join(list, to.count, to.joining);
  if (to.joining == Joining::inside) schedule_locked(to.edge, thread);
}

// VtpEngine::schedule, with the lock of h's face held: into this thread's queue. The list's depth is one more than the
// crossing's that reached it (saturating: only a statistic).
void ParallelPropagation::schedule_locked(std::uint32_t h, unsigned thread) {
  WindowLists::List& edge = state_.lists.record(h);
  const std::uint16_t depth = run_->scratch[thread].depth;
  edge.depth = std::max<std::uint16_t>(edge.depth, depth == UINT16_MAX ? depth : static_cast<std::uint16_t>(depth + 1));
  if (edge.scheduled) return;
  edge.scheduled = 1;
  run_->crossings.push(thread, h);
}

}  // namespace exactgeo::detail
