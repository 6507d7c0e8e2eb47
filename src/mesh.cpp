// The Mesh class: validation of the input arrays, then the build steps of mesh_build.hpp, timed one by one
// (see include/exactgeo/mesh.hpp for the policy and src/surface_mesh.hpp for the layout).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "exactgeo/error.hpp"
#include "exactgeo/mesh.hpp"
#include "mesh_build.hpp"
#include "surface_mesh.hpp"
#include "surface_point.hpp"

namespace exactgeo {
namespace detail {
namespace {

constexpr std::size_t kCheckGrain = 1 << 14;

// The first index in [0, count) where bad(i) holds, or count: the first element at fault, on any thread count.
template <class Bad>
std::size_t first_bad(const ParallelTeam& team, std::size_t count, Bad&& bad) {
  return team.reduce_ranges(
      count, kCheckGrain, count,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
          if (bad(i)) return i;
        return count;
      },
      [](std::size_t a, std::size_t b) { return std::min(a, b); });
}

void validate_arrays(const ParallelTeam& team, const std::vector<double>& positions,
                     const std::vector<std::uint32_t>& triangles) {
  if (positions.size() % 3 != 0)
    throw Error(ErrorCode::invalid_mesh, "positions array has " + std::to_string(positions.size()) +
                                             " values, not a multiple of 3");
  if (triangles.size() % 3 != 0)
    throw Error(ErrorCode::invalid_mesh, "triangles array has " + std::to_string(triangles.size()) +
                                             " indices, not a multiple of 3");
  // Halfedges and corners are numbered with 32-bit indices.
  if (triangles.size() > std::numeric_limits<std::uint32_t>::max())
    throw Error(ErrorCode::invalid_mesh, "mesh has " + std::to_string(triangles.size() / 3) +
                                             " triangles, more than 32-bit corner indices address (" +
                                             std::to_string(std::numeric_limits<std::uint32_t>::max() / 3) + ")");
  const std::size_t vertex_count = positions.size() / 3;
  const std::size_t bad_coordinate =
      first_bad(team, positions.size(), [&](std::size_t i) { return !std::isfinite(positions[i]); });
  if (bad_coordinate < positions.size())
    throw Error(ErrorCode::invalid_mesh, "vertex " + std::to_string(bad_coordinate / 3) + " has a non-finite coordinate");
  const std::size_t bad_index =
      first_bad(team, triangles.size(), [&](std::size_t i) { return triangles[i] >= vertex_count; });
  if (bad_index < triangles.size())
    throw Error(ErrorCode::invalid_mesh, "face " + std::to_string(bad_index / 3) + " names vertex " +
                                             std::to_string(triangles[bad_index]) + ", but the mesh has " +
                                             std::to_string(vertex_count) + " vertices");
  if (triangles.empty()) throw Error(ErrorCode::invalid_mesh, "mesh has no faces");
}

// The threads a build of `face_count` faces runs on.
unsigned build_threads(const MeshOptions& options, std::size_t face_count) {
  return threads_worth(options.threads, face_count, kFacesPerBuildThread);
}

// The build's steps in order, each timed into its field of MeshBuildStats, with the progress reported after
// each. The weights are the steps' shares of a build on one thread (the 1.6M-face subdivided nefertiti). The
// first step, timed with the validation, is take_input(team, surface): it fills input_positions and
// input_triangles, by a move or by copies made on the team.
template <class TakeInput>
std::shared_ptr<const SurfaceMesh> build_from(TakeInput&& take_input, const MeshOptions& options, unsigned threads,
                                              std::size_t grain) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto s = std::make_shared<SurfaceMesh>();
  MeshBuildStats& stats = s->build_stats;
  stats.threads = threads;
  WorkerPool pool(threads);
  const ParallelTeam team{pool, options.stop, grain};
  BuildState state;
  MeshReport& report = s->report;

