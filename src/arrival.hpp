// How a run's shortest paths arrive at vertices and points, recorded as the wavefront passes them so that the
// paths can be traced back afterwards (path.cpp).
#pragma once

#include <cmath>
#include <cstdint>

#include "surface_mesh.hpp"

namespace exactgeo::detail {

// How the last straight piece of a shortest path reaches a point: from pseudo-source `from` (a surface
// vertex, or vertex_count + i for point source i), which lies at (px, py) in the frame of `halfedge`, a
// halfedge of the face the piece ends in. The piece crosses that halfedge at x = crossing, or, if crossing
// is NaN, stays inside the face (the pseudo-source is one of its corners or a source inside it). A bend at
// the crossing is allowed only where the window that carried the path ends. halfedge is kNone at a source.
struct Arrival {
  std::uint32_t from = kNone;
  std::uint32_t halfedge = kNone;
  double crossing = 0, px = 0, py = 0;

  bool operator==(const Arrival&) const = default;
};

// Whether the arrival at v = apex(a.halfedge) comes straight from a pseudo-source (not across an edge)
// nearer to v than `near`.
inline bool arrives_straight_from_within(const SurfaceMesh& mesh, const Arrival& a, double near) {
  if (a.halfedge == kNone || !std::isnan(a.crossing)) return false;
  const HalfedgeGeometry& g = mesh.halfedges[a.halfedge];
  const double dx = g.apex_x - a.px, dy = g.apex_y - a.py;
  return dx * dx + dy * dy < near * near;
}

}  // namespace exactgeo::detail
