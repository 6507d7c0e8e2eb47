// Points anywhere on a mesh's surface: a triangle and barycentric coordinates, used as sources and targets,
// and found from positions in space by locate.
//
// Barycentric coordinates that are off by rounding are taken as the user meant them: each coordinate may be
// as low as -kBarycentricSlack and their sum may differ from 1 by up to kBarycentricSlack; they are then
// clamped to [0, 1] and rescaled to sum to 1, and a coordinate below kBarycentricSnap is set to 0. So
// (0.5, 0.5, -1e-17) is the midpoint of an edge and (1 - 1e-17, 1e-17, 0) is a vertex.
//
// A point at a corner is that input vertex, whichever face names it. Where the mesh policy split the vertex
// into several surface copies (a non-manifold vertex, mesh.hpp), a target there has the smallest distance
// over the copies, as GeodesicResult::distances has it, and its path goes to the copy with that distance; a
// source there starts from every copy, as a source vertex does.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "exactgeo/export.hpp"
#include "exactgeo/mesh.hpp"

namespace exactgeo {

struct SurfacePoint {
  std::uint32_t face = 0;                           // input triangle index
  std::array<double, 3> barycentric = {1, 0, 0};  // weights of the triangle's three corners, in its order
};

inline constexpr double kBarycentricSlack = 1e-6;
inline constexpr double kBarycentricSnap = 1e-12;

// The point at input vertex `vertex` (a corner of a kept triangle that uses it; as a source or target it is the
// vertex itself, see above). Throws exactgeo::Error(invalid_argument) if the index is out of range or the
// vertex is used by no kept triangle.
EXACTGEO_API SurfacePoint vertex_point(const Mesh& mesh, std::uint32_t vertex);

// The point (1 - t) * from + t * to on the edge between input vertices `from` and `to`, t in [0, 1] (on the
// first kept triangle with that edge). Throws exactgeo::Error(invalid_argument) if no kept triangle has the
// edge or t is outside [0, 1].
EXACTGEO_API SurfacePoint edge_point(const Mesh& mesh, std::uint32_t from, std::uint32_t to, double t);

// Where the point lies in space. Throws like the queries do for an invalid point.
EXACTGEO_API std::array<double, 3> point_position(const Mesh& mesh, const SurfacePoint& point);

struct LocateOptions {
  // Threads sharing the points: 0 takes one per core. Never more than the cores, nor than one per few
  // thousand points. The result is the same, bit for bit, on any count.
  unsigned threads = 0;
};

struct LocateResult {
  // Per point: the closest point of the surface, on a kept input triangle (never one the mesh policy dropped),
  // its barycentric coordinates in [0, 1] and summing to 1 up to rounding. Where several triangles hold a
  // closest point (an edge or a vertex), the lowest input triangle index among them. Usable as it is as a
  // source or target.
  std::vector<SurfacePoint> points;
  std::vector<double> distances;  // per point: the Euclidean distance to points[i], the distance to the surface
};

// The closest surface point of each 3D point `xyz` (x0 y0 z0 x1 ...), as a face and barycentric coordinates,
// and its distance: what CGAL's locate with an AABB tree and trimesh.proximity.closest_point answer. The
// first call on a mesh builds a bounding-volume hierarchy over its triangles (about 110 bytes per triangle),
// which the mesh keeps for later calls, from any thread. A point more than 2^26 times the mesh's extent away
// is searched from that far along its direction: its closest point is then right to about 1.5e-8 of the
// extent, about as far as rounding tells its distances apart. Throws exactgeo::Error(invalid_argument) if
// the array's size is not a multiple of 3, naming the first point with a non-finite coordinate, or naming
// the first point farther from the surface than the largest double.
EXACTGEO_API LocateResult locate(const Mesh& mesh, std::span<const double> xyz, const LocateOptions& options = {});

}  // namespace exactgeo
