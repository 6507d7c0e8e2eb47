// The VTP driver (paper Section 5.2, Algorithm 1): a priority queue of wavefront vertices; popping one
// adds its unvisited faces to the traversed area and propagates the window lists entering them, and
// whatever those lists reach inside the traversed area, until every list is pruned, has died on the
// boundary or waits on an edge of the wavefront.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <array>
#include <deque>
#include <numbers>
#include <string>

#include "exactgeo/error.hpp"
#include "exactgeo/geodesic.hpp"
#include "propagation.hpp"
#include "surface_mesh.hpp"
#include "tolerances.hpp"
#include "vertex_queue.hpp"
#include "windows.hpp"

namespace exactgeo {
namespace detail {
namespace {

enum class VertexState : std::uint8_t { unseen, queued, inside };

// How the last straight piece of a vertex's path arrives: through the point (position, 0) of `halfedge`,
// whose apex is the vertex. kNone for sources.
struct Arrival {
  std::uint32_t halfedge;
  double position;
};

// A set of directions around a vertex, as fan angles (SurfaceMesh::fan_angle_start), in up to two intervals.
class ShadowCone {
 public:
  static ShadowCone everything() { return ShadowCone({{{-HUGE_VAL, HUGE_VAL}, {0.0, 0.0}}}, 1, 0.0); }

  // The directions at least pi away on both sides from the arrival direction `arrival`, around a fan of
  // `total` angle that is closed (an interior vertex) or open (a boundary vertex, angles in [0, total]).
  static ShadowCone behind(double arrival, double total, bool closed) {
    if (closed)  // one interval, to be compared modulo the total angle
      return ShadowCone({{{arrival + std::numbers::pi - kShadowConeSlack,
                           arrival + total - std::numbers::pi + kShadowConeSlack},
                          {0.0, 0.0}}},
                        1, total);
    return ShadowCone({{{arrival + std::numbers::pi - kShadowConeSlack, HUGE_VAL},
                        {-HUGE_VAL, arrival - std::numbers::pi + kShadowConeSlack}}},
                      2, 0.0);
  }

  // The part [b0, b1] of the edge opposite to corner c (in the frame of halfedge next(c)) that rays from
  // the vertex in these directions reach; b1 <= b0 if none. Two separate parts are merged into one span:
  // a wider window is redundant, never wrong.
  std::pair<double, double> part_of_opposite_edge(const SurfaceMesh& mesh, std::uint32_t c) const {
    const double corner_angle = mesh.corner_angle[c];
    const double start = mesh.fan_angle_start[c];
    double lowest = HUGE_VAL, highest = -HUGE_VAL;
    for (int i = 0; i < count_; ++i) {
      for (int wrap = -1; wrap <= 1; ++wrap) {
        if (wrap != 0 && period_ == 0) continue;
        const double a0 = std::max(intervals_[i][0] + wrap * period_, start);
        const double a1 = std::min(intervals_[i][1] + wrap * period_, start + corner_angle);
        if (a1 < a0) continue;
        lowest = std::min(lowest, a0 - start);
        highest = std::max(highest, a1 - start);
      }
    }
    if (lowest > highest) return {0.0, 0.0};
    if (!mesh.corner_enters_forward[c]) {  // fan angles run from the corner's other edge
      const double flipped_low = corner_angle - highest;
      highest = corner_angle - lowest;
      lowest = flipped_low;
    }
    // A ray at angle phi from edge c meets the opposite edge XY at |vX| sin(phi) / sin(phi + angle at X).
    const std::uint32_t opposite = next_halfedge(c);
    const HalfedgeGeometry& o = mesh.halfedges[opposite];
    const double angle_at_x = mesh.corner_angle[opposite];
    const double to_x = mesh.halfedges[c].length;
    auto hit = [&](double phi) {
      if (phi <= 0) return 0.0;
      if (phi >= corner_angle) return o.length;
      return std::clamp(to_x * std::sin(phi) / std::sin(phi + angle_at_x), 0.0, o.length);
    };
    return {hit(lowest), hit(highest)};
  }

 private:
  ShadowCone(std::array<std::array<double, 2>, 2> intervals, int count, double period)
      : intervals_(intervals), count_(count), period_(period) {}
  std::array<std::array<double, 2>, 2> intervals_;
  int count_;
  double period_;  // the fan's total angle for a closed fan, 0 for an open one
};

class VtpEngine {
 public:
  VtpEngine(const SurfaceMesh& mesh, const GeodesicOptions& options)
      : mesh_(mesh),
        options_(options),
        tolerances_{kPruneTolerance * mesh.length_scale, kMinWindowWidth * mesh.length_scale} {}

