// Helpers shared by the test suites: the real meshes in ../shared/meshes (optional), independent reference
// computations (edge-graph Dijkstra), distance comparisons, and the four on/off combinations of the
// engine's pruning rules that every distance test runs under.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <optional>
#include <ostream>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "exactgeo/geodesic.hpp"
#include "exactgeo/mesh.hpp"
#include "exactgeo/surface_point.hpp"

namespace exactgeo_test {

using Vec3 = std::array<double, 3>;

// A seeded generator whose numbers are the same on every platform (std::mt19937_64 is fully specified;
// the standard distributions are not).
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  // Uniform in [lo, hi). The fraction is formed first: (hi - lo) times the 53-bit integer would overflow for
  // ranges above about 1e292 (the bounding boxes of meshes scaled by 1e300).
  double uniform(double lo, double hi) { return lo + (hi - lo) * (static_cast<double>(engine_() >> 11) * 0x1p-53); }
  // Uniform in [0, n); the modulo bias is irrelevant for test sizes.
  std::uint32_t below(std::size_t n) { return static_cast<std::uint32_t>(engine_() % n); }

 private:
  std::mt19937_64 engine_;
};

// ---- Real meshes ---------------------------------------------------------------------------------------

inline constexpr const char* kNoSharedMeshesMessage = "../shared/meshes not found: skipping tests on real meshes";

// True if the directory given by EXACTGEO_SHARED_MESH_DIR exists.
bool shared_meshes_available();

// File names (e.g. "cow.obj") of the meshes in the shared directory, sorted; empty if it is absent.
// The README and anything that is not a mesh format the library reads are left out.
std::vector<std::string> shared_mesh_names();

// The soup read from the shared directory, or nullopt if the directory is absent. A file missing from a
// directory that exists is a broken setup, not a reason to skip: read_mesh_soup's error propagates.
std::optional<exactgeo::MeshSoup> load_shared_mesh(std::string_view name);

// Skips the current test, with a message saying why, when the real meshes are not there.
#define EXACTGEO_SKIP_IF_NO_SHARED_MESHES()                                             \
  do {                                                                                  \
    if (!::exactgeo_test::shared_meshes_available())                                    \
      GTEST_SKIP() << ::exactgeo_test::kNoSharedMeshesMessage;                          \
  } while (false)

// ---- Geometry of a soup --------------------------------------------------------------------------------

Vec3 vertex_position(const exactgeo::MeshSoup& soup, std::uint32_t v);
double distance(const Vec3& a, const Vec3& b);
double distance_between(const exactgeo::MeshSoup& soup, std::uint32_t a, std::uint32_t b);

std::size_t vertex_count(const exactgeo::MeshSoup& soup);
std::size_t face_count(const exactgeo::MeshSoup& soup);

// Building soups in tests: add_vertex returns the new vertex's index.
std::uint32_t add_vertex(exactgeo::MeshSoup& soup, const Vec3& p);
void add_triangle(exactgeo::MeshSoup& soup, std::uint32_t a, std::uint32_t b, std::uint32_t c);

// The first vertex at exactly position p; a test failure (and vertex 0) if there is none.
std::uint32_t vertex_at(const exactgeo::MeshSoup& soup, const Vec3& p);

// True if the triangle names one vertex twice; the mesh policy drops such faces.
bool repeats_a_vertex(const exactgeo::MeshSoup& soup, std::size_t face);

// An undirected edge of the faces that do not repeat a vertex, and how many of them use it.
struct MeshEdge {
  std::uint32_t low, high;  // vertices, low < high
  std::uint32_t faces;
};
std::vector<MeshEdge> unique_edges(const exactgeo::MeshSoup& soup);

// Per vertex, 1 if its faces form more than one fan, fans being faces around it joined across edges shared
// by exactly two faces: the vertices the mesh policy splits into several surface vertices.
std::vector<std::uint8_t> non_manifold_vertices(const exactgeo::MeshSoup& soup);

// Shortest paths along mesh edges (Euclidean edge lengths) from `source`, +inf where there is none. Paths
// may end at, but not pass through, vertices marked in `blocked` (e.g. non_manifold_vertices, which a
// geodesic cannot cross from one fan to another). An upper bound on the geodesic distance when every
// split vertex is blocked.
std::vector<double> edge_graph_dijkstra(const exactgeo::MeshSoup& soup, std::uint32_t source,
                                        std::span<const std::uint8_t> blocked = {});

// A vertex on a boundary edge (an edge used by exactly one face), or nullopt for a closed mesh.
std::optional<std::uint32_t> first_boundary_vertex(const exactgeo::MeshSoup& soup);

