// exactgeo::locate, the closest surface point of points in space: against a search of every kept face with an
// independent formula in long double, on generated meshes (with zero-area and needle triangles) and on every
// shared mesh for 10,000 seeded random points on, near and far from the surface; closed forms, points exactly
// at corners and on edges, ties, dropped faces, threads, scale, far points, errors, and the located points as
// sources and targets.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "closest_point_reference.hpp"
#include "exactgeo/exactgeo.hpp"
#include "face_bvh.hpp"
#include "test_meshes.hpp"

namespace {

using namespace exactgeo_test::closest_point;  // the reference and its checks

using exactgeo::LocateResult;
using exactgeo::Mesh;
using exactgeo::MeshSoup;
using exactgeo::SurfacePoint;
using exactgeo_test::Random;
using exactgeo_test::Vec3;
using exactgeo_test::vertex_position;

#ifdef EXACTGEO_TESTS_SANITIZED
constexpr std::size_t kSharedMeshPoints = 1'000;
constexpr std::size_t kMaxSharedFaces = 13'000;
#else
constexpr std::size_t kSharedMeshPoints = 10'000;
constexpr std::size_t kMaxSharedFaces = std::numeric_limits<std::size_t>::max();
#endif

// ---- Closed forms -------------------------------------------------------------------------------------

MeshSoup right_triangle() {
  MeshSoup soup;
  exactgeo_test::add_vertex(soup, {0, 0, 0});
  exactgeo_test::add_vertex(soup, {1, 0, 0});
  exactgeo_test::add_vertex(soup, {0, 1, 0});
  exactgeo_test::add_triangle(soup, 0, 1, 2);
  return soup;
}

TEST(Locate, ClosedFormsOnOneTriangle) {
  const Mesh mesh(right_triangle());
  const LocateResult r = exactgeo::locate(mesh, flat({{0.25, 0.25, 2}, {2, -1, 0}, {0.5, -3, 4}, {-1, 3, 0}}));
  // Above the inside: the foot of the perpendicular.
  EXPECT_EQ(r.points[0].face, 0u);
  EXPECT_NEAR(r.points[0].barycentric[0], 0.5, 1e-15);
  EXPECT_NEAR(r.points[0].barycentric[1], 0.25, 1e-15);
  EXPECT_NEAR(r.points[0].barycentric[2], 0.25, 1e-15);
  EXPECT_DOUBLE_EQ(r.distances[0], 2);
  // Beyond corner 1: that corner, exactly.
  EXPECT_EQ(r.points[1].barycentric, (std::array<double, 3>{0, 1, 0}));
  EXPECT_DOUBLE_EQ(r.distances[1], std::sqrt(2.0));
  // Beside edge 01: its midpoint.
  EXPECT_EQ(r.points[2].barycentric, (std::array<double, 3>{0.5, 0.5, 0}));
  EXPECT_DOUBLE_EQ(r.distances[2], 5);
  // Beyond corner 2, off to the side: corner 2.
  EXPECT_EQ(r.points[3].barycentric, (std::array<double, 3>{0, 0, 1}));
  EXPECT_DOUBLE_EQ(r.distances[3], std::sqrt(5.0));
}

TEST(Locate, EmptyInputGivesEmptyResult) {
  const LocateResult r = exactgeo::locate(Mesh(right_triangle()), {});
  EXPECT_TRUE(r.points.empty());
  EXPECT_TRUE(r.distances.empty());
}

// ---- Corners, edges and ties ----------------------------------------------------------------------------

// A flat 8 x 8 grid of cells an eighth wide: corners and edge midpoints are exact in binary.
MeshSoup eighths_grid() { return exactgeo::make_grid(8, 8, 1.0, 1.0); }

// The lowest input face with a corner at vertex v.
std::uint32_t lowest_face_at(const MeshSoup& soup, std::uint32_t v) {
  for (std::uint32_t f = 0; f < exactgeo_test::face_count(soup); ++f)
    for (int k = 0; k < 3; ++k)
      if (soup.triangles[3 * f + k] == v) return f;
  return exactgeo::kNoSource;
}

TEST(Locate, PointsAtCornersAreTheCornersOnTheLowestFace) {
  const MeshSoup soup = eighths_grid();
  const Mesh mesh(soup);
  std::vector<Vec3> points;
  for (std::uint32_t v = 0; v < exactgeo_test::vertex_count(soup); ++v) points.push_back(vertex_position(soup, v));
  const LocateResult r = exactgeo::locate(mesh, flat(points));
  for (std::uint32_t v = 0; v < points.size(); ++v) {
    EXPECT_EQ(r.distances[v], 0.0) << "vertex " << v;
    EXPECT_EQ(r.points[v].face, lowest_face_at(soup, v)) << "vertex " << v;
    EXPECT_EQ(exactgeo::point_position(mesh, r.points[v]), points[v]) << "vertex " << v;
  }
}

TEST(Locate, PointsAboveCornersTieExactlyAndTakeTheLowestFace) {
  const MeshSoup soup = eighths_grid();
  std::vector<Vec3> points;
  for (std::uint32_t v = 0; v < exactgeo_test::vertex_count(soup); ++v) {
    Vec3 p = vertex_position(soup, v);
    p[2] = 0.75;
    points.push_back(p);
  }
  const LocateResult r = exactgeo::locate(Mesh(soup), flat(points));
  for (std::uint32_t v = 0; v < points.size(); ++v) {
    EXPECT_EQ(r.distances[v], 0.75) << "vertex " << v;
    EXPECT_EQ(r.points[v].face, lowest_face_at(soup, v)) << "vertex " << v;
  }
}

TEST(Locate, PointsOnEdgesLieOnTheLowestFaceOfTheEdge) {
  const MeshSoup soup = eighths_grid();
  const Mesh mesh(soup);
  const std::vector<exactgeo_test::MeshEdge> edges = exactgeo_test::unique_edges(soup);
  std::vector<Vec3> points;
  for (const auto& edge : edges) {
    const Vec3 a = vertex_position(soup, edge.low), b = vertex_position(soup, edge.high);
    points.push_back({(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
  }
  const LocateResult r = exactgeo::locate(mesh, flat(points));
  for (std::size_t i = 0; i < edges.size(); ++i) {
    std::uint32_t lowest = exactgeo::kNoSource;
    for (std::uint32_t f = 0; f < exactgeo_test::face_count(soup) && lowest == exactgeo::kNoSource; ++f) {
      const auto t = std::span(soup.triangles).subspan(3 * f, 3);
      if (std::count(t.begin(), t.end(), edges[i].low) && std::count(t.begin(), t.end(), edges[i].high)) lowest = f;
    }
    EXPECT_EQ(r.distances[i], 0.0) << "edge " << edges[i].low << "-" << edges[i].high;
    EXPECT_EQ(r.points[i].face, lowest) << "edge " << edges[i].low << "-" << edges[i].high;
    EXPECT_EQ(exactgeo::point_position(mesh, r.points[i]), points[i]);
  }
}

TEST(Locate, NeverOnADroppedFace) {
  // Face 0 repeats a vertex and face 2 repeats face 1 reversed: both dropped, face 2 in favour of face 1.
  MeshSoup soup;
  for (const Vec3& p : std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}})
    exactgeo_test::add_vertex(soup, p);
  exactgeo_test::add_triangle(soup, 0, 0, 1);
  exactgeo_test::add_triangle(soup, 0, 1, 2);
  exactgeo_test::add_triangle(soup, 2, 1, 0);
  exactgeo_test::add_triangle(soup, 0, 2, 3);
  const std::vector<double> xyz =
      flat({{0, 0, 0}, {0.5, 0, 0}, {0.5, -1, 0}, {0.7, 0.3, 1}, {0.2, 0.6, -1}, {1, 1, 0}});
  const LocateResult r = exactgeo::locate(Mesh(soup), xyz);
  const std::vector<std::uint32_t> expected = {1, 1, 1, 1, 3, 1};
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(r.points[i].face, expected[i]) << "point " << i;
  expect_matches_brute_force(soup, xyz, r, "dropped faces");
}

// ---- Generated meshes, degenerate triangles -------------------------------------------------------------

// Triangles of zero area (collinear corners, two or three coincident corners) and needles down to 1e-9 wide,
// some sharing edges with ordinary triangles, turned at random so that nothing is axis-aligned.
MeshSoup degenerate_soup(Random& random) {
  MeshSoup soup;
  const auto add = [&](const Vec3& a, const Vec3& b, const Vec3& c) {
    const std::uint32_t i = exactgeo_test::add_vertex(soup, a), j = exactgeo_test::add_vertex(soup, b),
                        k = exactgeo_test::add_vertex(soup, c);
    exactgeo_test::add_triangle(soup, i, j, k);
  };
  add({0, 0, 0}, {1, 0, 0}, {2, 0, 0});            // collinear
  add({0, 1, 0}, {0, 1, 0}, {1, 1, 0});            // two corners coincide
  add({2, 2, 2}, {2, 2, 2}, {2, 2, 2});            // a point
  add({0, 3, 0}, {1, 3, 0}, {0.5, 3 + 1e-9, 0});   // a needle across
  add({0, 4, 0}, {1e-9, 4, 0}, {0.5, 5, 0.25});    // a needle along
  add({3, 0, 0}, {4, 0, 0}, {3.5, 1e-12, 1e-12});  // thinner still
  for (int i = 0; i < 20; ++i) {
    const Vec3 a = {random.uniform(-1, 5), random.uniform(-1, 5), random.uniform(-1, 1)};
    const Vec3 b = {random.uniform(-1, 5), random.uniform(-1, 5), random.uniform(-1, 1)};
    const double t = random.uniform(-0.5, 1.5), lift = std::pow(10.0, random.uniform(-14, -3));
    add(a, b, {a[0] + t * (b[0] - a[0]) + lift, a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]) - lift});
  }
  // A fan of ordinary triangles around a needle, sharing its edges.
  const std::uint32_t hub = exactgeo_test::add_vertex(soup, {6, 6, 0});
  const std::uint32_t tip = exactgeo_test::add_vertex(soup, {8, 6, 0});
  const std::uint32_t side = exactgeo_test::add_vertex(soup, {7, 6 + 1e-10, 0});
  const std::uint32_t top = exactgeo_test::add_vertex(soup, {7, 8, 1});
  exactgeo_test::add_triangle(soup, hub, side, tip);
  exactgeo_test::add_triangle(soup, hub, top, side);
  exactgeo_test::add_triangle(soup, side, top, tip);
  return exactgeo_test::randomly_rotated(soup, random);
}