  double done = 0;
  auto step_start = start;
  const auto step = [&](double MeshBuildStats::*seconds, double weight, auto&& run) {
    run();
    const auto now = Clock::now();
    stats.*seconds = std::chrono::duration<double>(now - step_start).count();
    step_start = now;
    done += weight;
    throw_if_stopped(options.stop);
    if (options.progress) options.progress(std::min(done, 1.0));
  };
  step(&MeshBuildStats::validate_seconds, 0.02, [&] {
    take_input(team, *s);
    validate_arrays(team, s->input_positions, s->input_triangles);
    report.vertices = s->input_positions.size() / 3;
    report.faces = s->input_triangles.size() / 3;
  });
  step(&MeshBuildStats::duplicate_positions_seconds, 0.08, [&] { find_duplicate_positions(team, *s, state); });
  step(&MeshBuildStats::faces_seconds, 0.12,
       [&] { drop_repeated_faces(team, *s, state, options.weld_duplicate_positions); });
  step(&MeshBuildStats::face_order_seconds, 0.12, [&] { order_faces_in_space(team, *s, state); });
  step(&MeshBuildStats::edges_seconds, 0.22, [&] { match_edges(team, *s, state); });
  step(&MeshBuildStats::vertices_seconds, 0.14, [&] {
    number_vertices(team, *s, state);
    if (report.non_manifold_edges > 0) join_cut_edges_between_same_copies(*s);
  });
  state = {};  // the surface holds everything the later steps read
  MeshArray<std::uint8_t> degenerate;
  step(&MeshBuildStats::geometry_seconds, 0.18, [&] {
    choose_scale(team, *s);
    degenerate = compute_face_geometry(team, *s);
  });
  step(&MeshBuildStats::fan_walk_seconds, 0.06, [&] {
    walk_vertices(team, *s, degenerate);
    list_vertices_on_sides(team, *s);
  });
  degenerate = {};
  step(&MeshBuildStats::components_seconds, 0.06, [&] { report.components = count_components(team, *s); });
  report.surface_vertices = s->vertex_count;
  stats.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return s;
}

}  // namespace

std::shared_ptr<const SurfaceMesh> build_surface(std::vector<double>&& positions,
                                                 std::vector<std::uint32_t>&& triangles, const MeshOptions& options,
                                                 unsigned threads, std::size_t grain) {
  return build_from(
      [&](const ParallelTeam&, SurfaceMesh& s) {
        s.input_positions = std::move(positions);
        s.input_triangles = std::move(triangles);
      },
      options, threads, grain);
}

std::shared_ptr<const SurfaceMesh> build_surface_from_copies(std::span<const double> positions,
                                                             std::span<const std::uint32_t> triangles,
                                                             const MeshOptions& options) {
  return build_from(
      [&](const ParallelTeam& team, SurfaceMesh& s) {
        s.input_positions = copy_on_team(team, positions);
        s.input_triangles = copy_on_team(team, triangles);
      },
      options, build_threads(options, triangles.size() / 3), 0);
}

double SurfaceMesh::to_input_length_scaled(double engine_length) const {
  const double length = std::ldexp(engine_length, -scale_exponent);
  if (std::isinf(length) && !std::isinf(engine_length)) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "a geodesic length of %.17g * 2^%d exceeds the largest double (%.17g): the mesh's coordinates "
                  "are too large to express its distances",
                  engine_length, -scale_exponent, std::numeric_limits<double>::max());
    throw Error(ErrorCode::invalid_mesh, text);
  }
  return length;
}

}  // namespace detail

Mesh::Mesh(std::span<const double> positions, std::span<const std::uint32_t> triangles, const MeshOptions& options)
    : surface_(detail::build_surface_from_copies(positions, triangles, options)) {}

Mesh::Mesh(MeshSoup&& soup, const MeshOptions& options)
    : surface_(detail::build_surface(std::move(soup.positions), std::move(soup.triangles), options,
                                     detail::build_threads(options, soup.triangles.size() / 3))) {}


std::size_t Mesh::vertex_count() const noexcept { return surface_->report.vertices; }
std::size_t Mesh::face_count() const noexcept { return surface_->report.faces; }
std::span<const double> Mesh::positions() const noexcept { return surface_->input_positions; }
std::span<const std::uint32_t> Mesh::triangles() const noexcept { return surface_->input_triangles; }
const MeshReport& Mesh::report() const noexcept { return surface_->report; }
const MeshBuildStats& Mesh::build_stats() const noexcept { return surface_->build_stats; }

}  // namespace exactgeo
