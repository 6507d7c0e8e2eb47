// The windows kept for queries at any surface point: see face_windows.hpp, and docs/queries.md for why
// what is kept gives every point its exact distance.
#include "face_windows.hpp"

#include <algorithm>
#include <cmath>

#include "assert.hpp"

namespace exactgeo::detail {
namespace {

// Whether every point of the face that window w (on h, of length `edge_length`) reaches is reached at least
// as short from a corner of h at distance `tail_distance` or `head_distance` (final, or still an upper
// bound during the run), by more than `slack`, or lies beyond `cutoff`. Through w, the distance to a point
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

void FaceWindows::start(unsigned threads) {
  kept_ = false;
  logs_.clear();
  logs_.resize(threads);
  offsets_.clear();
  windows_.clear();
  face_sources_.clear();
}

void FaceWindows::record(const SurfaceMesh& mesh, std::uint32_t h, std::span<const Window> list, double tail_distance,
                         double head_distance, double cutoff, const Tolerances& tolerances, unsigned thread) {
  Log& log = logs_[thread];
  const double edge_length = mesh.halfedges[h].length;
  std::uint32_t logged = 0;
  for (const Window& w : list)
    if (!beaten_by_corners(w, edge_length, tail_distance, head_distance, cutoff, tolerances.prune)) {
      log.push(w);
      ++logged;
    }
  if (logged > 0) log.crossings.push_back({h, logged});
}

void FaceWindows::finish(const SurfaceMesh& mesh, std::span<const double> vertex_distance, double cutoff,
                         std::span<const SourceSite> sources, const Tolerances& tolerances) {
  // Group by halfedge without a second copy of the windows (the log is most of a keeping run's memory): a
  // count per halfedge and its prefix sums give every logged window its slot, the logs are permuted into
  // slot order where they lie, then moved into one array a chunk at a time, each chunk given back once read.
  const std::size_t halfedge_count = mesh.halfedges.size();
  offsets_.assign(halfedge_count + 1, 0);
  for (const Log& log : logs_)
    for (const Crossing& c : log.crossings) offsets_[c.halfedge + 1] += c.count;
  for (std::size_t h = 0; h < halfedge_count; ++h) offsets_[h + 1] += offsets_[h];
  const std::size_t total = offsets_.back();
  std::vector<std::uint32_t> slot;
  slot.reserve(total);
  {
    std::vector<std::uint32_t> fill(offsets_.begin(), offsets_.end() - 1);
    for (const Log& log : logs_)
      for (const Crossing& c : log.crossings)
        for (std::uint32_t i = 0; i < c.count; ++i) slot.push_back(fill[c.halfedge]++);
  }
  // Logged window i (the logs one after another) lies in its log's chunk i / kChunkWindows.
  std::vector<std::size_t> log_starts;
  for (std::size_t start = 0; const Log& log : logs_) {
    log_starts.push_back(start);
    start += log.chunks.empty() ? 0 : (log.chunks.size() - 1) * kChunkWindows + log.last_chunk_size;
  }
  const auto logged = [&](std::size_t i) -> Window& {
    std::size_t t = logs_.size() - 1;
    while (log_starts[t] > i) --t;
    const std::size_t j = i - log_starts[t];
    return logs_[t].chunks[j / kChunkWindows][j % kChunkWindows];
  };
  for (std::size_t i = 0; i < total; ++i)
    while (slot[i] != i) {  // each swap puts one window in its slot
      const std::uint32_t j = slot[i];
      std::swap(logged(i), logged(j));
      std::swap(slot[i], slot[j]);
    }
  slot = {};
  windows_.clear();
  windows_.reserve(total);
  for (Log& log : logs_)
    for (std::size_t k = 0; k < log.chunks.size(); ++k) {
      const std::size_t size = k + 1 == log.chunks.size() ? log.last_chunk_size : kChunkWindows;
      windows_.insert(windows_.end(), log.chunks[k].get(), log.chunks[k].get() + size);
      log.chunks[k].reset();
    }
  logs_.clear();
  // Now that every distance is final, drop what the corners beat, then what another window that entered
  // through the same halfedge beats (Rule 2 over the lists of every crossing: its pruning holds for every
  // point beyond the edge, the face's inside included). Kept windows move to the front, in order.
  std::uint32_t kept = 0;
  for (std::uint32_t h = 0; h < halfedge_count; ++h) {
    const std::uint32_t begin = offsets_[h], end = offsets_[h + 1];
    offsets_[h] = kept;
    const std::uint32_t first = kept;
    const double edge_length = mesh.halfedges[h].length;
    for (std::uint32_t i = begin; i < end; ++i)
      if (!beaten_by_corners(windows_[i], edge_length, vertex_distance[mesh.tail(h)], vertex_distance[mesh.head(h)],
                             cutoff, tolerances.prune))
        windows_[kept++] = windows_[i];
    if (kept - first > 1)
      kept = first + static_cast<std::uint32_t>(prune_list(std::span(windows_).subspan(first, kept - first), tolerances));
  }
  offsets_[halfedge_count] = kept;
  windows_.resize(kept);  // not shrunk to fit: a copy would hold both at once for a few percent

  for (std::uint32_t i = 0; i < sources.size(); ++i) {
    const LocatedPoint& point = sources[i].point;
    if (point.vertex != kNone) continue;  // a source at a vertex is a corner, at distance 0
    for (const LocatedPoint& in_face : {point, seen_across_edge(mesh, point)})
      if (in_face.face != kNone) face_sources_.push_back({in_face.face, mesh.vertex_count + i, in_face});
  }
  std::sort(face_sources_.begin(), face_sources_.end(),
            [](const FaceSource& a, const FaceSource& b) { return a.face < b.face || (a.face == b.face && a.id < b.id); });
  kept_ = true;
}

std::uint64_t FaceWindows::bytes() const {
  return windows_.capacity() * sizeof(Window) + offsets_.capacity() * sizeof(std::uint32_t) +
         face_sources_.capacity() * sizeof(FaceSource);
}

// The rules by which a run evaluates its targets (VtpEngine::evaluate_targets and the sources' own faces),
// over everything that entered the point's face during the run.
double FaceWindows::reach(const SurfaceMesh& mesh, std::span<const double> vertex_distance, const LocatedPoint& point,
                          Arrival& arrival) const {
  EXACTGEO_ASSERT(kept_ && point.vertex == kNone);
  const std::uint32_t f = point.face;
  double best = HUGE_VAL;
  const auto first = std::partition_point(face_sources_.begin(), face_sources_.end(),
                                          [f](const FaceSource& s) { return s.face < f; });
  for (auto s = first; s != face_sources_.end() && s->face == f; ++s) {
    const auto [sx, sy] = position_in_frame(mesh, s->point, 3 * f);
    const auto [qx, qy] = position_in_frame(mesh, point, 3 * f);
    const double d = length(qx - sx, qy - sy);
    if (d < best) {
      best = d;
      arrival = Arrival{s->id, 3 * f, std::nan(""), sx, sy};
    }
  }
  for (std::uint32_t h = 3 * f; h < 3 * f + 3; ++h) {
    const auto [qx, qy] = position_in_frame(mesh, point, h);
    for (const Window& w : entering(h)) {
      double x = 0;
      const double d = distance_through_window(w, qx, qy, x);
      if (d < best) {
        best = d;
        arrival = Arrival{w.pseudo_source, h, x, w.px, w.py};
      }
    }
  }
  for (std::uint32_t h = 3 * f; h < 3 * f + 3; ++h) {
    const double at_corner = vertex_distance[mesh.apex(h)];
    if (at_corner == HUGE_VAL) continue;
    const HalfedgeGeometry& g = mesh.halfedges[h];
    const auto [qx, qy] = position_in_frame(mesh, point, h);
    const double d = at_corner + length(qx - g.apex_x, qy - g.apex_y);
    if (d < best) {
      best = d;
      arrival = Arrival{mesh.apex(h), h, std::nan(""), g.apex_x, g.apex_y};
    }
  }
  return best;
}

}  // namespace exactgeo::detail
