// The public geodesic API: checks the query, runs the engine, maps surface vertices back to input vertices.
#include "exactgeo/geodesic.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "exactgeo/error.hpp"
#include "face_windows.hpp"
#include "nearest_source.hpp"
#include "surface_point.hpp"
#include "vtp_engine.hpp"
#include "worker_pool.hpp"

namespace exactgeo {

namespace {

// More threads than this for one run are a mistake (a count meant for something else), not a machine.
constexpr unsigned kMaxThreads = 1024;
// Faces per thread below which a thread more does not pay for its share of the synchronisation (measured on
// 2 cores, docs/performance.md: 2 threads break even at about 10,000 faces and gain from 20,000).
constexpr std::uint32_t kFacesPerThread = 10000;

}  // namespace

void detail::check_options(const GeodesicOptions& options) {
  algorithm_name(options.algorithm);  // throws for a value outside the enum
  if (!(options.max_distance >= 0))
    throw Error(ErrorCode::invalid_argument,
                "max_distance must be a non-negative number, not " + std::to_string(options.max_distance));
  if (options.threads > kMaxThreads)
    throw Error(ErrorCode::invalid_argument, "threads must be at most " + std::to_string(kMaxThreads) + " (0: one per core), not " +
                                                 std::to_string(options.threads));
}

unsigned recommended_threads(const Mesh& mesh) {
  const std::size_t worth = std::max<std::size_t>(1, mesh.face_count() / kFacesPerThread);
  return static_cast<unsigned>(std::min<std::size_t>(detail::threads_or_cores(0), worth));
}

namespace {

std::vector<detail::LocatedPoint> locate_all(const detail::SurfaceMesh& surface, std::span<const SurfacePoint> points,
                                             const char* what) {
  std::vector<detail::LocatedPoint> located;
  located.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    located.push_back(detail::locate_checked(surface, points[i], std::string(what) + " " + std::to_string(i)));
  return located;
}

}  // namespace

std::string_view algorithm_name(Algorithm algorithm) {
  for (const auto& [value, name] : kAlgorithmNames)
    if (value == algorithm) return name;
  throw Error(ErrorCode::invalid_argument,
              "unknown algorithm value " + std::to_string(static_cast<int>(algorithm)));
}

Algorithm parse_algorithm(std::string_view name) {
  std::string known;
  for (const auto& [value, known_name] : kAlgorithmNames) {
    if (known_name == name) return value;
    known += (known.empty() ? "" : ", ") + std::string(known_name);
  }
  throw Error(ErrorCode::invalid_argument, "unknown algorithm '" + std::string(name) + "' (known: " + known + ")");
}

GeodesicSolver::GeodesicSolver(const Mesh& mesh)
    : mesh_(&mesh), engine_(std::make_unique<detail::VtpEngine>(mesh.surface())) {}
GeodesicSolver::~GeodesicSolver() = default;
void GeodesicSolver::set_progress(std::function<void(double)> callback) { engine_->set_progress(std::move(callback)); }
GeodesicSolver::GeodesicSolver(GeodesicSolver&&) noexcept = default;
GeodesicSolver& GeodesicSolver::operator=(GeodesicSolver&&) noexcept = default;

const GeodesicResult& GeodesicSolver::solve(std::span<const SurfacePoint> sources,
                                            std::span<const SurfacePoint> targets, const GeodesicOptions& options) {
  if (sources.empty()) throw Error(ErrorCode::invalid_argument, "no source given");
  const detail::SurfaceMesh& surface = mesh_->surface();
  const std::vector<detail::LocatedPoint> located = locate_all(surface, sources, "source");
  std::vector<detail::SourceSite> sites;
  for (std::uint32_t i = 0; i < located.size(); ++i) {
    // A point at a corner is that input vertex: a source at each of its copies, as a vertex source is.
    if (located[i].vertex != detail::kNone)
      detail::add_vertex_sources(sites, surface.copies_with(located[i].vertex), i);
    else
      sites.push_back({located[i], i});
  }
  return run(sites, targets, options);
}

const GeodesicResult& GeodesicSolver::solve(std::span<const std::uint32_t> source_vertices,
                                            std::span<const SurfacePoint> targets, const GeodesicOptions& options) {
  if (source_vertices.empty()) throw Error(ErrorCode::invalid_argument, "no source vertex given");
  const detail::SurfaceMesh& surface = mesh_->surface();
  std::vector<detail::SourceSite> sites;
  for (std::uint32_t i = 0; i < source_vertices.size(); ++i)
    detail::add_vertex_sources(sites, detail::source_vertex_copies(surface, source_vertices[i]), i);
  return run(sites, targets, options);
}

const GeodesicResult& GeodesicSolver::run(std::span<const detail::SourceSite> sites,
                                          std::span<const SurfacePoint> targets, const GeodesicOptions& options) {
  detail::check_options(options);
  const detail::SurfaceMesh& surface = mesh_->surface();
  const std::vector<detail::LocatedPoint> located_targets = locate_all(surface, targets, "target");
  std::uint32_t source_count = 0;
  for (const detail::SourceSite& site : sites) source_count = std::max(source_count, site.label + 1);

  const auto start = std::chrono::steady_clock::now();
  detail::VtpEngine& engine = *engine_;
  engine.run(sites, located_targets, options);
  GeodesicResult& result = result_;
  result.stats = engine.stats();
  const std::span<const double> d = engine.distances();
  // With one source every reachable vertex belongs to it; otherwise follow the pseudo-source chains.
  std::vector<std::uint32_t> labels;
  if (source_count > 1) labels = detail::vertex_labels(engine);
  const auto label_of_vertex = [&](std::uint32_t s) { return labels.empty() ? 0u : labels[s]; };

  result.distances.resize(mesh_->vertex_count());
  result.nearest_source.resize(mesh_->vertex_count());
  engine.for_parts(mesh_->vertex_count(), [&](std::size_t begin, std::size_t end) {
    for (auto v = static_cast<std::uint32_t>(begin); v < end; ++v) {
      const std::uint32_t s = surface.nearest_copy(v, d);  // the smallest over the vertex's copies
      // Not reached: used by no face, unreached, or beyond the cut-off.
      const bool reached = s != detail::kNone && engine.answers(d[s]);
      result.distances[v] = reached ? surface.to_input_length(d[s]) : HUGE_VAL;
      result.nearest_source[v] = reached ? label_of_vertex(s) : kNoSource;
    }
  });
  result.target_distances.assign(targets.size(), HUGE_VAL);
  result.target_nearest_source.assign(targets.size(), kNoSource);
  for (std::size_t t = 0; t < targets.size(); ++t) {
    if (const std::uint32_t vertex = located_targets[t].vertex; vertex != detail::kNone) {
      // A point at a vertex (or at a corner of a face) is that input vertex: the per-vertex answer.
      const std::uint32_t v = surface.surface_to_input[vertex];
      result.target_distances[t] = result.distances[v];
      result.target_nearest_source[t] = result.nearest_source[v];
      continue;
    }
    const double distance = engine.target_distances()[t];
    if (!engine.answers(distance)) continue;
    result.target_distances[t] = surface.to_input_length(distance);
    result.target_nearest_source[t] =
        labels.empty() ? 0u : detail::label_of(engine, engine.target_arrivals()[t].from, labels);
  }
  result.stats.propagation_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

// The kept windows of the last run, for `query` (a name for the error message).
const detail::FaceWindows& GeodesicSolver::kept_windows(const char* query) const {
  const detail::FaceWindows* kept = engine_->kept_windows();
  if (result_.distances.empty() || !kept)
    throw Error(ErrorCode::invalid_argument, std::string(query) +
                                                 " needs the windows of the last run: solve with keep_windows "
                                                 "(GeodesicOptions::keep_windows = true) first");
  return *kept;
}

std::vector<double> GeodesicSolver::distance_at(std::span<const SurfacePoint> points) const {
  const detail::FaceWindows& kept = kept_windows("distance_at");
  const detail::SurfaceMesh& surface = mesh_->surface();
  const std::vector<detail::LocatedPoint> located = locate_all(surface, points, "point");
  // Answered face by face: a face's windows are read from memory once for all its points, which on a large
  // mesh is most of a query's time (random points on nefertiti: 3.7x faster than in the caller's order).
  std::vector<std::uint64_t> by_face(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) by_face[i] = std::uint64_t{located[i].face} << 32 | i;
  std::sort(by_face.begin(), by_face.end());
  std::vector<double> distances(points.size());
  for (const std::uint64_t key : by_face) {
    const auto i = static_cast<std::uint32_t>(key);
    const detail::LocatedPoint& point = located[i];
    if (point.vertex != detail::kNone) {  // that input vertex, as a target there reads it
      distances[i] = result_.distances[surface.surface_to_input[point.vertex]];
      continue;
    }
    detail::Arrival arrival;
    const double d = kept.reach(surface, engine_->distances(), point, arrival);
    distances[i] = engine_->answers(d) ? surface.to_input_length(d) : HUGE_VAL;
  }
  return distances;
}

GeodesicResult geodesic_distance(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                                 const GeodesicOptions& options) {
  GeodesicSolver solver(mesh);
  solver.solve(source_vertices, {}, options);
  return std::move(solver).result();
}

GeodesicResult geodesic_distance(const Mesh& mesh, std::uint32_t source_vertex, const GeodesicOptions& options) {
  return geodesic_distance(mesh, std::span<const std::uint32_t>(&source_vertex, 1), options);
}

GeodesicResult geodesic_distance(const Mesh& mesh, std::span<const SurfacePoint> sources,
                                 const GeodesicOptions& options) {
  GeodesicSolver solver(mesh);
  solver.solve(sources, {}, options);
  return std::move(solver).result();
}

}  // namespace exactgeo
