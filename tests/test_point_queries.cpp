// Queries at any surface point after one run (GeodesicOptions::keep_windows): distance_at and path_to_point.
// The reference is the engine's own targets mode, run again with the points as targets (its exactness is
// established against CGAL in test_oracle.cpp, which also checks the kept windows against CGAL directly):
// every point must agree with it to 1e-14 of the largest distance, on the shared meshes and on generated
// ones of many shapes and scales, under every variant and on several threads. Paths must measure their
// distance, end at the point and start at the source they name.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "test_meshes.hpp"

namespace {

using exactgeo::GeodesicOptions;
using exactgeo::GeodesicSolver;
using exactgeo::Mesh;
using exactgeo::MeshSoup;
using exactgeo::SurfacePoint;
using exactgeo_test::max_finite;
using exactgeo_test::Random;

constexpr double kAgreement = 1e-14;  // against targets mode, relative to the largest distance
constexpr double kPathLength = 1e-11;  // a path's length against its distance, relative to the largest distance

// `count` random points of kept faces: a third on edges, the rest inside faces.
std::vector<SurfacePoint> random_points(const MeshSoup& soup, Random& random, int count) {
  std::vector<SurfacePoint> points;
  for (int i = 0; i < count; ++i) points.push_back(exactgeo_test::random_face_point(soup, random, i % 3 == 0 ? 1 : 0));
  return points;
}

// What a check of distance_at against targets mode found.
struct Agreement {
  double worst = 0;     // largest difference, relative to the largest distance
  std::size_t finite = 0;  // points with a finite distance
};

// Runs from `sources` with keep_windows, then with `points` as targets, and compares distance_at with the
// targets' distances (relative to the largest vertex distance of the first run). Also checks that the same
// vertices are reached, and traces the path to every `path_every`-th point.
template <class Sources>
Agreement expect_queries_match_targets(const Mesh& mesh, const Sources& sources, const std::vector<SurfacePoint>& points,
                                       GeodesicOptions options, const std::string& where, std::size_t path_every = 0) {
  GeodesicSolver solver(mesh);
  GeodesicOptions kept = options;
  kept.keep_windows = true;
  const exactgeo::GeodesicResult full = solver.solve(sources, {}, kept);
  EXPECT_GT(full.stats.kept_windows, 0u) << where;
  EXPECT_GT(full.stats.kept_window_bytes, full.stats.kept_windows * 40) << where;
  const std::vector<double> queried = solver.distance_at(points);
  const double scale = max_finite(full.distances);
  Agreement agreement;
  EXPECT_EQ(queried.size(), points.size());
  for (std::size_t i = 0; path_every != 0 && i < points.size(); i += path_every) {
    const exactgeo::GeodesicPath path = solver.path_to_point(points[i]);
    if (std::isinf(queried[i])) {
      EXPECT_TRUE(path.points.empty()) << where << " point " << i;
      continue;
    }
    EXPECT_NEAR(path.length, queried[i], kPathLength * scale) << where << " point " << i;
    const exactgeo_test::Vec3 end = exactgeo::point_position(mesh, points[i]);
    EXPECT_LE(exactgeo_test::distance(path.points.back(), end), kPathLength * scale) << where << " point " << i;
    EXPECT_LT(path.source, std::size(sources)) << where << " point " << i;
  }
  GeodesicSolver reference(mesh);
  const exactgeo::GeodesicResult& targets = reference.solve(sources, points, options);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double expected = targets.target_distances[i];
    EXPECT_EQ(std::isinf(queried[i]), std::isinf(expected)) << where << " point " << i;
    if (std::isinf(queried[i]) || std::isinf(expected)) continue;
    ++agreement.finite;
    agreement.worst = std::max(agreement.worst, std::abs(queried[i] - expected) / scale);
  }
  EXPECT_LE(agreement.worst, kAgreement) << where;
  return agreement;
}

// ---- Generated meshes, every variant ---------------------------------------------------------------------

class KeptWindows : public testing::TestWithParam<GeodesicOptions> {};
INSTANTIATE_TEST_SUITE_P(Variants, KeptWindows, testing::ValuesIn(exactgeo_test::kAllVariants),
                         exactgeo_test::variant_name);
