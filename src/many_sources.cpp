// Many sources: one solver per worker thread, rows handed out from a shared counter and handed over in
// blocks; farthest-point sampling with shrinking cut-offs.
#include "exactgeo/many_sources.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <system_error>

#include "exactgeo/error.hpp"
#include "parallel.hpp"
#include "stop.hpp"
#include "surface_point.hpp"
#include "vtp_engine.hpp"
#include "worker_pool.hpp"

namespace exactgeo {

namespace {

// One worker's state per thread, the rows of one block shared between them: work(state, row) for each row in
// [0, rows), handed out from a shared counter. The first failure stops the block and is thrown here.
template <class States, class Work>
void share_rows(States& states, std::size_t rows, const Work& work) {
  using State = typename States::value_type;
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto take_rows = [&](State& state) {
    try {
      for (std::size_t r; (r = next.fetch_add(1)) < rows;) work(state, r);
    } catch (...) {
      const std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = rows;
    }
  };
  const unsigned workers = static_cast<unsigned>(std::min<std::size_t>(states.size(), rows));
  std::vector<std::unique_ptr<detail::WorkerThread>> pool;
  try {
    for (unsigned t = 1; t < workers && detail::room_for_threads(t); ++t)
      pool.push_back(std::make_unique<detail::WorkerThread>([&take_rows, &state = states[t]] { take_rows(state); }));
  } catch (const std::system_error&) {
    // The system would not start another thread (a process or address-space limit): the rows are shared
    // from one counter, so the threads that started do them all.
  }
  take_rows(states[0]);
  pool.clear();  // joins
  if (failure) std::rethrow_exception(failure);
}

// Worker threads for a matrix: never more than the rows, since each holds a solver as large as the mesh.
unsigned matrix_threads(const MatrixOptions& options, std::size_t rows) {
  return static_cast<unsigned>(
      std::clamp<std::size_t>(detail::threads_or_cores(options.threads), 1, std::max<std::size_t>(1, rows)));
}

std::size_t block_rows(const MatrixOptions& options, unsigned threads) {
  return std::max<std::size_t>(1, options.block_rows ? options.block_rows : 4 * threads);
}

// Checks the options and the sources (throws before any work).
void check_matrix_request(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                          const MatrixOptions& options) {
  detail::check_options(options.geodesic);
  for (std::uint32_t v : source_vertices) detail::source_vertex_copies(mesh.surface(), v);  // throws if invalid
}

// for_each_distance_block, telling `consume` the block's row count too (its rows may have no columns).
template <class Consume>
void distance_blocks(const Mesh& mesh, std::span<const std::uint32_t> source_vertices, const MatrixOptions& options,
                     const Consume& consume) {
  check_matrix_request(mesh, source_vertices, options);
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
  const unsigned threads = matrix_threads(options, source_vertices.size());
  const std::size_t rows_per_block = block_rows(options, threads);
  std::vector<double> block;
  std::vector<GeodesicSolver> solvers;
  for (unsigned t = 0; t < threads; ++t) solvers.emplace_back(mesh);
  // Sources are spread over the threads; a run sharing threads too would only compete with the others.
  GeodesicOptions per_run = options.geodesic;
  per_run.threads = 1;

  for (std::size_t first = 0; first < source_vertices.size(); first += rows_per_block) {
    const std::size_t rows = std::min(rows_per_block, source_vertices.size() - first);
    block.resize(rows * columns);
    share_rows(solvers, rows, [&](GeodesicSolver& solver, std::size_t r) {
      detail::throw_if_stopped(options.geodesic.stop);
      const std::uint32_t source = source_vertices[first + r];
      const auto row = block.begin() + static_cast<std::ptrdiff_t>(r * columns);
      if (options.target_vertices && targets.empty()) {  // no column a run can reach
        std::fill(row, row + static_cast<std::ptrdiff_t>(columns), HUGE_VAL);
        return;
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
    });
    consume(first, rows, std::span<const double>(block));
  }
}

}  // namespace

void for_each_distance_block(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                             const MatrixOptions& options,
                             const std::function<void(std::size_t first_row, std::span<const double> rows)>& consume) {
  distance_blocks(mesh, source_vertices, options,
                  [&](std::size_t first, std::size_t, std::span<const double> rows) { consume(first, rows); });
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

namespace {

// The input vertices whose distance surface vertex s carries (as nearest_copy picks it): s's input vertex,
// and, on a welded mesh, every input vertex welded into it.
class CarriedVertices {
 public:
  explicit CarriedVertices(const detail::SurfaceMesh& surface) : surface_(surface) {
    if (surface.canonical_input.empty()) return;
    detail::WorkerPool calling_thread(1);
    welded_ = detail::group_by_keys(detail::ParallelTeam{calling_thread}, surface.canonical_input,
                                    surface.canonical_input.size());
  }
  std::span<const std::uint32_t> of(std::uint32_t surface_vertex) const {
    const std::uint32_t& input = surface_.surface_to_input[surface_vertex];
    if (surface_.canonical_input.empty()) return {&input, 1};
    const std::uint32_t c = surface_.canonical(input);
    return {welded_.begin(c), welded_.end(c)};
  }

 private:
  const detail::SurfaceMesh& surface_;
  detail::Groups welded_;  // per canonical input vertex: the input vertices welded into it, in order
};

// Each input vertex the engine's last run reached, with its distance in the input's frame, as the dense result
// has them: visit(input vertex, distance). An input vertex's distance is its nearest copy's, so only that copy
// gives it. A run that stopped early lists the few vertices it reached; otherwise every vertex is looked at.
template <class Visit>
void for_each_reached_input(const detail::VtpEngine& engine, const detail::SurfaceMesh& surface,
                            const CarriedVertices& carried, const Visit& visit) {
  const std::span<const double> d = engine.distances();
  const auto visit_copy = [&](std::uint32_t s) {
    if (!engine.answers(d[s]) || surface.nearest_copy(surface.surface_to_input[s], d) != s) return;
    for (const std::uint32_t v : carried.of(s)) visit(v, surface.to_input_length(d[s]));
  };
  if (const auto reached = engine.reached_vertices()) {
    for (const std::uint32_t s : *reached) visit_copy(s);
  } else {
    for (std::uint32_t s = 0; s < surface.vertex_count; ++s) visit_copy(s);
  }
}

struct SparseRowWorker {
  explicit SparseRowWorker(const detail::SurfaceMesh& surface) : engine(surface) {}
  detail::VtpEngine engine;
  std::vector<detail::SourceSite> sites;
};

struct Entry {
  std::uint32_t column;
  double distance;
};

}  // namespace

void for_each_sparse_block(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                           const MatrixOptions& options,
                           const std::function<void(std::size_t first_row, const SparseDistances& block)>& consume) {
  if (options.target_vertices) {  // the targets' columns: from the dense rows, which stop at the targets
    distance_blocks(mesh, source_vertices, options,
                    [&](std::size_t first, std::size_t rows, std::span<const double> dense) {
                      SparseDistances block = finite_entries(dense, options.target_vertices->size());
                      block.rows = rows;  // also where there are no columns
                      consume(first, block);
                    });
    return;
  }
  check_matrix_request(mesh, source_vertices, options);
  const detail::SurfaceMesh& surface = mesh.surface();
  const CarriedVertices carried(surface);
  const unsigned threads = matrix_threads(options, source_vertices.size());
  const std::size_t rows_per_block = block_rows(options, threads);
  std::deque<SparseRowWorker> workers;  // an engine does not move
  for (unsigned t = 0; t < threads; ++t) workers.emplace_back(surface);
  GeodesicOptions per_run = options.geodesic;
  per_run.threads = 1;
  std::vector<std::vector<Entry>> rows_entries;
  for (std::size_t first = 0; first < source_vertices.size(); first += rows_per_block) {
    const std::size_t rows = std::min(rows_per_block, source_vertices.size() - first);
    rows_entries.resize(rows);
    share_rows(workers, rows, [&](SparseRowWorker& worker, std::size_t r) {
      detail::throw_if_stopped(options.geodesic.stop);
      worker.sites.clear();
      detail::add_vertex_sources(worker.sites, detail::source_vertex_copies(surface, source_vertices[first + r]), 0);
      worker.engine.run(worker.sites, {}, per_run);
      std::vector<Entry>& entries = rows_entries[r];
      entries.clear();
      for_each_reached_input(worker.engine, surface, carried, [&](std::uint32_t v, double distance) {
        entries.push_back({v, distance});
      });
      std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.column < b.column; });
    });
    SparseDistances block;
    block.rows = rows;
    block.columns = mesh.vertex_count();
    for (std::size_t r = 0; r < rows; ++r) {
      for (const Entry& e : rows_entries[r]) {
        block.row.push_back(static_cast<std::uint32_t>(r));
        block.column.push_back(e.column);
        block.distance.push_back(e.distance);
      }
    }
    consume(first, block);
  }
}

SparseDistances finite_entries(std::span<const double> rows, std::size_t columns) {
  SparseDistances matrix;
  matrix.columns = columns;
  matrix.rows = columns ? rows.size() / columns : 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (std::isinf(rows[i])) continue;
    matrix.row.push_back(static_cast<std::uint32_t>(i / columns));
    matrix.column.push_back(static_cast<std::uint32_t>(i % columns));
    matrix.distance.push_back(rows[i]);
  }
  return matrix;
}

