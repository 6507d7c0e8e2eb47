// Scale invariance: a mesh scaled by any factor that keeps its coordinates finite has its distances, path
// lengths and path points scaled by the same factor. The engine runs on positions scaled by a power of two
// (exact), so power-of-two factors give bit-identical answers; other factors round the input coordinates,
// and agree to 1e-12. Distances too large for a double are refused, not returned wrong. A mesh far from the
// origin loses the precision its coordinates lose, and no more.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/geodesic.hpp"
#include "exactgeo/mesh.hpp"
#include "exactgeo/shapes.hpp"
#include "exactgeo/surface_point.hpp"
#include "test_meshes.hpp"

namespace {

using exactgeo::GeodesicPath;
using exactgeo::GeodesicSolver;
using exactgeo::Mesh;
using exactgeo::MeshSoup;
using exactgeo::SurfacePoint;
using exactgeo_test::max_finite;
using exactgeo_test::vertex_count;

constexpr double kRounded = 1e-12;    // relative, when the factor rounds the coordinates
constexpr double kPathLength = 1e-9;  // path length against distance, relative

// A curved height field with a boundary whose extent lies in [1, 2), so that at unit scale and at every
// power-of-two scale the engine sees the same positions.
MeshSoup terrain() {
  MeshSoup soup = exactgeo::make_grid(12, 10, 1.5, 1.25);
  for (std::size_t v = 0; v < vertex_count(soup); ++v) {
    const double x = soup.positions[3 * v], y = soup.positions[3 * v + 1];
    soup.positions[3 * v + 2] = 0.2 * std::sin(4 * x) * std::cos(3 * y);
  }
  return soup;
}

MeshSoup scaled(MeshSoup soup, double factor) {
  for (double& c : soup.positions) c *= factor;
  return soup;
}

MeshSoup translated(MeshSoup soup, const std::array<double, 3>& offset) {
  for (std::size_t i = 0; i < soup.positions.size(); ++i) soup.positions[i] += offset[i % 3];
  return soup;
}

// What a run gives: distances from a vertex, distances to point targets from a point source (with a
// cut-off), and the paths to a few vertices.
struct Answers {
  std::vector<double> distances, target_distances, cut_distances;
  std::vector<GeodesicPath> paths;
};

Answers answers(const Mesh& mesh, const exactgeo::GeodesicOptions& options, double max_distance) {
  Answers a;
  GeodesicSolver solver(mesh);
  const std::uint32_t sources[] = {3};
  a.distances = solver.solve(sources, {}, options).distances;
  for (std::uint32_t v = 0; v < mesh.vertex_count(); v += 11) a.paths.push_back(solver.path_to_vertex(v));
  const auto face = [&](std::uint32_t f) { return static_cast<std::uint32_t>(f % mesh.face_count()); };
  const SurfacePoint source{face(5), {0.2, 0.3, 0.5}};
  const auto vertex = static_cast<std::uint32_t>(60 % mesh.vertex_count());
  const std::vector<SurfacePoint> targets = {{face(17), {0.6, 0.1, 0.3}}, {face(40), {0.5, 0.5, 0}},
                                             exactgeo::vertex_point(mesh, vertex)};
  a.target_distances = solver.solve(std::span(&source, 1), targets, options).target_distances;
  exactgeo::GeodesicOptions cut = options;
  cut.max_distance = max_distance;
  a.cut_distances = solver.solve(sources, {}, cut).distances;
  return a;
}

class ScaleOf : public testing::TestWithParam<exactgeo::GeodesicOptions> {};

INSTANTIATE_TEST_SUITE_P(Scale, ScaleOf, testing::ValuesIn(exactgeo_test::kAllVariants), exactgeo_test::variant_name);
INSTANTIATE_TEST_SUITE_P(ScaleThreads, ScaleOf, testing::ValuesIn(exactgeo_test::kParallelVariants),
                         exactgeo_test::variant_name);

// Before: squared lengths underflowed below about 1e-78 (errors up to 100%, or no end) and overflowed above
// about 1e79 (a crash) or 1e155 (every vertex but the source at +inf).
TEST_P(ScaleOf, PowerOfTwoFactorsGiveBitIdenticalAnswers) {
  const MeshSoup unit_soup = terrain();
  const Mesh unit(unit_soup);
  const Answers expected = answers(unit, GetParam(), 0.6);
  for (const int exponent : {-1000, -330, -140, 140, 330, 1000, 1020}) {
    SCOPED_TRACE("factor 2^" + std::to_string(exponent));
    const Mesh mesh(scaled(unit_soup, std::ldexp(1.0, exponent)));
    const Answers got = answers(mesh, GetParam(), std::ldexp(0.6, exponent));
    const auto expect_scaled = [&](const std::vector<double>& actual, const std::vector<double>& unit_values) {
      ASSERT_EQ(actual.size(), unit_values.size());
      for (std::size_t i = 0; i < actual.size(); ++i)
        EXPECT_EQ(actual[i], std::ldexp(unit_values[i], exponent)) << "entry " << i;
    };
    expect_scaled(got.distances, expected.distances);
    expect_scaled(got.target_distances, expected.target_distances);
    expect_scaled(got.cut_distances, expected.cut_distances);
    ASSERT_EQ(got.paths.size(), expected.paths.size());
    for (std::size_t i = 0; i < got.paths.size(); ++i) {
      EXPECT_EQ(got.paths[i].length, std::ldexp(expected.paths[i].length, exponent)) << "path " << i;
      ASSERT_EQ(got.paths[i].points.size(), expected.paths[i].points.size()) << "path " << i;
      for (std::size_t p = 0; p < got.paths[i].points.size(); ++p)
        for (int k = 0; k < 3; ++k)
          EXPECT_EQ(got.paths[i].points[p][k], std::ldexp(expected.paths[i].points[p][k], exponent)) << "path " << i;
    }
  }
}

TEST_P(ScaleOf, AnyFactorGivesScaledAnswers) {
  for (const MeshSoup& unit_soup : {terrain(), exactgeo::make_bumpy_torus(32, 12), exactgeo::make_grid(3, 3, 1, 1)}) {
    const Mesh unit(unit_soup);
    const double max_distance = 0.5 * max_finite(exactgeo::geodesic_distance(unit, 3u, GetParam()).distances);
    const Answers expected = answers(unit, GetParam(), max_distance);
    for (const double factor : {1e-300, 1e-100, 1e-80, 0.1, 3.0, 1e90, 1e100, 1e300}) {
      SCOPED_TRACE("factor " + std::to_string(std::log10(factor)) + " decades");
      const Mesh mesh(scaled(unit_soup, factor));
      // The cut-off is compared with distances at full precision: a vertex within rounding of it may fall on
      // either side, so it is chosen away from every vertex's distance (half the farthest, on these meshes).
      const Answers got = answers(mesh, GetParam(), max_distance * factor);
      const auto expect_scaled = [&](const std::vector<double>& actual, const std::vector<double>& unit_values) {
        ASSERT_EQ(actual.size(), unit_values.size());
        std::vector<double> back(actual.size());
        for (std::size_t i = 0; i < actual.size(); ++i) back[i] = actual[i] / factor;
        EXPECT_TRUE(exactgeo_test::distances_match(back, unit_values, kRounded));
      };
      expect_scaled(got.distances, expected.distances);
      expect_scaled(got.target_distances, expected.target_distances);
      expect_scaled(got.cut_distances, expected.cut_distances);
      for (std::size_t i = 0; i < got.paths.size(); ++i) {
        EXPECT_NEAR(got.paths[i].length / factor, expected.paths[i].length,
                    kRounded * max_finite(expected.distances)) << "path " << i;
        EXPECT_NEAR(got.paths[i].length, got.distances[11 * i], kPathLength * got.distances[11 * i]) << "path " << i;
        for (const auto& point : got.paths[i].points)
          for (double c : point) EXPECT_TRUE(std::isfinite(c)) << "path " << i;
      }
    }
  }
}

// The real meshes where the failures were found (cow.obj at 1e-80 did not finish in two minutes).
TEST(Scale, SharedMeshesAtExtremeScales) {
  EXACTGEO_SKIP_IF_NO_SHARED_MESHES();
  for (const std::string& name : exactgeo_test::shared_mesh_names()) {
    const MeshSoup soup = *exactgeo_test::load_shared_mesh(name);
    if (exactgeo_test::face_count(soup) > 13'000) continue;
    const std::uint32_t source = exactgeo_test::random_source_vertex(soup, 1);
    const std::vector<double> expected = exactgeo::geodesic_distance(Mesh(soup), source).distances;
    for (const double factor : {1e-300, 1e-80, 1e90, 1e150, 1e300}) {
      SCOPED_TRACE(name + " scaled by " + std::to_string(std::log10(factor)) + " decades");
      std::vector<double> back = exactgeo::geodesic_distance(Mesh(scaled(soup, factor)), source).distances;
      for (double& d : back) d /= factor;
      EXPECT_TRUE(exactgeo_test::distances_match(back, expected, kRounded));
    }
  }
}

TEST(Scale, DistancesBeyondTheLargestDoubleAreRefused) {
  // Coordinates up to 1e308 are finite, but the torus's geodesics are longer than the largest double.
  const Mesh mesh(scaled(exactgeo::make_bumpy_torus(24, 10), 1e308));
  try {
    exactgeo::geodesic_distance(mesh, 0u);
    ADD_FAILURE() << "distances beyond the largest double were returned";
  } catch (const exactgeo::Error& error) {
    EXPECT_EQ(error.code(), exactgeo::ErrorCode::invalid_mesh);
    EXPECT_NE(std::string(error.what()).find("exceeds the largest double"), std::string::npos) << error.what();
  }
  // Up to the cut-off, they fit.
  const exactgeo::GeodesicResult near = exactgeo::geodesic_distance(mesh, 0u, {.max_distance = 1.5e308});
  EXPECT_EQ(near.distances[0], 0.0);
  EXPECT_GT(max_finite(near.distances), 1e307);
}

// Far from the origin the coordinates themselves keep fewer digits of the shape (at 1e6, about 1e-10 of a
// unit): distances and paths keep that precision, no more is promised.
TEST_P(ScaleOf, FarFromTheOriginPrecisionFollowsTheCoordinates) {
  const MeshSoup unit_soup = terrain();
  const std::vector<double> expected = exactgeo::geodesic_distance(Mesh(unit_soup), 3u, GetParam()).distances;
  using Offset = std::array<double, 3>;
  for (const Offset& offset : {Offset{1e6, -1e6, 1e6}, Offset{0, 0, 1e9}}) {
    const Mesh mesh(translated(unit_soup, offset));
    GeodesicSolver solver(mesh);
    const std::uint32_t sources[] = {3};
    const std::vector<double> d = solver.solve(sources, {}, GetParam()).distances;
    const double coordinate_precision =
        1e-15 * std::max({std::abs(offset[0]), std::abs(offset[1]), std::abs(offset[2])});
    EXPECT_TRUE(exactgeo_test::distances_match(d, expected, 100 * coordinate_precision));
    for (std::uint32_t v = 0; v < mesh.vertex_count(); v += 7) {
      const GeodesicPath path = solver.path_to_vertex(v);
      EXPECT_NEAR(path.length, d[v], 1000 * coordinate_precision) << "vertex " << v;
    }
  }
}

}  // namespace