INSTANTIATE_TEST_SUITE_P(Threads, KeptWindows, testing::ValuesIn(exactgeo_test::kParallelVariants),
                         exactgeo_test::variant_name);

// The soup with every coordinate multiplied by `scale` (a power of two: the surface is the same, scaled).
MeshSoup scaled(MeshSoup soup, double scale) {
  for (double& c : soup.positions) c *= scale;
  return soup;
}

TEST_P(KeptWindows, MatchTargetsOnGeneratedMeshesOfEveryShapeAndScale) {
  Random random(35);
  struct Case {
    std::string name;
    MeshSoup soup;
  };
  std::vector<Case> cases;
  for (int i = 0; i < 3; ++i) {
    cases.push_back({"smooth height field " + std::to_string(i), exactgeo_test::random_height_field(random, 12, 10, 0.4, true)});
    cases.push_back({"noisy height field " + std::to_string(i), exactgeo_test::random_height_field(random, 9, 11, 0.15, false)});
    cases.push_back({"jittered grid with holes " + std::to_string(i), exactgeo_test::random_grid_with_holes(random, 12, 9, 2)});
  }
  cases.push_back({"bumpy torus", exactgeo::make_bumpy_torus(30, 14)});
  cases.push_back({"rotated convex polygon", exactgeo_test::randomly_rotated(exactgeo_test::random_convex_polygon(random, 9, 3), random)});
  cases.push_back({"height field at 2^-990", scaled(cases[0].soup, 0x1p-990)});
  cases.push_back({"height field at 2^990", scaled(cases[0].soup, 0x1p990)});
  for (const Case& c : cases) {
    const Mesh mesh(c.soup);
    const std::vector<SurfacePoint> points = random_points(c.soup, random, 150);
    const std::uint32_t source = exactgeo_test::random_source_vertex(c.soup, 7);
    expect_queries_match_targets(mesh, std::span(&source, 1), points, GetParam(), c.name, 10);
  }
}

// The queries are as exact wherever the sources are: inside faces, on edges, at vertices, several at once.
TEST_P(KeptWindows, MatchTargetsFromSeveralPointSources) {
  Random random(36);
  const MeshSoup soup = exactgeo_test::random_height_field(random, 14, 12, 0.5, true);
  const Mesh mesh(soup);
  const std::vector<SurfacePoint> sources = {exactgeo_test::random_face_point(soup, random, 0),
                                             exactgeo_test::random_face_point(soup, random, 1),
                                             exactgeo_test::random_face_point(soup, random, 2)};
  std::vector<SurfacePoint> points = random_points(soup, random, 200);
  points.insert(points.end(), sources.begin(), sources.end());  // a point on each source: distance 0
  expect_queries_match_targets(mesh, sources, points, GetParam(), "three point sources", 7);
  GeodesicSolver solver(mesh);
  GeodesicOptions options = GetParam();
  options.keep_windows = true;
  solver.solve(sources, {}, options);
  const std::vector<double> at_sources = solver.distance_at(sources);
  for (double d : at_sources) EXPECT_LE(d, 1e-15);
  // Each path starts at the source it names.
  for (std::size_t i = 0; i < 40; ++i) {
    const exactgeo::GeodesicPath path = solver.path_to_point(points[i]);
    ASSERT_LT(path.source, sources.size());
    EXPECT_LE(exactgeo_test::distance(path.points.front(), exactgeo::point_position(mesh, sources[path.source])), 1e-12)
        << "point " << i;
  }
}

// Points at vertices read `distances`, however the point names the vertex.
TEST_P(KeptWindows, VertexPointsReadTheVertexDistances) {
  Random random(37);
  const MeshSoup soup = exactgeo_test::random_grid_with_holes(random, 10, 10, 1);
  const Mesh mesh(soup);
  GeodesicSolver solver(mesh);
  GeodesicOptions options = GetParam();
  options.keep_windows = true;
  const std::uint32_t sources[] = {3, 115};  // on the border, which holes keep away from
  const exactgeo::GeodesicResult& result = solver.solve(sources, {}, options);
  std::vector<SurfacePoint> corners;
  std::vector<std::uint32_t> vertices;
  for (int i = 0; i < 100; ++i) {
    corners.push_back(exactgeo_test::random_face_point(soup, random, 2));
    const auto b = corners.back().barycentric;
    vertices.push_back(soup.triangles[3 * corners.back().face + (b[0] == 1 ? 0 : (b[1] == 1 ? 1 : 2))]);
  }
  const std::vector<double> queried = solver.distance_at(corners);
  for (std::size_t i = 0; i < corners.size(); ++i) {
    EXPECT_EQ(queried[i], result.distances[vertices[i]]) << "vertex " << vertices[i];
    const exactgeo::GeodesicPath path = solver.path_to_point(corners[i]);
    EXPECT_EQ(path.length, solver.path_to_vertex(vertices[i]).length);
  }
}

