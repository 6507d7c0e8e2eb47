// Many sources: one solver per worker thread, rows handed out from a shared counter and handed over in
// blocks; farthest-point sampling with shrinking cut-offs.
#include "exactgeo/many_sources.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <system_error>

#include "exactgeo/error.hpp"
#include "stop.hpp"
#include "surface_point.hpp"
#include "vtp_engine.hpp"
#include "worker_pool.hpp"

namespace exactgeo {

void for_each_distance_block(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                             const MatrixOptions& options,
                             const std::function<void(std::size_t first_row, std::span<const double> rows)>& consume) {
  detail::check_options(options.geodesic);
  for (std::uint32_t v : source_vertices) detail::source_vertex_copies(mesh.surface(), v);  // throws if invalid
  // Targets stop each run once final; their columns are then read from the vertex distances, as the full
  // matrix has them (the smallest over a split vertex's copies). The face-sorted variants run whole rows: with
  // targets they drop the windows beyond the farthest one as they go, which changes which of two windows
  // within rounding of each other survives, and so the last bit of a column now and then (fuzzed: 8 of 8,000
  // cases, every one face-sorted).
  const bool stop_at_targets = !detail::sorts_faces(options.geodesic.algorithm);
  // A vertex used by no face has +inf in every row of the full matrix, so in its column too: no run waits for it.
  std::vector<SurfacePoint> targets;
  if (options.target_vertices)
    for (std::uint32_t v : *options.target_vertices)
      if (v >= mesh.vertex_count() || !mesh.surface().copies_of(v).empty())
        targets.push_back(vertex_point(mesh, v));  // throws if out of range
  const std::size_t columns = options.target_vertices ? options.target_vertices->size() : mesh.vertex_count();
  // More threads than rows would only hold idle solvers (each as large as the mesh).
  const unsigned threads = static_cast<unsigned>(std::clamp<std::size_t>(
      detail::threads_or_cores(options.threads), 1, std::max<std::size_t>(1, source_vertices.size())));
  const std::size_t block_rows = std::max<std::size_t>(1, options.block_rows ? options.block_rows : 4 * threads);
  std::vector<double> block;
  std::vector<GeodesicSolver> solvers;
  for (unsigned t = 0; t < threads; ++t) solvers.emplace_back(mesh);
  // Sources are spread over the threads; a run sharing threads too would only compete with the others.
  GeodesicOptions per_run = options.geodesic;
  per_run.threads = 1;

  for (std::size_t first = 0; first < source_vertices.size(); first += block_rows) {
    const std::size_t rows = std::min(block_rows, source_vertices.size() - first);
    block.resize(rows * columns);
    std::atomic<std::size_t> next{0};
    std::exception_ptr failure;
    std::mutex failure_mutex;
    const auto work = [&](GeodesicSolver& solver) {
      try {
        for (std::size_t r; (r = next.fetch_add(1)) < rows;) {
          detail::throw_if_stopped(options.geodesic.stop);
          const std::uint32_t source = source_vertices[first + r];
          const auto row = block.begin() + static_cast<std::ptrdiff_t>(r * columns);
          if (options.target_vertices && targets.empty()) {  // no column a run can reach
            std::fill(row, row + static_cast<std::ptrdiff_t>(columns), HUGE_VAL);
            continue;
          }
          const GeodesicResult& result = solver.solve(
              std::span(&source, 1),
              stop_at_targets ? std::span<const SurfacePoint>(targets) : std::span<const SurfacePoint>(), per_run);
          if (options.target_vertices) {
            const std::vector<std::uint32_t>& column_vertices = *options.target_vertices;
            for (std::size_t t = 0; t < columns; ++t)
              row[static_cast<std::ptrdiff_t>(t)] = result.distances[column_vertices[t]];
          } else {
            std::copy(result.distances.begin(), result.distances.end(), row);
          }
        }
      } catch (...) {
        const std::lock_guard lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next = rows;
      }
    };
    const unsigned workers = static_cast<unsigned>(std::min<std::size_t>(threads, rows));
    std::vector<std::unique_ptr<detail::WorkerThread>> pool;
    try {
      for (unsigned t = 1; t < workers && detail::room_for_threads(t); ++t)
        pool.push_back(std::make_unique<detail::WorkerThread>([&work, &solver = solvers[t]] { work(solver); }));
    } catch (const std::system_error&) {
      // The system would not start another thread (a process or address-space limit): the rows are shared
      // from one counter, so the threads that started do them all.
    }
    work(solvers[0]);
    pool.clear();  // joins
    if (failure) std::rethrow_exception(failure);
    consume(first, block);
  }
}

std::vector<double> distance_matrix(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                                    const MatrixOptions& options) {
  const std::size_t columns = options.target_vertices ? options.target_vertices->size() : mesh.vertex_count();
  std::vector<double> matrix(source_vertices.size() * columns);
  for_each_distance_block(mesh, source_vertices, options, [&](std::size_t first, std::span<const double> rows) {
    std::copy(rows.begin(), rows.end(), matrix.begin() + static_cast<std::ptrdiff_t>(first * columns));
  });
  return matrix;
}

SparseDistances sparse_distance_matrix(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                                       const MatrixOptions& options) {
  SparseDistances sparse;
  sparse.rows = source_vertices.size();
  sparse.columns = options.target_vertices ? options.target_vertices->size() : mesh.vertex_count();
  for_each_distance_block(mesh, source_vertices, options, [&](std::size_t first, std::span<const double> rows) {
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (std::isinf(rows[i])) continue;
      sparse.row.push_back(static_cast<std::uint32_t>(first + i / sparse.columns));
      sparse.column.push_back(static_cast<std::uint32_t>(i % sparse.columns));
      sparse.distance.push_back(rows[i]);
    }
  });
  return sparse;
}

