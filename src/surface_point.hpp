// Surface points located on the manifold surface the engine runs on.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "exactgeo/surface_point.hpp"
#include "parallel.hpp"
#include "surface_mesh.hpp"
#include "tolerances.hpp"

namespace exactgeo::detail {

// A validated point: on surface face `face` with clean barycentric coordinates (see surface_point.hpp for the
// rounding policy). At a corner it is that surface vertex; on an edge, `edge` is the face's halfedge along it.
struct LocatedPoint {
  std::uint32_t face = kNone;
  std::array<double, 3> barycentric = {1, 0, 0};
  std::uint32_t vertex = kNone;  // the surface vertex it coincides with, if any
  std::uint32_t edge = kNone;    // the halfedge of `face` whose interior it lies on, if any
};

// Where a given surface point lies on the surface mesh, once checked (unlike the public exactgeo::locate,
// which finds the closest surface point of a point in space). Throws Error(invalid_argument) naming `what`
// (e.g. "source 2") for a face out of range or dropped by the mesh policy, non-finite coordinates, or
// coordinates that are not barycentric up to kBarycentricSlack.
LocatedPoint locate_checked(const SurfaceMesh& mesh, const SurfacePoint& point, const std::string& what);

// The surface copies of input vertex `vertex` as a source (several where the mesh policy split it). Throws
// Error(invalid_argument) if the index is out of range or the vertex is used by no face.
std::span<const std::uint32_t> source_vertex_copies(const SurfaceMesh& mesh, std::uint32_t vertex);

// How near a point must lie to a side's line to count as on it: the narrowest window the engine keeps
// (kMinWindowWidth of the mesh's size), in the engine's frame.
inline double on_side_tolerance(const SurfaceMesh& mesh) { return kMinWindowWidth * mesh.length_scale; }

// The tail of halfedge h as a point of h's face (its corner there).
inline LocatedPoint tail_as_point(std::uint32_t h) {
  LocatedPoint corner;
  corner.face = face_of(h);
  corner.barycentric = {0, 0, 0};
  corner.barycentric[h % 3] = 1;
  return corner;
}

// Whether the point, a point of face(h), lies on h's side: located on it, or, rounding apart, within the
// narrowest window (kMinWindowWidth of the mesh's size) of the segment, where the windows it would send
// across h are too thin to be kept.
bool lies_on_side(const SurfaceMesh& mesh, const LocatedPoint& point, std::uint32_t h);

// Whether the vertex at corner c (the tail of halfedge c) lies on the side opposite it in c's face: a
// T-junction's vertex on its sliver's long side. A glance at that side's apex height for nearly every corner.
inline bool lies_on_opposite_side(const SurfaceMesh& mesh, std::uint32_t c) {
  const std::uint32_t opposite = next_halfedge(c);
  return !(mesh.halfedges[opposite].apex_y > on_side_tolerance(mesh)) && lies_on_side(mesh, tail_as_point(c), opposite);
}

// Every face that holds the point, with the point as a point of that face, its own face first: the faces
// across the sides it lies on, and on across those faces' sides. Straight rays from the point reach into each
// of them. Beyond the face across an edge, this matters where faces have no area (a vertex doubled in place
// and stitched back by two of them, a sliver): such a face's sides lie on one line, a point of it on each
// side that holds it, and the faces with area around it are reached only across those sides. Sources start,
// targets are reached and queries answered in every placement.
std::vector<LocatedPoint> placements_of(const SurfaceMesh& mesh, const LocatedPoint& point);

// visit(placement) for each of placements_of(mesh, point); without allocating for a point on none of its
// face's sides (most queries).
template <class Visit>
void for_each_placement(const SurfaceMesh& mesh, const LocatedPoint& point, Visit&& visit) {
  const std::uint32_t h = 3 * point.face;
  if (!lies_on_side(mesh, point, h) && !lies_on_side(mesh, point, h + 1) && !lies_on_side(mesh, point, h + 2)) {
    visit(point);
    return;
  }
  for (const LocatedPoint& placement : placements_of(mesh, point)) visit(placement);
}

// Lists the mesh's vertices on the sides of faces they are no corner of (SurfaceMesh::vertices_on_sides): the
// placements (placements_of) of the vertices that lie on the side opposite them in one of their faces, in
// faces they are no corner of. A vertex's placements leave its own faces only through such a side, so these
// are all, and they are where the engine sends its rays (shadow_cone.hpp, for_each_emission_part). A step of
// the build (mesh.cpp), once the faces' geometry is known.
void list_vertices_on_sides(const ParallelTeam& team, SurfaceMesh& mesh);

// The vertices on the sides of face f but its corners (most faces have none; a glance when the mesh has none).
inline std::span<const VertexOnSide> vertices_on_sides(const SurfaceMesh& mesh, std::uint32_t f) {
  const auto& all = mesh.vertices_on_sides;
  const auto first = std::partition_point(all.begin(), all.end(), [f](const VertexOnSide& o) { return o.face < f; });
  const auto last = std::partition_point(first, all.end(), [f](const VertexOnSide& o) { return o.face == f; });
  return {first, last};
}

// A vertex on a side of a face, as a point of that face.
inline LocatedPoint as_point(const VertexOnSide& on_side) {
  LocatedPoint point;
  point.face = on_side.face;
  point.barycentric = on_side.barycentric;
  point.edge = on_side.edge;
  return point;
}

// Which coordinates a position in space is given in: the input's, or the engine's frame (the input's times
// 2^scale_exponent, see SurfaceMesh).
enum class PositionFrame : std::uint8_t { input, engine };

// The point with barycentric coordinates `barycentric` on surface face `face`, in space, in `frame`: the
// one sum of the corners behind the public point_position (input) and the goal of a goal-directed run (engine).
std::array<double, 3> face_point_position(const SurfaceMesh& mesh, std::uint32_t face,
                                          const std::array<double, 3>& barycentric, PositionFrame frame);

// The point in the frame of halfedge h, a halfedge of the point's face (tail at the origin, head at
// (length, 0), apex above the x axis).
std::array<double, 2> position_in_frame(const SurfaceMesh& mesh, const LocatedPoint& point, std::uint32_t h);

}  // namespace exactgeo::detail