void append_row_pointers(std::vector<std::int64_t>& indptr, const SparseDistances& block) {
  const std::int64_t before = indptr.empty() ? 0 : indptr.back();
  std::size_t k = 0;
  for (std::size_t r = 0; r < block.rows; ++r) {
    while (k < block.row.size() && block.row[k] == r) ++k;
    indptr.push_back(before + static_cast<std::int64_t>(k));
  }
}

void append_rows(CompressedSparseRows& rows, const SparseDistances& block) {
  append_row_pointers(rows.indptr, block);
  rows.data.insert(rows.data.end(), block.distance.begin(), block.distance.end());
  rows.indices.insert(rows.indices.end(), block.column.begin(), block.column.end());
}

SparseDistances sparse_distance_matrix(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                                       const MatrixOptions& options) {
  SparseDistances sparse;
  sparse.rows = source_vertices.size();
  sparse.columns = options.target_vertices ? options.target_vertices->size() : mesh.vertex_count();
  for_each_sparse_block(mesh, source_vertices, options, [&](std::size_t first, const SparseDistances& block) {
    for (const std::uint32_t r : block.row) sparse.row.push_back(static_cast<std::uint32_t>(first + r));
    sparse.column.insert(sparse.column.end(), block.column.begin(), block.column.end());
    sparse.distance.insert(sparse.distance.end(), block.distance.begin(), block.distance.end());
  });
  return sparse;
}

