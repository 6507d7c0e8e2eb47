// Pairs: one goal-directed engine run per pair (vtp_engine.hpp, set_goal_directed; docs/pairs.md), the pairs
// spread over a team of threads, each thread with an engine of its own on the shared mesh.
#include "exactgeo/pairs.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "exactgeo/error.hpp"
#include "mesh_build.hpp"
#include "stop.hpp"
#include "surface_point.hpp"
#include "vtp_engine.hpp"
#include "worker_pool.hpp"

namespace exactgeo {

namespace {

// The pairs' points, located (and so checked) before any search starts.
std::vector<detail::LocatedPoint> locate_pair_points(const detail::SurfaceMesh& surface,
                                                     std::span<const SurfacePoint> points, const char* side) {
  std::vector<detail::LocatedPoint> located;
  located.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    located.push_back(detail::locate_checked(surface, points[i], std::string(side) + " " + std::to_string(i)));
  return located;
}

void check_same_length(std::size_t a, std::size_t b) {
  if (a != b)
    throw Error(ErrorCode::invalid_argument, "a and b must have the same length (a has " + std::to_string(a) +
                                                 " points, b " + std::to_string(b) + ")");
}

// The connected pieces (face_components) a point lies in: its face's, or at a vertex those of every copy of
// it, which a split vertex may have in several pieces.
std::vector<std::uint32_t> pieces_of(const detail::SurfaceMesh& surface, std::span<const std::uint32_t> piece_of_face,
                                     const detail::LocatedPoint& point) {
  if (point.vertex == detail::kNone) return {piece_of_face[point.face]};
  std::vector<std::uint32_t> pieces;
  for (const std::uint32_t copy : surface.copies_with(point.vertex))
    for (std::uint32_t i = surface.vertex_corner_offsets[copy]; i < surface.vertex_corner_offsets[copy + 1]; ++i)
      pieces.push_back(piece_of_face[detail::face_of(surface.vertex_corners[i])]);
  return pieces;
}

// Whether a path can join the two points at all. A search between pieces apart would otherwise cross the
// whole of the first one before it finds the second out of reach.
bool in_one_piece(const detail::SurfaceMesh& surface, std::span<const std::uint32_t> piece_of_face,
                  const detail::LocatedPoint& a, const detail::LocatedPoint& b) {
  const std::vector<std::uint32_t> of_a = pieces_of(surface, piece_of_face, a),
                                   of_b = pieces_of(surface, piece_of_face, b);
  return std::ranges::any_of(of_a, [&](std::uint32_t piece) { return std::ranges::find(of_b, piece) != of_b.end(); });
}

// One pair's search on `engine`: from `from` (a point at a corner is that input vertex, a source at each of
// its copies) to `to`. Its distance in the input's units, and its path if asked for.
double search_pair(const Mesh& mesh, detail::VtpEngine& engine, const detail::LocatedPoint& from,
                   const detail::LocatedPoint& to, const GeodesicOptions& options, GeodesicPath* path) {
  const detail::SurfaceMesh& surface = mesh.surface();
  std::vector<detail::SourceSite> sites;
  if (from.vertex != detail::kNone) {
    detail::add_vertex_sources(sites, surface.copies_with(from.vertex), 0);
  } else {
    sites.push_back({from, 0});
  }
  engine.run(sites, std::span(&to, 1), options);
  // As GeodesicSolver reads a target: at a vertex, the smallest distance over its copies.
  const double distance =
      to.vertex != detail::kNone
          ? engine.distances()[surface.nearest_copy(surface.surface_to_input[to.vertex], engine.distances())]
          : engine.target_distances()[0];
  if (!engine.answers(distance)) return HUGE_VAL;  // unreachable, or beyond max_distance
  if (path) {
    *path = detail::trace_to_target(mesh, engine, 0);
    path->source = 0;
  }
  return surface.to_input_length(distance);
}

}  // namespace

PairResult pair_distances(const Mesh& mesh, std::span<const SurfacePoint> a, std::span<const SurfacePoint> b,
                          const PairOptions& options) {
  check_same_length(a.size(), b.size());
  detail::check_options(options.geodesic);
  const detail::SurfaceMesh& surface = mesh.surface();
  const std::vector<detail::LocatedPoint> from = locate_pair_points(surface, a, "a");
  const std::vector<detail::LocatedPoint> to = locate_pair_points(surface, b, "b");

  PairResult result;
  result.distances.assign(a.size(), HUGE_VAL);
  if (options.return_paths) result.paths.assign(a.size(), GeodesicPath{});
  if (a.empty()) return result;
  // Pairs are spread over the threads; a search sharing threads too would only compete with the others.
  GeodesicOptions per_search = options.geodesic;
  per_search.threads = 1;
  const auto threads = static_cast<unsigned>(
      std::clamp<std::size_t>(detail::threads_or_cores(options.threads), 1, a.size()));
  detail::WorkerPool pool(threads);  // fewer threads if the system would not start them all
  std::vector<std::unique_ptr<detail::VtpEngine>> engines;
  for (unsigned t = 0; t < pool.threads(); ++t) {
    engines.push_back(std::make_unique<detail::VtpEngine>(surface));
    engines.back()->set_goal_directed(true);
  }
  // Labelled only where there is more than one piece: on one, every pair is in it.
  const std::vector<std::uint32_t> piece_of_face = mesh.report().components > 1
                                                       ? detail::face_components(detail::ParallelTeam{pool}, surface)
                                                       : std::vector<std::uint32_t>{};
  pool.run(a.size(), [&](std::size_t i, unsigned thread) {
    detail::throw_if_stopped(options.geodesic.stop);
    if (!piece_of_face.empty() && !in_one_piece(surface, piece_of_face, from[i], to[i])) return;  // stays +inf
    result.distances[i] = search_pair(mesh, *engines[thread], from[i], to[i], per_search,
                                      options.return_paths ? &result.paths[i] : nullptr);
  });
  return result;
}

PairResult pair_distances(const Mesh& mesh, std::span<const std::uint32_t> a, std::span<const std::uint32_t> b,
                          const PairOptions& options) {
  const auto as_points = [&](std::span<const std::uint32_t> vertices, const char* side) {
    std::vector<SurfacePoint> points;
    points.reserve(vertices.size());
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      try {
        points.push_back(vertex_point(mesh, vertices[i]));
      } catch (const Error& error) {
        throw Error(error.code(), std::string(side) + " " + std::to_string(i) + ": " + error.what());
      }
    }
    return points;
  };
  check_same_length(a.size(), b.size());
  return pair_distances(mesh, as_points(a, "a"), as_points(b, "b"), options);
}

}  // namespace exactgeo
