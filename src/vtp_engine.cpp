// The VTP driver: see vtp_engine.hpp.
#include "vtp_engine.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>

#include "assert.hpp"
#include "face_windows.hpp"
#include "phase_timer.hpp"
#include "shadow_cone.hpp"
#include "stop.hpp"
#include "tolerances.hpp"

namespace exactgeo::detail {
namespace {

// A located point's position in space, in the engine's frame.
std::array<double, 3> engine_position(const SurfaceMesh& mesh, const LocatedPoint& point) {
  if (point.vertex != kNone) return mesh.position(mesh.surface_to_input[point.vertex]);
  return face_point_position(mesh, point.face, point.barycentric, PositionFrame::engine);
}

}  // namespace

VtpEngine::VtpEngine(const SurfaceMesh& mesh) : mesh_(mesh), state_(mesh) {}
VtpEngine::~VtpEngine() = default;

void VtpEngine::run(std::span<const SourceSite> sources, std::span<const LocatedPoint> targets,
                    const GeodesicOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  options_ = options;
  options_.max_distance = mesh_.to_engine_length(options.max_distance);  // the cut-off in the engine's frame
  face_sorted_ = sorts_faces(options.algorithm);
  order_preserving_ = options.algorithm == Algorithm::opvtp || options.algorithm == Algorithm::opftp;
  state_.tolerances = {kPruneTolerance * mesh_.length_scale, kMinWindowWidth * mesh_.length_scale,
                       kReemitTolerance * mesh_.length_scale, kBesidePseudoSource * mesh_.length_scale};
  stats_ = {};
  state_.cutoff = answered_up_to_ = options_.max_distance;
  sources_.assign(sources.begin(), sources.end());
  const std::uint32_t n = mesh_.vertex_count;
  const unsigned wanted = face_sorted_ ? 1 : threads_or_cores(options.threads);
  if (wanted > 1 && (!parallel_ || parallel_->threads_asked() != wanted))
    parallel_ = std::make_unique<ParallelPropagation>(*this, state_, wanted);
  threads_ = wanted > 1 ? parallel_->threads() : 1;  // fewer if the system would not start them all
  reset_state();
  vertex_queue_.reset(face_sorted_ ? 0 : n);
  face_queue_.reset(face_sorted_ ? mesh_.face_count() : 0);
  faces_to_join_.clear();
  if (face_sorted_)
    for (std::uint32_t v = 0; v < n; ++v)
      faces_to_join_.push_back(mesh_.vertex_corner_offsets[v + 1] - mesh_.vertex_corner_offsets[v]);
  pending_.clear();
  pending_front_ = 0;
  emit_queue_.clear();
  iteration_ = 0;
  state_.targets.assign(mesh_, targets);
  targets_changed_ = !targets.empty();
  // The parallel bands keep the plain order: pair_distances runs each search on one thread.
  state_.goal.clear();
  if (goal_directed_ && targets.size() == 1 && threads_ == 1) state_.goal.aim_at(engine_position(mesh_, targets[0]));
  if (options.keep_windows) {
    if (!kept_windows_) kept_windows_ = std::make_unique<FaceWindows>();
    kept_windows_->start(mesh_.halfedges.size(), threads_,
                         [&](std::size_t count, const auto& clear) { for_parts(count, clear); });
  } else {
    kept_windows_.reset();  // an ordinary run keeps nothing
  }
  stats_.threads = threads_;

  for (std::uint32_t i = 0; i < sources_.size(); ++i) {
    const std::uint32_t v = sources_[i].point.vertex;
    if (v == kNone) {
      start_point_source(i);
    } else {
      if (state_.source_label[v] == kNone) state_.source_label[v] = sources_[i].label;
      relax(v, 0.0, Arrival{v});
    }
  }
  stats_.setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (face_sorted_) {
    run_face_sorted();
  } else if (threads_ > 1) {
    parallel_->run();
  } else {
    run_vertex_sorted();
  }
  reached_complete_ = threads_ == 1 && !face_sorted_;  // only relax, on one thread, lists what it reaches
  // Paths through a corner are only final now that every vertex distance is.
  for (const std::uint32_t f : state_.targets.faces()) evaluate_targets_from_corners(f);
  targets_changed_ = true;
  update_cutoff();
  answered_up_to_ = state_.cutoff < options_.max_distance
                        ? std::min(options_.max_distance, state_.cutoff + state_.tolerances.prune)
                        : state_.cutoff;
  stats_.window_propagations = stats_.prime_propagations + stats_.secondary_propagations;
  stats_.peak_windows = state_.lists.peak_live();
  stats_.peak_window_bytes = state_.lists.arena_bytes();
  if (kept_windows_) {
    kept_windows_->finish(mesh_, state_.distance, state_.cutoff, sources_, state_.tolerances);
    stats_.kept_windows = kept_windows_->window_count();
    stats_.kept_window_bytes = kept_windows_->bytes(mesh_.halfedges.size());
  }
}

// Every vertex unseen at +inf with no label, every face outside the traversed area, every list empty, as a
// run starts: all of it, or only what the last run reached where that is known and a small part of the mesh.
void VtpEngine::reset_state() {
  const std::uint32_t n = mesh_.vertex_count;
  const bool only_reached =
      reached_complete_ && state_.distance.size() == n && reached_.size() <= n / kResetAllFromShare;
  reached_complete_ = false;  // until this run ends normally
  if (only_reached) {
    reset_reached();
    state_.lists.start_run(threads_);
    EXACTGEO_ASSERT(state_is_reset());
  } else {
    // Written on the threads, which also places the fresh pages.
    EngineState::for_each_vertex_array(state_, [&](auto& array, const auto&) { array.resize(n); });
    state_.face_visited_at.resize(mesh_.face_count());
    for_parts(n, [&](std::size_t begin, std::size_t end) {
      EngineState::for_each_vertex_array(state_, [&](auto& array, const auto& unreached) {
        std::fill(array.begin() + begin, array.begin() + end, unreached);
      });
    });
    for_parts(mesh_.face_count(), [&](std::size_t begin, std::size_t end) {
      std::fill(state_.face_visited_at.begin() + begin, state_.face_visited_at.begin() + end, kNone);
    });
    state_.lists.reset(mesh_.halfedges.size(), threads_,
                       [&](std::size_t count, const auto& clear) { for_parts(count, clear); });
  }
  reached_.clear();
}

// Resets what the last run (one thread, vertex-sorted, ended normally) changed: the state of the vertices
// it reached (relax lists each vertex the first time it reaches it; only those get a distance, and only
// vertices with a distance are queued, taken and emit) and the visits of their faces (a face joins when one of
// its corners is taken). Its lists are all empty already: the run went on until its queue ran dry, and every
// list it made lies on a side of a face with a reached corner (a crossing's windows leave across the sides
// at the corner it reaches, an emission's or a source point's across sides between corners it reaches), so
// that face joined once that corner was taken, and the list crossed it. state_is_reset checks all of that
// where assertions are on. About 80 bytes a reached vertex, against the 160 bytes a vertex of a full reset.
void VtpEngine::reset_reached() {
  for (const std::uint32_t v : reached_) {
    EngineState::for_each_vertex_array(state_, [&](auto& array, const auto& unreached) { array[v] = unreached; });
    for (std::uint32_t i = mesh_.vertex_corner_offsets[v]; i < mesh_.vertex_corner_offsets[v + 1]; ++i)
      state_.face_visited_at[face_of(mesh_.vertex_corners[i])] = kNone;
  }
}

bool VtpEngine::state_is_reset() const {
  bool reset = true;
  EngineState::for_each_vertex_array(state_, [&](const auto& array, const auto& unreached) {
    reset = reset && std::all_of(array.begin(), array.end(), [&](const auto& value) { return value == unreached; });
  });
  if (!reset) return false;
  for (std::uint32_t f = 0; f < mesh_.face_count(); ++f)
    if (state_.face_visited_at[f] != kNone) return false;
  for (std::uint32_t h = 0; h < mesh_.halfedges.size(); ++h)
    if (!state_.lists.untouched(h)) return false;
  return true;
}

const FaceWindows* VtpEngine::kept_windows() const {
  return kept_windows_ && kept_windows_->kept() ? kept_windows_.get() : nullptr;
}

// With keep_windows: the list entering face(h) through h, logged for queries after the run.
void VtpEngine::keep_entering(std::uint32_t h, std::span<const Window> list, unsigned thread) {
  kept_windows_->record(mesh_, h, list, state_.distance_now(mesh_.tail(h)), state_.distance_now(mesh_.head(h)),
                        state_.cutoff, state_.tolerances, thread);
}

// Vertex-sorted (VTP, OPVTP): each iteration pops the nearest wavefront vertex and adds all its faces.
// Flattened: the steps the one-thread loop shares with the parallel bands (move_inside, cross_list,
// hand_over, join, ...) are functions of their own, and their calls cost the one-thread run 2-5% of its time
// (measured against the engine before it had parallel rounds); inlined here, it is level with that engine again.
[[gnu::flatten]] void VtpEngine::run_vertex_sorted() {
  while (!vertex_queue_.empty()) {
    update_cutoff();
    std::uint32_t v;
    {
      const PhaseTimer timer(options_.collect_timings, stats_.queue_seconds);
      v = vertex_queue_.pop();
    }
    ++iteration_;
    enclose_vertex(v);
    drain();
  }
}

// v, just taken from the queue, moves inside: as a pseudo-source it emits, and its faces join the traversed
// area.
void VtpEngine::enclose_vertex(std::uint32_t v) {
  move_inside(v);
  if (state_.bends_paths(v)) emit(v);
  enter_faces_of(v);
}

void VtpEngine::move_inside(std::uint32_t v) {
  // A vertex's state only moves forward (unseen, queued, inside): only queued vertices are in the queue.
  EXACTGEO_ASSERT(state_.vertex_state[v] == VertexState::queued);
  state_.vertex_state[v] = VertexState::inside;
  ++stats_.vertex_pops;
  checkpoint(stats_.vertex_pops, static_cast<double>(stats_.vertex_pops) / mesh_.vertex_count);
}

void VtpEngine::enter_faces_of(std::uint32_t v) {
  state_.prefetch_faces_of(v);
  for (std::uint32_t i = mesh_.vertex_corner_offsets[v]; i < mesh_.vertex_corner_offsets[v + 1]; ++i) {
    const std::uint32_t f = face_of(mesh_.vertex_corners[i]);
    if (state_.face_visited_at[f] == kNone) enter_face(f);
  }
}

// Face-sorted (FTP, OPFTP): each iteration pops one triangle of the wavefront. Its priority (paper Section
// 5.1) is the shortest distance to its far corner through the lists waiting on its edges. A triangle that
// borders the traversed area with no window on the shared edge (behind a saddle, say, whose windows only
// its own emission brings) is queued at the larger distance of that edge's ends, so that it joins once the
// wavefront has passed it; otherwise the saddle would never be enclosed.
void VtpEngine::run_face_sorted() {
  // Sources at vertices start with their whole one-ring inside (paper Section 5.1, Initialization).
  for (const SourceSite& site : sources_) {
    const std::uint32_t v = site.point.vertex;
    if (v == kNone) {
      // A source in a face or on an edge: the faces that hold it.
      for_each_placement(mesh_, site.point, [&](const LocatedPoint& in_face) { join_face(in_face.face); });
      continue;
    }
    for (std::uint32_t i = mesh_.vertex_corner_offsets[v]; i < mesh_.vertex_corner_offsets[v + 1]; ++i)
      join_face(face_of(mesh_.vertex_corners[i]));
  }
  while (!face_queue_.empty()) {
    update_cutoff();
    std::uint32_t f;
    {
      const PhaseTimer timer(options_.collect_timings, stats_.queue_seconds);
      f = face_queue_.pop();
    }
    if (state_.face_visited_at[f] != kNone) continue;  // joined with a source's one-ring while queued
    ++stats_.face_pops;
    checkpoint(stats_.face_pops, static_cast<double>(stats_.face_pops) / mesh_.face_count());
    join_face(f);
  }
}

// Every kProgressInterval pops: stops if the caller asked for it, else reports progress.
void VtpEngine::checkpoint(std::uint64_t pops, double fraction) {
  if (pops % kProgressInterval != 0) return;
  throw_if_stopped(options_.stop);
  if (progress_) progress_(fraction);
}

// Adds f to the traversed area in the current iteration: the lists waiting on its edges will cross it.
void VtpEngine::enter_face(std::uint32_t f) {
  state_.face_visited_at[f] = iteration_;
  for (std::uint32_t h = 3 * f; h < 3 * f + 3; ++h)
    if (!state_.lists.empty(h)) schedule(h);
}

// Face-sorted: f joins the traversed area as one iteration. Then each corner whose faces have all joined is
// enclosed: a pseudo-source among them emits (paper Section 5.2, Saddle Vertices, first scenario), with the
// distance that crossing f may just have lowered. Neighbours across edges that carried no window are queued.
void VtpEngine::join_face(std::uint32_t f) {
  if (state_.face_visited_at[f] != kNone) return;
  ++iteration_;
  enter_face(f);
  drain();
  for (std::uint32_t h = 3 * f; h < 3 * f + 3; ++h) {
    const std::uint32_t v = mesh_.tail(h);
    EXACTGEO_ASSERT(faces_to_join_[v] > 0 && state_.vertex_state[v] != VertexState::inside);
    if (--faces_to_join_[v] != 0) continue;
    state_.vertex_state[v] = VertexState::inside;
    if (state_.bends_paths(v) && state_.distance[v] < HUGE_VAL) {
      emit(v);
      drain();
    }
  }
  for (std::uint32_t h = 3 * f; h < 3 * f + 3; ++h) {
    const std::uint32_t g = mesh_.twin[h];
    if (g == kNone || state_.face_visited_at[face_of(g)] != kNone || face_queue_.contains(face_of(g))) continue;
    const double key =
        state_.goal.key(mesh_, mesh_.apex(g), std::max(state_.distance[mesh_.tail(h)], state_.distance[mesh_.head(h)]));
    const PhaseTimer timer(options_.collect_timings, stats_.queue_seconds);
    face_queue_.push_or_decrease(face_of(g), key);
  }
}

// A source inside a face or on an edge: straight rays reach the corners of every face that holds it
// (placements_of) and cross their sides, so it starts as windows spanning each side it does not lie on, and as
// distances at the corners.
void VtpEngine::start_point_source(std::uint32_t site) {
  const std::uint32_t id = mesh_.vertex_count + site;
  for_each_placement(mesh_, sources_[site].point, [&](const LocatedPoint& in_face) {
    const std::uint32_t f = in_face.face;
    for_each_ray_from_point(
        mesh_, in_face, id, 0.0, state_.tolerances.min_width,
        [&](std::uint32_t u, double d, const Arrival& arrival) { relax(u, d, arrival); },
        [&](std::uint32_t g, const Window& w) { place_new_window(g, w); },
        [&](std::uint32_t u) { emit_everywhere(u); });
    // Targets in the same face are reached straight.
    if (!state_.targets.in_faces()) return;
    for (const RunTargets::InFace& in : state_.targets.in_face(f))
      reach_straight(mesh_, in_face, id, 0.0, in.at, [&](double d, const Arrival& arrival) {
        state_.targets.offer(in.target, d, arrival, state_.cutoff, targets_changed_);
      });
  });
}

// The queue push, out of line (and timed when asked): relax runs for every list crossing and stays small.
void VtpEngine::push_vertex(std::uint32_t v, double d) {
  const PhaseTimer timer(options_.collect_timings, stats_.queue_seconds);
  vertex_queue_.push_or_decrease(v, state_.goal.key(mesh_, v, d));
}

// A path of length d reaches v, arriving as `arrival` says.
void VtpEngine::relax(std::uint32_t v, double d, const Arrival& arrival) {
  EXACTGEO_ASSERT(d >= 0);  // and not NaN
  if (!(d < state_.distance[v])) return;
  if (state_.vertex_state[v] == VertexState::unseen) reached_.push_back(v);
  state_.lower(
      v, d, arrival, targets_changed_,
      [&] {
        if (!face_sorted_) push_vertex(v, d);
      },
      [&] { emit_queue_.push_back(v); });
}

void VtpEngine::schedule(std::uint32_t h) {
  WindowLists::List& list = state_.lists.record(h);
  if (list.scheduled) return;
  list.scheduled = 1;
  pending_.push_back(h);
}

// A window just created on g (by a pseudo-source or a source point): it waits on the wavefront, or moves on
// at once if g's face is already traversed.
void VtpEngine::place_new_window(std::uint32_t g, const Window& w) {
  if (state_.beyond_cutoff(w, state_.goal_across(g))) return;
  if (state_.face_visited_at[face_of(g)] != kNone) {
    state_.lists.append(g, {&w, 1}, 0);
    schedule(g);
  } else {
    if (face_sorted_) queue_face(g, {&w, 1});
    state_.lists.prepend(g, {&w, 1}, 0);
  }
}

// Face-sorted: windows arriving on g, an edge of a triangle outside the traversed area, may bring its
// priority (the distance to the corner opposite g) forward.
void VtpEngine::queue_face(std::uint32_t g, std::span<const Window> arriving) {
  if (arriving.empty()) return;
  const double key = state_.goal.key(
      mesh_, mesh_.apex(g), reach_apex(arriving, face_frame(mesh_, g), key_splits_, state_.tolerances.prune).distance);
  const PhaseTimer timer(options_.collect_timings, stats_.queue_seconds);
  face_queue_.push_or_decrease(face_of(g), key);
}

// Paper Section 5.2, "Saddle Vertices": a pseudo-source sends windows across the edges opposite to it in
// its one-ring and offers its distance to its neighbours. A shortest path bends at v only into the
// directions at least pi away, on both sides, from the direction it arrived from (else it could be
// shortened around v): only that shadow cone gets windows, which for a scan's many near-flat saddles is
// a sliver. Sources, and vertices without reliable angles, send windows everywhere.
void VtpEngine::emit(std::uint32_t v) {
  EXACTGEO_ASSERT(state_.distance[v] < HUGE_VAL);  // it was reached: queued, or enclosed with a distance
  if (state_.emission_beyond_cutoff(v, state_.distance[v])) return;
  state_.emitted_at[v] = state_.distance[v];
  ++stats_.pseudo_source_emissions;
  for_each_emission_part(
      mesh_, v, state_.distance[v], state_.arrival[v], state_.emits_everywhere[v], state_.tolerances.min_width,
      [&](std::uint32_t u, double d, const Arrival& arrival) { relax(u, d, arrival); },
      [&](std::uint32_t g, const Window& w) { place_new_window(g, w); }, [&](std::uint32_t u) { emit_everywhere(u); });
}

// Rays that no window carries pass beside u (for_each_ray_from_point): u emits everywhere, now if it is inside.
void VtpEngine::emit_everywhere(std::uint32_t u) {
  if (state_.emit_everywhere(u)) emit_queue_.push_back(u);
}

void VtpEngine::drain() {
  while (pending_front_ < pending_.size() || !emit_queue_.empty()) {
    if (!emit_queue_.empty()) {
      emit_lowered_pseudo_source();
      continue;
    }
    const std::uint32_t h = pending_[pending_front_++];
    if (pending_front_ < pending_.size()) {  // the next to cross
      state_.lists.prefetch_windows(pending_[pending_front_]);
      state_.prefetch_crossing(pending_[pending_front_]);
    }
    if (pending_front_ == pending_.size()) {
      pending_.clear();
      pending_front_ = 0;
    }
    state_.lists.record(h).scheduled = 0;
    cross(h);
  }
}

// A pseudo-source inside the traversed area whose distance dropped since it emitted emits again.
void VtpEngine::emit_lowered_pseudo_source() {
  const std::uint32_t v = emit_queue_.back();
  emit_queue_.pop_back();
  state_.emit_scheduled[v] = 0;
  if (state_.lowered_since_emission(v, state_.distance[v])) emit(v);
}

// Propagates the list entering face(h) through h across that face (paper Section 4). Flattened, like
// run_vertex_sorted, for the face-sorted variants' sake.
[[gnu::flatten]] void VtpEngine::cross(std::uint32_t h) {
  if (state_.lists.empty(h)) return;
  ++stats_.list_crossings;
  state_.prefetch_destinations(h);
  // Read in place: nothing below changes the lists until this one is cleared.
  const std::span<const Window> incoming = list_to_cross(h, 0, stats_);
  if (kept_windows_) keep_entering(h, incoming, 0);
  const bool prime = state_.face_visited_at[face_of(h)] == iteration_;
  ApexReach reach;
  Arrival at_apex;
  to_ac_.clear();
  to_bc_.clear();
  std::uint64_t propagations;
  {
    const PhaseTimer timer(options_.collect_timings, stats_.window_propagation_seconds);
    propagations = cross_list(h, incoming, splits_, to_ac_, to_bc_, reach, at_apex);
  }
  relax(mesh_.apex(h), reach.distance, at_apex);
  if (state_.targets.in_faces()) evaluate_targets(h, incoming);
  (prime ? stats_.prime_propagations : stats_.secondary_propagations) += propagations;
  state_.lists.clear(h, 0);
  deliver(prev_halfedge(h), to_ac_, mesh_.tail(h), prime);
  deliver(next_halfedge(h), to_bc_, mesh_.head(h), prime);
}

// The list entering face(h), ready to cross it: with Rules 2 and 3 on, first pruned as a whole (prune_list)
// if it gathered several runs of windows (see worth_pruning).
std::span<const Window> VtpEngine::list_to_cross(std::uint32_t h, unsigned thread, GeodesicStats& stats) {
  if (worth_pruning(state_.lists.record(h))) {
    const PhaseTimer timer(options_.collect_timings, stats.pruning_seconds);
    state_.lists.shrink_to(h, prune_list(state_.lists.edit(h), state_.tolerances), thread);
  }
  return state_.lists.view(h);
}

// Crosses `incoming`, the list entering face(h), into to_ac and to_bc (splits: scratch space) and returns the
// window propagations; `reach` and `at_apex` say how the list reaches the opposite corner C. The corners'
// distances are read as they stand, C's as it is once the list has offered its own there. Changes nothing
// of the engine's, so the parallel bands call it from several threads at once.
std::uint64_t VtpEngine::cross_list(std::uint32_t h, std::span<const Window> incoming, std::vector<double>& splits,
                                    std::vector<Window>& to_ac, std::vector<Window>& to_bc, ApexReach& reach,
                                    Arrival& at_apex) const {
  const FaceFrame frame = face_frame(mesh_, h);
  reach = reach_apex(incoming, frame, splits, state_.tolerances.prune);
  EXACTGEO_ASSERT(reach.window < incoming.size());  // some window reaches C
  const Window& best = incoming[reach.window];
  at_apex = Arrival{best.pseudo_source, h, reach.separating_point, best.px, best.py};
  const CornerDistances corners = {state_.distance_now(mesh_.tail(h)), state_.distance_now(mesh_.head(h)),
                                   std::min(state_.distance_now(mesh_.apex(h)), reach.distance)};
  return cross_face(incoming, splits, frame, reach, options_.rule1, corners,
                    exit_through(mesh_, prev_halfedge(h), mesh_.tail(h)),
                    exit_through(mesh_, next_halfedge(h), mesh_.head(h)), state_.tolerances, to_ac, to_bc);
}

// Hands windows that crossed to `side` (a halfedge of the face just crossed; their frame has `origin` at
// x = 0) to the list on the other side of that edge.
void VtpEngine::deliver(std::uint32_t side, std::vector<Window>& windows, std::uint32_t origin, bool prime) {
  if (windows.empty()) return;
  const Handover to = hand_over(side, windows, origin, prime);
  if (to.edge == kNone) return;
  windows.resize(to.count);
  if (to.joining != Joining::inside) {
    if (face_sorted_) queue_face(to.edge, windows);
    if (!state_.lists.empty(to.edge)) ++(prime ? stats_.prime_merges : stats_.secondary_merges);
  }
  const std::span<Window> list = state_.lists.extend(to.edge, windows.size(), 0);
  std::copy(windows.begin(), windows.end(), list.end() - static_cast<std::ptrdiff_t>(windows.size()));
  join(list, windows.size(), to.joining);
  if (to.joining == Joining::inside) schedule(to.edge);
}

// Of the windows that crossed to `side` (already in the frame of the halfedge on the other side, as
// cross_face leaves them), drops those beyond the cut-off (the kept ones come first), and says how they join
// that halfedge's list.
Handover VtpEngine::hand_over(std::uint32_t side, std::span<Window> windows, std::uint32_t origin, bool prime) const {
  const std::uint32_t g = mesh_.twin[side];
  if (g == kNone) return {kNone, Joining::inside, 0};  // a boundary edge: the windows leave the surface
  const bool reversed = mesh_.tail(g) != origin;
  auto kept = windows.end();
  if (state_.cutoff < HUGE_VAL) {
    const GoalAcross goal = state_.goal_across(g);
    kept =
        std::remove_if(windows.begin(), windows.end(), [&](const Window& w) { return state_.beyond_cutoff(w, goal); });
  }
  Joining joining;
  if (state_.face_inside(face_of(g)))
    joining = Joining::inside;
  else if (prime && options_.rule23)
    joining = Joining::prime_merge;
  else if (order_preserving_)
    joining = Joining::wavefront_ordered;
  else
    joining = reversed ? Joining::wavefront_back : Joining::wavefront_front;
  return {g, joining, static_cast<std::uint32_t>(kept - windows.begin())};
}

// ---------------------------------------------------------------------------------------------------
// Targets.

// The targets in face(h) through the list entering it, and from its corners (targets.hpp).
void VtpEngine::evaluate_targets(std::uint32_t h, std::span<const Window> list) {
  state_.targets.evaluate_list(mesh_, h, list, state_.cutoff, targets_changed_);
  evaluate_targets_from_corners(face_of(h));
}

void VtpEngine::evaluate_targets_from_corners(std::uint32_t f) {
  state_.targets.evaluate_from_corners(
      mesh_, f, [&](std::uint32_t v) { return state_.distance_now(v); }, state_.cutoff, targets_changed_);
}

// The cut-off: max_distance, lowered to the farthest target's distance once every target has one. A window
// that cannot come closer than that can improve no target.
void VtpEngine::update_cutoff() {
  if (!targets_changed_) return;
  targets_changed_ = false;
  state_.cutoff =
      std::min(options_.max_distance,
               state_.targets.points().empty() ? HUGE_VAL : state_.targets.farthest(mesh_, state_.distance));
}

}  // namespace exactgeo::detail
