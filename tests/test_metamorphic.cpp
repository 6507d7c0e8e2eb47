// Metamorphic check: 1-to-4 midpoint subdivision leaves the surface unchanged, so the distances at the
// original vertices must not change (<= 1e-10 * the largest distance), for every variant and rule
// combination. The new midpoint vertices are flat (angle sum 2*pi up to rounding) and must not be taken for
// saddles.
#include <gtest/gtest.h>

#include <span>
#include <string>

#include "exactgeo/exactgeo.hpp"
#include "test_meshes.hpp"

namespace {

constexpr double kRelativeTolerance = 1e-10;

void expect_subdivision_invariant(const exactgeo::MeshSoup& soup, std::uint32_t source, const std::string& label) {
  const exactgeo::Mesh coarse(soup);
  const exactgeo::Mesh fine(exactgeo::subdivide_midpoint(soup));
  EXPECT_EQ(fine.report().saddle_vertices, coarse.report().saddle_vertices)
      << label << ": midpoint vertices classified as saddles";
  for (const exactgeo::GeodesicOptions& options : exactgeo_test::kAllVariants) {
    const auto before = exactgeo::geodesic_distance(coarse, source, options);
    const auto after = exactgeo::geodesic_distance(fine, source, options);
    const std::span<const double> original_vertices(after.distances.data(), coarse.vertex_count());
    EXPECT_TRUE(exactgeo_test::distances_match(original_vertices, before.distances, kRelativeTolerance))
        << label << " " << exactgeo_test::variant_label(options);
  }
}

TEST(Metamorphic, SubdivisionKeepsDistancesOnGeneratedMeshes) {
  expect_subdivision_invariant(exactgeo::make_bumpy_torus(32, 18), 0, "bumpy torus");
  expect_subdivision_invariant(exactgeo::make_icosphere(2), 7, "icosphere");
}

class MetamorphicShared : public testing::TestWithParam<std::string> {};

TEST_P(MetamorphicShared, SubdivisionKeepsDistances) {
  const auto soup = exactgeo_test::load_shared_mesh(GetParam() + ".obj");
  if (!soup) GTEST_SKIP() << exactgeo_test::kNoSharedMeshesMessage;
  expect_subdivision_invariant(*soup, exactgeo_test::random_source_vertex(*soup, 7), GetParam());
}

// Not beetle or suzanne: their non-manifold edges are cut, and the two faces of a cut edge that meet the same
// copies of both its ends are joined again (mesh.hpp). Subdivision splits such an edge's midpoint into one copy
// per face, so the subdivided mesh is joined differently and is not the same surface.
INSTANTIATE_TEST_SUITE_P(SharedMeshes, MetamorphicShared,
                         testing::Values("woody", "cow", "spot", "teapot", "homer", "fandisk"),
                         [](const auto& info) { return info.param; });

}  // namespace
