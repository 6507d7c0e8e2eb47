// Closest points on the surface (exactgeo::locate): a bounding-volume hierarchy over the kept faces, in the
// engine's frame, built once per mesh by the first query and kept with the mesh for the later ones.
//
// The tree splits a node's faces in two halves by count, along the longest side of their centroids' box, so
// its shape depends on the face count alone: every node's place in the depth-first array is known before a
// face is sorted, each level's nodes are split side by side on the team, and the tree is the same, bit for
// bit, on any thread count.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mesh_build.hpp"
#include "surface_mesh.hpp"

namespace exactgeo::detail {

// A point of a triangle: barycentric weights of its three corners, in their order, and its squared distance
// to the point it was found for.
struct TrianglePoint {
  std::array<double, 3> barycentric = {1, 0, 0};
  double squared_distance = HUGE_VAL;
};

// The closest point of the triangle to `point`: the nearest point of its three edges, or the foot of the
// perpendicular where that falls inside. A triangle of zero area (collinear or coincident corners) is its
// edges. Each edge is measured from its lexicographically smaller end, so that the faces sharing it find the
// same point to the last bit and tie exactly. Weights lie in [0, 1] and sum to 1 up to rounding; the squared
// distance is that of the point they give (point_at), so it never understates how far that point is.
TrianglePoint closest_point_on_triangle(const Vec3& point, const std::array<Vec3, 3>& corners);

// sum_k barycentric[k] * corners[k]: exactly the corner at a corner, whatever the other weights' rounding.
Vec3 point_at(const std::array<Vec3, 3>& corners, const std::array<double, 3>& barycentric);

struct FaceBvhNode {
  Vec3 lo, hi;          // the box of its faces' corners, widened by FaceBvh::margin
  std::uint32_t first;  // a leaf's first entry; an inner node's second child (its first child is the next node)
  std::uint32_t count;  // a leaf's entries (1 to kMaxLeafFaces); 0 for an inner node
};

struct FaceBvh {
  static constexpr std::uint32_t kMaxLeafFaces = 4;

  std::vector<FaceBvhNode> nodes;  // depth first, the root at 0
  // Per entry, leaves' entries in order: the face's corners in the engine's frame, and the input triangle
  // the face is (the kept one of duplicates) whose corner order they follow.
  std::vector<std::array<Vec3, 3>> corners;
  std::vector<std::uint32_t> input_faces;
  // How far rounding may put a computed point of a face outside the box of its corners: a few ulps of the
  // largest coordinate. Boxes are widened by it, so that no box hides a face that a query would pick.
  double margin = 0;
};

// The hierarchy of all the surface's faces, built on the team.
FaceBvh build_face_bvh(const ParallelTeam& team, const SurfaceMesh& mesh);

// The mesh's hierarchy: built by the first call (on up to `threads` threads, 0 for one per core), which any
// concurrent call waits for, and kept in the mesh (SurfaceMesh::face_bvh) for every later one.
const FaceBvh& face_bvh(const SurfaceMesh& mesh, unsigned threads);

// The closest point of the surface to `point` (engine's frame): the face, as its entry's input triangle, and
// the point on it. The smallest squared distance as closest_point_on_triangle computes it over every face,
// ties to the lowest input triangle, so the answer is the one a search of every face gives, bit for bit.
struct SurfaceClosestPoint {
  std::uint32_t input_face = kNone;
  TrianglePoint point;
};
SurfaceClosestPoint closest_surface_point(const FaceBvh& bvh, const Vec3& point);

}  // namespace exactgeo::detail