// A cut-off answers +inf beyond it, as targets get: with max_distance, and with targets, whose farthest ends
// the run.
TEST_P(KeptWindows, CutOffsGiveInfinityBeyondAsTargetsDo) {
  Random random(38);
  const MeshSoup soup = exactgeo::make_bumpy_torus(40, 16);
  const Mesh mesh(soup);
  const std::vector<SurfacePoint> points = random_points(soup, random, 300);
  const double farthest = max_finite(exactgeo::geodesic_distance(mesh, 0u).distances);
  GeodesicOptions options = GetParam();
  options.max_distance = 0.4 * farthest;
  const std::uint32_t source = 0;
  const Agreement agreement = expect_queries_match_targets(mesh, std::span(&source, 1), points, options, "cut off", 13);
  EXPECT_GT(agreement.finite, 20u);
  EXPECT_LT(agreement.finite, 250u);

  GeodesicSolver solver(mesh);
  options.max_distance = HUGE_VAL;
  options.keep_windows = true;
  const SurfacePoint near_target = points[0];
  const auto& run = solver.solve(std::span(&source, 1), std::span(&near_target, 1), options);
  const std::vector<double> queried = solver.distance_at(points);
  const std::vector<double> exact = [&] {
    GeodesicSolver full(mesh);
    return full.solve(std::span(&source, 1), points, GetParam()).target_distances;
  }();
  EXPECT_NEAR(queried[0], run.target_distances[0], kAgreement * farthest);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (exact[i] < run.target_distances[0] * (1 - 1e-12)) {
      EXPECT_NEAR(queried[i], exact[i], kAgreement * farthest) << "point " << i;
    } else if (exact[i] > run.target_distances[0] * (1 + 1e-12)) {
      EXPECT_TRUE(std::isinf(queried[i])) << "point " << i;
    }
  }
}

// ---- The shared meshes ---------------------------------------------------------------------------------------

class KeptWindowsOnSharedMeshes : public testing::TestWithParam<std::string> {};

TEST_P(KeptWindowsOnSharedMeshes, MatchTargetsAtAThousandFaceAndEdgePointsFromTwelveSources) {
  const auto soup = exactgeo_test::load_shared_mesh(GetParam());
  if (!soup) GTEST_SKIP() << exactgeo_test::kNoSharedMeshesMessage;
  const Mesh mesh(*soup);
  Random random(2016);
  const std::vector<SurfacePoint> points = random_points(*soup, random, 1200);
  // Several sources at random corners, so that meshes of many pieces (teapot, beetle) are reached nearly
  // everywhere.
  std::vector<SurfacePoint> sources;
  for (int i = 0; i < 12; ++i) sources.push_back(exactgeo_test::random_face_point(*soup, random, 2));
  std::vector<GeodesicOptions> variants;
  for (const auto& [algorithm, name] : exactgeo::kAlgorithmNames) variants.push_back({.algorithm = algorithm});
  variants.push_back({.threads = 2});
  variants.push_back({.algorithm = exactgeo::Algorithm::opvtp, .threads = 3});
  for (const GeodesicOptions& options : variants) {
    const Agreement agreement = expect_queries_match_targets(mesh, sources, points, options,
                                                             GetParam() + " " + exactgeo_test::variant_label(options),
                                                             options.threads == 1 ? 20 : 0);
    if (exactgeo_test::is_default_variant(options) && options.threads == 1)
      std::printf("[ queries  ] %-22s %zu points: max rel difference to targets mode %.2e\n", GetParam().c_str(),
                  agreement.finite, agreement.worst);
  }
}