  // Sources are surface vertices; source_of_vertex[v] names the source index a source vertex belongs to.
  void run(std::span<const std::uint32_t> source_vertices, std::span<const std::uint32_t> source_index) {
    const std::uint32_t n = mesh_.vertex_count;
    distance_.assign(n, HUGE_VAL);
    emitted_at_.assign(n, HUGE_VAL);
    parent_.assign(n, kNone);
    arrival_.assign(n, {kNone, 0.0});
    state_.assign(n, VertexState::unseen);
    emit_scheduled_.assign(n, 0);
    source_label_.assign(n, kNone);
    face_visited_at_.assign(mesh_.face_count(), kNone);
    scheduled_.assign(mesh_.halfedges.size(), 0);
    lists_.reset(mesh_.halfedges.size());
    queue_.reset(n);
    iteration_ = 0;

    for (std::size_t i = 0; i < source_vertices.size(); ++i) {
      const std::uint32_t s = source_vertices[i];
      source_label_[s] = source_index[i];
      relax(s, 0.0, s, {kNone, 0.0});
    }
    while (!queue_.empty()) {
      const std::uint32_t v = queue_.pop();
      state_[v] = VertexState::inside;
      ++iteration_;
      ++stats_.vertex_pops;
      if (bends_paths(v)) emit(v);
      for (std::uint32_t i = mesh_.vertex_corner_offsets[v]; i < mesh_.vertex_corner_offsets[v + 1]; ++i) {
        const std::uint32_t f = face_of(mesh_.vertex_corners[i]);
        if (face_visited_at_[f] != kNone) continue;
        face_visited_at_[f] = iteration_;
        for (std::uint32_t h = 3 * f; h < 3 * f + 3; ++h)
          if (!lists_.empty(h)) schedule(h);
      }
      drain();
    }
    stats_.peak_windows = lists_.peak_live();
    stats_.peak_window_bytes = lists_.arena_bytes();
  }

  const std::vector<double>& distances() const { return distance_; }
  GeodesicStats& stats() { return stats_; }

  // The source each surface vertex's path starts from: the label of the first vertex on its chain of
  // pseudo-sources that is a source. Parents are reached with strictly smaller distances, so resolving
  // vertices in order of distance needs one step each.
  std::vector<std::uint32_t> nearest_sources() const {
    std::vector<std::uint32_t> order;
    for (std::uint32_t v = 0; v < mesh_.vertex_count; ++v)
      if (distance_[v] < HUGE_VAL) order.push_back(v);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
      return distance_[a] < distance_[b] || (distance_[a] == distance_[b] && a < b);
    });
    std::vector<std::uint32_t> label(mesh_.vertex_count, kNone);
    for (std::uint32_t v : order)
      label[v] = source_label_[v] != kNone ? source_label_[v] : label[parent_[v]];
    // A parent at exactly the same distance (across a zero-length edge) may come later in that order.
    for (std::uint32_t v : order)
      for (std::uint32_t u = v, steps = 0; label[v] == kNone && u != kNone && steps <= mesh_.vertex_count; ++steps)
        label[v] = label[u = parent_[u]];
    return label;
  }

 private:
  // The directions around v (as fan angles, see SurfaceMesh) into which a shortest path arriving at v can
  // continue without being shortcut: at least pi from the arrival direction on both sides.
  ShadowCone shadow_cone(std::uint32_t v) const {
    const Arrival a = arrival_[v];
    if (a.halfedge == kNone || !mesh_.fan_angles_reliable[v]) return ShadowCone::everything();
    // The path reaches v = apex(h) from the point (t, 0) of h; measure that direction in v's corner of
    // face(h), from its edge towards tail(h), then as a fan angle.
    const HalfedgeGeometry& g = mesh_.halfedges[a.halfedge];
    const double to_a_x = -g.apex_x, to_a_y = -g.apex_y;
    const double to_t_x = a.position - g.apex_x, to_t_y = -g.apex_y;
    const double local = std::atan2(std::abs(to_a_x * to_t_y - to_a_y * to_t_x), to_a_x * to_t_x + to_a_y * to_t_y);
    const std::uint32_t corner = prev_halfedge(a.halfedge);  // leaves v towards tail(h)
    const double corner_angle = mesh_.corner_angle[corner];
    const double arrival = mesh_.fan_angle_start[corner] +
                           (mesh_.corner_enters_forward[corner] ? local : corner_angle - local);
    return ShadowCone::behind(arrival, mesh_.fan_total_angle[v], mesh_.fan_closed[v]);
  }

  bool bends_paths(std::uint32_t v) const { return mesh_.is_pseudo_source[v] || source_label_[v] != kNone; }

