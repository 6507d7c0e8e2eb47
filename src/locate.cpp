// exactgeo::locate: the closest surface point of points in space, searched in the mesh's face hierarchy
// (face_bvh.hpp) on a thread team, one point at a time.
#include <algorithm>
#include <cmath>
#include <string>

#include "exactgeo/error.hpp"
#include "exactgeo/surface_point.hpp"
#include "face_bvh.hpp"
#include "parallel.hpp"
#include "worker_pool.hpp"

namespace exactgeo {
namespace detail {
namespace {

// Points per thread at least: below that, starting a thread costs more than its share of the searches.
constexpr std::size_t kPointsPerThread = 4096;
constexpr std::size_t kPointGrain = 256;

// How far from the mesh's centre, in half extents of the mesh, a point is searched from; a point farther away
// is searched from this far along the same direction. As a point recedes along a direction, its closest
// point moves by about extent^2 / distance, here 2^-26 of the extent, while squared distances tell points of
// the surface apart only to about 2^-53 of the distance, here 2^-27 of the extent: the two errors balance.
// Farther out, rounding would pick the point ever less precisely (from 2^53 extents away, anywhere on the
// surface), and then squares overflow.
constexpr double kFarthestSearch = 0x1p27;

// The point to search from, in the engine's frame (see kFarthestSearch), for a mesh whose box has this centre
// and half extent there.
Vec3 search_point(const SurfaceMesh& mesh, const Vec3& center, double half_extent, const Vec3& point) {
  // The offset from the centre in the input's units, halved so that it cannot overflow.
  Vec3 half_offset;
  double largest = 0;
  for (int k = 0; k < 3; ++k) {
    half_offset[k] = 0.5 * point[k] - 0.5 * std::ldexp(center[k], -mesh.scale_exponent);
    largest = std::max(largest, std::abs(half_offset[k]));
  }
  Vec3 search;
  const double farthest = kFarthestSearch * half_extent;
  if (std::ldexp(largest, mesh.scale_exponent + 1) <= farthest) {
    for (int k = 0; k < 3; ++k) search[k] = std::ldexp(point[k], mesh.scale_exponent);
  } else {
    for (int k = 0; k < 3; ++k) search[k] = center[k] + farthest * (half_offset[k] / largest);
  }
  return search;
}

}  // namespace
}  // namespace detail

LocateResult locate(const Mesh& mesh, std::span<const double> xyz, const LocateOptions& options) {
  using namespace detail;
  const SurfaceMesh& s = mesh.surface();
  if (xyz.size() % 3 != 0)
    throw Error(ErrorCode::invalid_argument,
                "xyz has " + std::to_string(xyz.size()) + " values, not a multiple of 3 (x, y, z per point)");
  const std::size_t count = xyz.size() / 3;
  for (std::size_t i = 0; i < xyz.size(); ++i)
    if (!std::isfinite(xyz[i]))
      throw Error(ErrorCode::invalid_argument, "point " + std::to_string(i / 3) + " has a non-finite coordinate");
  LocateResult result;
  result.points.resize(count);
  result.distances.resize(count);
  if (count == 0) return result;

  const FaceBvh& bvh = face_bvh(s, options.threads);
  const FaceBvhNode& root = bvh.nodes[0];
  Vec3 center;
  double half_extent = 0;
  for (int k = 0; k < 3; ++k) {
    center[k] = 0.5 * root.lo[k] + 0.5 * root.hi[k];
    half_extent = std::max(half_extent, 0.5 * root.hi[k] - 0.5 * root.lo[k]);
  }
  WorkerPool pool(threads_worth(options.threads, count, kPointsPerThread));
  ParallelTeam{pool}.for_each(count, kPointGrain, [&](std::size_t i) {
    const Vec3 point = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
    const SurfaceClosestPoint closest = closest_surface_point(bvh, search_point(s, center, half_extent, point));
    result.points[i] = {closest.input_face, closest.point.barycentric};
    // The distance in the input's units, from the point as given (the search may have started elsewhere):
    // not finite only where it exceeds the largest double (NaN where a coordinate of the offset overflowed:
    // libstdc++'s hypot divides it by itself).
    std::array<Vec3, 3> corners;
    for (int k = 0; k < 3; ++k)
      corners[k] = s.input_position(s.input_triangles[3 * std::size_t{closest.input_face} + k]);
    const Vec3 offset = sub(point, point_at(corners, closest.point.barycentric));
    result.distances[i] = std::hypot(offset[0], offset[1], offset[2]);
  });
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(result.distances[i]))
      throw Error(ErrorCode::invalid_argument,
                  "point " + std::to_string(i) + " is farther from the surface than the largest double");
  return result;
}

}  // namespace exactgeo
