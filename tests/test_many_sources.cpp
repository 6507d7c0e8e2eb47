// Distance matrices and farthest-point sampling, checked against independent single-source runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "exactgeo/many_sources.hpp"
#include "test_meshes.hpp"

namespace {

using exactgeo::Mesh;
using exactgeo::MatrixOptions;

const Mesh& torus() {
  static const Mesh mesh(exactgeo::make_bumpy_torus(32, 12));
  return mesh;
}

TEST(DistanceMatrix, RowsAreSingleSourceRunsWhateverTheThreadsAndBlocks) {
  const Mesh& mesh = torus();
  const std::vector<std::uint32_t> sources = {0, 17, 200, 333, 5, 17, 90};
  const std::size_t n = mesh.vertex_count();
  for (unsigned threads : {1u, 2u, 3u}) {
    for (std::size_t block : {std::size_t{1}, std::size_t{3}, std::size_t{0}}) {
      const std::vector<double> matrix =
          exactgeo::distance_matrix(mesh, sources, MatrixOptions{.geodesic = {}, .threads = threads, .block_rows = block});
      ASSERT_EQ(matrix.size(), sources.size() * n);
      for (std::size_t i = 0; i < sources.size(); ++i) {
        const std::vector<double> row = exactgeo::geodesic_distance(mesh, sources[i]).distances;
        for (std::size_t v = 0; v < n; ++v)
          ASSERT_EQ(std::bit_cast<std::uint64_t>(matrix[i * n + v]), std::bit_cast<std::uint64_t>(row[v]))
              << "threads " << threads << " block " << block << " row " << i << " vertex " << v;
      }
    }
  }
}

// A thread count beyond the sources is capped at them: a solver per requested thread (each as large as the
// mesh) would run out of memory long before 2^31 threads, and the extra ones would have no work anyway.
TEST(DistanceMatrix, ThreadsAreCappedAtTheWorkAvailable) {
  const Mesh& mesh = torus();
  const std::vector<std::uint32_t> sources = {0, 17};
  const std::vector<double> capped = exactgeo::distance_matrix(mesh, sources, {.geodesic = {}, .threads = 1u << 31});
  EXPECT_EQ(capped, exactgeo::distance_matrix(mesh, sources, {.geodesic = {}, .threads = 1}));
}

TEST(DistanceMatrix, IsSymmetricBetweenSources) {
  const Mesh& mesh = torus();
  const std::vector<std::uint32_t> sources = {3, 77, 150, 290};
  const std::vector<double> matrix = exactgeo::distance_matrix(mesh, sources);
  const double scale = exactgeo_test::max_finite(matrix);
  for (std::size_t i = 0; i < sources.size(); ++i)
    for (std::size_t j = 0; j < sources.size(); ++j)
      EXPECT_NEAR(matrix[i * mesh.vertex_count() + sources[j]], matrix[j * mesh.vertex_count() + sources[i]],
                  1e-12 * scale);
}

TEST(DistanceMatrix, SparseWithACutOffHoldsTheEntriesWithinIt) {
  const Mesh& mesh = torus();
  const std::vector<std::uint32_t> sources = {0, 40, 41, 300};
  const std::vector<double> dense = exactgeo::distance_matrix(mesh, sources);
  const double radius = 0.3 * exactgeo_test::max_finite(dense);
  MatrixOptions options;
  options.geodesic.max_distance = radius;
  options.threads = 2;
  const exactgeo::SparseDistances sparse = exactgeo::sparse_distance_matrix(mesh, sources, options);
  EXPECT_EQ(sparse.rows, sources.size());
  EXPECT_EQ(sparse.columns, mesh.vertex_count());
  std::vector<double> rebuilt(dense.size(), HUGE_VAL);
  for (std::size_t k = 0; k < sparse.distance.size(); ++k)
    rebuilt[sparse.row[k] * sparse.columns + sparse.column[k]] = sparse.distance[k];
  for (std::size_t i = 0; i < dense.size(); ++i) {
    if (dense[i] < radius * (1 - 1e-9)) {
      EXPECT_NEAR(rebuilt[i], dense[i], 1e-12 * radius) << i;
    } else if (dense[i] > radius * (1 + 1e-9)) {
      EXPECT_TRUE(std::isinf(rebuilt[i])) << i;
    }
  }
  EXPECT_LT(sparse.distance.size(), dense.size() / 2);
}

TEST(DistanceMatrix, InvalidSourcesFailBeforeAnyWork) {
  const Mesh& mesh = torus();
  const std::vector<std::uint32_t> sources = {0, 1, 100000};
  bool called = false;
  EXPECT_THROW(exactgeo::for_each_distance_block(mesh, sources, {}, [&](std::size_t, std::span<const double>) {
    called = true;
  }), exactgeo::Error);
  EXPECT_FALSE(called);
}

TEST(FarthestPointSampling, EachSampleIsFarthestFromThePreviousOnes) {
  const Mesh& mesh = torus();
  const exactgeo::Sampling sampling = exactgeo::farthest_point_sampling(mesh, 8, 5);
  ASSERT_EQ(sampling.samples.size(), 8u);
  EXPECT_EQ(sampling.samples[0], 5u);
  // Reference: the minimum over full single-source runs of the samples so far.
  std::vector<double> nearest(mesh.vertex_count(), HUGE_VAL);
  for (std::size_t k = 0; k < sampling.samples.size(); ++k) {
    if (k > 0) {
      const double best = *std::max_element(nearest.begin(), nearest.end());
      EXPECT_NEAR(nearest[sampling.samples[k]], best, 1e-12 * best) << "sample " << k;
      EXPECT_NEAR(sampling.radii[k], best, 1e-12 * best) << "sample " << k;
    }
    const auto run = exactgeo::geodesic_distance(mesh, sampling.samples[k]).distances;
    for (std::size_t v = 0; v < nearest.size(); ++v) nearest[v] = std::min(nearest[v], run[v]);
  }
  const double scale = exactgeo_test::max_finite(nearest);
  for (std::size_t v = 0; v < nearest.size(); ++v) {
    EXPECT_NEAR(sampling.distances[v], nearest[v], 1e-12 * scale) << v;
    const auto s = sampling.nearest_sample[v];
    ASSERT_LT(s, sampling.samples.size());
  }
  std::vector<std::uint32_t> sorted = sampling.samples;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "samples repeat";
}

// Given first samples are taken in their order, each with its distance to those before as radius; from
// the first samples of a plain run, the same run comes out, bit for bit.
TEST(FarthestPointSampling, SeveralFirstSamplesContinueAsOneRunWould) {
  const Mesh& mesh = torus();
  const exactgeo::Sampling plain = exactgeo::farthest_point_sampling(mesh, 8, 5);
  const std::vector<std::uint32_t> seeds(plain.samples.begin(), plain.samples.begin() + 3);
  const exactgeo::Sampling seeded = exactgeo::farthest_point_sampling(mesh, 8, seeds);
  EXPECT_EQ(seeded.samples, plain.samples);
  EXPECT_EQ(seeded.radii, plain.radii);
  EXPECT_EQ(seeded.distances, plain.distances);
  EXPECT_EQ(seeded.nearest_sample, plain.nearest_sample);

  const std::vector<std::uint32_t> chosen = {40, 7};
  const exactgeo::Sampling from_chosen = exactgeo::farthest_point_sampling(mesh, 4, chosen);
  ASSERT_EQ(from_chosen.samples.size(), 4u);
  EXPECT_EQ(from_chosen.samples[0], 40u);
  EXPECT_EQ(from_chosen.samples[1], 7u);
  EXPECT_EQ(from_chosen.radii[1], exactgeo::geodesic_distance(mesh, 40).distances[7]);
  const std::vector<std::uint32_t> invalid = {3, 100000};
  EXPECT_THROW(exactgeo::farthest_point_sampling(mesh, 4, invalid), exactgeo::Error);
}

TEST(FarthestPointSampling, StopsWhenEveryVertexIsASample) {
  const Mesh mesh(exactgeo::make_icosphere(0));  // 12 vertices
  EXPECT_EQ(exactgeo::farthest_point_sampling(mesh, 50).samples.size(), 12u);
  EXPECT_TRUE(exactgeo::farthest_point_sampling(mesh, 0).samples.empty());
}

}  // namespace
