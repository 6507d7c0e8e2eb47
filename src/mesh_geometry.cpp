// Geometry steps of the mesh build (mesh_build.hpp): the scale frame, then per face its edge lengths,
// unfolding frames and corner angles, then per vertex, in one pass over its corners, its angle sum and
// pseudo-source flag and the walk around its fan. On the team; every sum runs in the order a single thread
// would take, so the geometry is the same bit for bit on any thread count.
#include <cmath>
#include <numbers>

#include "mesh_build.hpp"
#include "tolerances.hpp"

namespace exactgeo::detail {
namespace {

constexpr std::size_t kGeometryGrain = 1 << 12;

}  // namespace

void choose_scale(const ParallelTeam& team, SurfaceMesh& s) {
  const Box box = bounding_box(team, s.vertex_count, [&](std::size_t v) { return s.input_position(s.surface_to_input[v]); });
  // Half of each side: hi - lo itself may overflow (coordinates of both signs near the largest double).
  double half_extent = 0;
  for (int k = 0; k < 3; ++k) half_extent = std::max(half_extent, 0.5 * box.hi[k] - 0.5 * box.lo[k]);
  const int exponent = half_extent > 0 ? std::ilogb(half_extent) + 1 : 0;  // extent in [2^e, 2^(e+1)), about
  s.scale_exponent = std::abs(exponent) <= kOrdinaryScaleExponent ? 0 : -exponent;
  Vec3 scaled_lo, scaled_hi;
  for (int k = 0; k < 3; ++k) {
    scaled_lo[k] = std::ldexp(box.lo[k], s.scale_exponent);
    scaled_hi[k] = std::ldexp(box.hi[k], s.scale_exponent);
  }
  const double diagonal =
      std::hypot(scaled_hi[0] - scaled_lo[0], scaled_hi[1] - scaled_lo[1], scaled_hi[2] - scaled_lo[2]);
  s.length_scale = diagonal > 0 ? diagonal : 1.0;
}

MeshArray<std::uint8_t> compute_face_geometry(const ParallelTeam& team, SurfaceMesh& s) {
  const std::uint32_t face_count = s.face_count();
  s.halfedges.resize(3 * std::size_t{face_count});
  s.corner_angle.resize(3 * std::size_t{face_count});
  MeshArray<std::uint8_t> degenerate(face_count);
  // The faces in blocks of a fixed size, whatever the threads: each block sums its halfedges' lengths in
  // halfedge order, and the blocks' sums are added in block order, so the mean edge length (the band width
  // of parallel runs derives from it) is the same on any thread count, and no thread reads the halfedges
  // again to sum them alone.
  constexpr std::size_t kBlockFaces = 1 << 10;
  const std::size_t blocks = (std::size_t{face_count} + kBlockFaces - 1) / kBlockFaces;
  std::vector<double> block_length(blocks);
  std::vector<std::size_t> block_degenerate(blocks);
  team.for_ranges(blocks, kGeometryGrain / kBlockFaces, [&](std::size_t first_block, std::size_t last_block) {
    for (std::size_t b = first_block; b < last_block; ++b) {
      std::size_t degenerate_in_block = 0;
      double length_in_block = 0;
      for (std::size_t f = b * kBlockFaces; f < std::min<std::size_t>(face_count, (b + 1) * kBlockFaces); ++f) {
        const std::array<Vec3, 3> corner = {s.position(s.surface_to_input[s.corner_vertex[3 * f]]),
                                            s.position(s.surface_to_input[s.corner_vertex[3 * f + 1]]),
                                            s.position(s.surface_to_input[s.corner_vertex[3 * f + 2]])};
        double longest = 0;
        for (int i = 0; i < 3; ++i) {
          const Vec3 ab = sub(corner[(i + 1) % 3], corner[i]);
          const Vec3 ac = sub(corner[(i + 2) % 3], corner[i]);
          const double length = norm(ab);
          longest = std::max(longest, length);
          length_in_block += length;
          HalfedgeGeometry& g = s.halfedges[3 * f + i];
          g.length = length;
          if (length > 0) {
            g.apex_x = dot(ac, ab) / length;
            g.apex_y = norm(cross(ac, ab)) / length;
          } else {  // A and B coincide: place C straight above them, which keeps the unfolding consistent
            g.apex_x = 0;
            g.apex_y = norm(ac);
          }
          s.corner_angle[3 * f + i] = std::atan2(g.apex_y, g.apex_x);
        }
        const double doubled_area = norm(cross(sub(corner[1], corner[0]), sub(corner[2], corner[0])));
        degenerate[f] = doubled_area <= kDegenerateAreaRatio * longest * longest;
        degenerate_in_block += degenerate[f];
      }
      block_length[b] = length_in_block;
      block_degenerate[b] = degenerate_in_block;
    }
  });
  double total_length = 0;
  s.report.degenerate_faces = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    total_length += block_length[b];
    s.report.degenerate_faces += block_degenerate[b];
  }
  s.mean_edge_length = total_length / std::max(1.0, 3.0 * face_count);
  return degenerate;
}

