// GeodesicSolver: runs (interruptible on large meshes) and the queries about the last run, from any Python
// thread.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <stop_token>
#include <utility>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "interruption.hpp"
#include "marshalling.hpp"
#include "registration.hpp"

using namespace nb::literals;

namespace exactgeo::python {

namespace {

// A solver bound to Python. It keeps its own handle on the mesh (a shared pointer inside exactgeo::Mesh), so
// the Python mesh may be dropped first. The GIL is released while it runs, so two Python threads could call
// the same solver at once: the mutex makes the second one wait. Runs are numbered, so that a path query can
// tell that another thread ran the solver since the run the caller means.
struct Solver {
  explicit Solver(const exactgeo::Mesh& mesh_) : mesh(mesh_), solver(mesh) {}
  exactgeo::Mesh mesh;
  exactgeo::GeodesicSolver solver;
  std::mutex busy;
  std::uint64_t runs = 0;
};

// What `query` answers about run `run` (the caller's last), refused if the solver has run again since.
auto ask(Solver& self, std::uint64_t run, const auto& query) {
  nb::gil_scoped_release release;
  const std::lock_guard lock(self.busy);
  if (run != self.runs)
    throw std::runtime_error(
        "this GeodesicSolver has run again since this thread's solve() (from another thread): its answers "
        "would belong to that run. Use one GeodesicSolver per thread.");
  return query(self.solver);
}

// A path of run `run`, as ask() gets it.
nb::tuple trace(Solver& self, std::uint64_t run, const auto& query) {
  return path_arrays(ask(self, run, query), self.mesh);
}

// Single runs on meshes this large take long enough (tens of milliseconds and more) to be worth a worker
// thread that Ctrl-C can stop; smaller ones run on the calling thread, where that overhead would show.
constexpr std::size_t kInterruptibleVertices = 20000;

// What a run returns to Python: per vertex distance and nearest source, per target the same, statistics.
// `run(solver, options)` starts the run with the options it is given.
nb::tuple solve(Solver& self, exactgeo::GeodesicOptions options, const nb::object& progress, const auto& run) {
  std::vector<double> distances, target_distances;
  std::vector<std::int64_t> nearest, target_nearest;
  exactgeo::GeodesicStats stats;
  std::uint64_t run_number = 0;
  const auto copy_result = [&](const exactgeo::GeodesicResult& result) {
    // Copies: the solver keeps its result for path queries.
    distances = result.distances;
    target_distances = result.target_distances;
    nearest = signed_indices(result.nearest_source);
    target_nearest = signed_indices(result.target_nearest_source);
    stats = result.stats;
  };
  if (progress.is_none() && self.mesh.vertex_count() < kInterruptibleVertices) {
    nb::gil_scoped_release release;
    const std::lock_guard lock(self.busy);
    run_number = ++self.runs;  // before the run: a failed run invalidates the paths of the one before
    copy_result(run(self.solver, options));
  } else {
    run_interruptibly(progress, [&](std::stop_token stop, ProgressCounter& counter) {
      const std::lock_guard lock(self.busy);
      run_number = ++self.runs;
      // Progress in thousandths of the vertices the wavefront has passed.
      counter.total = 1000;
      self.solver.set_progress([&](double fraction) { counter.done = static_cast<std::size_t>(1000 * fraction); });
      options.stop = stop;
      try {
        copy_result(run(self.solver, options));
      } catch (...) {
        self.solver.set_progress({});
        throw;
      }
      self.solver.set_progress({});
      return true;
    });
  }
  const std::size_t vertices = distances.size(), targets = target_distances.size();
  return nb::make_tuple(to_numpy(std::move(distances), {vertices}), to_numpy(std::move(nearest), {vertices}),
                        to_numpy(std::move(target_distances), {targets}),
                        to_numpy(std::move(target_nearest), {targets}), nb::cast(stats), run_number);
}

}  // namespace

void register_solver(nb::module_& m) {
  nb::class_<Solver>(m, "GeodesicSolver")
      .def(nb::init<const exactgeo::Mesh&>(), "mesh"_a)
      .def(
          "solve_from_vertices",
          [](Solver& self, const IndexArray& sources, const IndexArray& target_faces,
             const PointArray& target_barycentric, const exactgeo::GeodesicOptions& options,
             const nb::object& progress) {
            const std::vector<exactgeo::SurfacePoint> targets = surface_points(target_faces, target_barycentric);
            return solve(self, options, progress,
                         [&](exactgeo::GeodesicSolver& solver,
                             const exactgeo::GeodesicOptions& run_options) -> const exactgeo::GeodesicResult& {
                           return solver.solve(span_of(sources), targets, run_options);
                         });
          },
          "sources"_a.noconvert(), "target_faces"_a.noconvert(), "target_barycentric"_a.noconvert(), "options"_a,
          "progress"_a.none())
      .def(
          "solve_from_points",
          [](Solver& self, const IndexArray& source_faces, const PointArray& source_barycentric,
             const IndexArray& target_faces, const PointArray& target_barycentric,
             const exactgeo::GeodesicOptions& options, const nb::object& progress) {
            const std::vector<exactgeo::SurfacePoint> sources = surface_points(source_faces, source_barycentric);
            const std::vector<exactgeo::SurfacePoint> targets = surface_points(target_faces, target_barycentric);
            return solve(self, options, progress,
                         [&](exactgeo::GeodesicSolver& solver,
                             const exactgeo::GeodesicOptions& run_options) -> const exactgeo::GeodesicResult& {
                           return solver.solve(sources, targets, run_options);
                         });
          },
          "source_faces"_a.noconvert(), "source_barycentric"_a.noconvert(), "target_faces"_a.noconvert(),
          "target_barycentric"_a.noconvert(), "options"_a, "progress"_a.none())
      .def(
          "path_to_vertex",
          [](Solver& self, std::uint32_t vertex, std::uint64_t run) {
            return trace(self, run,
                         [&](const exactgeo::GeodesicSolver& solver) { return solver.path_to_vertex(vertex); });
          },
          "vertex"_a, "run"_a)
      .def(
          "path_to_target",
          [](Solver& self, std::size_t target, std::uint64_t run) {
            return trace(self, run,
                         [&](const exactgeo::GeodesicSolver& solver) { return solver.path_to_target(target); });
          },
          "target"_a, "run"_a)
      .def(
          "distance_at",
          [](Solver& self, const IndexArray& faces, const PointArray& barycentric, std::uint64_t run) {
            const std::vector<exactgeo::SurfacePoint> points = surface_points(faces, barycentric);
            std::vector<double> distances =
                ask(self, run, [&](const exactgeo::GeodesicSolver& solver) { return solver.distance_at(points); });
            return to_numpy(std::move(distances), {points.size()});
          },
          "faces"_a.noconvert(), "barycentric"_a.noconvert(), "run"_a)
      .def(
          "path_to_point",
          [](Solver& self, const IndexArray& faces, const PointArray& barycentric, std::uint64_t run) {
            const std::vector<exactgeo::SurfacePoint> points = surface_points(faces, barycentric);
            if (points.size() != 1)
              throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument, "path_to_point takes one point");
            return trace(self, run,
                         [&](const exactgeo::GeodesicSolver& solver) { return solver.path_to_point(points[0]); });
          },
          "faces"_a.noconvert(), "barycentric"_a.noconvert(), "run"_a);
}

}  // namespace exactgeo::python
