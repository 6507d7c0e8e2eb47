// Exactness against an independent oracle: CGAL's Surface_mesh_shortest_path on every shared mesh, from
// vertex 0, a boundary vertex where there is one and a seeded random vertex, for every combination of the
// paper's rules. Required: max |ours - CGAL| <= 1e-10 * the largest finite distance, and the same set of
// unreachable vertices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cgal_oracle.hpp"
#include "exactgeo/exactgeo.hpp"
#include "test_meshes.hpp"

namespace {

constexpr double kRelativeTolerance = 1e-10;

class OracleTest : public testing::TestWithParam<std::string> {};

TEST_P(OracleTest, MatchesCgalFromSeveralSourcesWithEveryRuleCombination) {
  const auto soup = exactgeo_test::load_shared_mesh(GetParam() + ".obj");
  if (!soup) GTEST_SKIP() << exactgeo_test::kNoSharedMeshesMessage;
  const exactgeo::Mesh mesh(*soup);

  std::vector<std::uint32_t> sources = {0};
  if (auto boundary = exactgeo_test::first_boundary_vertex(*soup)) sources.push_back(*boundary);
  sources.push_back(exactgeo_test::random_source_vertex(*soup, /*seed=*/20161124));

  for (std::uint32_t source : sources) {
    const std::uint32_t source_list[] = {source};
    const auto oracle = exactgeo_oracle::cgal_geodesic_distances(soup->positions, soup->triangles, source_list);
    ASSERT_TRUE(oracle.loaded_as_manifold) << GetParam() << ": CGAL could not load the mesh";
    for (const exactgeo::GeodesicOptions& options : exactgeo_test::kAllRuleCombinations) {
      const auto result = exactgeo::geodesic_distance(mesh, source, options);
      double error = 0;
      EXPECT_TRUE(exactgeo_test::distances_match(result.distances, oracle.distances, kRelativeTolerance, &error))
          << GetParam() << " source " << source << " rule1=" << options.rule1 << " rule23=" << options.rule23;
      if (options.rule1 && options.rule23)
        std::printf("[ oracle   ] %-18s source %6u  max rel error %.2e  ours %.3fs (%llu propagations)  CGAL %.3fs\n",
                    GetParam().c_str(), source, error, result.stats.propagation_seconds,
                    static_cast<unsigned long long>(result.stats.window_propagations),
                    oracle.build_seconds + oracle.query_seconds);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(SharedMeshes, OracleTest,
                         testing::Values("woody", "suzanne", "beetle", "cow", "spot", "teapot", "homer", "fandisk",
                                         "rocker-arm", "stanford-bunny", "nefertiti"),
                         [](const auto& info) {
                           std::string name = info.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

}  // namespace
