// Exact geodesic distances on a triangle mesh with the VTP algorithm (Qin et al., SIGGRAPH 2016).
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "exactgeo/mesh.hpp"

namespace exactgeo {

enum class Algorithm {
  vtp,  // vertex-sorted wavefront, order-free secondary merge (the paper's final algorithm)
};

struct GeodesicOptions {
  Algorithm algorithm = Algorithm::vtp;
  // Paper Section 4.1, Rule 1 "One Angle Two Sides": prune with the window list's separating point.
  // Off: every window covering the opposite vertex is split in two, nothing pruned there.
  bool rule1 = true;
  // Paper Sections 4.2-4.3, Rules 2 and 3: pairwise checks between neighbouring windows of a list.
  bool rule23 = true;
};

struct GeodesicStats {
  std::uint64_t window_propagations = 0;  // one window across one triangle (a split counts twice)
  std::uint64_t peak_windows = 0;         // most windows alive at once
  std::uint64_t peak_window_bytes = 0;    // bytes of window storage at its largest (live and reusable)
  std::uint64_t vertex_pops = 0;          // wavefront vertices taken from the priority queue
  std::uint64_t pseudo_source_emissions = 0;  // saddle or boundary vertices that re-emitted windows
  double propagation_seconds = 0.0;       // wall time of the propagation
};

struct GeodesicResult {
  std::vector<double> distances;             // per input vertex; +inf where unreachable
  std::vector<std::uint32_t> nearest_source;  // per input vertex: index into the sources; UINT32_MAX if unreachable
  GeodesicStats stats;
};

inline constexpr std::uint32_t kNoSource = std::numeric_limits<std::uint32_t>::max();

// Distances from one source vertex (an input vertex index). Throws exactgeo::Error(invalid_argument)
// if the index is out of range or names a vertex used by no face.
GeodesicResult geodesic_distance(const Mesh& mesh, std::uint32_t source_vertex,
                                 const GeodesicOptions& options = {});

// Distances to the nearest of several source vertices, and which source that is.
GeodesicResult geodesic_distance(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                                 const GeodesicOptions& options = {});

}  // namespace exactgeo