// A reproducible pseudo-random vertex that a geodesic query can start from: a corner of a random face of
// the largest piece of the mesh, pieces being faces joined across edges shared by exactly two faces (the
// joins the mesh policy keeps). The same seed gives the same vertex on every platform.
std::uint32_t random_source_vertex(const exactgeo::MeshSoup& soup, std::uint64_t seed);

// A uniformly random point of a random triangle that repeats no vertex (one the mesh policy keeps): inside
// it (zeros 0), on one of its edges (1) or at one of its corners (2).
exactgeo::SurfacePoint random_face_point(const exactgeo::MeshSoup& soup, Random& random, int zeros);

// ---- Random meshes (seeded property tests) -------------------------------------------------------------

// A height field over an nx-by-ny grid of the unit square (exactgeo::make_grid) whose heights reach about
// `amplitude`: smooth (a sum of three random sine waves) or noisy (independent uniform heights).
exactgeo::MeshSoup random_height_field(Random& random, int nx, int ny, double amplitude, bool smooth);

// make_grid(n, n, 1, 1) with heights +-amplitude alternating like a checkerboard over the vertices: every
// inner vertex a peak, a pit or a saddle, where geodesics bend.
exactgeo::MeshSoup checkerboard_height_field(int n, double amplitude);

// A flat convex polygon in the z=0 plane: `sides` corners at random angles on a random ellipse around the
// origin, triangulated by a fan from the origin to the first of `rings` nested, scaled copies and by strips
// between them. A geodesic on it is the straight segment between its ends.
exactgeo::MeshSoup random_convex_polygon(Random& random, int sides, int rings);

// A flat nx-by-ny grid of the unit square with up to `holes` rectangular holes (whole cells removed), each
// at least one cell away from the border and from the others, so the domain stays connected and manifold.
// Vertices off the outer border are moved by up to 0.15 of a cell, which keeps every triangle's orientation.
// Vertices of removed cells only are left in, unreferenced.
exactgeo::MeshSoup random_grid_with_holes(Random& random, int nx, int ny, int holes);

// The soup turned by a random rotation about the origin.
exactgeo::MeshSoup randomly_rotated(exactgeo::MeshSoup soup, Random& random);

// ---- Coincident vertices and non-manifold junctions (seeded fuzzing) ------------------------------------

// Manifold pieces glued at shared vertices into one soup: vertex k of pieces[i] is soup vertex vertex_of[i][k].
struct GluedPieces {
  exactgeo::MeshSoup soup;
  std::vector<exactgeo::MeshSoup> pieces;
  std::vector<std::vector<std::uint32_t>> vertex_of;
};

// `wings` random height-field patches (1 to 4 by 1 to 4 cells, each turned at random) sharing one vertex,
// inside or on the border of each: a bowtie, whose vertex the mesh policy splits into one copy per wing.
GluedPieces random_bowtie(Random& random, int wings);

// `pages` bumpy pages at spread random angles around a spine of 1 to 4 edges that they all share: with three
// pages or more, each spine edge is non-manifold, and the mesh policy cuts the pages apart.
GluedPieces random_book(Random& random, int pages);

// A random height field with a bumpy fin standing on a chain of inner edges along one grid row: each edge of
// the chain has three faces and is cut, which takes the fin off and slits the sheet (so the surface is not
// just its pieces apart).
exactgeo::MeshSoup random_sheet_with_fin(Random& random);

// The soup with `count` more vertices, each at the position of a vertex a that the mesh policy does not split
// and joined to it by a zero-length edge: either a random face (a, b, c) takes the new vertex a2 in a's place
// and two zero-area faces (a, a2, b) and (a2, a, c) stitch it back to what lay across ab and ac, or a boundary
// edge ab gets a zero-area face (b, a2, a) hanging on it (the smallest case of issue 34). The surface stays the
// same, so do the distances, a2's being a's. stands_for[v] is the vertex of the given soup at whose place each
// vertex of the result lies (v itself for the given ones).
exactgeo::MeshSoup with_coincident_vertices(exactgeo::MeshSoup soup, Random& random, int count,
                                            std::vector<std::uint32_t>& stands_for);

// The soup with `count` T-junctions closed by slivers: a random face (a, b, c) is cut at a point m of its side
// ab (10% to 90% of the way) into (a, m, c) and (m, b, c), and a sliver (a, b, m), of no area, joins those to
// the face beyond ab (or hangs on the boundary). Slivers may be cut again. The surface stays the same; m is
// the point of ab where it lies. With a `lift`, m is moved off the line along the face's normal by that share of
// ab's length (near-slivers: the surface moves by as much).
exactgeo::MeshSoup with_t_junctions(exactgeo::MeshSoup soup, Random& random, int count, double lift = 0);

