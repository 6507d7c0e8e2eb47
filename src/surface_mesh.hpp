// The manifold surface the engine runs on: compact connectivity as index arrays and cached geometry.
//
// Halfedge h = 3 * face + i runs from corner i to corner (i + 1) % 3 of its face; the corner opposite it is
// (i + 2) % 3. Windows on h are windows on that edge about to enter h's face. Each halfedge has a local 2D
// frame: its tail A at the origin, its head B at (length, 0), the opposite corner C at (apex_x, apex_y) with
// apex_y >= 0. Faces keep the input winding; the engine never relies on consistent orientation.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "exactgeo/mesh.hpp"

namespace exactgeo::detail {

inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

// Memory for the arrays below. Large arrays are mapped on their own in huge pages where the system offers
// them (Linux's transparent huge pages on request): a build or a run touches hundreds of megabytes once, and
// in 4 KB pages a tenth of its time went to page faults, while random reads through the mesh missed the TLB.
void* allocate_mesh_bytes(std::size_t bytes, std::size_t alignment);
void free_mesh_bytes(void* p, std::size_t bytes, std::size_t alignment) noexcept;
// The same for memory from elsewhere (a std::vector of the public API): advises the huge pages inside a
// large range that nothing has touched yet, so that its first touch faults in 2 MB at a time, not 4 KB.
void advise_huge_pages(const void* p, std::size_t bytes) noexcept;
// Faults in the pages of an untouched range for writing (Linux 5.14 on; elsewhere, and where it fails, the
// first write does it), so that threads can share the faulting of an array one thread is about to fill
// (populate_on_team in parallel.hpp).
void populate_for_writing(void* p, std::size_t bytes) noexcept;

struct FaceBvh;  // face_bvh.hpp

// An array of the surface: its elements start uninitialised, so that the build's passes, which write every
// element on the thread team, are not preceded by one thread zeroing (and first touching) the whole array.
// That holds for plain structs with default member initialisers too (the engine's Arrival, 32 bytes a vertex):
// growing the array does not run them; the team's fill that follows writes each element.
template <class T>
struct UninitializedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    if (n > std::numeric_limits<std::size_t>::max() / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(allocate_mesh_bytes(n * sizeof(T), alignof(T)));
  }
  void deallocate(T* p, std::size_t n) noexcept { free_mesh_bytes(p, n * sizeof(T), alignof(T)); }
  template <class U>
  void construct(U* p) noexcept {
    if constexpr (!(std::is_trivially_copyable_v<U> && std::is_trivially_destructible_v<U>))
      ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T>
using MeshArray = std::vector<T, UninitializedAllocator<T>>;

inline std::uint32_t face_of(std::uint32_t halfedge) { return halfedge / 3; }
// One remainder each: h % 3 is a multiply and a shift, and a second one for the neighbour's place would double it.
inline std::uint32_t next_halfedge(std::uint32_t h) { return h % 3 == 2 ? h - 2 : h + 1; }
inline std::uint32_t prev_halfedge(std::uint32_t h) { return h % 3 == 0 ? h + 2 : h - 1; }

struct HalfedgeGeometry {
  double length;  // |AB|
  double apex_x;  // C in the halfedge frame
  double apex_y;
};

// A vertex that lies on a side of a face it is no corner of, as a point of that face: where a T-junction is
// closed by a sliver (a face of no area along that side), or a vertex doubled in place is stitched back. Paths
// from it run straight into the face, as from the face's corners.
struct VertexOnSide {
  std::uint32_t face;
  std::uint32_t vertex;
  std::uint32_t edge;                 // the halfedge of `face` whose side it lies on
  std::array<double, 3> barycentric;  // by the face's corners
  bool operator==(const VertexOnSide&) const = default;
};

struct SurfaceMesh {
  // The input as given (positions and the kept triangles, in input order).
  std::vector<double> input_positions;
  std::vector<std::uint32_t> input_triangles;
  MeshReport report;
  MeshBuildStats build_stats;

  // The engine works on the input positions times 2^scale_exponent (0 unless the mesh's extent is far from
  // 1, see kOrdinaryScaleExponent), so that squared lengths neither overflow nor underflow at any scale. All
  // geometry below (lengths, frames, length_scale) is in that frame; distances are scaled back on output.
  int scale_exponent = 0;
  // An input vertex's position as given, and in the engine's frame.
  std::array<double, 3> input_position(std::uint32_t input_vertex) const {
    const double* p = input_positions.data() + 3 * std::size_t{input_vertex};
    return {p[0], p[1], p[2]};
  }
  std::array<double, 3> position(std::uint32_t input_vertex) const {
    const double* p = input_positions.data() + 3 * std::size_t{input_vertex};
    if (scale_exponent == 0) return {p[0], p[1], p[2]};  // the ordinary scale: ldexp is a call per coordinate
    return {std::ldexp(p[0], scale_exponent), std::ldexp(p[1], scale_exponent), std::ldexp(p[2], scale_exponent)};
  }
  double to_engine_length(double input_length) const { return std::ldexp(input_length, scale_exponent); }
  // Throws Error(invalid_mesh) if the length exceeds the largest double once scaled back. Inline for the
  // ordinary scale, where nothing changes: it runs once per vertex of every result.
  double to_input_length(double engine_length) const {
    return scale_exponent == 0 ? engine_length : to_input_length_scaled(engine_length);
  }
  double to_input_length_scaled(double engine_length) const;

  // Surface vertices: input vertices, split where non-manifold.
  std::uint32_t vertex_count = 0;
  MeshArray<std::uint32_t> surface_to_input;         // surface vertex -> input vertex
  MeshArray<std::uint32_t> input_copies_offsets;     // input vertex -> [offsets[v], offsets[v+1]) in input_copies
  MeshArray<std::uint32_t> input_copies;             // surface vertices of each input vertex
  // Input vertex -> the one it was welded into (or itself); empty unless welding, when every vertex is its own.
  MeshArray<std::uint32_t> canonical_input;
  std::uint32_t canonical(std::uint32_t input_vertex) const {
    return canonical_input.empty() ? input_vertex : canonical_input[input_vertex];
  }

  // Faces that survived validation (faces repeating a vertex are dropped), each keeping its input corner
  // order. Faces, and surface vertices, are numbered in spatial order, not in input order (mesh.cpp,
  // spatial_order): the maps below and surface_to_input lead back to the input.
  MeshArray<std::uint32_t> input_face_to_surface;  // input triangle -> surface face, kNone if dropped
  MeshArray<std::uint32_t> surface_face_to_input;  // surface face -> input triangle
  MeshArray<std::uint32_t> corner_vertex;   // 3 per face: surface vertex at each corner
  MeshArray<std::uint32_t> twin;            // per halfedge: the halfedge across its edge, or kNone
  MeshArray<HalfedgeGeometry> halfedges;    // per halfedge
  MeshArray<double> corner_angle;           // per corner (= halfedge leaving it): the angle at its tail

  // Corners around each surface vertex (corner c = halfedge index of the halfedge leaving that corner).
  MeshArray<std::uint32_t> vertex_corner_offsets;
  MeshArray<std::uint32_t> vertex_corners;

  // Vertices where geodesics can bend: saddles, boundary vertices with angle above pi, vertices of
  // degenerate faces (kept conservatively). They re-emit windows as pseudo-sources.
  MeshArray<std::uint8_t> is_pseudo_source;

  // Angles around each vertex, walking its fan of corners from one boundary edge (or any edge if the fan
  // is closed). Corner c (the halfedge leaving its vertex) is entered through its edge c when
  // corner_enters_forward[c], else through its other edge at the vertex (prev(c)); fan_angle_start[c] is
  // the angle already walked when entering it. Vertices of degenerate faces have no reliable fan angles.
  MeshArray<double> fan_angle_start;             // per corner
  MeshArray<std::uint8_t> corner_enters_forward;  // per corner
  MeshArray<double> fan_total_angle;              // per vertex
  MeshArray<std::uint8_t> fan_closed;             // per vertex: no boundary edge around it
  MeshArray<std::uint8_t> fan_angles_reliable;    // per vertex

  // Every vertex on a side of a face but its corners, sorted by face, then vertex (surface_point.cpp,
  // list_vertices_on_sides): none on most meshes.
  std::vector<VertexOnSide> vertices_on_sides;

  double length_scale = 1.0;  // bounding-box diagonal of the used vertices (in the engine's frame)
  double mean_edge_length = 0;  // over the halfedges (each inner edge counted twice)

  // The faces' bounding-volume hierarchy for locate (face_bvh.hpp): built by the first call that needs it,
  // which concurrent ones wait for, then shared by every later one. A mesh never located pays nothing.
  mutable std::once_flag face_hierarchy_built;
  mutable std::shared_ptr<const FaceBvh> face_hierarchy;

  // Surface vertices that carry input vertex v's distance (none if v is used by no face).
  std::span<const std::uint32_t> copies_of(std::uint32_t input_vertex) const {
    const std::uint32_t c = canonical(input_vertex);
    return {input_copies.data() + input_copies_offsets[c], input_copies.data() + input_copies_offsets[c + 1]};
  }
  // The copies of the input vertex that surface vertex s belongs to, s among them. A point at s (a source or
  // target at a vertex, or at a corner of a face) is that input vertex, so it stands for all of them.
  std::span<const std::uint32_t> copies_with(std::uint32_t surface_vertex) const {
    return copies_of(surface_to_input[surface_vertex]);
  }
  // Of input vertex v's copies, the one with the smallest of `distances` (per surface vertex; the first in
  // copies_of order on a tie), kNone if v is used by no face: the copy that carries v's distance and its path.
  std::uint32_t nearest_copy(std::uint32_t input_vertex, std::span<const double> distances) const {
    std::uint32_t nearest = kNone;
    for (std::uint32_t s : copies_of(input_vertex))
      if (nearest == kNone || distances[s] < distances[nearest]) nearest = s;
    return nearest;
  }
  std::uint32_t face_count() const { return static_cast<std::uint32_t>(corner_vertex.size() / 3); }
  std::uint32_t tail(std::uint32_t h) const { return corner_vertex[h]; }
  std::uint32_t head(std::uint32_t h) const { return corner_vertex[next_halfedge(h)]; }
  std::uint32_t apex(std::uint32_t h) const { return corner_vertex[prev_halfedge(h)]; }
  bool has_corner(std::uint32_t f, std::uint32_t v) const {
    return corner_vertex[3 * f] == v || corner_vertex[3 * f + 1] == v || corner_vertex[3 * f + 2] == v;
  }
};

}  // namespace exactgeo::detail
