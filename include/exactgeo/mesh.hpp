// exactgeo::Mesh: a validated triangle mesh built once from flat arrays, ready for geodesic queries.
//
// Policy for real-world input (reported in MeshReport and by `exactgeo info`):
// - vertices used by no face are kept, so output order never changes; their distance is +inf;
// - faces that repeat a vertex index are dropped and counted;
// - faces with the same three vertices as an earlier face (in any order, so of either orientation: a
//   double-sided export) are dropped and counted; a surface point on one is taken as on the kept face;
// - zero-area faces and zero-length edges are kept and handled by the engine without NaN;
// - edges shared by more than two faces are cut (each face sees a boundary there), and vertices whose
//   faces then form several separate fans are split into one surface vertex per fan; distances are exact
//   on that manifold surface, and an input vertex's distance is the smallest over its copies, also as a
//   target (by index, or as a point at any corner of it; a source there starts from every copy);
// - face orientation is irrelevant: an edge shared by two faces joins them whatever their winding;
// - vertices with identical positions stay apart unless MeshOptions::weld_duplicate_positions is set;
// - any finite coordinates work, from subnormal to the largest double: the engine runs on the positions
//   scaled by a power of two (exactly, and only when the mesh's extent is beyond about 1e12 or below 1e-12),
//   and distances, path lengths and points come back in the input's units; a distance beyond the largest
//   double is refused (Error invalid_mesh). A mesh far from the origin keeps the precision its coordinates
//   have (at an offset of 1e6, about 1e-10 absolute), no more.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <stop_token>
#include <vector>

#include "exactgeo/export.hpp"