  // A path of length d reaches v, its last straight piece starting at pseudo-source `from` and arriving
  // through `arrival` (kNone for a source).
  void relax(std::uint32_t v, double d, std::uint32_t from, Arrival arrival) {
    if (!(d < distance_[v])) return;
    distance_[v] = d;
    parent_[v] = from;
    arrival_[v] = arrival;
    if (state_[v] != VertexState::inside) {
      state_[v] = VertexState::queued;
      queue_.push_or_decrease(v, d);
    } else if (bends_paths(v) && d < emitted_at_[v] - tolerances_.prune && !emit_scheduled_[v]) {
      // Paper Section 5.2, third scenario: a pseudo-source inside the traversed area got shorter.
      emit_scheduled_[v] = 1;
      emit_queue_.push_back(v);
    }
  }

  void schedule(std::uint32_t h) {
    if (scheduled_[h]) return;
    scheduled_[h] = 1;
    pending_.push_back(h);
  }

  // Paper Section 5.2, "Saddle Vertices": a pseudo-source sends windows across the edges opposite to it in
  // its one-ring and offers its distance to its neighbours. A shortest path bends at v only into the
  // directions at least pi away, on both sides, from the direction it arrived from (else it could be
  // shortened around v): only that shadow cone gets windows, which for a scan's many near-flat saddles is
  // a sliver. Sources, and vertices without reliable angles, send windows everywhere.
  void emit(std::uint32_t v) {
    emitted_at_[v] = distance_[v];
    ++stats_.pseudo_source_emissions;
    const ShadowCone cone = shadow_cone(v);
    for (std::uint32_t i = mesh_.vertex_corner_offsets[v]; i < mesh_.vertex_corner_offsets[v + 1]; ++i) {
      const std::uint32_t c = mesh_.vertex_corners[i];  // halfedge leaving v
      const std::uint32_t opposite = next_halfedge(c);
      relax(mesh_.head(c), distance_[v] + mesh_.halfedges[c].length, v, {prev_halfedge(c), mesh_.halfedges[prev_halfedge(c)].length});
      relax(mesh_.apex(c), distance_[v] + mesh_.halfedges[prev_halfedge(c)].length, v, {c, 0.0});
      const std::uint32_t g = mesh_.twin[opposite];
      if (g == kNone) continue;
      const HalfedgeGeometry& o = mesh_.halfedges[opposite];
      const auto [b0, b1] = cone.part_of_opposite_edge(mesh_, c);
      if (!(b1 - b0 > tolerances_.min_width)) continue;
      Window w{b0, b1, o.apex_x, -o.apex_y, distance_[v], v};
      w = to_twin_frame(w, o.length, mesh_.tail(g) != mesh_.tail(opposite));
      if (face_visited_at_[face_of(g)] != kNone) {
        lists_.append(g, {&w, 1});
        schedule(g);
      } else {
        lists_.prepend(g, {&w, 1});
      }
    }
  }

  void drain() {
    while (!pending_.empty() || !emit_queue_.empty()) {
      if (!emit_queue_.empty()) {
        const std::uint32_t v = emit_queue_.back();
        emit_queue_.pop_back();
        emit_scheduled_[v] = 0;
        if (distance_[v] < emitted_at_[v] - tolerances_.prune) emit(v);
        continue;
      }
      const std::uint32_t h = pending_.front();
      pending_.pop_front();
      scheduled_[h] = 0;
      cross(h);
    }
  }

  // Propagates the list entering face(h) through h across that face (paper Section 4).
  void cross(std::uint32_t h) {
    // Read in place: nothing below changes the lists until this one is cleared.
    const std::span<const Window> incoming = lists_.view(h);
    if (incoming.empty()) return;
    const HalfedgeGeometry& g = mesh_.halfedges[h];
    const FaceFrame frame{g.length, g.apex_x, g.apex_y, mesh_.halfedges[prev_halfedge(h)].length,
                          mesh_.halfedges[next_halfedge(h)].length};
    const std::uint32_t a = mesh_.tail(h), b = mesh_.head(h), c = mesh_.apex(h);
    const ApexReach reach = reach_apex(incoming, frame, splits_);
    relax(c, reach.distance, incoming[reach.window].pseudo_source, {h, reach.separating_point});

    to_ac_.clear();
    to_bc_.clear();
    stats_.window_propagations += cross_face(incoming, splits_, frame, reach, options_.rule1,
                                             {distance_[a], distance_[b], distance_[c]}, tolerances_, to_ac_, to_bc_);
    lists_.clear(h);
    const bool prime = face_visited_at_[face_of(h)] == iteration_;
    deliver(prev_halfedge(h), to_ac_, a, prime);
    deliver(next_halfedge(h), to_bc_, b, prime);
  }