Sampling farthest_point_sampling(const Mesh& mesh, std::size_t count, std::span<const std::uint32_t> first_samples,
                                 const GeodesicOptions& options, const std::function<void(std::size_t)>& progress) {
  if (first_samples.empty()) throw Error(ErrorCode::invalid_argument, "no first sample given");
  for (std::uint32_t v : first_samples) detail::source_vertex_copies(mesh.surface(), v);  // throws if invalid
  Sampling sampling;
  if (count == 0) return sampling;
  GeodesicSolver solver(mesh);
  sampling.samples.push_back(first_samples[0]);
  sampling.radii.push_back(HUGE_VAL);
  const GeodesicResult& start = solver.solve(first_samples.first(1), {}, options);
  sampling.distances = start.distances;
  sampling.nearest_sample.assign(mesh.vertex_count(), kNoSource);
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    if (!std::isinf(sampling.distances[v])) sampling.nearest_sample[v] = 0;
  if (progress) progress(1);
  while (sampling.samples.size() < count) {
    detail::throw_if_stopped(options.stop);
    // The given first samples in their order, then the farthest vertex from the samples so far; either way,
    // nothing farther than the next sample's current distance can get closer to it.
    std::uint32_t next = kNoSource;
    if (sampling.samples.size() < first_samples.size()) {
      next = first_samples[sampling.samples.size()];
    } else {
      for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
        if (!std::isinf(sampling.distances[v]) && (next == kNoSource || sampling.distances[v] > sampling.distances[next]))
          next = v;
      if (next == kNoSource || sampling.distances[next] == 0) break;  // every reachable vertex is a sample
    }
    GeodesicOptions cut = options;
    cut.max_distance = std::min(options.max_distance, sampling.distances[next]);
    const GeodesicResult& run = solver.solve(std::span(&next, 1), {}, cut);
    const auto index = static_cast<std::uint32_t>(sampling.samples.size());
    sampling.samples.push_back(next);
    sampling.radii.push_back(sampling.distances[next]);
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
      if (run.distances[v] < sampling.distances[v]) {
        sampling.distances[v] = run.distances[v];
        sampling.nearest_sample[v] = index;
      }
    }
    if (progress) progress(sampling.samples.size());
  }
  return sampling;
}

Sampling farthest_point_sampling(const Mesh& mesh, std::size_t count, std::uint32_t first,
                                 const GeodesicOptions& options, const std::function<void(std::size_t)>& progress) {
  return farthest_point_sampling(mesh, count, std::span(&first, 1), options, progress);
}

}  // namespace exactgeo
