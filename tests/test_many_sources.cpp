// Distance matrices and farthest-point sampling, checked against independent single-source runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
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

// A sources x targets block: the targets' columns of the full matrix, bit for bit, in the targets' order
// (repeats and unsorted allowed), dense and sparse, with and without a cut-off, for any thread count.
TEST(DistanceMatrix, TargetColumnsAreTheFullMatrixColumns) {
  const Mesh& mesh = torus();
  const std::vector<std::uint32_t> sources = {0, 17, 200, 333, 5};
  const std::vector<std::uint32_t> targets = {90, 3, 17, 90, 250, 0};
  const std::size_t n = mesh.vertex_count();
  for (const double cutoff : {HUGE_VAL, 1.0}) {
    const exactgeo::GeodesicOptions geodesic{.max_distance = cutoff};
    const std::vector<double> full = exactgeo::distance_matrix(mesh, sources, {.geodesic = geodesic, .threads = 1});
    for (unsigned threads : {1u, 2u}) {
      const MatrixOptions options{.geodesic = geodesic, .threads = threads, .block_rows = 2, .target_vertices = targets};
      const std::vector<double> block = exactgeo::distance_matrix(mesh, sources, options);
      ASSERT_EQ(block.size(), sources.size() * targets.size());
      std::size_t finite = 0;
      for (std::size_t i = 0; i < sources.size(); ++i)
        for (std::size_t t = 0; t < targets.size(); ++t) {
          ASSERT_EQ(std::bit_cast<std::uint64_t>(block[i * targets.size() + t]),
                    std::bit_cast<std::uint64_t>(full[i * n + targets[t]]))
              << "cut-off " << cutoff << " row " << i << " target " << t;
          finite += std::isfinite(block[i * targets.size() + t]);
        }
      if (std::isinf(cutoff)) EXPECT_EQ(finite, block.size());
      else EXPECT_LT(finite, block.size()) << "the cut-off leaves some targets out";
      const exactgeo::SparseDistances sparse = exactgeo::sparse_distance_matrix(mesh, sources, options);
      EXPECT_EQ(sparse.rows, sources.size());
      EXPECT_EQ(sparse.columns, targets.size());
      ASSERT_EQ(sparse.distance.size(), finite);
      for (std::size_t k = 0; k < finite; ++k)
        EXPECT_EQ(sparse.distance[k], block[sparse.row[k] * targets.size() + sparse.column[k]]);
    }
  }
}

// Two grids touching at one corner: the mesh splits that vertex into two copies. A target there reads the
// nearer copy, as the full matrix's column does.
TEST(DistanceMatrix, TargetColumnsAtASplitVertexAreTheFullMatrixColumns) {
  exactgeo::MeshSoup soup = exactgeo::make_grid(3, 3, 3, 3);
  const std::uint32_t pinch = exactgeo_test::vertex_at(soup, {3, 3, 0});
  const exactgeo::MeshSoup other = exactgeo::make_grid(3, 3, 3, 3);
  std::vector<std::uint32_t> index(exactgeo_test::vertex_count(other));
  for (std::uint32_t v = 0; v < index.size(); ++v) {
    const exactgeo_test::Vec3 p = exactgeo_test::vertex_position(other, v);
    index[v] = v == 0 ? pinch : exactgeo_test::add_vertex(soup, {p[0] + 3, p[1] + 3, p[2] + 0.5 * p[0]});
  }
  for (std::size_t f = 0; f < exactgeo_test::face_count(other); ++f)
    exactgeo_test::add_triangle(soup, index[other.triangles[3 * f]], index[other.triangles[3 * f + 1]],
                                index[other.triangles[3 * f + 2]]);
  const Mesh mesh(soup);
  ASSERT_EQ(mesh.report().non_manifold_vertices, 1u);
  const std::vector<std::uint32_t> sources = {0, pinch, index[5], 7};
  const std::vector<std::uint32_t> targets = {pinch, index[15], 2, index[3]};
  const std::vector<double> full = exactgeo::distance_matrix(mesh, sources);
  MatrixOptions options;
  options.target_vertices = targets;
  const std::vector<double> block = exactgeo::distance_matrix(mesh, sources, options);
  const std::size_t n = mesh.vertex_count();
  for (std::size_t i = 0; i < sources.size(); ++i)
    for (std::size_t t = 0; t < targets.size(); ++t)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(block[i * targets.size() + t]), std::bit_cast<std::uint64_t>(full[i * n + targets[t]]))
          << "row " << i << " target " << t;
}

