// The mesh policy of include/exactgeo/mesh.hpp: what validation reports, what it rejects, and what distances
// come out on meshes with unused vertices, dropped and degenerate faces, several components, non-manifold
// edges and vertices, and seams. Distance tests run with the paper's pruning rules on and off.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/geodesic.hpp"
#include "exactgeo/mesh.hpp"
#include "exactgeo/shapes.hpp"
#include "test_meshes.hpp"

namespace {

using exactgeo::ErrorCode;
using exactgeo::MeshSoup;
using exactgeo_test::add_triangle;
using exactgeo_test::add_vertex;
using exactgeo_test::distance;
using exactgeo_test::distances_match;
using exactgeo_test::face_count;
using exactgeo_test::Vec3;
using exactgeo_test::vertex_at;
using exactgeo_test::vertex_count;
using exactgeo_test::vertex_position;

constexpr double kExact = 1e-12;  // fraction of the largest distance

// Appends `part` to `soup` as more vertices and faces.
void append(MeshSoup& soup, const MeshSoup& part) {
  const auto offset = static_cast<std::uint32_t>(vertex_count(soup));
  soup.positions.insert(soup.positions.end(), part.positions.begin(), part.positions.end());
  for (std::uint32_t v : part.triangles) soup.triangles.push_back(v + offset);
}

// A flat n-by-n grid of unit squares on [0,n]^2 (z = 0), or mapped by `place` from (x, y) to 3D.
MeshSoup unit_grid(int n, Vec3 (*place)(double, double) = nullptr) {
  MeshSoup soup = exactgeo::make_grid(n, n, n, n);
  if (place)
    for (std::uint32_t v = 0; v < vertex_count(soup); ++v) {
      const Vec3 p = place(soup.positions[3 * v], soup.positions[3 * v + 1]);
      for (int k = 0; k < 3; ++k) soup.positions[3 * v + k] = p[k];
    }
  return soup;
}

// Straight-line distances from `source` where `reachable` says so, +inf elsewhere.
template <typename Reachable>
std::vector<double> euclidean_where(const MeshSoup& soup, std::uint32_t source, Reachable reachable) {
  std::vector<double> d(vertex_count(soup), HUGE_VAL);
  for (std::uint32_t v = 0; v < d.size(); ++v)
    if (reachable(v)) d[v] = exactgeo_test::distance_between(soup, source, v);
  return d;
}
std::vector<double> euclidean(const MeshSoup& soup, std::uint32_t source) {
  return euclidean_where(soup, source, [](std::uint32_t) { return true; });
}

// The face of the soup with an edge from a to b (either direction), and the corner opposite that edge.
struct FaceAtEdge {
  std::size_t face;
  std::uint32_t opposite;
};
FaceAtEdge face_at_edge(const MeshSoup& soup, std::uint32_t a, std::uint32_t b) {
  for (std::size_t f = 0; f < face_count(soup); ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t p = soup.triangles[3 * f + k], q = soup.triangles[3 * f + (k + 1) % 3];
      if ((p == a && q == b) || (p == b && q == a)) return {f, soup.triangles[3 * f + (k + 2) % 3]};
    }
  ADD_FAILURE() << "no face with edge " << a << "-" << b;
  return {0, 0};
}

// `action` must throw exactgeo::Error with this code and a message containing each of message_parts.
template <typename Action>
void expect_error(Action action, ErrorCode code, const std::vector<std::string>& message_parts) {
  try {
    action();
  } catch (const exactgeo::Error& error) {
    const std::string message = error.what();
    EXPECT_EQ(error.code(), code) << message;
    for (const std::string& part : message_parts)
      EXPECT_NE(message.find(part), std::string::npos) << "'" << message << "' lacks '" << part << "'";
    return;
  }
  ADD_FAILURE() << "no exactgeo::Error thrown";
}

exactgeo::Mesh mesh_of(const std::vector<double>& positions, const std::vector<std::uint32_t>& triangles) {
  return exactgeo::Mesh(positions, triangles);
}

// ---- Reports and errors ---------------------------------------------------------------------------------

TEST(MeshReport, CountsOnAGridAndASphere) {
  const exactgeo::Mesh grid(exactgeo::make_grid(4, 3, 2.0, 1.0));
  const exactgeo::MeshReport& r = grid.report();
  EXPECT_EQ(grid.vertex_count(), 20u);
  EXPECT_EQ(grid.face_count(), 24u);
  EXPECT_EQ(r.vertices, 20u);
  EXPECT_EQ(r.faces, 24u);
  EXPECT_EQ(r.faces_used, 24u);
  EXPECT_EQ(r.boundary_edges, 14u);
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.surface_vertices, 20u);
  EXPECT_EQ(r.saddle_vertices, 0u);
  EXPECT_EQ(r.faces_repeating_a_vertex + r.duplicate_faces + r.degenerate_faces + r.zero_length_edges +
                r.unreferenced_vertices + r.duplicate_positions + r.welded_vertices + r.non_manifold_edges +
                r.non_manifold_vertices,
            0u);