struct NamedSoup {
  std::string name;
  MeshSoup soup;
};

std::vector<NamedSoup> generated_meshes() {
  using namespace exactgeo_test;
  Random random(35);
  std::vector<std::uint32_t> stands_for;
  const MeshSoup torus = exactgeo::make_bumpy_torus(24, 10);
  return {{"icosphere", exactgeo::make_icosphere(3)},
          {"bumpy torus", exactgeo::make_bumpy_torus(40, 16)},
          {"grid", exactgeo::make_grid(12, 9, 3.0, 2.0)},
          {"noisy height field", random_height_field(random, 16, 12, 0.4, false)},
          {"smooth height field", random_height_field(random, 16, 12, 0.4, true)},
          {"grid with holes", random_grid_with_holes(random, 14, 10, 3)},
          {"convex polygon", random_convex_polygon(random, 9, 3)},
          {"sheet with fin", random_sheet_with_fin(random)},
          {"degenerate triangles", degenerate_soup(random)},
          {"coincident vertices", with_coincident_vertices(torus, random, 12, stands_for)}};
}

TEST(Locate, GeneratedMeshesMatchBruteForce) {
  std::uint64_t seed = 1;
  for (const NamedSoup& mesh : generated_meshes()) {
    const std::vector<double> xyz = random_points(mesh.soup, 2000, seed++);
    expect_matches_brute_force(mesh.soup, xyz, exactgeo::locate(Mesh(mesh.soup), xyz), mesh.name);
  }
}

