// The shadow cone of a pseudo-source (paper Section 5.2, "Saddle Vertices"): the directions around a vertex
// into which a shortest path that arrived there can go on, at least pi from its arrival direction on both
// sides, and the part of each opposite edge that rays in those directions reach. Only these get windows when
// the vertex emits, which for_each_emission_part lists, and the rays of a point (a source, or a pseudo-source
// on a side) across the faces that hold it. Inline: the engine asks once per emission.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "arrival.hpp"
#include "propagation.hpp"
#include "surface_mesh.hpp"
#include "surface_point.hpp"
#include "tolerances.hpp"
#include "windows.hpp"

namespace exactgeo::detail {

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
        // Clamped to the corner from it, not as fan angles: a cone that holds the whole corner then gives its
        // ends exactly, where (start + corner_angle) - start could miss by an ulp of the fan angle, which the
        // thin corner of a near-sliver at the opposite edge's end magnifies to 1e-4 of the edge (a wedge that
        // the windows of a source on the sliver missed).
        const double a0 = std::max(intervals_[i][0] + wrap * period_ - start, 0.0);
        const double a1 = std::min(intervals_[i][1] + wrap * period_ - start, corner_angle);
        if (a1 < a0) continue;
        lowest = std::min(lowest, a0);
        highest = std::max(highest, a1);
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

// The directions around v (as fan angles, see SurfaceMesh) into which a shortest path arriving at v as
// `a` says can continue without being shortcut: at least pi from the arrival direction on both sides.
inline ShadowCone shadow_cone(const SurfaceMesh& mesh, std::uint32_t v, const Arrival& a) {
  if (a.halfedge == kNone || !mesh.fan_angles_reliable[v]) return ShadowCone::everything();
  // The path reaches v = apex(h) from the point where it crosses h, or straight from the pseudo-source in
  // the face; measure that direction in v's corner of face(h), from its edge towards tail(h), then as a fan
  // angle.
  const HalfedgeGeometry& g = mesh.halfedges[a.halfedge];
  const bool crosses = !std::isnan(a.crossing);
  const double to_a_x = -g.apex_x, to_a_y = -g.apex_y;
  const double to_t_x = (crosses ? a.crossing : a.px) - g.apex_x, to_t_y = (crosses ? 0.0 : a.py) - g.apex_y;
  const double local = std::atan2(std::abs(to_a_x * to_t_y - to_a_y * to_t_x), to_a_x * to_t_x + to_a_y * to_t_y);
  const std::uint32_t corner = prev_halfedge(a.halfedge);  // leaves v towards tail(h)
  const double corner_angle = mesh.corner_angle[corner];
  const double arrival = mesh.fan_angle_start[corner] +
                         (mesh.corner_enters_forward[corner] ? local : corner_angle - local);
  return ShadowCone::behind(arrival, mesh.fan_total_angle[v], mesh.fan_closed[v]);
}

// The straight rays from a point of face(in_face.face) at distance d (a source point at 0, or a pseudo-source
// on one of the face's sides), numbered `id` as Arrival::from counts: offer(u, distance, arrival) for each
// corner u, place(g, window) for a window across each side the point does not lie on (from a side's line it
// would be seen under a zero angle: those rays run into the face beyond as another placement of the point).
// A point within min_width of a side's line but beyond one of its ends (a stack of near-slivers) is no
// placement beyond the side and sends it no window either: the rays that cross the side graze its line past
// that end, u, within min_width of it, and graze(u) has u emit everywhere in their stead (the paths through u
// are longer by about min_width squared over their length).
template <class Offer, class Place, class Graze>
void for_each_ray_from_point(const SurfaceMesh& mesh, const LocatedPoint& in_face, std::uint32_t id, double d,
                             double min_width, Offer&& offer, Place&& place, Graze&& graze) {
  for (std::uint32_t h = 3 * in_face.face; h < 3 * in_face.face + 3; ++h) {
    const auto [x, y] = position_in_frame(mesh, in_face, h);
    const HalfedgeGeometry& g = mesh.halfedges[h];
    offer(mesh.apex(h), d + length(g.apex_x - x, g.apex_y - y), Arrival{id, h, std::nan(""), x, y});
    const std::uint32_t across = mesh.twin[h];
    if (across == kNone || !(g.length > min_width)) continue;
    if (!(y > min_width)) {
      if (!lies_on_side(mesh, in_face, h)) graze(x < 0 ? mesh.tail(h) : mesh.head(h));
      continue;
    }
    place(across, to_twin_frame(Window{0, g.length, x, -y, d, id}, g.length, mesh.tail(across) != mesh.tail(h)));
  }
}

// The parts of pseudo-source v's emission at distance d, reached as `arrival` says, in order: offer(u,
// distance, arrival) for each neighbour u, place(g, window) for each window wider than min_width across the
// edges opposite v, within its shadow cone, or `everywhere`. Reads only the mesh.
// Where an opposite side runs through v (a face of no area: the sliver that closes a T-junction, v at the
// junction), v is a point of that side, and its rays run on into the faces beyond, as a source point's do:
// those placements of v emit everything (v's fan angles are not reliable there anyway), and graze(u) as
// for_each_ray_from_point says.
template <class Offer, class Place, class Graze>
void for_each_emission_part(const SurfaceMesh& mesh, std::uint32_t v, double d, const Arrival& arrival, bool everywhere,
                            double min_width, Offer&& offer, Place&& place, Graze&& graze) {
  const ShadowCone cone = everywhere ? ShadowCone::everything() : shadow_cone(mesh, v, arrival);
  LocatedPoint on_a_side;  // v as a corner of a face whose opposite side holds it, if any
  for (std::uint32_t i = mesh.vertex_corner_offsets[v]; i < mesh.vertex_corner_offsets[v + 1]; ++i) {
    const std::uint32_t c = mesh.vertex_corners[i];  // halfedge leaving v
    const std::uint32_t opposite = next_halfedge(c), back = prev_halfedge(c);
    offer(mesh.head(c), d + mesh.halfedges[c].length, Arrival{v, back, std::nan(""), mesh.halfedges[back].length, 0});
    offer(mesh.apex(c), d + mesh.halfedges[back].length, Arrival{v, c, std::nan(""), 0, 0});
    const std::uint32_t g = mesh.twin[opposite];
    if (g == kNone) continue;
    const HalfedgeGeometry& o = mesh.halfedges[opposite];
    if (on_a_side.face == kNone && lies_on_opposite_side(mesh, c)) on_a_side = tail_as_point(c);
    const auto [b0, b1] = cone.part_of_opposite_edge(mesh, c);
    if (!(b1 - b0 > min_width)) continue;
    place(g, to_twin_frame(Window{b0, b1, o.apex_x, -o.apex_y, d, v}, o.length, mesh.tail(g) != mesh.tail(opposite)));
  }
  if (on_a_side.face == kNone) return;
  for_each_placement(mesh, on_a_side, [&](const LocatedPoint& in_face) {
    if (!mesh.has_corner(in_face.face, v))  // the faces of v's fan are done above
      for_each_ray_from_point(mesh, in_face, v, d, min_width, offer, place, graze);
  });
}

}  // namespace exactgeo::detail