namespace {

// A run that reaches fewer input vertices than this is not worth sharing between threads (2 threads break
// even at about 10,000 faces, recommended_threads): farthest-point sampling runs the next ones on one thread.
constexpr std::size_t kVerticesWorthThreads = 10000;

// The vertices by their distance to the samples, farthest first (ties to the lowest index, as a scan in
// vertex order picks), in a heap. A vertex's distance only ever decreases, and each decrease pushes it
// again: an entry whose distance is no longer the vertex's is dropped when it comes up, or with all the
// others when such entries outnumber the vertices. So each sample costs what its run reached, not the mesh.
class FarthestVertices {
 public:
  explicit FarthestVertices(std::span<const double> distances) : distances_(distances) { rebuild(); }

  void decreased(std::uint32_t v) {
    heap_.push_back({distances_[v], v});
    std::push_heap(heap_.begin(), heap_.end(), nearer);
    if (heap_.size() > 2 * distances_.size()) rebuild();
  }

  // The farthest reachable vertex; kNoSource when there is none.
  std::uint32_t farthest() {
    while (!heap_.empty() && heap_.front().distance != distances_[heap_.front().vertex]) {
      std::pop_heap(heap_.begin(), heap_.end(), nearer);
      heap_.pop_back();
    }
    return heap_.empty() ? kNoSource : heap_.front().vertex;
  }