TEST(Locate, DegenerateTrianglesAlone) {
  // Only zero-area faces: every answer lies on their edges.
  MeshSoup soup;
  for (const Vec3& p : std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 0, 0}, {2, 3, 0}})
    exactgeo_test::add_vertex(soup, p);
  exactgeo_test::add_triangle(soup, 0, 1, 2);
  exactgeo_test::add_triangle(soup, 2, 3, 4);
  const std::vector<double> xyz = random_points(soup, 500, 7);
  expect_matches_brute_force(soup, xyz, exactgeo::locate(Mesh(soup), xyz), "zero-area faces");
}

// ---- Threads, concurrency, scale, far points, errors -----------------------------------------------------

void expect_same(const LocateResult& a, const LocateResult& b) {
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    ASSERT_EQ(a.points[i].face, b.points[i].face) << "point " << i;
    ASSERT_EQ(a.points[i].barycentric, b.points[i].barycentric) << "point " << i;
    ASSERT_EQ(a.distances[i], b.distances[i]) << "point " << i;
  }
}

TEST(Locate, SameResultOnAnyThreadCount) {
  const MeshSoup soup = exactgeo::make_bumpy_torus(200, 60);  // 24,000 faces: the hierarchy's build is shared too
  const std::vector<double> xyz = random_points(soup, 20000, 11);
  const LocateResult one = exactgeo::locate(Mesh(soup), xyz, {.threads = 1});
  expect_same(one, exactgeo::locate(Mesh(soup), xyz, {.threads = 3}));
  expect_same(one, exactgeo::locate(Mesh(soup), xyz, {.threads = 0}));
}