  // Hands windows that crossed to `side` (a halfedge of the face just crossed; their frame has `origin` at
  // x = 0) to the list on the other side of that edge.
  void deliver(std::uint32_t side, std::vector<Window>& windows, std::uint32_t origin, bool prime) {
    if (windows.empty()) return;
    const std::uint32_t g = mesh_.twin[side];
    if (g == kNone) return;  // a boundary edge: the windows leave the surface
    const bool reversed = mesh_.tail(g) != origin;
    const double length = mesh_.halfedges[side].length;
    for (Window& w : windows) w = to_twin_frame(w, length, reversed);
    if (reversed) std::reverse(windows.begin(), windows.end());  // keep the list ordered along g

    const bool inside = face_visited_at_[face_of(g)] != kNone;
    if (!inside && prime && options_.rule23) {
      // Rule 3: PrimeMerge on a new wavefront edge. The Rule 2 walk over the crossed windows continues from
      // the list already there, so it prunes them among themselves and across the junction in one pass.
      const std::span<Window> list = lists_.extend(g, windows.size());
      const std::size_t old_size = list.size() - windows.size();
      std::copy(windows.begin(), windows.end(), list.begin() + static_cast<std::ptrdiff_t>(old_size));
      lists_.shrink_to(g, prune_neighbours(list, old_size, tolerances_));
      return;
    }
    if (options_.rule23) windows.resize(prune_neighbours(windows, 0, tolerances_));  // Rule 2
    if (inside) {  // inside the traversed area: keep moving
      lists_.append(g, windows);
      schedule(g);
    } else if (!reversed) {  // order-free SecondMerge: windows from the side of g's tail go first
      lists_.prepend(g, windows);
    } else {
      lists_.append(g, windows);
    }
  }

  const SurfaceMesh& mesh_;
  GeodesicOptions options_;
  Tolerances tolerances_;
  GeodesicStats stats_;

  std::vector<double> distance_, emitted_at_;
  std::vector<Arrival> arrival_;
  std::vector<std::uint32_t> parent_, source_label_, face_visited_at_;
  std::vector<VertexState> state_;
  std::vector<std::uint8_t> scheduled_, emit_scheduled_;
  std::uint32_t iteration_ = 0;
  WindowLists lists_;
  VertexQueue queue_;
  std::deque<std::uint32_t> pending_;
  std::vector<std::uint32_t> emit_queue_;
  std::vector<Window> to_ac_, to_bc_;
  std::vector<double> splits_;
};

}  // namespace
}  // namespace detail

GeodesicResult geodesic_distance(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                                 const GeodesicOptions& options) {
  const detail::SurfaceMesh& surface = mesh.surface();
  if (source_vertices.empty()) throw Error(ErrorCode::invalid_argument, "no source vertex given");
  std::vector<std::uint32_t> surface_sources, source_index;
  for (std::size_t i = 0; i < source_vertices.size(); ++i) {
    const std::uint32_t v = source_vertices[i];
    if (v >= mesh.vertex_count())
      throw Error(ErrorCode::invalid_argument, "source vertex " + std::to_string(v) + " is out of range (mesh has " +
                                                   std::to_string(mesh.vertex_count()) + " vertices)");
    const auto copies = surface.copies_of(v);
    if (copies.empty())
      throw Error(ErrorCode::invalid_argument, "source vertex " + std::to_string(v) + " is used by no face");
    for (std::uint32_t s : copies) {
      surface_sources.push_back(s);
      source_index.push_back(static_cast<std::uint32_t>(i));
    }
  }

  const auto start = std::chrono::steady_clock::now();
  detail::VtpEngine engine(surface, options);
  engine.run(surface_sources, source_index);
  GeodesicResult result;
  result.stats = engine.stats();
  result.distances.assign(mesh.vertex_count(), HUGE_VAL);
  result.nearest_source.assign(mesh.vertex_count(), kNoSource);
  const std::vector<double>& d = engine.distances();
  // With one source every reachable vertex belongs to it; otherwise follow the pseudo-source chains.
  const std::vector<std::uint32_t> labels =
      source_vertices.size() > 1 ? engine.nearest_sources() : std::vector<std::uint32_t>();
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    for (std::uint32_t s : surface.copies_of(v)) {
      if (d[s] < result.distances[v]) {
        result.distances[v] = d[s];
        result.nearest_source[v] = labels.empty() ? 0 : labels[s];
      }
    }
  }
  result.stats.propagation_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

GeodesicResult geodesic_distance(const Mesh& mesh, std::uint32_t source_vertex, const GeodesicOptions& options) {
  return geodesic_distance(mesh, std::span<const std::uint32_t>(&source_vertex, 1), options);
}

}  // namespace exactgeo