 private:
  struct Candidate {
    double distance;
    std::uint32_t vertex;
  };
  static bool nearer(const Candidate& a, const Candidate& b) {
    return a.distance < b.distance || (a.distance == b.distance && a.vertex > b.vertex);
  }
  void rebuild() {
    heap_.clear();
    for (std::uint32_t v = 0; v < distances_.size(); ++v)
      if (!std::isinf(distances_[v])) heap_.push_back({distances_[v], v});
    std::make_heap(heap_.begin(), heap_.end(), nearer);
  }

  std::span<const double> distances_;  // per input vertex, to the nearest sample
  std::vector<Candidate> heap_;
};

}  // namespace

Sampling farthest_point_sampling(const Mesh& mesh, std::size_t count, std::span<const std::uint32_t> first_samples,
                                 const GeodesicOptions& options, const std::function<void(std::size_t)>& progress) {
  if (first_samples.empty()) throw Error(ErrorCode::invalid_argument, "no first sample given");
  detail::check_options(options);
  const detail::SurfaceMesh& surface = mesh.surface();
  for (std::uint32_t v : first_samples) detail::source_vertex_copies(surface, v);  // throws if invalid
  Sampling sampling;
  if (count == 0) return sampling;
  const CarriedVertices carried(surface);
  detail::VtpEngine engine(surface);
  std::vector<detail::SourceSite> sites;
  GeodesicOptions run_options = options;
  // A run from `source` cut off at `cutoff`, each input vertex it reached handed to visit(vertex, distance).
  const auto run_from = [&](std::uint32_t source, double cutoff, const auto& visit) {
    sites.clear();
    detail::add_vertex_sources(sites, detail::source_vertex_copies(surface, source), 0);
    run_options.max_distance = cutoff;
    engine.run(sites, {}, run_options);
    std::size_t reached = 0;
    for_each_reached_input(engine, surface, carried, [&](std::uint32_t v, double distance) {
      ++reached;
      visit(v, distance);
    });
    // The cut-offs only shrink, and the runs' reach with them.
    if (reached < kVerticesWorthThreads) run_options.threads = 1;
  };

  sampling.samples.push_back(first_samples[0]);
  sampling.radii.push_back(HUGE_VAL);
  sampling.distances.assign(mesh.vertex_count(), HUGE_VAL);
  sampling.nearest_sample.assign(mesh.vertex_count(), kNoSource);
  run_from(first_samples[0], options.max_distance, [&](std::uint32_t v, double distance) {
    sampling.distances[v] = distance;
    sampling.nearest_sample[v] = 0;
  });
  if (progress) progress(1);
  FarthestVertices farthest(sampling.distances);
  while (sampling.samples.size() < count) {
    detail::throw_if_stopped(options.stop);
    // The given first samples in their order, then the farthest vertex from the samples so far; either way,
    // nothing farther than the next sample's current distance can get closer to it.
    std::uint32_t next = kNoSource;
    if (sampling.samples.size() < first_samples.size()) {
      next = first_samples[sampling.samples.size()];
    } else {
      next = farthest.farthest();
      if (next == kNoSource || sampling.distances[next] == 0) break;  // every reachable vertex is a sample
    }
    const auto index = static_cast<std::uint32_t>(sampling.samples.size());
    sampling.samples.push_back(next);
    sampling.radii.push_back(sampling.distances[next]);
    run_from(next, std::min(options.max_distance, sampling.distances[next]), [&](std::uint32_t v, double distance) {
      if (distance < sampling.distances[v]) {
        sampling.distances[v] = distance;
        sampling.nearest_sample[v] = index;
        farthest.decreased(v);
      }
    });
    if (progress) progress(sampling.samples.size());
  }
  return sampling;
}

Sampling farthest_point_sampling(const Mesh& mesh, std::size_t count, std::uint32_t first,
                                 const GeodesicOptions& options, const std::function<void(std::size_t)>& progress) {
  return farthest_point_sampling(mesh, count, std::span(&first, 1), options, progress);
}

}  // namespace exactgeo
