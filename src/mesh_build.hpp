// The steps that build the manifold surface (surface_mesh.hpp) from validated input arrays, in the order
// mesh.cpp runs them. Each is one or a few data-parallel passes over flat arrays on the build's team
// (parallel.hpp), and gives the same result on any thread count: the surface is the same, bit for bit.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "exactgeo/mesh.hpp"
#include "parallel.hpp"
#include "surface_mesh.hpp"

namespace exactgeo::detail {

// Faces per build thread at least (the mesh's, and the hierarchy locate builds): below that, starting a
// thread costs more than its share saves.
inline constexpr std::size_t kFacesPerBuildThread = 20000;

// The whole build on `threads` threads (what Mesh's constructors call, with the count MeshOptions::threads
// and the mesh's size allow), every pass cut into ranges of `grain` items if set (ParallelTeam).
std::shared_ptr<const SurfaceMesh> build_surface(std::vector<double>&& positions, std::vector<std::uint32_t>&& triangles,
                                                 const MeshOptions& options, unsigned threads, std::size_t grain = 0);

// The same from copies of the caller's arrays, made on the build's threads (Mesh's constructor from spans).
std::shared_ptr<const SurfaceMesh> build_surface_from_copies(std::span<const double> positions,
                                                             std::span<const std::uint32_t> triangles,
                                                             const MeshOptions& options);

using Vec3 = std::array<double, 3>;

inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

struct Box {
  Vec3 lo = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
};

// The bounding box of point_of(i) for i in [0, count).
template <class PointOf>
Box bounding_box(const ParallelTeam& team, std::size_t count, PointOf&& point_of) {
  const auto merge = [](Box a, const Box& b) {
    for (int k = 0; k < 3; ++k) {
      a.lo[k] = std::min(a.lo[k], b.lo[k]);
      a.hi[k] = std::max(a.hi[k], b.hi[k]);
    }
    return a;
  };
  return team.reduce_ranges(
      count, 1 << 13, Box{},
      [&](std::size_t begin, std::size_t end) {
        Box box;
        for (std::size_t i = begin; i < end; ++i) {
          const Vec3 p = point_of(i);
          box = merge(box, Box{p, p});
        }
        return box;
      },
      merge);
}

// What the steps hand each other besides the SurfaceMesh they fill.
struct BuildState {
  // Each input vertex's representative: itself, or the first vertex at the same position.
  MeshArray<std::uint32_t> same_position;
  // The input vertex at each corner of each kept face (after welding, if asked), 3 per face: in input
  // order after drop_repeated_faces, in the surface's face order after order_faces_in_space.
  MeshArray<std::uint32_t> corner_input_vertex;
  // The corners of each input vertex, in increasing order, and the number of its fans (match_edges).
  Groups corners_of_input_vertex;
  MeshArray<std::uint32_t> fan_count;
};

// Counts the vertices whose position repeats an earlier vertex's and records each one's representative.
void find_duplicate_positions(const ParallelTeam& team, SurfaceMesh& s, BuildState& state);

// Drops faces that repeat a vertex, and faces with the same three vertices as an earlier one (mapped to it);
// counts them, the faces used and the unreferenced vertices; fills corner_input_vertex in input order.
void drop_repeated_faces(const ParallelTeam& team, SurfaceMesh& s, BuildState& state, bool weld);

// Renumbers the kept faces in spatial order of their centroids.
void order_faces_in_space(const ParallelTeam& team, SurfaceMesh& s, BuildState& state);

// Groups the corners by input vertex. Pairs halfedges along edges into twins (edges of one face are
// boundary, of three or more are cut) and splits every input vertex's corners into fans, joined across the
// edges paired at the vertex.
void match_edges(const ParallelTeam& team, SurfaceMesh& s, BuildState& state);
// One surface vertex per fan, numbered in spatial order of the input vertices; fills the corner and copy
// maps. After it, cut edges whose faces meet the same copies of both ends are joined again (a mesh with
// non-manifold edges only).
void number_vertices(const ParallelTeam& team, SurfaceMesh& s, BuildState& state);
void join_cut_edges_between_same_copies(SurfaceMesh& s);

// The power of two the engine scales positions by, and the length scale of the tolerances.
void choose_scale(const ParallelTeam& team, SurfaceMesh& s);
// Edge lengths, unfolding frames, corner angles and the mean edge length; counts the degenerate faces and
// returns which faces are (1) for walk_vertices.
MeshArray<std::uint8_t> compute_face_geometry(const ParallelTeam& team, SurfaceMesh& s);
// Per vertex, in one pass over its corners (they are read once for both): angle sums, saddles and
// pseudo-sources, then the order of its corners around it (SurfaceMesh::fan_angle_start).
void walk_vertices(const ParallelTeam& team, SurfaceMesh& s, const MeshArray<std::uint8_t>& degenerate);
// Connected pieces of the surface (faces joined across edges): how many, and which one each face is in
// (labelled by one of its faces). The mesh keeps only the count; pairs ask for the labels when there are several.
std::size_t count_components(const ParallelTeam& team, const SurfaceMesh& s);
std::vector<std::uint32_t> face_components(const ParallelTeam& team, const SurfaceMesh& s);

}  // namespace exactgeo::detail
