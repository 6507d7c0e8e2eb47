// The state of a run that both drivers of the engine change: the sequential steps of VtpEngine and the
// concurrent ones of ParallelPropagation (parallel_propagation.hpp), which do the same under the locks of
// what they change. Each rule they share is an inline member here, written once (lower: a vertex reached
// shorter), so that neither driver pays a call for it.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>

#include "arrival.hpp"
#include "cache_hint.hpp"
#include "goal.hpp"
#include "propagation.hpp"
#include "surface_mesh.hpp"
#include "targets.hpp"
#include "windows.hpp"

namespace exactgeo::detail {

// A vertex's state only moves forward: reached by no path yet, on the wavefront, inside the traversed area.
enum class VertexState : std::uint8_t { unseen, queued, inside };

struct EngineState {
  explicit EngineState(const SurfaceMesh& surface) : mesh(surface) {}

  const SurfaceMesh& mesh;
  Tolerances tolerances{};
  double cutoff = HUGE_VAL;  // distances above it are not final
  RunTargets targets;
  Goal goal;  // of a goal-directed run (VtpEngine::set_goal_directed), else none
  // Per surface vertex.
  MeshArray<double> distance, emitted_at;
  MeshArray<Arrival> arrival;
  MeshArray<std::uint32_t> source_label;  // the label of the source there, kNone elsewhere
  MeshArray<VertexState> vertex_state;
  MeshArray<std::uint8_t> emit_scheduled;
  // Whether the vertex bends paths in every direction: a pseudo-source reached it straight from nearer than
  // tolerances.beside (arrival.hpp; tolerances.hpp, kBesidePseudoSource), or the rays of a point graze a side's line
  // past it (shadow_cone.hpp, for_each_ray_from_point).
  MeshArray<std::uint8_t> emits_everywhere;
  // Each per-vertex array above with the value it holds at a vertex no run has reached: the one list the full
  // reset, the reset of what a run reached and their check read (VtpEngine::reset_state), so that an array added
  // here is reset everywhere. `state` is this state or a const one.
  template <class State, class Visit>
  static void for_each_vertex_array(State& state, Visit&& visit) {
    visit(state.distance, HUGE_VAL);
    visit(state.emitted_at, HUGE_VAL);
    visit(state.arrival, Arrival{});
    visit(state.source_label, kNone);
    visit(state.vertex_state, VertexState::unseen);
    visit(state.emit_scheduled, std::uint8_t{0});
    visit(state.emits_everywhere, std::uint8_t{0});
  }
  // Per surface face: the iteration in which it joined the traversed area, kNone before.
  MeshArray<std::uint32_t> face_visited_at;
  WindowLists lists;  // per halfedge: the windows entering its face through it

  // The flag is read atomically: on threads, another may be setting it (under v's lock, in lower or emit_everywhere).
  bool bends_paths(std::uint32_t v) const {
    return mesh.is_pseudo_source[v] || source_label[v] != kNone ||
           std::atomic_ref<std::uint8_t>(const_cast<std::uint8_t&>(emits_everywhere[v]))
               .load(std::memory_order_relaxed);
  }
  // v emits everywhere from now on (under v's lock, on threads). Returns whether it must emit now: it is inside the
  // traversed area with a distance, where it has emitted (in its shadow cone) or, bending no paths, would not.
  bool emit_everywhere(std::uint32_t v) {
    if (emits_everywhere[v]) return false;
    std::atomic_ref<std::uint8_t>(emits_everywhere[v]).store(1, std::memory_order_relaxed);
    if (vertex_state[v] != VertexState::inside || !(distance[v] < HUGE_VAL) || emit_scheduled[v]) return false;
    emitted_at[v] = HUGE_VAL;
    emit_scheduled[v] = 1;
    return true;
  }
  // Whether distance d of v, inside the traversed area, is enough below the one it emitted at to emit again.
  bool lowered_since_emission(std::uint32_t v, double d) const { return d < emitted_at[v] - tolerances.reemit; }

  // v's distance as it stands, while other threads may be lowering it (under v's lock).
  double distance_now(std::uint32_t v) const {
    return std::atomic_ref<double>(const_cast<double&>(distance[v])).load(std::memory_order_relaxed);
  }
  // Whether f is in the traversed area, while other threads may be adding faces to it.
  bool face_inside(std::uint32_t f) const {
    return std::atomic_ref<std::uint32_t>(const_cast<std::uint32_t&>(face_visited_at[f]))
               .load(std::memory_order_relaxed) != kNone;
  }