// A random case of the junction fuzzing: a height field, a bowtie of 2 to 4 wings, a book of 3 to 6 pages or a
// sheet with a fin, with 0 to 6 vertices doubled in place (with_coincident_vertices). `family` names it.
struct JunctionCase {
  std::string family;
  exactgeo::MeshSoup soup;
  // The surface is its pieces apart, some vertices doubled in place: the pieces' own distances, a doubled
  // vertex's being its original's, are every distance. Empty for a fin, which slits its sheet.
  GluedPieces glued;
  std::vector<std::uint32_t> stands_for;
};
JunctionCase random_junction_case(Random& random);

// A random height field of 1x1 to 8x8 cells whose sides were split at 1 to 6 T-junctions (with_t_junctions):
// slivers, of no area, or with `near`, near-slivers lifted off their sides by 1e-17 to 1e-9 of their length
// (either way). `field` is the height field before: the same surface, or within `lift` of it.
struct SliverCase {
  std::string family;
  exactgeo::MeshSoup soup, field;
  int slivers = 0;
  double lift = 0;  // near-slivers: m off ab by this share of its length, so the surface moved by as much
};
SliverCase random_sliver_case(Random& random, bool near);

// ---- Distances -----------------------------------------------------------------------------------------

// Largest finite value, or 0 if there is none.
double max_finite(std::span<const double> values);

// Succeeds if both arrays have the same size, agree on which entries are finite, and every finite entry
// of `actual` is within relative_tolerance * max_finite(expected) of `expected`. The failure message names
// the worst vertex. The achieved error is written to *max_relative_error if given.
testing::AssertionResult distances_match(std::span<const double> actual, std::span<const double> expected,
                                         double relative_tolerance, double* max_relative_error = nullptr);

// Two runs of the same surface from the same sources under `options`: the same distances bit for bit on one
// thread; on several, to 1e-14 of the largest (which thread crosses what, and when, may change the last
// bits).
testing::AssertionResult same_run_distances(std::span<const double> actual, std::span<const double> expected,
                                            const exactgeo::GeodesicOptions& options);

// ---- Engine options ------------------------------------------------------------------------------------

// Every variant of the paper (vtp, opvtp, ftp, opftp), each with its pruning rules switched on and off in
// all four combinations: every distance must be exact under each of them.
inline const std::array<exactgeo::GeodesicOptions, 16> kAllVariants = [] {
  std::array<exactgeo::GeodesicOptions, 16> variants{};
  std::size_t i = 0;
  for (const auto& [algorithm, name] : exactgeo::kAlgorithmNames)
    for (const bool rule1 : {true, false})
      for (const bool rule23 : {true, false}) variants[i++] = {.algorithm = algorithm, .rule1 = rule1, .rule23 = rule23};
  return variants;
}();

// The parallel propagation (vertex-sorted variants only) on 2 and 3 threads, with each pruning rule switched
// off once: the suites of generated inputs run under these too.
inline const std::array<exactgeo::GeodesicOptions, 4> kParallelVariants = {{
    {.algorithm = exactgeo::Algorithm::vtp, .threads = 2},
    {.algorithm = exactgeo::Algorithm::opvtp, .threads = 3},
    {.algorithm = exactgeo::Algorithm::vtp, .rule1 = false, .threads = 2},
    {.algorithm = exactgeo::Algorithm::vtp, .rule23 = false, .threads = 3},
}};

// The library's defaults: the variant whose figures the tests print.
inline bool is_default_variant(const exactgeo::GeodesicOptions& options) {
  return options.algorithm == exactgeo::Algorithm::vtp && options.rule1 && options.rule23;
}

// For messages, e.g. "ftp, rule1 off, rule23 on" or "vtp, rule1 on, rule23 on, 2 threads".
std::string variant_label(const exactgeo::GeodesicOptions& options);

// Test-name suffix for a parameter from kAllVariants or kParallelVariants, e.g. "ftp_Rule1On_Rule23Off" or
// "vtp_Rule1On_Rule23On_Threads2".
std::string variant_name(const testing::TestParamInfo<exactgeo::GeodesicOptions>& info);

}  // namespace exactgeo_test

namespace exactgeo {
// How GoogleTest shows a GeodesicOptions parameter, e.g. "rule1 on, rule23 off" (found by argument lookup).
void PrintTo(const GeodesicOptions& options, std::ostream* out);
}  // namespace exactgeo
