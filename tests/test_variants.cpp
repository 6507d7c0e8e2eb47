// The paper's variants (vtp, opvtp, ftp, opftp) and ablations: their statistics add up and mean what they
// say, the rules save work, and order-preserving merges keep lists ordered. Their exactness is checked with
// every other test, which all run under every variant (kAllVariants).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/geodesic.hpp"
#include "exactgeo/shapes.hpp"
#include "test_meshes.hpp"

namespace {

using exactgeo::Algorithm;
using exactgeo::GeodesicOptions;

bool face_sorted(Algorithm algorithm) { return algorithm == Algorithm::ftp || algorithm == Algorithm::opftp; }

TEST(AlgorithmNames, RoundTripAndUnknownNamesAreListed) {
  for (const auto& [algorithm, name] : exactgeo::kAlgorithmNames) {
    EXPECT_EQ(exactgeo::algorithm_name(algorithm), name);
    EXPECT_EQ(exactgeo::parse_algorithm(name), algorithm);
  }
  try {
    exactgeo::parse_algorithm("mmp");
    FAIL() << "no error for an unknown name";
  } catch (const exactgeo::Error& error) {
    EXPECT_EQ(error.code(), exactgeo::ErrorCode::invalid_argument);
    EXPECT_NE(std::string(error.what()).find("'mmp'"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("vtp, opvtp, ftp, opftp"), std::string::npos) << error.what();
  }
  const exactgeo::Mesh mesh(exactgeo::make_icosphere(1));
  EXPECT_THROW(exactgeo::geodesic_distance(mesh, 0, {.algorithm = static_cast<Algorithm>(17)}), exactgeo::Error);
}

class VariantStats : public testing::TestWithParam<GeodesicOptions> {};

TEST_P(VariantStats, CountsAddUpAndMatchTheWavefrontKind) {
  const exactgeo::Mesh mesh(exactgeo::make_bumpy_torus(48, 20));
  const GeodesicOptions options = GetParam();
  const exactgeo::GeodesicStats stats = exactgeo::geodesic_distance(mesh, 0, options).stats;
  EXPECT_EQ(stats.window_propagations, stats.prime_propagations + stats.secondary_propagations);
  // Most work happens in the newly added triangles (the paper measures 96% on average).
  EXPECT_GT(stats.prime_propagations, stats.secondary_propagations);
  EXPECT_GT(stats.prime_merges, 0u);
  if (face_sorted(options.algorithm)) {
    EXPECT_EQ(stats.vertex_pops, 0u);
    EXPECT_GT(stats.face_pops, 0u);
    EXPECT_LE(stats.face_pops, mesh.face_count());
  } else {
    EXPECT_EQ(stats.face_pops, 0u);
    EXPECT_EQ(stats.vertex_pops, mesh.vertex_count());
  }
  // The set-up is timed always, as part of the whole; without collect_timings the split stays empty.
  EXPECT_GT(stats.setup_seconds, 0.0);
  EXPECT_LT(stats.setup_seconds, stats.propagation_seconds);
  EXPECT_EQ(stats.window_propagation_seconds, 0.0);
  EXPECT_EQ(stats.pruning_seconds, 0.0);
  EXPECT_EQ(stats.queue_seconds, 0.0);
}

TEST_P(VariantStats, TimersSplitThePropagationTime) {
  const exactgeo::Mesh mesh(exactgeo::make_bumpy_torus(48, 20));
  GeodesicOptions options = GetParam();
  options.collect_timings = true;
  const exactgeo::GeodesicStats stats = exactgeo::geodesic_distance(mesh, 0, options).stats;
  EXPECT_GT(stats.window_propagation_seconds, 0.0);
  EXPECT_GT(stats.queue_seconds, 0.0);
  if (options.rule23)
    EXPECT_GT(stats.pruning_seconds, 0.0);
  else
    EXPECT_EQ(stats.pruning_seconds, 0.0);
  // The parts are measured inside the whole.
  EXPECT_LE(stats.window_propagation_seconds + stats.pruning_seconds + stats.queue_seconds, stats.propagation_seconds);
}

INSTANTIATE_TEST_SUITE_P(Variants, VariantStats, testing::ValuesIn(exactgeo_test::kAllVariants),
                         exactgeo_test::variant_name);

// The ablations of paper Figure 12: switching a rule off must cost window propagations on a curved mesh,
// and give the same distances.
TEST(VariantAblations, EachRuleSavesPropagationsInEveryVariant) {
  const exactgeo::Mesh mesh(exactgeo::make_bumpy_torus(96, 40));
  for (const auto& [algorithm, name] : exactgeo::kAlgorithmNames) {
    const auto all_rules = exactgeo::geodesic_distance(mesh, 0, {.algorithm = algorithm});
    const auto no_rule1 = exactgeo::geodesic_distance(mesh, 0, {.algorithm = algorithm, .rule1 = false});
    const auto no_rule23 = exactgeo::geodesic_distance(mesh, 0, {.algorithm = algorithm, .rule23 = false});
    EXPECT_GT(no_rule1.stats.window_propagations, all_rules.stats.window_propagations) << name;
    EXPECT_GT(no_rule23.stats.window_propagations, all_rules.stats.window_propagations) << name;
    EXPECT_TRUE(exactgeo_test::distances_match(no_rule1.distances, all_rules.distances, 1e-12)) << name;
    EXPECT_TRUE(exactgeo_test::distances_match(no_rule23.distances, all_rules.distances, 1e-12)) << name;
  }
}

TEST(VariantAblations, AllVariantsAgree) {
  const exactgeo::Mesh mesh(exactgeo::make_bumpy_torus(96, 40));
  const auto reference = exactgeo::geodesic_distance(mesh, 5, {}).distances;
  for (const GeodesicOptions& options : exactgeo_test::kAllVariants) {
    double error = 0;
    EXPECT_TRUE(exactgeo_test::distances_match(exactgeo::geodesic_distance(mesh, 5, options).distances, reference,
                                               1e-12, &error))
        << exactgeo_test::variant_label(options) << ": " << error;
  }
}

}  // namespace