  // The goal tests (goal.hpp) with this run's goal, cut-off and tolerance.
  GoalAcross goal_across(std::uint32_t h) const { return goal.across(mesh, h); }
  bool beyond_cutoff(const Window& w, const GoalAcross& across) const {
    return window_beyond_cutoff(w, across, cutoff, tolerances.prune);
  }
  bool emission_beyond_cutoff(std::uint32_t v, double d) const {
    return goal.emission_beyond_cutoff(mesh, v, d, cutoff, tolerances.prune);
  }

  // Cache hints for the records entering v's faces reads: each face's visit and its three lists.
  void prefetch_faces_of(std::uint32_t v) const {
    for (std::uint32_t i = mesh.vertex_corner_offsets[v]; i < mesh.vertex_corner_offsets[v + 1]; ++i) {
      const std::uint32_t f = face_of(mesh.vertex_corners[i]);
      prefetch(&face_visited_at[f]);
      lists.prefetch_record(3 * f);
      lists.prefetch_record(3 * f + 2);  // the three records may straddle a cache line
    }
  }

  // Cache hints for a face's frames, twins and corners (its halfedges' frames may straddle a cache line).
  void prefetch_face(std::uint32_t f) const {
    prefetch(&mesh.halfedges[3 * f]);
    prefetch(&mesh.halfedges[3 * f + 2]);
    prefetch(&mesh.twin[3 * f]);
    prefetch(&mesh.corner_vertex[3 * f]);
  }

  // Cache hints for what crossing the list on h reads first: its record and its face. Issued one list ahead
  // by the sequential engine (drain), which asks for the list's windows too.
  void prefetch_crossing(std::uint32_t h) const {
    lists.prefetch_record(h);
    prefetch_face(face_of(h));
  }

  // Cache hints for what the list on h reads once it has crossed: the distances at its face's corners, the
  // opposite corner's records for relaxing it, and the lists, faces and face frames its windows go to (a list
  // reached inside the traversed area most often crosses next). Issued as the list starts to cross, so that
  // they arrive during the pruning and crossing. Reads only the mesh.
  void prefetch_destinations(std::uint32_t h) const {
    const std::uint32_t first = h - h % 3;
    for (std::uint32_t corner = first; corner < first + 3; ++corner) prefetch(&distance[mesh.tail(corner)]);
    const std::uint32_t apex = mesh.apex(h);
    prefetch(&arrival[apex]);
    prefetch(&vertex_state[apex]);
    for (const std::uint32_t side : {prev_halfedge(h), next_halfedge(h)}) {
      const std::uint32_t g = mesh.twin[side];
      if (g == kNone) continue;
      lists.prefetch_record(g);
      prefetch(&face_visited_at[face_of(g)]);
      prefetch_face(face_of(g));
    }
  }

  // A path of length d, shorter than v's distance, reaches v: the one rule of VtpEngine::relax and
  // ParallelPropagation::relax_concurrently, which hold v. Outside the traversed area v is queued (queue()); inside, a
  // pseudo-source lowered enough since it emitted emits again (emit_again()), once however often it is
  // lowered meanwhile. The distance is stored atomically: other threads read it without v's lock
  // (distance_now).
  template <class Queue, class EmitAgain>
  void lower(std::uint32_t v, double d, const Arrival& reached_by, bool& targets_changed, Queue&& queue,
             EmitAgain&& emit_again) {
    if (targets.at_vertex(v) && distance[v] >= cutoff) targets_changed = true;
    std::atomic_ref<double>(distance[v]).store(d, std::memory_order_relaxed);
    arrival[v] = reached_by;
    if (arrives_straight_from_within(mesh, reached_by, tolerances.beside))
      std::atomic_ref<std::uint8_t>(emits_everywhere[v]).store(1, std::memory_order_relaxed);
    if (vertex_state[v] != VertexState::inside) {
      vertex_state[v] = VertexState::queued;
      queue();
    } else if (bends_paths(v) && lowered_since_emission(v, d) && !emit_scheduled[v]) {
      // Paper Section 5.2, third scenario: a pseudo-source inside the traversed area got shorter.
      emit_scheduled[v] = 1;
      emit_again();
    }
  }
};

}  // namespace exactgeo::detail
