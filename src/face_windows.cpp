// The windows kept for queries at any surface point: see face_windows.hpp, and docs/queries.md for why
// what is kept gives every point its exact distance.
#include "face_windows.hpp"

#include <algorithm>
#include <cmath>

#include "assert.hpp"
#include "targets.hpp"

namespace exactgeo::detail {
namespace {

// Whether window w (on h, of length `edge_length`) is useless in its face: a corner of h, at distance
// `tail_distance` or `head_distance` (final, or still an upper bound during the run), reaches every point
// that w reaches shorter by more than `slack`, or all those points lie beyond `cutoff`. Through w, the distance to a point
// q of the face whose ray crosses h at x is w(x) + |xq|; from h's tail A it is at most d(A) + |Aq| <=
// d(A) + x + |xq|. w(x) - x never grows with x (its slope is (x - px) / |x - p| - 1 <= 0), so w(b1) - b1
// >= d(A) means w(x) >= d(A) + x on the whole window: A beats w everywhere. The mirror image holds for the
// head B at b0. And no point through w is closer than w's closest point of the edge.
bool beaten_by_corners(const Window& w, double edge_length, double tail_distance, double head_distance,
                       double cutoff, double slack) {
  const double at_b1 = w.sigma + length(w.b1 - w.px, w.py);
  if (at_b1 - w.b1 > tail_distance + slack) return true;
  const double at_b0 = w.sigma + length(w.b0 - w.px, w.py);
  if (at_b0 - (edge_length - w.b0) > head_distance + slack) return true;
  return cutoff < HUGE_VAL && w.sigma + length(std::clamp(w.px, w.b0, w.b1) - w.px, w.py) > cutoff + slack;
}

}  // namespace

void FaceWindows::record(const SurfaceMesh& mesh, std::uint32_t h, std::span<const Window> list, double tail_distance,
                         double head_distance, double cutoff, const Tolerances& tolerances, unsigned thread) {
  const double edge_length = mesh.halfedges[h].length;
  const std::span<Window> kept = lists_.extend(h, list.size(), thread);
  std::size_t size = kept.size() - list.size();
  for (const Window& w : list)
    if (!beaten_by_corners(w, edge_length, tail_distance, head_distance, cutoff, tolerances.prune)) kept[size++] = w;
  lists_.shrink_to(h, size, thread);
}

void FaceWindows::finish(const SurfaceMesh& mesh, std::span<const double> vertex_distance, double cutoff,
                         std::span<const SourceSite> sources, const Tolerances& tolerances) {
  // Now that every distance is final, drop what the corners beat, then what another window that entered
  // through the same halfedge beats (Rule 2 over the lists of every crossing: its pruning holds for every
  // point beyond the edge, the face's inside included).
  for (std::uint32_t h = 0; h < mesh.halfedges.size(); ++h) {
    const std::span<Window> windows = lists_.edit(h);
    const double edge_length = mesh.halfedges[h].length;
    std::size_t size = 0;
    for (const Window& w : windows)
      if (!beaten_by_corners(w, edge_length, vertex_distance[mesh.tail(h)], vertex_distance[mesh.head(h)], cutoff,
                             tolerances.prune))
        windows[size++] = w;
    if (size > 1) size = prune_list(windows.first(size), tolerances);
    lists_.shrink_to(h, size, 0);
    window_count_ += size;
  }

  for (std::uint32_t i = 0; i < sources.size(); ++i) {
    const LocatedPoint& point = sources[i].point;
    if (point.vertex != kNone) continue;  // a source at a vertex is a corner, at distance 0
    for_each_placement(mesh, point, [&](const LocatedPoint& in_face) {
      face_sources_.push_back({in_face.face, mesh.vertex_count + i, in_face});
    });
  }
  std::sort(face_sources_.begin(), face_sources_.end(),
            [](const FaceSource& a, const FaceSource& b) { return a.face < b.face || (a.face == b.face && a.id < b.id); });
  kept_ = true;
}

std::uint64_t FaceWindows::bytes(std::size_t halfedge_count) const {
  return lists_.arena_bytes() + halfedge_count * sizeof(WindowLists::List) +
         face_sources_.capacity() * sizeof(FaceSource);
}

// The rules by which a run evaluates its targets (VtpEngine::evaluate_targets and the sources' own faces; the
// source, window and corner steps are targets.hpp's), over everything that entered a face that holds the
// point during the run.
double FaceWindows::reach(const SurfaceMesh& mesh, std::span<const double> vertex_distance, const LocatedPoint& point,
                          Arrival& arrival) const {
  EXACTGEO_ASSERT(kept_ && point.vertex == kNone);
  double best = HUGE_VAL;
  auto keep_shortest = [&](double d, const Arrival& reached_by) {
    if (!(d < best)) return;
    best = d;
    arrival = reached_by;
  };
  for_each_placement(mesh, point, [&](const LocatedPoint& in_face) {
    const std::uint32_t f = in_face.face;
    const auto first = std::partition_point(face_sources_.begin(), face_sources_.end(),
                                            [f](const FaceSource& s) { return s.face < f; });
    for (auto s = first; s != face_sources_.end() && s->face == f; ++s)
      reach_straight(mesh, s->point, s->id, 0.0, in_face, keep_shortest);
    for (std::uint32_t h = 3 * f; h < 3 * f + 3; ++h) {
      const auto [qx, qy] = position_in_frame(mesh, in_face, h);
      for (const Window& w : entering(h)) reach_through_window(w, h, qx, qy, keep_shortest);
    }
    reach_from_corners(
        mesh, f, [&](std::uint32_t v) { return vertex_distance[v]; }, in_face, keep_shortest);
  });
  return best;
}

}  // namespace exactgeo::detail
