// Pair distances (exactgeo::pair_distances) against CGAL's Surface_mesh_shortest_path: from a random vertex to
// random vertices, and from a point inside a face to points inside faces, for every variant of the paper with
// every combination of its rules. Required, as in test_oracle.cpp: within 1e-14 of the largest distance CGAL
// finds from that source, and unreachable where CGAL says so.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "cgal_oracle.hpp"
#include "exactgeo/exactgeo.hpp"
#include "test_meshes.hpp"

namespace {

constexpr double kRelativeTolerance = 1e-14;

class PairsOracleTest : public testing::TestWithParam<std::string> {};

// A point strictly inside a random kept face.
exactgeo::SurfacePoint inner_point(const exactgeo::MeshSoup& soup, exactgeo_test::Random& random) {
  std::uint32_t face;
  do face = random.below(exactgeo_test::face_count(soup));
  while (exactgeo_test::repeats_a_vertex(soup, face));
  const double u = random.uniform(0.05, 0.9), v = random.uniform(0.05, 0.95 - u);
  return {face, {u, v, 1 - u - v}};
}

TEST_P(PairsOracleTest, MatchCgalWithEveryVariant) {
  const std::optional<exactgeo::MeshSoup> soup =
      GetParam() == "bumpy_torus" ? exactgeo::make_bumpy_torus(48, 20) : exactgeo_test::load_shared_mesh(GetParam() + ".obj");
  if (!soup) GTEST_SKIP() << exactgeo_test::kNoSharedMeshesMessage;
  const exactgeo::Mesh mesh(*soup);
  exactgeo_test::Random random(3535);

  // From a vertex to vertices: one CGAL run gives every b.
  const std::uint32_t source = exactgeo_test::random_source_vertex(*soup, 35);
  const std::uint32_t source_list[] = {source};
  const auto from_vertex = exactgeo_oracle::cgal_geodesic_distances(soup->positions, soup->triangles, source_list);
  ASSERT_TRUE(from_vertex.loaded_as_manifold) << GetParam() << ": CGAL could not load the mesh";
  std::vector<std::uint32_t> a, b;
  std::vector<double> expected;
  for (int i = 0; i < 24; ++i) {
    a.push_back(source);
    b.push_back(soup->triangles[random.below(soup->triangles.size())]);
    expected.push_back(from_vertex.distances[b.back()]);
  }
  const double largest = exactgeo_test::max_finite(from_vertex.distances);

  // From a face point to face points.
  const exactgeo::SurfacePoint from = inner_point(*soup, random);
  std::vector<exactgeo::SurfacePoint> to;
  std::vector<exactgeo_oracle::FacePoint> oracle_targets;
  for (int i = 0; i < 12; ++i) {
    to.push_back(inner_point(*soup, random));
    oracle_targets.push_back({to.back().face, to.back().barycentric});
  }
  const exactgeo_oracle::FacePoint oracle_source[] = {{from.face, from.barycentric}};
  const auto from_point =
      exactgeo_oracle::cgal_geodesic_distances(soup->positions, soup->triangles, {}, oracle_source, oracle_targets);
  const std::vector<exactgeo::SurfacePoint> point_a(to.size(), from);
  const double point_largest = exactgeo_test::max_finite(from_point.distances);

  for (const exactgeo::GeodesicOptions& options : exactgeo_test::kAllVariants) {
    const auto vertices = exactgeo::pair_distances(mesh, a, b, {.geodesic = options});
    double error = 0;
    for (std::size_t i = 0; i < b.size(); ++i) {
      ASSERT_EQ(std::isinf(vertices.distances[i]), std::isinf(expected[i])) << GetParam() << " vertex " << b[i];
      if (!std::isinf(expected[i])) error = std::max(error, std::abs(vertices.distances[i] - expected[i]) / largest);
    }
    EXPECT_LE(error, kRelativeTolerance) << GetParam() << " " << exactgeo_test::variant_label(options);
    const auto points = exactgeo::pair_distances(mesh, point_a, to, {.geodesic = options});
    double point_error = 0;
    for (std::size_t i = 0; i < to.size(); ++i) {
      ASSERT_EQ(std::isinf(points.distances[i]), std::isinf(from_point.target_distances[i])) << GetParam() << " point " << i;
      if (!std::isinf(points.distances[i]))
        point_error = std::max(point_error, std::abs(points.distances[i] - from_point.target_distances[i]) / point_largest);
    }
    EXPECT_LE(point_error, kRelativeTolerance) << GetParam() << " " << exactgeo_test::variant_label(options);
    if (exactgeo_test::is_default_variant(options))
      std::printf("[ pairs    ] %-12s max rel error: vertex pairs %.2e, point pairs %.2e\n", GetParam().c_str(), error,
                  point_error);
  }
}

INSTANTIATE_TEST_SUITE_P(Meshes, PairsOracleTest,
                         testing::Values("bumpy_torus", "woody", "suzanne", "beetle", "cow", "teapot", "homer",
                                         "fandisk"),
                         [](const auto& info) { return info.param; });

}  // namespace