TEST(Locate, HierarchyIsTheSameOnAnyTeam) {
  // Three threads and ranges of one item, whatever the cores and the mesh's size: the parallel build, which
  // locate only uses on large meshes with cores to spare, gives the one-thread hierarchy bit for bit.
  using exactgeo::detail::FaceBvh;
  const Mesh mesh(exactgeo::make_bumpy_torus(60, 24));
  exactgeo::detail::WorkerPool one(1), three(3);
  const FaceBvh a = exactgeo::detail::build_face_bvh({one}, mesh.surface());
  const FaceBvh b = exactgeo::detail::build_face_bvh({three, {}, 1}, mesh.surface());
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (std::size_t i = 0; i < a.nodes.size(); ++i) {
    EXPECT_EQ(a.nodes[i].lo, b.nodes[i].lo) << "node " << i;
    EXPECT_EQ(a.nodes[i].hi, b.nodes[i].hi) << "node " << i;
    EXPECT_EQ(a.nodes[i].first, b.nodes[i].first) << "node " << i;
    EXPECT_EQ(a.nodes[i].count, b.nodes[i].count) << "node " << i;
  }
  EXPECT_EQ(a.corners, b.corners);
  EXPECT_EQ(a.input_faces, b.input_faces);
  EXPECT_EQ(a.margin, b.margin);
}

TEST(Locate, ConcurrentFirstCallsShareOneHierarchy) {
  const MeshSoup soup = exactgeo::make_bumpy_torus(60, 24);
  const Mesh mesh(soup);
  const std::vector<double> xyz = random_points(soup, 3000, 12);
  std::vector<LocateResult> results(4);
  {
    std::vector<std::jthread> threads;
    for (LocateResult& result : results)
      threads.emplace_back([&] { result = exactgeo::locate(mesh, xyz, {.threads = 2}); });
  }
  for (const LocateResult& result : results) expect_same(results[0], result);
  expect_same(results[0], exactgeo::locate(Mesh(soup), xyz, {.threads = 1}));
}

TEST(Locate, ScaledMeshesLocateTheSamePoints) {
  // A power of two scales exactly: the same faces and weights, distances scaled (to rounding of the norm).
  const MeshSoup soup = exactgeo::make_bumpy_torus(30, 12);
  const std::vector<double> xyz = random_points(soup, 1000, 13);
  const LocateResult unscaled = exactgeo::locate(Mesh(soup), xyz);
  for (const int exponent : {-1000, -700, 700, 960}) {
    MeshSoup scaled = soup;
    std::vector<double> scaled_xyz = xyz;
    for (double& c : scaled.positions) c = std::ldexp(c, exponent);
    for (double& c : scaled_xyz) c = std::ldexp(c, exponent);
    const LocateResult r = exactgeo::locate(Mesh(scaled), scaled_xyz);
    for (std::size_t i = 0; i < r.points.size(); ++i) {
      ASSERT_EQ(r.points[i].face, unscaled.points[i].face) << "2^" << exponent << ", point " << i;
      ASSERT_EQ(r.points[i].barycentric, unscaled.points[i].barycentric) << "2^" << exponent << ", point " << i;
      // At 2^-1000 the offsets of points on the surface are subnormal: a few of their steps, scaled back.
      const double subnormal_step = std::ldexp(1.0, -1074 - exponent);
      ASSERT_NEAR(std::ldexp(r.distances[i], -exponent), unscaled.distances[i],
                  1e-15 * unscaled.distances[i] + 8 * subnormal_step)
          << "2^" << exponent << ", point " << i;
    }
  }
}

