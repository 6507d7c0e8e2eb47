// The targets of a run: points whose distances are evaluated as the window lists cross their faces (paper
// Section 5.2 evaluates vertices only), with the arrivals their paths are traced back from. Points inside
// faces or on edges are listed per face; a point at a vertex reads that vertex. Inline: the engine evaluates
// every list crossing a face that holds targets.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "arrival.hpp"
#include "assert.hpp"
#include "propagation.hpp"
#include "surface_mesh.hpp"
#include "surface_point.hpp"
#include "windows.hpp"

namespace exactgeo::detail {

// The ways a path reaches a point q inside a face, at (qx, qy) in the frame of h, a halfedge of that face:
// the rules of a run's targets (RunTargets) and of the points queried after it (FaceWindows::reach), written
// once. reached(d, arrival) is called with the path's length and how it arrives, if there is a path.
//
// Straight from the pseudo-source of w, a window of the list entering the face through h, if the ray to q
// crosses w.
template <class Reached>
void reach_through_window(const Window& w, std::uint32_t h, double qx, double qy, Reached&& reached) {
  double x = 0;
  const double d = distance_through_window(w, qx, qy, x);
  if (d < HUGE_VAL) reached(d, Arrival{w.pseudo_source, h, x, w.px, w.py});
}

// Straight from the face's corner opposite h, at distance at_corner (HUGE_VAL: not reached).
template <class Reached>
void reach_from_corner(const SurfaceMesh& mesh, std::uint32_t h, double at_corner, const LocatedPoint& q,
                       Reached&& reached) {
  if (at_corner == HUGE_VAL) return;
  const HalfedgeGeometry& g = mesh.halfedges[h];
  const auto [qx, qy] = position_in_frame(mesh, q, h);
  reached(at_corner + length(qx - g.apex_x, qy - g.apex_y), Arrival{mesh.apex(h), h, std::nan(""), g.apex_x, g.apex_y});
}

// Straight from a point of the face (a source inside it or on one of its edges, or a vertex on one of its
// sides: vertices_on_sides) at distance `at_from`, numbered `from_id` as Arrival::from counts, when q
// is in the same face.
template <class Reached>
void reach_straight(const SurfaceMesh& mesh, const LocatedPoint& from, std::uint32_t from_id, double at_from,
                    const LocatedPoint& q, Reached&& reached) {
  if (at_from == HUGE_VAL) return;
  const std::uint32_t h = 3 * from.face;
  const auto [sx, sy] = position_in_frame(mesh, from, h);
  const auto [qx, qy] = position_in_frame(mesh, q, h);
  reached(at_from + length(qx - sx, qy - sy), Arrival{from_id, h, std::nan(""), sx, sy});
}

// Straight from the face's corners, and from the vertices on its sides, at the distances distance_at(v)
// gives.
template <class DistanceAt, class Reached>
void reach_from_corners(const SurfaceMesh& mesh, std::uint32_t f, DistanceAt&& distance_at, const LocatedPoint& q,
                        Reached&& reached) {
  for (std::uint32_t h = 3 * f; h < 3 * f + 3; ++h) reach_from_corner(mesh, h, distance_at(mesh.apex(h)), q, reached);
  for (const VertexOnSide& on_side : vertices_on_sides(mesh, f))
    reach_straight(mesh, as_point(on_side), on_side.vertex, distance_at(on_side.vertex), q, reached);
}

class RunTargets {
 public:
  // A target inside face f or on its sides, as a point of f (one of its placements).
  struct InFace {
    std::uint32_t target;
    LocatedPoint at;
  };

  // Forgets the last run's targets and lists these, none reached yet. The per-vertex and per-face marks are
  // kept from run to run and only the last run's targets are unmarked, so that a run with a few targets on a
  // large mesh (a pair search, a nearby target) does not pay for the mesh's size.
  void assign(const SurfaceMesh& mesh, std::span<const LocatedPoint> targets) {
    for (const LocatedPoint& point : points_)
      if (point.vertex != kNone)
        for (std::uint32_t copy : mesh.copies_with(point.vertex)) is_vertex_[copy] = 0;
    for (const std::uint32_t f : faces_) face_range_[f] = kNone;
    faces_.clear();
    first_of_face_.clear();
    face_targets_.clear();
    points_.assign(targets.begin(), targets.end());
    distance_.assign(targets.size(), HUGE_VAL);
    arrival_.assign(targets.size(), Arrival{});
    // A target inside a face or on an edge is listed in every face that holds it.
    for (std::uint32_t t = 0; t < points_.size(); ++t) {
      if (points_[t].vertex != kNone) {
        // A target at a vertex is that input vertex, carried by whichever of its copies is nearest: lowering
        // any copy may lower it.
        if (is_vertex_.size() != mesh.vertex_count) is_vertex_.assign(mesh.vertex_count, 0);
        for (std::uint32_t copy : mesh.copies_with(points_[t].vertex)) is_vertex_[copy] = 1;
        continue;
      }
      for_each_placement(mesh, points_[t], [&](const LocatedPoint& at) { face_targets_.push_back({t, at}); });
    }
    if (face_targets_.empty()) return;
    // Grouped by face (in target order within one), each face's group found through face_range_.
    std::stable_sort(face_targets_.begin(), face_targets_.end(),
                     [](const InFace& a, const InFace& b) { return a.at.face < b.at.face; });
    if (face_range_.size() != mesh.face_count()) face_range_.assign(mesh.face_count(), kNone);
    for (std::uint32_t i = 0; i < face_targets_.size(); ++i) {
      const std::uint32_t f = face_targets_[i].at.face;
      if (faces_.empty() || faces_.back() != f) {
        face_range_[f] = static_cast<std::uint32_t>(faces_.size());
        faces_.push_back(f);
        first_of_face_.push_back(i);
      }
    }
    first_of_face_.push_back(static_cast<std::uint32_t>(face_targets_.size()));
  }