INSTANTIATE_TEST_SUITE_P(SharedMeshes, KeptWindowsOnSharedMeshes, testing::ValuesIn(exactgeo_test::shared_mesh_names()),
                         [](const auto& mesh_name) {
                           std::string name = mesh_name.param.substr(0, mesh_name.param.find('.'));
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(KeptWindowsOnSharedMeshes);

// ---- What is refused ---------------------------------------------------------------------------------------

void expect_error_naming(const auto& call, const std::string& words) {
  try {
    call();
    ADD_FAILURE() << "no error; expected one naming: " << words;
  } catch (const exactgeo::Error& e) {
    EXPECT_EQ(e.code(), exactgeo::ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(KeptWindowsErrors, QueriesNeedARunThatKeptItsWindowsAndValidPoints) {
  const Mesh mesh(exactgeo::make_grid(4, 4, 1.0, 1.0));
  GeodesicSolver solver(mesh);
  const SurfacePoint point{3, {0.2, 0.3, 0.5}};
  expect_error_naming([&] { solver.distance_at(std::span(&point, 1)); }, "distance_at needs the windows");
  expect_error_naming([&] { solver.path_to_point(point); }, "path_to_point needs the windows");
  solver.solve(std::vector<std::uint32_t>{0}, {}, {});
  expect_error_naming([&] { solver.distance_at(std::span(&point, 1)); }, "keep_windows");
  solver.solve(std::vector<std::uint32_t>{0}, {}, {.keep_windows = true});
  EXPECT_EQ(solver.distance_at(std::span(&point, 1)).size(), 1u);
  const std::vector<SurfacePoint> bad = {point, {99, {1, 0, 0}}};
  expect_error_naming([&] { solver.distance_at(bad); }, "point 1: face 99 is out of range");
  expect_error_naming([&] { solver.path_to_point({0, {0.5, 0.5, 0.5}}); }, "point: (0.5, 0.5, 0.5) are not barycentric");
  EXPECT_TRUE(solver.distance_at({}).empty());
  // An ordinary run after it keeps nothing: the windows belonged to the run before.
  const auto& ordinary = solver.solve(std::vector<std::uint32_t>{1}, {}, {});
  EXPECT_EQ(ordinary.stats.kept_windows, 0u);
  EXPECT_EQ(ordinary.stats.kept_window_bytes, 0u);
  expect_error_naming([&] { solver.path_to_point(point); }, "keep_windows");
}

// std::move(solver).result() hands the run's arrays over (the same storage, not a copy) and leaves the solver as
// before any run: its queries say so, and it runs again.
TEST(SolverResult, HandedOverItIsTheRunsAndTheSolverIsAsBeforeAnyRun) {
  const Mesh mesh(exactgeo::make_grid(4, 4, 1.0, 1.0));
  GeodesicSolver solver(mesh);
  const SurfacePoint target{3, {0.2, 0.3, 0.5}};
  const std::vector<std::uint32_t> sources = {0, 24};
  const exactgeo::GeodesicResult copy = solver.solve(sources, std::span(&target, 1), {.keep_windows = true});
  const double* storage = solver.result().distances.data();
  const exactgeo::GeodesicResult handed = std::move(solver).result();
  EXPECT_EQ(handed.distances.data(), storage);
  EXPECT_EQ(handed.distances, copy.distances);
  EXPECT_EQ(handed.nearest_source, copy.nearest_source);
  EXPECT_EQ(handed.target_distances, copy.target_distances);
  EXPECT_EQ(handed.target_nearest_source, copy.target_nearest_source);
  EXPECT_EQ(handed.stats.window_propagations, copy.stats.window_propagations);
  EXPECT_TRUE(solver.result().distances.empty());
  EXPECT_TRUE(solver.result().target_distances.empty());
  expect_error_naming([&] { solver.path_to_vertex(5); }, "solve first");
  expect_error_naming([&] { solver.path_to_target(0); }, "out of range");
  expect_error_naming([&] { solver.distance_at(std::span(&target, 1)); }, "distance_at needs the windows");
  EXPECT_EQ(solver.solve(sources, std::span(&target, 1), {}).distances, copy.distances);
  EXPECT_EQ(solver.path_to_vertex(5).length, copy.distances[5]);
}

}  // namespace
