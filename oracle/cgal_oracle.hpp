// An independent exactness oracle: geodesic distances from CGAL's Surface_mesh_shortest_path (Chen-Han
// style sequence tree, Epick kernel). Test and benchmark code only; it depends on CGAL and the standard
// library, never on exactgeo, so the two implementations share no code.
//
// The soup is turned into a CGAL::Surface_mesh the way CGAL recommends: triangles repeating a vertex are
// dropped, orient_polygon_soup cuts edges shared by more than two triangles (or by two triangles whose
// orientations cannot agree) and duplicates the points where the surface is then not a disk, and
// polygon_soup_to_polygon_mesh builds the halfedge mesh. Each input vertex may therefore have several
// surface copies; its distance is the smallest over them, and a source seeds all of its copies.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace exactgeo_oracle {

// A point on input triangle `face`: the weights of its three corners, in the triangle's order.
struct FacePoint {
  std::uint32_t face = 0;
  std::array<double, 3> barycentric = {1, 0, 0};
};

struct OracleResult {
  std::vector<double> distances;      // one per input vertex; +inf if unreachable or used by no kept face
  std::vector<double> target_distances;  // one per target point, likewise
  bool loaded_as_manifold = false;    // false if CGAL could not turn the soup into a valid polygon mesh
                                      // (distances is then empty)
  std::size_t duplicated_points = 0;  // points orient_polygon_soup had to duplicate (non-manifold fixes)
  double build_seconds = 0;           // soup -> Surface_mesh
  double query_seconds = 0;           // build the sequence tree + query every surface vertex
};

// positions: vertex_count * 3 coordinates; triangles: face_count * 3 vertex indices; source_vertices: input
// vertex indices; source_points and target_points: points on input triangles that repeat no vertex. A source
// vertex used by no kept face seeds nothing (its own distance stays +inf).
// Throws std::invalid_argument for array sizes that are not multiples of 3 and out-of-range indices.
OracleResult cgal_geodesic_distances(std::span<const double> positions, std::span<const std::uint32_t> triangles,
                                     std::span<const std::uint32_t> source_vertices,
                                     std::span<const FacePoint> source_points = {},
                                     std::span<const FacePoint> target_points = {});

}  // namespace exactgeo_oracle
