// Work over many sources or pairs, interruptible and with progress: distance matrices (dense, written into
// the caller's array, or sparse), distances between pairs of points, farthest-point sampling.
#include <nanobind/nanobind.h>
#include <nanobind/stl/tuple.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <stop_token>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "interruption.hpp"
#include "marshalling.hpp"
#include "registration.hpp"

using namespace nb::literals;

namespace exactgeo::python {

void register_many_sources(nb::module_& m) {
  // Matrix options from the arguments: columns are the targets when has_targets, else every vertex.
  const auto matrix_options = [](const exactgeo::GeodesicOptions& options, unsigned threads, const IndexArray& targets,
                                 bool has_targets) {
    exactgeo::MatrixOptions matrix{.geodesic = options, .threads = threads};
    if (has_targets) matrix.target_vertices.emplace(span_of(targets).begin(), span_of(targets).end());
    return matrix;
  };

  // The dense matrix written into `out` (sources x columns, float64, or float32: each distance rounded to
  // nearest) as the library hands over its blocks of a few rows: no other copy of the matrix is made, so a
  // float32 matrix never exists as float64 in full.
  using MatrixArray = nb::ndarray<nb::ndim<2>, nb::c_contig, nb::device::cpu>;
  m.def(
      "fill_distance_matrix",
      [matrix_options](const exactgeo::Mesh& mesh, const IndexArray& sources, const IndexArray& targets,
                       bool has_targets, exactgeo::GeodesicOptions options, unsigned threads, const MatrixArray& out,
                       const nb::object& progress) {
        const std::size_t columns = has_targets ? targets.shape(0) : mesh.vertex_count();
        if (out.shape(0) != sources.shape(0) || out.shape(1) != columns)
          throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument,
                                "out has shape (" + std::to_string(out.shape(0)) + ", " + std::to_string(out.shape(1)) +
                                    "), not (" + std::to_string(sources.shape(0)) + ", " + std::to_string(columns) +
                                    ")");
        const auto fill = [&](auto* values) {
          run_interruptibly(progress, [&](std::stop_token stop, ProgressCounter& counter) {
            options.stop = stop;
            counter.total = sources.shape(0);
            exactgeo::for_each_distance_block(
                mesh, span_of(sources), matrix_options(options, threads, targets, has_targets),
                [&](std::size_t first, std::span<const double> block) {
                  using Value = std::remove_pointer_t<decltype(values)>;
                  std::transform(block.begin(), block.end(), values + first * columns,
                                 [](double distance) { return static_cast<Value>(distance); });
                  counter.done = first + (columns ? block.size() / columns : 0);
                });
            return true;
          });
        };
        if (out.dtype() == nb::dtype<double>())
          fill(static_cast<double*>(out.data()));
        else if (out.dtype() == nb::dtype<float>())
          fill(static_cast<float*>(out.data()));
        else
          throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument, "out must hold float64 or float32 values");
      },
      "mesh"_a, "sources"_a.noconvert(), "targets"_a.noconvert(), "has_targets"_a, "options"_a, "threads"_a,
      "out"_a.noconvert(), "progress"_a.none());

  // The finite entries as compressed sparse rows: values, column indices and row offsets.
  m.def(
      "sparse_distance_matrix",
      [matrix_options](const exactgeo::Mesh& mesh, const IndexArray& sources, const IndexArray& targets,
                       bool has_targets, exactgeo::GeodesicOptions options, unsigned threads,
                       const nb::object& progress) {
        const std::size_t rows = sources.shape(0);
        exactgeo::CompressedSparseRows matrix;
        run_interruptibly(progress, [&](std::stop_token stop, ProgressCounter& counter) {
          options.stop = stop;
          counter.total = rows;
          exactgeo::for_each_sparse_block(mesh, span_of(sources),
                                          matrix_options(options, threads, targets, has_targets),
                                          [&](std::size_t first, const exactgeo::SparseDistances& block) {
                                            exactgeo::append_rows(matrix, block);
                                            counter.done = first + block.rows;
                                          });
          return true;
        });
        const std::size_t entries = matrix.data.size();
        return std::make_tuple(to_numpy(std::move(matrix.data), {entries}),
                               to_numpy(std::move(matrix.indices), {entries}),
                               to_numpy(std::move(matrix.indptr), {rows + 1}));
      },
      "mesh"_a, "sources"_a.noconvert(), "targets"_a.noconvert(), "has_targets"_a, "options"_a, "threads"_a,
      "progress"_a.none());

  // Distances (and paths) between pairs of points, each from a search of its own, on `threads` threads.
  m.def(
      "pair_distances",
      [](const exactgeo::Mesh& mesh, const IndexArray& a_faces, const PointArray& a_barycentric,
         const IndexArray& b_faces, const PointArray& b_barycentric, exactgeo::GeodesicOptions options,
         unsigned threads, bool return_paths) {
        const std::vector<exactgeo::SurfacePoint> a = surface_points(a_faces, a_barycentric);
        const std::vector<exactgeo::SurfacePoint> b = surface_points(b_faces, b_barycentric);
        exactgeo::PairResult result = run_interruptibly(nb::none(), [&](std::stop_token stop, ProgressCounter&) {
          options.stop = stop;
          return exactgeo::pair_distances(mesh, a, b,
                                          {.geodesic = options, .threads = threads, .return_paths = return_paths});
        });
        nb::list paths;
        for (const exactgeo::GeodesicPath& path : result.paths) paths.append(path_arrays(path, mesh));
        const std::size_t n = result.distances.size();
        return std::make_tuple(to_numpy(std::move(result.distances), {n}), paths);
      },
      "mesh"_a, "a_faces"_a.noconvert(), "a_barycentric"_a.noconvert(), "b_faces"_a.noconvert(),
      "b_barycentric"_a.noconvert(), "options"_a, "threads"_a, "return_paths"_a);

  m.def(
      "farthest_point_sampling",
      [](const exactgeo::Mesh& mesh, std::size_t count, const IndexArray& first, exactgeo::GeodesicOptions options,
         const nb::object& progress) {
        exactgeo::Sampling sampling = run_interruptibly(progress, [&](std::stop_token stop, ProgressCounter& counter) {
          options.stop = stop;
          counter.total = count;
          return exactgeo::farthest_point_sampling(mesh, count, span_of(first), options,
                                                   [&](std::size_t taken) { counter.done = taken; });
        });
        std::vector<std::int64_t> samples(sampling.samples.begin(), sampling.samples.end());
        std::vector<std::int64_t> nearest = signed_indices(sampling.nearest_sample);
        const std::size_t taken = samples.size(), vertices = nearest.size();
        return std::make_tuple(to_numpy(std::move(samples), {taken}), to_numpy(std::move(sampling.radii), {taken}),
                               to_numpy(std::move(sampling.distances), {vertices}),
                               to_numpy(std::move(nearest), {vertices}));
      },
      "mesh"_a, "count"_a, "first"_a.noconvert(), "options"_a, "progress"_a.none());
}

}  // namespace exactgeo::python
