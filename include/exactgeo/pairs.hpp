// Exact geodesic distances between given pairs of points, each from its own search aimed at the pair's second
// point, which stops once nothing left can reach it shorter: a fraction of a full run (docs/pairs.md).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "exactgeo/export.hpp"
#include "exactgeo/geodesic.hpp"
#include "exactgeo/mesh.hpp"
#include "exactgeo/surface_point.hpp"

namespace exactgeo {

struct PairOptions {
  GeodesicOptions geodesic;   // per pair: algorithm, rules, max_distance (pairs farther apart get +inf) and stop;
                              // each search runs on one thread (its `threads` is not used: pairs are spread instead)
  unsigned threads = 0;       // worker threads the pairs are spread over; 0: one per core
  bool return_paths = false;  // also trace each pair's shortest path
};

struct PairResult {
  // Per pair i: the geodesic distance from a[i] to b[i], +inf where b[i] cannot be reached from a[i] (another
  // piece of the mesh) or lies beyond max_distance. The same on any thread count, bit for bit, and equal to
  // a run from a[i] with b[i] as its target to within 1e-14 of the distance.
  std::vector<double> distances;
  // With return_paths, per pair: a shortest path from a[i] to b[i] (`source` is 0, the pair's one source;
  // empty where the distance is +inf); empty otherwise.
  std::vector<GeodesicPath> paths;
};

// Distances between a[i] and b[i] for every i. A point at a corner is that input vertex (GeodesicSolver::solve).
// Throws exactgeo::Error(invalid_argument) before any work if a and b differ in length, or naming the point
// ("a 3", "b 0") or option at fault.
EXACTGEO_API PairResult pair_distances(const Mesh& mesh, std::span<const SurfacePoint> a,
                                       std::span<const SurfacePoint> b, const PairOptions& options = {});
// The same between input vertices.
EXACTGEO_API PairResult pair_distances(const Mesh& mesh, std::span<const std::uint32_t> a,
                                       std::span<const std::uint32_t> b, const PairOptions& options = {});

}  // namespace exactgeo
