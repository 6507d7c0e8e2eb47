// Work over many sources: distance matrices computed across sources in parallel, and geodesic
// farthest-point sampling.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "exactgeo/export.hpp"
#include "exactgeo/geodesic.hpp"
#include "exactgeo/mesh.hpp"

namespace exactgeo {

struct MatrixOptions {
  GeodesicOptions geodesic;    // per-source options; max_distance gives a sparse (cut-off) matrix; each run is
                               // on one thread (its `threads` is not used: sources are spread instead)
  unsigned threads = 0;        // worker threads; 0: one per core
  std::size_t block_rows = 0;  // rows computed before they are handed over; 0: 4 per thread
  // The columns: these input vertices, in their order (a sources x targets block; each run stops as soon as
  // they are final, so nearby targets cost a fraction of a full row; the face-sorted variants run whole rows).
  // Unset: every input vertex. A column holds the same values as that vertex's column of the full matrix, bit
  // for bit (+inf for a vertex no face uses); with max_distance, targets beyond it are +inf like any vertex (run
  // without max_distance to have them all).
  std::optional<std::vector<std::uint32_t>> target_vertices{};
};

// Calls `consume(first_row, rows)` for consecutive blocks of rows, in order: row i holds the distances from
// source_vertices[i] to every input vertex, or to each of options.target_vertices (+inf where unreachable or
// beyond max_distance), rows back to back. At most one block is held in memory, so any number of sources
// fits. `consume` runs on the calling thread. Throws exactgeo::Error(invalid_argument) for an invalid
// source, target or option before any work.
EXACTGEO_API void for_each_distance_block(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                             const MatrixOptions& options,
                             const std::function<void(std::size_t first_row, std::span<const double> rows)>& consume);

// The whole matrix, sources x vertices (or x target_vertices), row-major.
EXACTGEO_API std::vector<double> distance_matrix(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                                    const MatrixOptions& options = {});

// The finite entries of the matrix (with a cut-off most are +inf), in row-major order.
struct SparseDistances {
  std::size_t rows = 0, columns = 0;
  std::vector<std::uint32_t> row, column;
  std::vector<double> distance;
};
// The same as for_each_distance_block, each block of rows as its finite entries: `block` is the sparse matrix
// of rows [first_row, first_row + block.rows), its row numbers counted from first_row, its entries in
// row-major order and each row's by column. For cut-off matrices too large to hold dense: with max_distance
// and no target_vertices, a row costs what its run reaches, not the mesh's size (the one-thread
// vertex-sorted variants; the others read each run's distances whole).
EXACTGEO_API void for_each_sparse_block(
    const Mesh& mesh, std::span<const std::uint32_t> source_vertices, const MatrixOptions& options,
    const std::function<void(std::size_t first_row, const SparseDistances& block)>& consume);
// The finite entries of dense rows (row-major, `columns` values a row), as the sparse matrix of those rows.
EXACTGEO_API SparseDistances finite_entries(std::span<const double> rows, std::size_t columns);
// Compressed sparse rows, as scipy.sparse.csr_matrix holds them: the entries' distances (data) and columns
// (indices) row after row, and where each row's entries start (indptr: one more than the rows, from 0).
struct CompressedSparseRows {
  std::vector<double> data;
  std::vector<std::uint32_t> indices;
  std::vector<std::int64_t> indptr = {0};

  std::size_t rows() const { return indptr.size() - 1; }
};
// Appends the rows of `block` (its entries in row order) after those `rows` holds.
EXACTGEO_API void append_rows(CompressedSparseRows& rows, const SparseDistances& block);
// Appends to compressed sparse rows' pointers `indptr` where each row of `block` ends, for its entries stored
// after those before (append_rows's pointers, for a writer that keeps the entries elsewhere).
EXACTGEO_API void append_row_pointers(std::vector<std::int64_t>& indptr, const SparseDistances& block);
EXACTGEO_API SparseDistances sparse_distance_matrix(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                                       const MatrixOptions& options = {});

// Geodesic farthest-point sampling: starting from `first`, each next sample is the vertex farthest from all
// samples so far (ties to the lowest index). Stops early if every vertex reachable from `first` is a
// sample; vertices on other pieces of the mesh are never sampled. `progress`, if given, is called with the
// number of samples taken so far after each one. Each run
// after the first is cut off at the current largest distance to the samples, beyond which it cannot change
// anything, so later samples cost less: a sample costs what its run reaches, not the mesh. Runs share
// `options.threads` until one reaches fewer than 10,000 vertices; the later ones run on one thread.
struct Sampling {
  std::vector<std::uint32_t> samples;
  std::vector<double> radii;      // per sample: its distance to the samples before it (+inf for the first)
  std::vector<double> distances;  // per input vertex: to the nearest sample (+inf where unreachable)
  std::vector<std::uint32_t> nearest_sample;  // per input vertex: index into samples, kNoSource if unreachable
};
EXACTGEO_API Sampling farthest_point_sampling(const Mesh& mesh, std::size_t count, std::uint32_t first = 0,
                                 const GeodesicOptions& options = {},
                                 const std::function<void(std::size_t samples)>& progress = {});
// The same from several given first samples, taken in their order (each one's radius its distance to the
// ones before), then farthest points. A seed sampled twice gets radius 0.
EXACTGEO_API Sampling farthest_point_sampling(const Mesh& mesh, std::size_t count, std::span<const std::uint32_t> first_samples,
                                 const GeodesicOptions& options = {},
                                 const std::function<void(std::size_t samples)>& progress = {});

}  // namespace exactgeo