namespace exactgeo {

namespace detail {
struct SurfaceMesh;
}

// A triangle soup: flat arrays as read from a file or generated, before validation.
struct MeshSoup {
  std::vector<double> positions;         // vertex_count * 3 coordinates
  std::vector<std::uint32_t> triangles;  // face_count * 3 zero-based vertex indices
};

struct MeshOptions {
  bool weld_duplicate_positions = false;  // merge vertices whose three coordinates are identical
  // Threads building the mesh: 0 takes one per core. Never more than the cores, nor than one per 20,000
  // faces (starting a thread would cost more than it saves). The mesh is the same, bit for bit, on any count.
  unsigned threads = 0;
  std::stop_token stop = {};  // a stop request ends the build with Error(cancelled) within milliseconds
  // Called with the fraction of the build done (0 to 1), from the calling thread, between the build's steps.
  std::function<void(double)> progress = {};
};

// Where the time of building a mesh went, step by step (the steps run one after the other, each on the
// build's threads). Each field's meaning is in for_each_build_stats_field below.
struct MeshBuildStats {
  unsigned threads = 0;
  double seconds = 0;
  double validate_seconds = 0;
  double duplicate_positions_seconds = 0;
  double faces_seconds = 0;
  double face_order_seconds = 0;
  double edges_seconds = 0;
  double vertices_seconds = 0;
  double geometry_seconds = 0;
  double fan_walk_seconds = 0;
  double components_seconds = 0;
};

// Every field of MeshBuildStats in declaration order: visit(name, member pointer, description).
template <class Visit>
constexpr void for_each_build_stats_field(Visit&& visit) {
  using B = MeshBuildStats;
  visit("threads", &B::threads, "threads the mesh was built on");
  visit("seconds", &B::seconds, "the whole build, from the arrays to the surface the engine runs on");
  visit("validate_seconds", &B::validate_seconds, "checking coordinates and indices, keeping the input arrays");
  visit("duplicate_positions_seconds", &B::duplicate_positions_seconds, "finding vertices at the same position");
  visit("faces_seconds", &B::faces_seconds, "dropping faces that repeat a vertex or an earlier face");
  visit("face_order_seconds", &B::face_order_seconds, "numbering the faces in spatial order");
  visit("edges_seconds", &B::edges_seconds, "pairing faces across edges (cutting non-manifold ones), fans at vertices");
  visit("vertices_seconds", &B::vertices_seconds, "one surface vertex per fan, numbered in spatial order");
  visit("geometry_seconds", &B::geometry_seconds, "edge lengths, unfolding frames, angles of each face");
  visit("fan_walk_seconds", &B::fan_walk_seconds, "angle sums and saddles per vertex, its corners in order around it");
  visit("components_seconds", &B::components_seconds, "counting the connected pieces");
}

// What validation found. Counts refer to the input unless said otherwise; each field's meaning is in
// for_each_report_field below.
struct MeshReport {
  std::size_t vertices = 0;
  std::size_t faces = 0;
  std::size_t faces_used = 0;
  std::size_t faces_repeating_a_vertex = 0;
  std::size_t duplicate_faces = 0;
  std::size_t degenerate_faces = 0;
  std::size_t zero_length_edges = 0;
  std::size_t unreferenced_vertices = 0;
  std::size_t duplicate_positions = 0;
  std::size_t welded_vertices = 0;
  std::size_t boundary_edges = 0;
  std::size_t non_manifold_edges = 0;
  std::size_t non_manifold_vertices = 0;
  std::size_t surface_vertices = 0;
  std::size_t components = 0;
  std::size_t saddle_vertices = 0;
};

// Every field of MeshReport in declaration order, with what it means: calls
// visit(name, member pointer, description) once per field. `exactgeo info` and the Python class are
// generated from this list, so a new field reaches both by being added here.
template <class Visit>
constexpr void for_each_report_field(Visit&& visit) {
  using R = MeshReport;
  visit("vertices", &R::vertices, "input vertices, used or not");
  visit("faces", &R::faces, "input triangles");
  visit("faces_used", &R::faces_used, "triangles kept (input minus dropped)");
  visit("faces_repeating_a_vertex", &R::faces_repeating_a_vertex, "dropped: a triangle naming one vertex twice");
  visit("duplicate_faces", &R::duplicate_faces, "dropped: the same three vertices as an earlier triangle");
  visit("degenerate_faces", &R::degenerate_faces, "kept: zero area (collinear or coincident corners)");
  visit("zero_length_edges", &R::zero_length_edges, "kept: edges whose two end positions coincide");
  visit("unreferenced_vertices", &R::unreferenced_vertices, "used by no kept face; distance +inf");
  visit("duplicate_positions", &R::duplicate_positions, "vertices whose position repeats an earlier vertex");
  visit("welded_vertices", &R::welded_vertices, "vertices merged into an earlier one by welding");
  visit("boundary_edges", &R::boundary_edges, "edges with one face");
  visit("non_manifold_edges", &R::non_manifold_edges, "edges with three or more faces (cut)");
  visit("non_manifold_vertices", &R::non_manifold_vertices, "vertices split into several surface vertices");
  visit("surface_vertices", &R::surface_vertices, "vertices of the manifold surface the engine runs on");
  visit("components", &R::components, "connected pieces of that surface");
  visit("saddle_vertices", &R::saddle_vertices, "interior vertices with angle sum above 2*pi");
}

class EXACTGEO_API Mesh {
 public:
  // positions: vertex_count * 3 coordinates (x0 y0 z0 x1 ...); triangles: face_count * 3 vertex indices.
  // Throws exactgeo::Error(invalid_mesh) naming the element for NaN/inf coordinates, indices out of range,
  // array sizes that are not multiples of 3, or a mesh with no usable face.
  Mesh(std::span<const double> positions, std::span<const std::uint32_t> triangles,
       const MeshOptions& options = {});
  explicit Mesh(const MeshSoup& soup, const MeshOptions& options = {})
      : Mesh(soup.positions, soup.triangles, options) {}
  // Takes the soup's arrays over instead of copying them (what load_mesh does).
  explicit Mesh(MeshSoup&& soup, const MeshOptions& options = {});

  std::size_t vertex_count() const noexcept;  // input vertices
  std::size_t face_count() const noexcept;    // input triangles
  std::span<const double> positions() const noexcept;
  std::span<const std::uint32_t> triangles() const noexcept;
  const MeshReport& report() const noexcept;
  const MeshBuildStats& build_stats() const noexcept;

  // The manifold surface the engine runs on; internal layout, not a stable API.
  const detail::SurfaceMesh& surface() const noexcept { return *surface_; }

 private:
  std::shared_ptr<const detail::SurfaceMesh> surface_;
};

}  // namespace exactgeo