TEST(Locate, FarPointsFindTheSupportingPoint) {
  // Seen from far along a direction, the closest point of a convex mesh is the one farthest out that way (to
  // about extent^2 / distance): here a vertex. Its distance is exact to rounding, even where squaring it would
  // overflow.
  const MeshSoup soup = exactgeo::make_icosphere(2);
  const Mesh mesh(soup);
  const std::array<Vec3, 4> directions = {{{1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {0.48, -0.6, 0.64}}};
  for (const double far : {1e3, 1e6, 1e9, 1e20, 1e160, 1e300}) {
    std::vector<double> xyz;
    for (const Vec3& u : directions)
      for (double c : u) xyz.push_back(far * c);
    const LocateResult r = exactgeo::locate(mesh, xyz);
    for (std::size_t i = 0; i < directions.size(); ++i) {
      const Vec3& u = directions[i];
      double support = -HUGE_VAL;
      for (std::size_t v = 0; v < exactgeo_test::vertex_count(soup); ++v) {
        const Vec3 p = vertex_position(soup, static_cast<std::uint32_t>(v));
        support = std::max(support, p[0] * u[0] + p[1] * u[1] + p[2] * u[2]);
      }
      const std::array<double, 3> q = exactgeo::point_position(mesh, r.points[i]);
      EXPECT_NEAR(q[0] * u[0] + q[1] * u[1] + q[2] * u[2], support, 1e-7 + 4 / far) << far << ", direction " << i;
      EXPECT_NEAR(r.distances[i], far - support, 1e-15 * far + 4 / far) << far << ", direction " << i;
    }
  }
}

TEST(Locate, FarPointsOfAFarMeshMatchBruteForce) {
  // A mesh 1e6 from the origin, points 1e4 diagonals away.
  MeshSoup soup = exactgeo::make_bumpy_torus(24, 10);
  for (std::size_t v = 0; v < exactgeo_test::vertex_count(soup); ++v) soup.positions[3 * v] += 1e6;
  Random random(14);
  std::vector<double> xyz;
  for (int i = 0; i < 300; ++i)
    for (int k = 0; k < 3; ++k) xyz.push_back((k == 0 ? 1e6 : 0) + random.uniform(-3e4, 3e4));
  expect_matches_brute_force(soup, xyz, exactgeo::locate(Mesh(soup), xyz), "far from the origin");
}

void expect_error(const Mesh& mesh, const std::vector<double>& xyz, const std::string& message) {
  try {
    exactgeo::locate(mesh, xyz);
    ADD_FAILURE() << "no error; expected: " << message;
  } catch (const exactgeo::Error& e) {
    EXPECT_EQ(e.code(), exactgeo::ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
}

TEST(Locate, ErrorsNameThePoint) {
  const Mesh mesh(right_triangle());
  expect_error(mesh, {0, 0, 0, 1, 2, 3, 4}, "xyz has 7 values, not a multiple of 3");
  expect_error(mesh, {0, 0, 0, 1, 2, 3, 4, NAN, 5}, "point 2 has a non-finite coordinate");
  expect_error(mesh, {0, 0, 0, 1, 2, 3, 4, 5, -INFINITY}, "point 2 has a non-finite coordinate");
  MeshSoup far = right_triangle();
  for (double& c : far.positions) c = 1e308 - c * 1e300;
  expect_error(Mesh(far), {1e308, 1e308, 1e308, -1e308, 0, 0},
               "point 1 is farther from the surface than the largest double");
}

// ---- The located points as sources and targets ------------------------------------------------------------

TEST(Locate, LocatedPointsAreSourcesAndTargets) {
  const MeshSoup soup = exactgeo::make_bumpy_torus(40, 16);
  const Mesh mesh(soup);
  // Points at the vertices locate to the vertices: as targets, the vertices' own distances.
  std::vector<double> at_vertices(soup.positions.begin(), soup.positions.begin() + 3 * 50);
  const LocateResult vertices = exactgeo::locate(mesh, at_vertices);
  exactgeo::GeodesicSolver solver(mesh);
  const std::vector<std::uint32_t> source = {123};
  const exactgeo::GeodesicResult& to_vertices = solver.solve(source, vertices.points);
  for (std::uint32_t v = 0; v < 50; ++v)
    EXPECT_EQ(to_vertices.target_distances[v], to_vertices.distances[v]) << "vertex " << v;
  // Points off the surface as sources and as targets: the distance between two of them is the same both ways.
  const std::vector<double> xyz = random_points(soup, 10, 15);
  const std::vector<SurfacePoint> points = exactgeo::locate(mesh, xyz).points;
  std::vector<std::vector<double>> between;
  for (const SurfacePoint& point : points)
    between.push_back(solver.solve(std::span(&point, 1), points).target_distances);
  const double largest = exactgeo_test::max_finite(between[0]);
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(between[i][i], 0.0) << "point " << i;
    for (std::size_t j = 0; j < i; ++j) EXPECT_NEAR(between[i][j], between[j][i], 1e-12 * largest) << i << ", " << j;
  }
}

// ---- Every shared mesh ------------------------------------------------------------------------------------

class LocateOnSharedMesh : public testing::TestWithParam<std::string> {};

TEST_P(LocateOnSharedMesh, MatchesBruteForceAtRandomPoints) {
  const MeshSoup soup = *exactgeo_test::load_shared_mesh(GetParam());
  if (exactgeo_test::face_count(soup) > kMaxSharedFaces) GTEST_SKIP() << "left to the unsanitized build";
  const std::vector<double> xyz = random_points(soup, kSharedMeshPoints, 35);
  expect_matches_brute_force(soup, xyz, exactgeo::locate(Mesh(soup), xyz), GetParam());
}

TEST_P(LocateOnSharedMesh, VerticesLocateExactly) {
  const MeshSoup soup = *exactgeo_test::load_shared_mesh(GetParam());
  const Mesh mesh(soup);
  const std::vector<bool> kept = kept_faces(soup);
  Random random(36);
  std::vector<std::uint32_t> vertices;
  for (int i = 0; i < 200; ++i) {
    const std::uint32_t f = random.below(kept.size());
    if (kept[f]) vertices.push_back(soup.triangles[3 * f + random.below(3)]);
  }
  std::vector<double> xyz;
  for (std::uint32_t v : vertices) {
    const Vec3 p = vertex_position(soup, v);
    xyz.insert(xyz.end(), p.begin(), p.end());
  }
  const LocateResult r = exactgeo::locate(mesh, xyz);
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const Vec3 p = vertex_position(soup, vertices[i]);
    EXPECT_EQ(r.distances[i], 0.0) << GetParam() << ", vertex " << vertices[i];
    // The lowest kept face with a corner at that position, or a lower one whose edge passes exactly through it.
    std::uint32_t lowest = exactgeo::kNoSource;
    for (std::uint32_t f = 0; f < kept.size() && lowest == exactgeo::kNoSource; ++f)
      for (int k = 0; k < 3; ++k)
        if (kept[f] && vertex_position(soup, soup.triangles[3 * f + k]) == p) lowest = f;
    EXPECT_LE(r.points[i].face, lowest) << GetParam() << ", vertex " << vertices[i];
  }
}

TEST(LocateOnSharedMeshes, Available) { EXACTGEO_SKIP_IF_NO_SHARED_MESHES(); }

// "stanford-bunny.obj" as "stanford_bunny": test names take letters, digits and underscores.
std::string mesh_test_name(const testing::TestParamInfo<std::string>& mesh) {
  std::string name = mesh.param.substr(0, mesh.param.find('.'));
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

INSTANTIATE_TEST_SUITE_P(Locate, LocateOnSharedMesh, testing::ValuesIn(exactgeo_test::shared_mesh_names()),
                         mesh_test_name);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(LocateOnSharedMesh);

}  // namespace
