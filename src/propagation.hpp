// Propagating a window list across one triangle (paper Section 4): the list is pruned, each window against
// its neighbours in order of start (Rules 2 and 3); Rule 1 splits it at its separating point, each part
// crosses to one opposite edge, and the crossed windows are checked against the edge's vertices (Case 12).
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "assert.hpp"
#include "windows.hpp"

namespace exactgeo::detail {

// Plain sqrt of squares: coordinates are mesh-sized, far from overflow, and std::hypot's scaling is slow.
inline double length(double dx, double dy) { return std::sqrt(dx * dx + dy * dy); }

// Triangle ABC seen from halfedge AB: A at the origin, B at (length, 0), C at (apex_x, apex_y).
struct FaceFrame {
  double length;
  double apex_x, apex_y;
  double length_ac, length_bc;
};

struct Tolerances {
  double prune;      // absolute: a window is pruned only if beaten by more than this
  double min_width;  // absolute: narrower windows are dropped
  double reemit;     // absolute: a pseudo-source inside emits again when its distance drops by more than this
  double beside;     // absolute: a vertex reached straight from a pseudo-source nearer than this emits everywhere
};

// How a list reaches C (paper Section 4.1): the shortest distance to C through any of its windows, the
// window giving it (w_s) and where that path crosses AB (the list's separating point).
struct ApexReach {
  double distance;
  std::uint32_t window;  // index into the list
  double separating_point;
  // Whether every other window reaches C longer by more than the prune tolerance, as Rule 1 needs: where
  // another comes as close (two unfoldings of one pseudo-source around a sliver, a tie on a symmetric
  // mesh), which is best is rounding, and Rule 1 would drop rays that carry shortest paths.
  bool unrivalled;
};
// Also fills `splits` with each window's own split point: where the line from its pseudo-source through C
// meets AB (rays left of it head for AC, rays right of it for BC).
ApexReach reach_apex(std::span<const Window> list, const FaceFrame& frame, std::vector<double>& splits,
                     double prune_tolerance);

// Distances known at the vertices of the triangle, for checking crossed windows against them.
struct CornerDistances {
  double a, b, c;
};

// Where windows leaving the triangle through a side go: to the halfedge across it (none on a boundary, where
// they leave the surface), whose frame starts at the same end as the side (A for AC, B for BC) or, reversed,
// at the other.
struct SideExit {
  bool open;
  bool reversed;
};

// Crosses every window of `list` (on AB, with the split points from reach_apex) into the triangle and appends
// the parts leaving through AC to `to_ac` and through BC to `to_bc`, each in the frame of the halfedge across
// that side and ordered along it, dropping parts that Rule 1 (if `rule1`) or the vertex check shows
// redundant. Returns the number of window propagations performed.
std::uint64_t cross_face(std::span<const Window> list, std::span<const double> splits, const FaceFrame& frame,
                         const ApexReach& reach, bool rule1, const CornerDistances& corners, SideExit ac_exit,
                         SideExit bc_exit, const Tolerances& tolerances, std::vector<Window>& to_ac,
                         std::vector<Window>& to_bc);

// Rule 2 (paper Section 4.2) over a whole list about to cross its face: orders the windows by start, then
// walks them once, checking each against the windows kept before it (backtracking while those get removed)
// and trimming or removing whatever part of either is longer than the other over their overlap. Returns
// the count of survivors, moved, in order, to the front. The windows must lie on one edge with all
// pseudo-sources on the same side.
// A list gathers the windows arriving from both edges of the face behind it, and from pseudo-sources, each
// run ordered along the edge but overlapping the others. In order of start, a window is next to the windows
// that overlap it, whichever run they came from: walking each run on its own, as it arrived, left a fifth of
// the windows crossing nefertiti's faces beaten everywhere by a window of another run.
std::size_t prune_list(std::span<Window> windows, const Tolerances& tolerances);

// Re-expresses a window on an edge in the frame of the halfedge on the other side of that edge: x runs
// from the same end (`reversed` false) or from the other end (true); the pseudo-source stays below.
inline Window to_twin_frame(Window w, double edge_length, bool reversed) {
  // Every window that changes frames lies on its edge, its pseudo-source below it (clamped there by
  // cross_face and by the windows' other makers).
  EXACTGEO_ASSERT(0 <= w.b0 && w.b0 <= w.b1 && w.b1 <= edge_length && w.py <= 0 && w.sigma >= 0);
  if (reversed) {
    const double b0 = edge_length - w.b1;
    w.b1 = edge_length - w.b0;
    w.b0 = b0;
    w.px = edge_length - w.px;
  }
  return w;
}

}  // namespace exactgeo::detail