  const std::vector<LocatedPoint>& points() const { return points_; }
  const std::vector<double>& distances() const { return distance_; }  // in the engine's frame
  const std::vector<Arrival>& arrivals() const { return arrival_; }
  // Whether some target lies inside a face or on an edge; the faces that hold one; the targets that face f holds.
  bool in_faces() const { return !faces_.empty(); }
  const std::vector<std::uint32_t>& faces() const { return faces_; }
  std::span<const InFace> in_face(std::uint32_t f) const {
    const std::uint32_t range = face_range_[f];
    if (range == kNone) return {};
    return {face_targets_.data() + first_of_face_[range], face_targets_.data() + first_of_face_[range + 1]};
  }
  // Whether surface vertex v carries a target (is a copy of a target's input vertex).
  bool at_vertex(std::uint32_t v) const { return !is_vertex_.empty() && is_vertex_[v]; }

  // A path of length d reaches target t as `arrival` says. Sets `farthest_changed` if the target's distance
  // was not below the cut-off: it may have been the farthest.
  void offer(std::uint32_t t, double d, const Arrival& arrival, double cutoff, bool& farthest_changed) {
    double& best = distance_[t];
    if (!(d < best)) return;
    if (best >= cutoff) farthest_changed = true;
    best = d;
    arrival_[t] = arrival;
  }

  // The straight rays of a list entering face(h) reach the targets inside the face: a target q is reached
  // through window w if the ray from w's pseudo-source to q crosses the window. The list is taken before
  // Rule 1 and the vertex checks, which only prune what leaves the face.
  void evaluate_list(const SurfaceMesh& mesh, std::uint32_t h, std::span<const Window> list, double cutoff,
                     bool& farthest_changed) {
    for (const InFace& in : in_face(face_of(h))) {
      const auto [qx, qy] = position_in_frame(mesh, in.at, h);
      for (const Window& w : list)
        reach_through_window(
            w, h, qx, qy, [&](double d, const Arrival& arrival) { offer(in.target, d, arrival, cutoff, farthest_changed); });
    }
  }

  // Paths that reach a target in face f straight from one of its corners (or a vertex on its sides), at the
  // distances distance_at(v) gives.
  template <class DistanceAt>
  void evaluate_from_corners(const SurfaceMesh& mesh, std::uint32_t f, DistanceAt&& distance_at, double cutoff,
                             bool& farthest_changed) {
    for (const InFace& in : in_face(f)) {
      reach_from_corners(mesh, f, distance_at, in.at, [&](double d, const Arrival& arrival) {
        offer(in.target, d, arrival, cutoff, farthest_changed);
      });
    }
  }

  // The largest distance of a target (0 without targets), given the surface vertices' distances. A target at
  // a vertex has the smallest distance over the vertex's copies: at most each copy's, and final once the
  // wavefront has passed it, whatever the copies beyond.
  double farthest(const SurfaceMesh& mesh, std::span<const double> vertex_distance) const {
    double farthest = 0;
    for (std::uint32_t t = 0; t < points_.size(); ++t) {
      const std::uint32_t vertex = points_[t].vertex;
      const double distance = vertex != kNone
                                  ? vertex_distance[mesh.nearest_copy(mesh.surface_to_input[vertex], vertex_distance)]
                                  : distance_[t];
      farthest = std::max(farthest, distance);
    }
    return farthest;
  }

 private:
  std::vector<LocatedPoint> points_;
  std::vector<double> distance_;
  std::vector<Arrival> arrival_;
  std::vector<InFace> face_targets_;          // grouped by face
  std::vector<std::uint32_t> faces_;          // the faces holding targets, in order
  std::vector<std::uint32_t> first_of_face_;  // faces_[i]'s targets: face_targets_[first_of_face_[i], [i + 1])
  std::vector<std::uint32_t> face_range_;     // per surface face: its index in faces_, kNone if it holds none
  std::vector<std::uint8_t> is_vertex_;       // per surface vertex, once a run had a target at a vertex
};

}  // namespace exactgeo::detail
