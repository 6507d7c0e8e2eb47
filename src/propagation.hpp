// Propagating a window list across one triangle (paper Section 4): Rule 1 splits the list at its
// separating point, each part crosses to one opposite edge, and the crossed windows are checked against
// the edge's vertices (Case 12) and against their neighbours in the list (Rules 2 and 3).
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
};

// How a list reaches C (paper Section 4.1): the shortest distance to C through any of its windows, the
// window giving it (w_s) and where that path crosses AB (the list's separating point).
struct ApexReach {
  double distance;
  std::uint32_t window;  // index into the list
  double separating_point;
};
// Also fills `splits` with each window's own split point: where the line from its pseudo-source through C
// meets AB (rays left of it head for AC, rays right of it for BC).
ApexReach reach_apex(std::span<const Window> list, const FaceFrame& frame, std::vector<double>& splits);

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

// Rule 2 (paper Section 4.2): walks the windows once, checking each against the windows kept before it
// (backtracking while those get removed) and trimming or removing whatever part of either is strictly
// longer than the other over their overlap. The survivors are moved, in order, to the front; returns their
// count. The windows must lie on one edge with all pseudo-sources on the same side. With already_pruned = k
// the first k windows are taken as pruned among themselves: that is Rule 3 (PrimeMerge, paper Section 4.3),
// which appends a newly crossed list to the list already on the edge and continues the walk across the
// junction.
std::size_t prune_neighbours(std::span<Window> windows, std::size_t already_pruned, const Tolerances& tolerances);

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