void walk_vertices(const ParallelTeam& team, SurfaceMesh& s, const MeshArray<std::uint8_t>& degenerate) {
  const std::size_t corner_count = s.corner_vertex.size();
  s.fan_angles_reliable.resize(s.vertex_count);
  s.is_pseudo_source.resize(s.vertex_count);
  s.fan_angle_start.resize(corner_count);
  s.corner_enters_forward.resize(corner_count);
  s.fan_total_angle.resize(s.vertex_count);
  s.fan_closed.resize(s.vertex_count);
  s.report.saddle_vertices = team.count_if(s.vertex_count, kGeometryGrain, [&](std::size_t vertex) {
    const auto v = static_cast<std::uint32_t>(vertex);
    const std::uint32_t begin = s.vertex_corner_offsets[v], end = s.vertex_corner_offsets[v + 1];
    // Over the corners in increasing order (the order of the faces): the angle sum, whether the vertex is
    // on the boundary or on a degenerate face, and so whether geodesics may bend there; and where the walk
    // starts, at the first corner with a free edge, entering through it (a closed fan starts anywhere).
    double angle_sum = 0;
    bool on_boundary = false, near_degenerate = false;
    std::uint32_t start = s.vertex_corners[begin];
    bool start_forward = true;
    for (std::uint32_t i = begin; i < end; ++i) {
      const std::uint32_t c = s.vertex_corners[i];
      angle_sum += s.corner_angle[c];
      // The corner's halfedge leaves the vertex, the one before it arrives: on the boundary if either is.
      const bool leaving_free = s.twin[c] == kNone, arriving_free = s.twin[prev_halfedge(c)] == kNone;
      if (!on_boundary && (leaving_free || arriving_free)) {
        start = c;
        start_forward = leaving_free;
        on_boundary = true;
      }
      near_degenerate = near_degenerate || degenerate[face_of(c)];
    }
    const double full = on_boundary ? std::numbers::pi : 2 * std::numbers::pi;
    // A shortest path through a vertex leaves it at an angle of at least pi on both sides (interior) or on
    // the surface side (boundary), so it bends only where the angle sum exceeds 2*pi or pi.
    const bool bends = angle_sum > full + kSaddleAngleTolerance;
    s.is_pseudo_source[v] = bends || near_degenerate;
    s.fan_angles_reliable[v] = !near_degenerate;
    s.fan_closed[v] = !on_boundary;

    // Each corner has two edges at v and each edge one twin, so the walk meets no corner twice; it returns
    // how many it met.
    const auto walk = [&] {
      double walked = 0;
      std::uint32_t c = start, met = 0;
      bool forward = start_forward;
      for (std::uint32_t step = begin; step < end; ++step) {
        s.fan_angle_start[c] = walked;
        s.corner_enters_forward[c] = forward;
        walked += s.corner_angle[c];
        ++met;
        const std::uint32_t exit = forward ? prev_halfedge(c) : c;  // the corner's other edge at v
        const std::uint32_t across = s.twin[exit];
        if (across == kNone) break;
        // The corner of v beyond that edge is entered through it: forward if v is the twin's tail.
        forward = s.tail(across) == v;
        c = forward ? across : next_halfedge(across);
        if (c == start) break;
      }
      s.fan_total_angle[v] = walked;
      return met;
    };
    if (walk() != end - begin) {
      // A broken fan (around a degenerate face) leaves corners unreached: they take the defaults, and the
      // walk writes the reached ones again. Rare, so that the common fan writes each corner once.
      for (std::uint32_t i = begin; i < end; ++i) {
        s.fan_angle_start[s.vertex_corners[i]] = 0.0;
        s.corner_enters_forward[s.vertex_corners[i]] = 1;
      }
      walk();
    }
    return !on_boundary && bends;
  });
}

}  // namespace exactgeo::detail
