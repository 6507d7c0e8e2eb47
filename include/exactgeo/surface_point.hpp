// Points anywhere on a mesh's surface: a triangle and barycentric coordinates, used as sources and targets.
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

}  // namespace exactgeo
