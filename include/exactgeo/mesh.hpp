// exactgeo::Mesh: a validated triangle mesh built once from flat arrays, ready for geodesic queries.
//
// Policy for real-world input (reported in MeshReport and by `exactgeo info`):
// - vertices used by no face are kept, so output order never changes; their distance is +inf;
// - faces that repeat a vertex index are dropped and counted;
// - zero-area faces and zero-length edges are kept and handled by the engine without NaN;
// - edges shared by more than two faces are cut (each face sees a boundary there), and vertices whose
//   faces then form several separate fans are split into one surface vertex per fan; distances are exact
//   on that manifold surface, and an input vertex's distance is the smallest over its copies;
// - face orientation is irrelevant: an edge shared by two faces joins them whatever their winding;
// - vertices with identical positions stay apart unless MeshOptions::weld_duplicate_positions is set.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
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
};

// What validation found. Counts refer to the input unless said otherwise.
struct MeshReport {
  std::size_t vertices = 0;                     // input vertices, used or not
  std::size_t faces = 0;                        // input triangles
  std::size_t faces_used = 0;                   // triangles kept (input minus dropped)
  std::size_t faces_repeating_a_vertex = 0;     // dropped: a triangle naming one vertex twice
  std::size_t degenerate_faces = 0;             // kept: zero area (collinear or coincident corners)
  std::size_t zero_length_edges = 0;            // kept: edges whose two end positions coincide
  std::size_t unreferenced_vertices = 0;        // used by no kept face; distance +inf
  std::size_t duplicate_positions = 0;          // vertices whose position repeats an earlier vertex
  std::size_t welded_vertices = 0;              // vertices merged into an earlier one by welding
  std::size_t boundary_edges = 0;               // edges with one face
  std::size_t non_manifold_edges = 0;           // edges with three or more faces (cut)
  std::size_t non_manifold_vertices = 0;        // vertices split into several surface vertices
  std::size_t surface_vertices = 0;             // vertices of the manifold surface the engine runs on
  std::size_t components = 0;                   // connected pieces of that surface
  std::size_t saddle_vertices = 0;              // interior vertices with angle sum above 2*pi
};

class EXACTGEO_API Mesh {
 public:
  // positions: vertex_count * 3 coordinates (x0 y0 z0 x1 ...); triangles: face_count * 3 vertex indices.
  // Throws exactgeo::Error(invalid_mesh) naming the element for NaN/inf coordinates, indices out of range,
  // array sizes that are not multiples of 3, or a mesh with no usable face.
  Mesh(std::span<const double> positions, std::span<const std::uint32_t> triangles,
       const MeshOptions& options = {});
  explicit Mesh(const MeshSoup& soup, const MeshOptions& options = {})
      : Mesh(soup.positions, soup.triangles, options) {}

  std::size_t vertex_count() const noexcept;  // input vertices
  std::size_t face_count() const noexcept;    // input triangles
  std::span<const double> positions() const noexcept;
  std::span<const std::uint32_t> triangles() const noexcept;
  const MeshReport& report() const noexcept;

  // The manifold surface the engine runs on; internal layout, not a stable API.
  const detail::SurfaceMesh& surface() const noexcept { return *surface_; }

 private:
  std::shared_ptr<const detail::SurfaceMesh> surface_;
};

}  // namespace exactgeo