// Each run stops once its targets are final: a near target costs a fraction of a full row.
TEST(DistanceMatrix, NearTargetsStopTheRunsEarly) {
  const Mesh mesh(exactgeo::make_grid(60, 60, 60, 60));
  const std::vector<std::uint32_t> source = {0};
  exactgeo::GeodesicSolver solver(mesh);
  const std::uint64_t pops_all = solver.solve(source).stats.vertex_pops;
  const std::uint64_t pops_near = solver.solve(source, std::vector{exactgeo::vertex_point(mesh, 62)}).stats.vertex_pops;
  EXPECT_LT(pops_near * 20, pops_all);
  MatrixOptions options;
  options.target_vertices = {62};
  const std::vector<double> near = exactgeo::distance_matrix(mesh, source, options);
  ASSERT_EQ(near.size(), 1u);
  EXPECT_NEAR(near[0], std::sqrt(2.0), 1e-12);
}

// A column of a vertex no face uses is +inf, as in the full matrix (it threw "vertex N is used by no face").
TEST(DistanceMatrix, ColumnsOfVerticesNoFaceUsesAreInfinite) {
  exactgeo::MeshSoup soup = exactgeo::make_grid(3, 3, 3, 3);
  const auto unused = exactgeo_test::add_vertex(soup, {1, 1, 5});
  const Mesh mesh(soup);
  const std::vector<std::uint32_t> sources = {0, 5};
  const std::vector<double> full = exactgeo::distance_matrix(mesh, sources);
  for (const std::vector<std::uint32_t>& targets :
       {std::vector<std::uint32_t>{unused, 4, unused}, std::vector{unused}}) {
    MatrixOptions options;
    options.target_vertices = targets;
    const std::vector<double> block = exactgeo::distance_matrix(mesh, sources, options);
    ASSERT_EQ(block.size(), sources.size() * targets.size());
    for (std::size_t i = 0; i < sources.size(); ++i)
      for (std::size_t t = 0; t < targets.size(); ++t)
        EXPECT_EQ(block[i * targets.size() + t], full[i * mesh.vertex_count() + targets[t]])
            << "row " << i << " target " << t;
    EXPECT_EQ(block[0], HUGE_VAL);
  }
}

TEST(DistanceMatrix, BadOrNoTargets) {
  const Mesh& mesh = torus();
  const std::vector<std::uint32_t> sources = {0, 1};
  MatrixOptions options;
  options.target_vertices = {1, 99999};
  EXPECT_THROW(exactgeo::distance_matrix(mesh, sources, options), exactgeo::Error);
  options.target_vertices = std::vector<std::uint32_t>{};
  EXPECT_TRUE(exactgeo::distance_matrix(mesh, sources, options).empty());
  EXPECT_EQ(exactgeo::sparse_distance_matrix(mesh, sources, options).columns, 0u);
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

// Dense rows to their finite entries, and blocks of them appended to compressed sparse rows: empty rows, a row of
// nothing but entries, a block with no rows and a block of empty rows.
TEST(SparseRows, FiniteEntriesAppendedAsCompressedRows) {
  const double inf = HUGE_VAL;
  const std::vector<double> dense = {inf, 1.0, inf, inf, inf, inf, 2.0, 3.0, 4.0, inf, inf, inf};
  const exactgeo::SparseDistances m = exactgeo::finite_entries(dense, 3);
  EXPECT_EQ(m.rows, 4u);
  EXPECT_EQ(m.columns, 3u);
  EXPECT_EQ(m.row, (std::vector<std::uint32_t>{0, 2, 2, 2}));
  EXPECT_EQ(m.column, (std::vector<std::uint32_t>{1, 0, 1, 2}));
  EXPECT_EQ(m.distance, (std::vector<double>{1.0, 2.0, 3.0, 4.0}));
  const exactgeo::SparseDistances none = exactgeo::finite_entries({}, 0);
  EXPECT_EQ(none.rows, 0u);
  exactgeo::SparseDistances empty_rows;
  empty_rows.rows = 2;
  const exactgeo::SparseDistances last = exactgeo::finite_entries(std::vector<double>{inf, 5.0, 6.0}, 3);

  const std::array<const exactgeo::SparseDistances*, 4> blocks = {&m, &none, &empty_rows, &last};
  exactgeo::CompressedSparseRows rows;
  for (const exactgeo::SparseDistances* block : blocks) exactgeo::append_rows(rows, *block);
  EXPECT_EQ(rows.rows(), 7u);
  EXPECT_EQ(rows.indptr, (std::vector<std::int64_t>{0, 1, 1, 4, 4, 4, 4, 6}));
  EXPECT_EQ(rows.indices, (std::vector<std::uint32_t>{1, 0, 1, 2, 1, 2}));
  EXPECT_EQ(rows.data, (std::vector<double>{1.0, 2.0, 3.0, 4.0, 5.0, 6.0}));
  // The pointers alone, as a writer keeping the entries elsewhere appends them.
  std::vector<std::int64_t> indptr = {0};
  for (const exactgeo::SparseDistances* block : blocks) exactgeo::append_row_pointers(indptr, *block);
  EXPECT_EQ(indptr, rows.indptr);
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