  const exactgeo::Mesh sphere(exactgeo::make_icosphere(2));
  EXPECT_EQ(sphere.report().boundary_edges, 0u);
  EXPECT_EQ(sphere.report().components, 1u);
  EXPECT_EQ(sphere.report().saddle_vertices, 0u);  // convex: every angle sum is below 2*pi
}

// The counts of the real meshes (all but the largest, to stay fast), recomputed here from the soup.
TEST(MeshReport, MatchesIndependentCountsOnSharedMeshes) {
  EXACTGEO_SKIP_IF_NO_SHARED_MESHES();
  for (const std::string& name : exactgeo_test::shared_mesh_names()) {
    SCOPED_TRACE(name);
    const MeshSoup soup = *exactgeo_test::load_shared_mesh(name);
    if (face_count(soup) > 70'000) continue;
    const exactgeo::MeshReport r = exactgeo::Mesh(soup).report();
    // The faces kept: neither repeating a vertex nor with the vertex set of an earlier kept face.
    MeshSoup kept{soup.positions, {}};
    std::set<std::array<std::uint32_t, 3>> vertex_sets;
    std::size_t repeating = 0, duplicates = 0;
    for (std::size_t f = 0; f < face_count(soup); ++f) {
      const std::uint32_t a = soup.triangles[3 * f], b = soup.triangles[3 * f + 1], c = soup.triangles[3 * f + 2];
      std::array<std::uint32_t, 3> set = {a, b, c};
      std::sort(set.begin(), set.end());
      if (exactgeo_test::repeats_a_vertex(soup, f))
        ++repeating;
      else if (!vertex_sets.insert(set).second)
        ++duplicates;
      else
        add_triangle(kept, a, b, c);
    }
    std::size_t boundary = 0, non_manifold = 0;
    std::vector<std::uint8_t> used(vertex_count(soup), 0);
    for (const exactgeo_test::MeshEdge& e : exactgeo_test::unique_edges(kept)) {
      boundary += e.faces == 1;
      non_manifold += e.faces > 2;
      used[e.low] = used[e.high] = 1;
    }
    const auto split = exactgeo_test::non_manifold_vertices(kept);
    EXPECT_EQ(r.vertices, vertex_count(soup));
    EXPECT_EQ(r.faces, face_count(soup));
    EXPECT_EQ(r.faces_repeating_a_vertex, repeating);
    EXPECT_EQ(r.duplicate_faces, duplicates);
    EXPECT_EQ(r.faces_used, face_count(soup) - repeating - duplicates);
    EXPECT_EQ(r.boundary_edges, boundary);
    EXPECT_EQ(r.non_manifold_edges, non_manifold);
    EXPECT_EQ(r.non_manifold_vertices, std::size_t(std::count(split.begin(), split.end(), 1)));
    EXPECT_EQ(r.unreferenced_vertices, std::size_t(std::count(used.begin(), used.end(), 0)));
  }
}

TEST(MeshErrors, InvalidArraysNameTheElement) {
  const std::vector<double> square = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = HUGE_VAL;
  std::vector<double> with_nan = square;
  with_nan[7] = nan;  // vertex 2, y
  expect_error([&] { mesh_of(with_nan, {0, 1, 2, 0, 2, 3}); }, ErrorCode::invalid_mesh, {"vertex 2"});
  std::vector<double> with_inf = square;
  with_inf[9] = -inf;  // vertex 3, x
  expect_error([&] { mesh_of(with_inf, {0, 1, 2, 0, 2, 3}); }, ErrorCode::invalid_mesh, {"vertex 3"});
  expect_error([&] { mesh_of(square, {0, 1, 2, 0, 2, 7}); }, ErrorCode::invalid_mesh, {"face 1", "7"});
  expect_error([&] { mesh_of({0, 0, 0, 1, 0, 0, 1, 1, 0, 0}, {0, 1, 2}); }, ErrorCode::invalid_mesh,
               {"positions", "10"});
  expect_error([&] { mesh_of(square, {0, 1, 2, 0}); }, ErrorCode::invalid_mesh, {"triangles", "4"});
  expect_error([&] { mesh_of({}, {}); }, ErrorCode::invalid_mesh, {});
  expect_error([&] { mesh_of(square, {}); }, ErrorCode::invalid_mesh, {"no face"});
  expect_error([&] { mesh_of(square, {0, 0, 1, 2, 3, 3}); }, ErrorCode::invalid_mesh, {"no usable face"});
}

TEST(MeshErrors, InvalidSourcesAreInvalidArguments) {
  // Vertex 4 is used by no face.
  const exactgeo::Mesh mesh = mesh_of({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 5, 5, 5}, {0, 1, 2, 0, 2, 3});
  expect_error([&] { exactgeo::geodesic_distance(mesh, 5u); }, ErrorCode::invalid_argument, {"5", "out of range"});
  expect_error([&] { exactgeo::geodesic_distance(mesh, 4u); }, ErrorCode::invalid_argument, {"4", "no face"});
  const std::vector<std::uint32_t> none, one_bad = {0, 9};
  expect_error([&] { exactgeo::geodesic_distance(mesh, none); }, ErrorCode::invalid_argument, {});
  expect_error([&] { exactgeo::geodesic_distance(mesh, one_bad); }, ErrorCode::invalid_argument, {"9"});
}

// ---- Distances under the policy -------------------------------------------------------------------------

class MeshPolicy : public testing::TestWithParam<exactgeo::GeodesicOptions> {
 protected:
  exactgeo::GeodesicResult run(const MeshSoup& soup, std::uint32_t source, const exactgeo::MeshOptions& options = {}) {
    return exactgeo::geodesic_distance(exactgeo::Mesh(soup, options), source, GetParam());
  }
};

INSTANTIATE_TEST_SUITE_P(Mesh, MeshPolicy, testing::ValuesIn(exactgeo_test::kAllVariants),
                         exactgeo_test::variant_name);
INSTANTIATE_TEST_SUITE_P(MeshThreads, MeshPolicy, testing::ValuesIn(exactgeo_test::kParallelVariants),
                         exactgeo_test::variant_name);

TEST_P(MeshPolicy, UnreferencedVerticesAreKeptAtInfinity) {
  // Vertex 0 and the last vertex are used by no face; the grid's vertices follow vertex 0.
  MeshSoup soup;
  add_vertex(soup, {0.5, 0.5, 3});
  append(soup, unit_grid(6));
  const std::uint32_t last = add_vertex(soup, {2, 2, 0});
  const exactgeo::Mesh mesh(soup);
  EXPECT_EQ(mesh.report().unreferenced_vertices, 2u);
  EXPECT_EQ(mesh.report().vertices, vertex_count(soup));

  const std::uint32_t source = 1 + 3 * 7 + 3;  // grid point (3, 3)
  const exactgeo::GeodesicResult result = run(soup, source);
  EXPECT_TRUE(distances_match(result.distances,
                              euclidean_where(soup, source, [&](std::uint32_t v) { return v != 0 && v != last; }),
                              kExact));
  EXPECT_EQ(result.nearest_source[0], exactgeo::kNoSource);
  EXPECT_EQ(result.nearest_source[last], exactgeo::kNoSource);
  EXPECT_EQ(result.nearest_source[source], 0u);
}

TEST_P(MeshPolicy, FacesRepeatingAVertexAreDroppedAndCounted) {
  MeshSoup soup = unit_grid(5);
  const std::size_t grid_faces = face_count(soup);
  add_triangle(soup, 0, 0, 7);
  add_triangle(soup, 8, 14, 8);
  add_triangle(soup, 3, 3, 3);
  const std::uint32_t lonely = add_vertex(soup, {9, 9, 9});  // used only by a dropped face
  add_triangle(soup, lonely, 2, lonely);
  const exactgeo::MeshReport r = exactgeo::Mesh(soup).report();
  EXPECT_EQ(r.faces, grid_faces + 4);
  EXPECT_EQ(r.faces_used, grid_faces);
  EXPECT_EQ(r.faces_repeating_a_vertex, 4u);
  EXPECT_EQ(r.unreferenced_vertices, 1u);
  EXPECT_EQ(r.boundary_edges, 20u);

  EXPECT_TRUE(distances_match(run(soup, 3).distances,
                              euclidean_where(soup, 3, [&](std::uint32_t v) { return v != lonely; }), kExact));
}

// A double-sided export lists every face twice. Kept, each edge had four faces and was cut, shattering the
// surface (doubling spot.obj left 2923 of its 2930 vertices at +inf). Duplicates are dropped, whatever their
// corner order and orientation, and the surface is exactly the single-sided one.
TEST_P(MeshPolicy, DuplicateFacesAreDroppedAndCounted) {
  MeshSoup terrain = unit_grid(6, [](double x, double y) { return Vec3{x, y, 0.3 * std::sin(x) * std::cos(y)}; });
  for (const MeshSoup& single : {exactgeo::make_bumpy_torus(24, 10), terrain}) {
    const std::size_t faces = face_count(single);
    const std::vector<double> expected = run(single, 1).distances;
    // Every face again after all of them, in the same order and reversed; and each right after itself,
    // rotated.
    MeshSoup same = single, reversed = single, interleaved = single;
    interleaved.triangles.clear();
    for (std::size_t f = 0; f < faces; ++f) {
      const std::uint32_t a = single.triangles[3 * f], b = single.triangles[3 * f + 1], c = single.triangles[3 * f + 2];
      add_triangle(same, a, b, c);
      add_triangle(reversed, a, c, b);
      add_triangle(interleaved, a, b, c);
      add_triangle(interleaved, b, c, a);
    }
    for (const MeshSoup* doubled : {&same, &reversed, &interleaved}) {
      const exactgeo::MeshReport r = exactgeo::Mesh(*doubled).report();
      EXPECT_EQ(r.faces, 2 * faces);
      EXPECT_EQ(r.duplicate_faces, faces);
      EXPECT_EQ(r.faces_used, faces);
      EXPECT_EQ(r.non_manifold_edges, 0u);
      EXPECT_EQ(r.components, 1u);
      EXPECT_TRUE(exactgeo_test::same_run_distances(run(*doubled, 1).distances, expected, GetParam()));
    }
    // A point on a dropped duplicate is the same point on the kept face: the weights follow the corners.
    const exactgeo::Mesh mesh(reversed);
    const exactgeo::SurfacePoint on_kept{2, {0.2, 0.3, 0.5}};
    const exactgeo::SurfacePoint on_duplicate{static_cast<std::uint32_t>(faces + 2), {0.2, 0.5, 0.3}};
    EXPECT_EQ(exactgeo::point_position(mesh, on_duplicate), exactgeo::point_position(mesh, on_kept));
    const std::vector<double> from_kept =
        exactgeo::geodesic_distance(mesh, std::span(&on_kept, 1), GetParam()).distances;
    EXPECT_TRUE(exactgeo_test::same_run_distances(
        exactgeo::geodesic_distance(mesh, std::span(&on_duplicate, 1), GetParam()).distances, from_kept, GetParam()));
  }
}

// Only the same vertex set is a duplicate: faces sharing two vertices, or the same positions under other
// vertex indices (unless welded), are not.
TEST(MeshReport, DuplicateFacesNeedTheSameThreeVertices) {
  MeshSoup soup = unit_grid(2);
  const std::size_t faces = face_count(soup);
  const std::uint32_t a = soup.triangles[0], b = soup.triangles[1], c = soup.triangles[2];
  const std::uint32_t c_copy = add_vertex(soup, vertex_position(soup, c));
  add_triangle(soup, a, b, c_copy);
  EXPECT_EQ(exactgeo::Mesh(soup).report().duplicate_faces, 0u);
  EXPECT_EQ(exactgeo::Mesh(soup).report().faces_used, faces + 1);
  const exactgeo::MeshReport welded = exactgeo::Mesh(soup, {.weld_duplicate_positions = true}).report();
  EXPECT_EQ(welded.duplicate_faces, 1u);
  EXPECT_EQ(welded.faces_used, faces);
}

// A flat grid with a zero-area sliver: face (a, b, c) across the interior edge ab is split at the edge's
// midpoint m into (a, m, c) and (m, b, c), and the sliver (a, b, m) closes the gap between m and the face
// on the other side of ab. The surface is still the flat square, so distances stay Euclidean.
TEST_P(MeshPolicy, ZeroAreaSliverInAFlatGrid) {
  MeshSoup soup = unit_grid(6);
  const std::uint32_t a = vertex_at(soup, {2, 3, 0}), b = vertex_at(soup, {3, 3, 0});
  const std::uint32_t m = add_vertex(soup, {2.5, 3, 0});
  const FaceAtEdge split = face_at_edge(soup, a, b);
  const std::uint32_t c = split.opposite;
  for (int k = 0; k < 3; ++k) {
    std::uint32_t& corner = soup.triangles[3 * split.face + k];
    if (corner == b) corner = m;  // (a, b, c) becomes (a, m, c)
  }
  add_triangle(soup, m, b, c);
  add_triangle(soup, a, b, m);

  const exactgeo::MeshReport r = exactgeo::Mesh(soup).report();
  EXPECT_EQ(r.degenerate_faces, 1u);
  EXPECT_EQ(r.boundary_edges, 24u);
  EXPECT_EQ(r.non_manifold_edges, 0u);
  for (std::uint32_t source : {a, m, b, vertex_at(soup, {0, 0, 0}), vertex_at(soup, {2, 5, 0})}) {
    SCOPED_TRACE(testing::Message() << "source " << source);
    EXPECT_TRUE(distances_match(run(soup, source).distances, euclidean(soup, source), kExact));
  }
}

// A flat grid with a zero-length edge: interior vertex a gets a twin a2 at the same position; one face
// (a, b, c) around a becomes (a2, b, c), and two zero-area faces (a, a2, b) and (a2, a, c) stitch a2 to the
// faces across ab and ac. The surface is unchanged, so distances stay Euclidean, also at a2.
TEST_P(MeshPolicy, ZeroLengthEdgeInAFlatGrid) {
  MeshSoup soup = unit_grid(6);
  const std::uint32_t a = vertex_at(soup, {3, 3, 0}), b = vertex_at(soup, {4, 3, 0});
  const std::uint32_t a2 = add_vertex(soup, {3, 3, 0});
  const FaceAtEdge moved = face_at_edge(soup, a, b);
  const std::uint32_t c = moved.opposite;
  for (int k = 0; k < 3; ++k) {
    std::uint32_t& corner = soup.triangles[3 * moved.face + k];
    if (corner == a) corner = a2;
  }
  add_triangle(soup, a, a2, b);
  add_triangle(soup, a2, a, c);

  const exactgeo::MeshReport r = exactgeo::Mesh(soup).report();
  EXPECT_EQ(r.zero_length_edges, 1u);
  EXPECT_EQ(r.degenerate_faces, 2u);
  EXPECT_EQ(r.duplicate_positions, 1u);
  EXPECT_EQ(r.boundary_edges, 24u);
  for (std::uint32_t source : {a, a2, b, c, vertex_at(soup, {6, 0, 0}), vertex_at(soup, {1, 4, 0})}) {
    SCOPED_TRACE(testing::Message() << "source " << source);
    const std::vector<double> d = run(soup, source).distances;
    EXPECT_TRUE(distances_match(d, euclidean(soup, source), kExact));
    EXPECT_NEAR(d[a], d[a2], 1e-15 * 6);
  }
}

TEST_P(MeshPolicy, TwoComponentsLeaveTheOtherAtInfinity) {
  MeshSoup soup = unit_grid(4);
  const auto first_part = static_cast<std::uint32_t>(vertex_count(soup));
  append(soup, unit_grid(5, [](double x, double y) { return Vec3{x + 10, 0.5 * y, y}; }));
  EXPECT_EQ(exactgeo::Mesh(soup).report().components, 2u);
  for (std::uint32_t source : {7u, first_part + 12}) {
    SCOPED_TRACE(testing::Message() << "source " << source);
    const bool in_first = source < first_part;
    const auto same_part = [&](std::uint32_t v) { return (v < first_part) == in_first; };
    const exactgeo::GeodesicResult result = run(soup, source);
    EXPECT_TRUE(distances_match(result.distances, euclidean_where(soup, source, same_part), kExact));
    for (std::uint32_t v = 0; v < vertex_count(soup); ++v)
      EXPECT_EQ(result.nearest_source[v], same_part(v) ? 0u : exactgeo::kNoSource) << "vertex " << v;
  }
  // Targets inside a face of each part, from one source and from two: the other part's is +inf, of no source
  // (it was labelled with source 0: an unreached target's +inf passed the test against an infinite cut-off).
  const exactgeo::Mesh mesh(soup);
  const auto first_part_faces = static_cast<std::uint32_t>(face_count(unit_grid(4)));
  const std::vector<exactgeo::SurfacePoint> targets = {{3, {0.2, 0.3, 0.5}}, {first_part_faces + 5, {0.6, 0.1, 0.3}}};
  for (const std::vector<std::uint32_t>& sources : {std::vector<std::uint32_t>{7}, std::vector<std::uint32_t>{7, 2}}) {
    SCOPED_TRACE(testing::Message() << sources.size() << " sources");
    exactgeo::GeodesicSolver solver(mesh);
    const exactgeo::GeodesicResult& result = solver.solve(sources, targets, GetParam());
    EXPECT_TRUE(std::isfinite(result.target_distances[0]));
    EXPECT_LT(result.target_nearest_source[0], sources.size());
    EXPECT_EQ(result.target_distances[1], HUGE_VAL);
    EXPECT_EQ(result.target_nearest_source[1], exactgeo::kNoSource);
    EXPECT_TRUE(solver.path_to_target(1).points.empty());
  }
}

TEST_P(MeshPolicy, SourcesOnTheBoundary) {
  const MeshSoup soup = unit_grid(7);
  for (const Vec3& p : {Vec3{0, 0, 0}, Vec3{3, 0, 0}, Vec3{7, 4, 0}, Vec3{7, 7, 0}}) {
    const std::uint32_t source = vertex_at(soup, p);
    EXPECT_TRUE(distances_match(run(soup, source).distances, euclidean(soup, source), kExact)) << "source " << source;
  }
}

// Three flat pages sharing the spine x = y = 0, z in [0, 4]: every spine edge has three faces, so it is cut
// and the pages come apart; spine vertices keep the distance of their nearest copy.
TEST_P(MeshPolicy, NonManifoldEdgesBookOfThreeSeparatePages) {
  MeshSoup soup;
  std::vector<std::uint32_t> spine;
  for (int z = 0; z <= 4; ++z) spine.push_back(add_vertex(soup, {0, 0, double(z)}));
  std::vector<std::vector<std::uint32_t>> page_vertices(3);
  for (int page = 0; page < 3; ++page) {
    const double angle = 2.0 * page;  // radians, pages about 115 degrees apart
    std::vector<std::uint32_t> column = spine;
    for (int r = 1; r <= 3; ++r) {
      std::vector<std::uint32_t> next;
      for (int z = 0; z <= 4; ++z)
        next.push_back(add_vertex(soup, {r * std::cos(angle), r * std::sin(angle), double(z)}));
      for (int z = 0; z < 4; ++z) {
        add_triangle(soup, column[z], next[z], next[z + 1]);
        add_triangle(soup, column[z], next[z + 1], column[z + 1]);
      }
      page_vertices[page].insert(page_vertices[page].end(), next.begin(), next.end());
      column = next;
    }
  }
  const exactgeo::MeshReport r = exactgeo::Mesh(soup).report();
  EXPECT_EQ(r.non_manifold_edges, 4u);
  EXPECT_EQ(r.non_manifold_vertices, 5u);
  EXPECT_EQ(r.surface_vertices, vertex_count(soup) + 2 * 5);
  EXPECT_EQ(r.components, 3u);

  const auto on_page = [&](int page, std::uint32_t v) {
    return v < spine.size() ||
           std::find(page_vertices[page].begin(), page_vertices[page].end(), v) != page_vertices[page].end();
  };
  // From inside page 0: that page and the spine only. From the spine: every page, each flat.
  const std::uint32_t inside = page_vertices[0][5 + 2];  // r = 2, z = 2
  EXPECT_TRUE(distances_match(run(soup, inside).distances,
                              euclidean_where(soup, inside, [&](std::uint32_t v) { return on_page(0, v); }), kExact));
  EXPECT_TRUE(distances_match(run(soup, spine[1]).distances, euclidean(soup, spine[1]), kExact));
}

// A flat 12 x 12 sheet with a fin standing on the segment x = 6, y in [3, 9]: the six edges along that
// segment have three faces each, so they are cut. The fin comes off, and the sheet gets a slit: paths from
// one side of the slit to the other go around one of its ends.
TEST_P(MeshPolicy, NonManifoldEdgesSheetWithAFin) {
  MeshSoup soup = unit_grid(12);
  const auto sheet_vertices = static_cast<std::uint32_t>(vertex_count(soup));
  std::vector<std::uint32_t> fin_index(7 * 5);  // fin grid point (y - 3, z) at z * 7 + y - 3
  for (int z = 0; z <= 4; ++z)
    for (int y = 3; y <= 9; ++y)
      fin_index[z * 7 + y - 3] =
          z == 0 ? vertex_at(soup, {6, double(y), 0}) : add_vertex(soup, {6, double(y), double(z)});
  for (int z = 0; z < 4; ++z)
    for (int i = 0; i < 6; ++i) {
      const std::uint32_t p = fin_index[z * 7 + i], q = fin_index[z * 7 + i + 1], s = fin_index[(z + 1) * 7 + i],
                          t = fin_index[(z + 1) * 7 + i + 1];
      add_triangle(soup, p, q, t);
      add_triangle(soup, p, t, s);
    }
  const exactgeo::MeshReport r = exactgeo::Mesh(soup).report();
  EXPECT_EQ(r.non_manifold_edges, 6u);
  EXPECT_EQ(r.non_manifold_vertices, 7u);  // the slit's 5 inner vertices (3 copies) and its 2 ends (2 copies)
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(r.boundary_edges, 48u + 14u);

  const auto is_fin = [&](std::uint32_t v) { return v >= sheet_vertices; };
  const auto on_slit = [&](const Vec3& p) { return p[2] == 0 && p[0] == 6 && p[1] >= 3 && p[1] <= 9; };
  // Sheet distances from a sheet point s: straight, unless the segment crosses the open slit.
  const auto around_slit = [&](const Vec3& s, const Vec3& t) {
    if ((s[0] - 6) * (t[0] - 6) < 0) {
      const double y = s[1] + (6 - s[0]) * (t[1] - s[1]) / (t[0] - s[0]);
      if (y > 3 && y < 9) {
        const Vec3 low = {6, 3, 0}, high = {6, 9, 0};
        return std::min(distance(s, low) + distance(low, t), distance(s, high) + distance(high, t));
      }
    }
    return distance(s, t);
  };
  for (const Vec3& p : {Vec3{4, 6, 0}, Vec3{9, 5, 0}, Vec3{6, 1, 0}}) {
    const std::uint32_t source = vertex_at(soup, p);
    std::vector<double> expected(vertex_count(soup), HUGE_VAL);
    for (std::uint32_t v = 0; v < expected.size(); ++v)
      if (!is_fin(v)) expected[v] = around_slit(p, vertex_position(soup, v));
    EXPECT_TRUE(distances_match(run(soup, source).distances, expected, kExact)) << "source " << source;
  }
  // From the fin: the fin and the slit only. From the slit: everything, straight.
  const std::uint32_t on_fin = fin_index[2 * 7 + 3];
  EXPECT_TRUE(distances_match(
      run(soup, on_fin).distances,
      euclidean_where(soup, on_fin, [&](std::uint32_t v) { return is_fin(v) || on_slit(vertex_position(soup, v)); }),
      kExact));
  const std::uint32_t slit = vertex_at(soup, {6, 6, 0});
  EXPECT_TRUE(distances_match(run(soup, slit).distances, euclidean(soup, slit), kExact));
}

// Two open pyramids, one pointing up and one down, touching at their tips: the tip's faces form two fans, so
// it is split in two and the pyramids are separate surfaces. Only a source at the tip reaches both. With 6
// sides the tip has 12 corners, whose edges the build groups in a small table; with 12 sides, 24, which it
// sorts: both ways must find the same two fans.
TEST_P(MeshPolicy, NonManifoldVertexTwoPyramidsTouchingAtTheTip) {
  for (const int sides : {6, 12}) {
    SCOPED_TRACE(sides);
    MeshSoup soup;
    const std::uint32_t tip = add_vertex(soup, {0, 0, 0});
    for (double up : {1.0, -1.0}) {
      std::vector<std::uint32_t> inner(sides), outer(sides);
      for (int i = 0; i < sides; ++i) {
        const double angle = 2 * std::numbers::pi * i / sides;
        inner[i] = add_vertex(soup, {std::cos(angle), std::sin(angle), up * 1.5});
        outer[i] = add_vertex(soup, {2 * std::cos(angle), 2 * std::sin(angle), up * 3.0});
      }
      for (int i = 0; i < sides; ++i) {
        const int j = (i + 1) % sides;
        add_triangle(soup, tip, inner[i], inner[j]);
        add_triangle(soup, inner[i], outer[i], outer[j]);
        add_triangle(soup, inner[i], outer[j], inner[j]);
      }
    }
    const exactgeo::MeshReport r = exactgeo::Mesh(soup).report();
    EXPECT_EQ(r.non_manifold_vertices, 1u);
    EXPECT_EQ(r.non_manifold_edges, 0u);
    EXPECT_EQ(r.surface_vertices, vertex_count(soup) + 1);
    EXPECT_EQ(r.components, 2u);
    EXPECT_EQ(r.boundary_edges, 2u * sides);

    // From the tip every vertex is straight up or down a ray of edges.
    EXPECT_TRUE(distances_match(run(soup, tip).distances, euclidean(soup, tip), kExact));
    // From the upper pyramid's rim: the lower pyramid stays out of reach, except its tip, which is also the
    // upper pyramid's tip, reached down a ray.
    const std::uint32_t rim = 2;  // outer vertex on ray 0 of the upper pyramid
    const exactgeo::GeodesicResult result = run(soup, rim);
    EXPECT_NEAR(result.distances[tip], exactgeo_test::distance_between(soup, rim, tip), kExact * 4);
    for (std::uint32_t v = 1; v < vertex_count(soup); ++v) {
      const bool upper = vertex_position(soup, v)[2] > 0;
      EXPECT_EQ(std::isfinite(result.distances[v]), upper) << "vertex " << v;
      if (upper) {
        EXPECT_GE(result.distances[v], exactgeo_test::distance_between(soup, rim, v) * (1 - kExact));
      }
    }
  }
}

// Issue 34, finding 2: a bowtie, two triangles meeting at vertex 0 only, which the policy splits into one copy
// per wing. A target at vertex 0, named by index or as a corner of either face, is the input vertex: its
// distance is the smallest over the copies, as in the per-vertex distances, and its path goes to that copy;
// a source at either corner is vertex 0, in both wings. Before, each such point stood on one face only: from
// the other wing, inf.
TEST_P(MeshPolicy, NonManifoldVertexBowtieAsTargetAndSourceIsOneVertex) {
  // Wing A: vertices 0, 1, 2 in the plane z = 0; wing B: 0, 3, 4 in the plane y = 0.
  const MeshSoup soup{{0, 0, 0, 3, 0, 0, 0, 4, 0, -2, 0, 0, 0, 0, -1}, {0, 1, 2, 0, 3, 4}};
  const exactgeo::Mesh mesh(soup);
  ASSERT_EQ(mesh.report().non_manifold_vertices, 1u);
  const std::vector<exactgeo::SurfacePoint> at_zero = {exactgeo::vertex_point(mesh, 0), {0, {1, 0, 0}}, {1, {1, 0, 0}}};
  for (std::uint32_t source = 1; source < 5; ++source) {
    SCOPED_TRACE(testing::Message() << "source " << source);
    const double along_edge = exactgeo_test::distance_between(soup, source, 0);
    exactgeo::GeodesicSolver solver(mesh);
    const std::uint32_t sources[] = {source};
    const exactgeo::GeodesicResult& result = solver.solve(sources, at_zero, GetParam());
    EXPECT_NEAR(result.distances[0], along_edge, kExact * 4);
    for (std::size_t t = 0; t < at_zero.size(); ++t) {
      EXPECT_EQ(result.target_distances[t], result.distances[0]) << "target " << t;
      EXPECT_EQ(result.target_nearest_source[t], 0u) << "target " << t;
      const exactgeo::GeodesicPath path = solver.path_to_target(t);
      EXPECT_NEAR(path.length, along_edge, kExact * 4) << "target " << t;
      ASSERT_FALSE(path.locations.empty()) << "target " << t;
      EXPECT_EQ(path.locations.back().kind, exactgeo::PathPointLocation::Kind::vertex);
      EXPECT_EQ(path.locations.back().vertex, 0u);
    }
  }
  for (std::size_t corner = 0; corner < at_zero.size(); ++corner) {
    const std::span<const exactgeo::SurfacePoint> source(&at_zero[corner], 1);
    const std::vector<double> d = exactgeo::geodesic_distance(mesh, source, GetParam()).distances;
    EXPECT_TRUE(distances_match(d, euclidean(soup, 0), kExact)) << "source at corner " << corner;
  }
}

// Two halves of a flat 12 x 6 sheet, each with its own copy of the 7 vertices on the seam x = 6.
TEST_P(MeshPolicy, WeldMergesASeam) {
  MeshSoup soup = unit_grid(6);
  const auto left = static_cast<std::uint32_t>(vertex_count(soup));
  append(soup, unit_grid(6, [](double x, double y) { return Vec3{x + 6, y, 0}; }));
  const std::uint32_t source = vertex_at(soup, {2, 3, 0});

  const exactgeo::MeshReport apart = exactgeo::Mesh(soup).report();
  EXPECT_EQ(apart.duplicate_positions, 7u);
  EXPECT_EQ(apart.welded_vertices, 0u);
  EXPECT_EQ(apart.components, 2u);
  EXPECT_TRUE(distances_match(run(soup, source).distances,
                              euclidean_where(soup, source, [&](std::uint32_t v) { return v < left; }), kExact));

  const exactgeo::MeshOptions weld{.weld_duplicate_positions = true};
  const exactgeo::MeshReport welded = exactgeo::Mesh(soup, weld).report();
  EXPECT_EQ(welded.duplicate_positions, 7u);
  EXPECT_EQ(welded.welded_vertices, 7u);
  EXPECT_EQ(welded.components, 1u);
  EXPECT_EQ(welded.boundary_edges, 36u);
  EXPECT_TRUE(distances_match(run(soup, source, weld).distances, euclidean(soup, source), kExact));
  // A source given as the seam copy that was merged away works like the copy it was merged into.
  const std::uint32_t right_copy = left + 3 * 7;  // (6, 3) in the right half
  ASSERT_EQ(vertex_position(soup, right_copy), (Vec3{6, 3, 0}));
  EXPECT_TRUE(distances_match(run(soup, right_copy, weld).distances, euclidean(soup, right_copy), kExact));
}

// Welding compares positions by value, like the STL reader: a seam whose copies write -0 where the others
// write 0 is still one seam.
TEST_P(MeshPolicy, WeldTreatsMinusZeroAsZero) {
  MeshSoup soup = unit_grid(6, [](double x, double y) { return Vec3{x - 6, y, 0}; });
  append(soup, unit_grid(6, [](double x, double y) { return Vec3{x == 0 ? -0.0 : x, y, -0.0}; }));
  const std::uint32_t source = vertex_at(soup, {-4, 3, 0});
  const exactgeo::MeshOptions weld{.weld_duplicate_positions = true};
  const exactgeo::MeshReport welded = exactgeo::Mesh(soup, weld).report();
  EXPECT_EQ(welded.duplicate_positions, 7u);
  EXPECT_EQ(welded.welded_vertices, 7u);
  EXPECT_EQ(welded.components, 1u);
  EXPECT_TRUE(distances_match(run(soup, source, weld).distances, euclidean(soup, source), kExact));
}

}  // namespace
