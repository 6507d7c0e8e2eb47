// Connectivity steps of the mesh build (mesh_build.hpp): duplicate positions and faces, the spatial order of
// faces and vertices, twins, fans and components. Matching is done by grouping (counting sorts on the
// team, parallel.hpp) rather than hash maps, and no step is quadratic in a vertex's valence: wherever a
// group may be large it is sorted, and only groups of a few items are compared pairwise.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <numeric>
#include <string>

#include "exactgeo/error.hpp"
#include "mesh_build.hpp"
#include "same_position.hpp"

namespace exactgeo::detail {
namespace {

// Items per range of the passes below: a few microseconds of work each.
constexpr std::size_t kTopologyGrain = 1 << 13;

// Spreads the low 21 bits of x so that two zero bits follow each (bit i moves to bit 3i).
std::uint64_t spread_bits(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffff;
  x = (x | x << 16) & 0x1f0000ff0000ff;
  x = (x | x << 8) & 0x100f00f00f00f00f;
  x = (x | x << 4) & 0x10c30c30c30c30c3;
  x = (x | x << 2) & 0x1249249249249249;
  return x;
}

// The items [0, count) in Morton (Z-curve) order of point_of(item) over their bounding box, ties in order of
// tie_of(item) (distinct per item). The engine numbers faces and vertices this way: a propagation touches
// the faces and vertices around the wavefront, and near each other in space they are then near each other
// in memory. On the scans we hold that is 9-15% of a propagation against their files' own order; a mesh
// stored in random order ran 29% slower than in its file's. Sorted by grouping on the codes' high bits, then
// each group on its own.
template <class PointOf, class TieOf>
MeshArray<std::uint32_t> spatial_order(const ParallelTeam& team, std::size_t count, PointOf&& point_of,
                                         TieOf&& tie_of) {
  const Box box = bounding_box(team, count, point_of);
  constexpr double kCells = (1 << 21) - 1;
  MeshArray<std::uint64_t> code(count);
  team.for_each(count, kTopologyGrain, [&](std::size_t i) {
    const Vec3 p = point_of(i);
    std::uint64_t c = 0;
    for (int k = 0; k < 3; ++k) {
      // Halved, so that no difference overflows; a flat box side (0 / 0) gives NaN, taken as 0.
      const double t = (0.5 * p[k] - 0.5 * box.lo[k]) / (0.5 * box.hi[k] - 0.5 * box.lo[k]);
      const double cell = t > 0 ? std::min(t, 1.0) * kCells : 0.0;
      c |= spread_bits(static_cast<std::uint64_t>(cell)) << k;
    }
    code[i] = c;
  });
  const int bits = group_bits(count);
  Groups groups = group_by_key(team, count, std::size_t{1} << bits,
                               [&](std::size_t i) { return bits == 0 ? 0 : code[i] >> (63 - bits); });
  const std::size_t group_count = groups.offsets.size() - 1;
  team.for_ranges(group_count, kTopologyGrain, [&](std::size_t first, std::size_t last) {
    for (std::size_t g = first; g < last; ++g) {
      if (groups.size(g) < 2) continue;
      std::sort(groups.items.data() + groups.offsets[g], groups.items.data() + groups.offsets[g + 1],
                [&](std::uint32_t a, std::uint32_t b) {
                  return code[a] != code[b] ? code[a] < code[b] : tie_of(a) < tie_of(b);
                });
    }
  });
  return std::move(groups.items);
}

// The three vertices of a face in increasing order: equal for faces with the same vertex set.
using VertexSet = std::array<std::uint32_t, 3>;

}  // namespace

void find_duplicate_positions(const ParallelTeam& team, SurfaceMesh& s, BuildState& state) {
  const std::size_t vertex_count = s.input_positions.size() / 3;
  state.same_position = first_at_same_position(
      team, vertex_count, [&](std::size_t v) { return s.input_position(static_cast<std::uint32_t>(v)); });
  s.report.duplicate_positions =
      team.count_if(vertex_count, kTopologyGrain, [&](std::size_t v) { return state.same_position[v] != v; });
}

void drop_repeated_faces(const ParallelTeam& team, SurfaceMesh& s, BuildState& state, bool weld) {
  const std::vector<std::uint32_t>& triangles = s.input_triangles;
  const std::size_t face_count = triangles.size() / 3, vertex_count = s.input_positions.size() / 3;
  MeshReport& report = s.report;
  const auto vertex_set = [&](std::size_t f) {
    VertexSet v = {triangles[3 * f], triangles[3 * f + 1], triangles[3 * f + 2]};
    if (weld)
      for (auto& x : v) x = state.same_position[x];
    // Three compare-and-swaps: std::sort's loop costs several times more on three items.
    if (v[0] > v[1]) std::swap(v[0], v[1]);
    if (v[1] > v[2]) std::swap(v[1], v[2]);
    if (v[0] > v[1]) std::swap(v[0], v[1]);
    return v;
  };
  // A face with the same three vertices as a kept one (a double-sided export, say) would make each of its
  // edges an edge of four faces, which the policy cuts: it is dropped instead, and points on it are located
  // on the kept face. first_face[f]: the first face with f's vertex set, kNone if f repeats a vertex.
  MeshArray<std::uint32_t> first_face(face_count);
  {
    const Groups by_lowest = group_by_key(team, face_count, vertex_count,
                                          [&](std::size_t f) { return vertex_set(f)[0]; });
    team.for_ranges(vertex_count, kTopologyGrain, [&](std::size_t first, std::size_t last) {
      std::vector<std::pair<VertexSet, std::uint32_t>> sorted;
      std::array<VertexSet, kPairwiseGroupSize> sets;
      for (std::size_t g = first; g < last; ++g) {
        const std::uint32_t* faces = by_lowest.begin(g);
        const std::size_t n = by_lowest.size(g);
        if (n <= kPairwiseGroupSize) {
          for (std::size_t j = 0; j < n; ++j) {
            const VertexSet& v = sets[j] = vertex_set(faces[j]);
            first_face[faces[j]] = v[0] == v[1] || v[1] == v[2] ? kNone : faces[j];
            if (first_face[faces[j]] == kNone) continue;
            for (std::size_t i = 0; i < j; ++i)
              if (sets[i] == v && first_face[faces[i]] != kNone) {
                first_face[faces[j]] = faces[i];
                break;
              }
          }
          continue;
        }
        sorted.clear();
        for (const std::uint32_t* f = faces; f != by_lowest.end(g); ++f) {
          const VertexSet v = vertex_set(*f);
          first_face[*f] = *f;
          if (v[0] == v[1] || v[1] == v[2])
            first_face[*f] = kNone;
          else
            sorted.push_back({v, *f});
        }
        std::sort(sorted.begin(), sorted.end());
        for (std::size_t i = 0; i < sorted.size();) {
          std::size_t j = i;
          for (; j < sorted.size() && sorted[j].first == sorted[i].first; ++j) first_face[sorted[j].second] = sorted[i].second;
          i = j;
        }
      }
    });
  }
  // Kept faces are numbered in input order.
  MeshArray<std::uint32_t> kept_index(face_count);
  team.for_each(face_count, kTopologyGrain, [&](std::size_t f) { kept_index[f] = first_face[f] == f; });
  report.faces_used = exclusive_prefix_sum(team, kept_index);
  report.faces_repeating_a_vertex = team.count_if(face_count, kTopologyGrain, [&](std::size_t f) { return first_face[f] == kNone; });
  report.duplicate_faces = face_count - report.faces_used - report.faces_repeating_a_vertex;
  if (report.faces_used == 0)
    throw Error(ErrorCode::invalid_mesh, "mesh has no usable face: all " + std::to_string(report.faces) +
                                             " faces repeat a vertex");

  MeshArray<std::uint8_t> used(vertex_count, 0);
  s.input_face_to_surface.resize(face_count);
  s.surface_face_to_input.resize(report.faces_used);
  state.corner_input_vertex.resize(3 * report.faces_used);
  team.for_each(face_count, kTopologyGrain, [&](std::size_t f) {
    const std::uint32_t first = first_face[f];
    s.input_face_to_surface[f] = first == kNone ? kNone : kept_index[first];
    if (first != f) return;
    const std::uint32_t k = kept_index[f];
    s.surface_face_to_input[k] = static_cast<std::uint32_t>(f);
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t v = triangles[3 * f + i];
      state.corner_input_vertex[3 * std::size_t{k} + i] = weld ? state.same_position[v] : v;
      std::atomic_ref(used[v]).store(1, std::memory_order_relaxed);  // other faces may mark it at once
    }
  });
  report.unreferenced_vertices = team.count_if(vertex_count, kTopologyGrain, [&](std::size_t v) { return !used[v]; });
  if (weld) {
    s.canonical_input.assign(state.same_position.begin(), state.same_position.end());
    report.welded_vertices = team.count_if(vertex_count, kTopologyGrain, [&](std::size_t v) { return s.canonical_input[v] != v; });
  }
}

void order_faces_in_space(const ParallelTeam& team, SurfaceMesh& s, BuildState& state) {
  MeshArray<std::uint32_t>& corners = state.corner_input_vertex;
  const std::size_t face_count = corners.size() / 3;
  MeshArray<Vec3> centroids(face_count);
  team.for_each(face_count, kTopologyGrain, [&](std::size_t f) {
    const double* a = s.input_positions.data() + 3 * std::size_t{corners[3 * f]};
    const double* b = s.input_positions.data() + 3 * std::size_t{corners[3 * f + 1]};
    const double* c = s.input_positions.data() + 3 * std::size_t{corners[3 * f + 2]};
    // Thirds summed (no overflow) in corner order from +0, as the face order has always summed them; the
    // corners read once, not once per coordinate.
    for (int k = 0; k < 3; ++k) centroids[f][k] = 0.0 + a[k] / 3 + b[k] / 3 + c[k] / 3;
  });
  const MeshArray<std::uint32_t> order = spatial_order(
      team, face_count, [&](std::size_t f) { return centroids[f]; }, [](std::size_t f) { return f; });
  centroids = {};
  MeshArray<std::uint32_t> ordered_corners(corners.size()), face_to_input(face_count), renumbered(face_count);
  team.for_each(face_count, kTopologyGrain, [&](std::size_t f) {
    const std::uint32_t old = order[f];
    std::copy_n(corners.begin() + 3 * std::ptrdiff_t{old}, 3, ordered_corners.begin() + 3 * std::ptrdiff_t(f));
    face_to_input[f] = s.surface_face_to_input[old];
    renumbered[old] = static_cast<std::uint32_t>(f);
  });
  corners = std::move(ordered_corners);
  s.surface_face_to_input = std::move(face_to_input);
  team.for_each(s.input_face_to_surface.size(), kTopologyGrain, [&](std::size_t f) {
    std::uint32_t& surface_face = s.input_face_to_surface[f];
    if (surface_face != kNone) surface_face = renumbered[surface_face];
  });
}

void match_edges(const ParallelTeam& team, SurfaceMesh& s, BuildState& state) {
  const MeshArray<std::uint32_t>& corners = state.corner_input_vertex;
  const std::size_t corner_count = corners.size(), vertex_count = s.input_positions.size() / 3;
  state.corners_of_input_vertex = group_by_keys(team, corners, vertex_count);
  const Groups& corners_of = state.corners_of_input_vertex;
  // Filled on the team: one thread filling fresh memory pays its first touch alone (populate_on_team).
  s.twin.resize(corner_count);
  team.for_each(corner_count, kTopologyGrain, [&](std::size_t h) { s.twin[h] = kNone; });
  s.corner_vertex.resize(corner_count);
  state.fan_count.resize(vertex_count);
  team.for_each(vertex_count, kTopologyGrain, [&](std::size_t v) { state.fan_count[v] = 0; });
  struct EdgeCounts {
    std::size_t zero_length = 0, boundary = 0, non_manifold = 0;
  };
  // Each vertex v on its own: the halfedges at its corners (the corner's own, leaving v, and the one before
  // it, arriving) by their other end. An edge with exactly two faces joins the corners of v in them (one
  // fan); it is paired into twins, and counted, at its lower end only. Nothing is read across an edge, so
  // each vertex touches only its own faces.
  const EdgeCounts counts = team.reduce_ranges(
      vertex_count, kTopologyGrain, EdgeCounts{},
      [&](std::size_t first, std::size_t last) {
        EdgeCounts c;
        // A side is coded as the corner's place among v's corners (its slot) times two, plus one for the
        // arriving halfedge. Sides are grouped by their other end; what a group does does not depend on the
        // order of the groups or of the sides in them (the fans' union-find keeps each set's smallest slot
        // as root), so both ways of grouping below give the same result.
        const auto slot_of = [](std::uint32_t side) { return side >> 1; };
        std::vector<std::uint32_t> parent, fan_of_slot;
        const auto find = [&](std::uint32_t x) {
          while (parent[x] != x) x = parent[x] = parent[parent[x]];
          return x;
        };
        // Up to kHashedCorners corners (nearly every vertex), sides are grouped in a small open-addressing
        // table, stamped with the vertex so that it is never cleared: the step took 868 instructions per face
        // with sorting, 741 so (callgrind, nefertiti). More corners are sorted, so that no vertex is quadratic.
        constexpr std::uint32_t kHashedCorners = 16, kTableBits = 6;  // a table at most half full
        struct SideGroup {
          std::uint64_t stamp = 0;  // v + 1 while the group belongs to vertex v
          std::uint32_t other = 0, count = 0, first_side = 0, second_side = 0;
        };
        std::array<SideGroup, std::size_t{1} << kTableBits> table{};
        std::array<std::uint32_t, 2 * kHashedCorners> group_at{};  // the table's groups, in the order met
        std::vector<std::uint64_t> sorted_sides;                   // other end (high half), side (low half)
        for (std::size_t v = first; v < last; ++v) {
          const std::uint32_t* begin = corners_of.begin(v);
          const auto n = static_cast<std::uint32_t>(corners_of.size(v));
          if (n == 0) continue;
          // The halfedge of a side: the corner's own (leaving v) or the one before it (arriving).
          const auto halfedge_of = [&](std::uint32_t side) {
            const std::uint32_t leaving = begin[slot_of(side)];
            return side & 1 ? prev_halfedge(leaving) : leaving;
          };
          // The other end of each side: the head of the leaving halfedge, the tail of the arriving one.
          const auto other_end = [&](std::uint32_t side) {
            const std::uint32_t leaving = begin[slot_of(side)];
            return corners[side & 1 ? prev_halfedge(leaving) : next_halfedge(leaving)];
          };
          parent.resize(n);
          std::iota(parent.begin(), parent.end(), 0u);
          // An edge of v with `count` sides at v, two of them `a` and `b` when count is 2. A vertex is on no
          // face twice (such faces are dropped), so n < 2^31 and the side codes fit 32 bits.
          const auto settle_edge = [&](std::uint32_t other, std::uint32_t count, std::uint32_t a, std::uint32_t b) {
            if (count == 2) {
              const std::uint32_t x = find(slot_of(a)), y = find(slot_of(b));
              parent[std::max(x, y)] = std::min(x, y);
            }
            if (other <= v) return;
            c.zero_length += state.same_position[v] == state.same_position[other];
            if (count == 1) {
              ++c.boundary;
            } else if (count == 2) {
              const std::uint32_t h = halfedge_of(a), t = halfedge_of(b);
              s.twin[h] = t;
              s.twin[t] = h;
            } else {
              ++c.non_manifold;
            }
          };
          if (n <= kHashedCorners) {
            const std::uint64_t stamp = v + 1;
            std::uint32_t groups = 0;
            for (std::uint32_t side = 0; side < 2 * n; ++side) {
              const std::uint32_t other = other_end(side);
              std::uint32_t at = (other * 0x9e3779b1u) >> (32 - kTableBits);
              while (table[at].stamp == stamp && table[at].other != other) at = (at + 1) & ((1u << kTableBits) - 1);
              SideGroup& group = table[at];
              if (group.stamp != stamp) {
                group = {stamp, other, 1, side, 0};
                group_at[groups++] = at;
              } else if (++group.count == 2) {
                group.second_side = side;
              }
            }
            for (std::uint32_t g = 0; g < groups; ++g) {
              const SideGroup& group = table[group_at[g]];
              settle_edge(group.other, group.count, group.first_side, group.second_side);
            }
          } else {
            sorted_sides.resize(2 * std::size_t{n});
            for (std::uint32_t side = 0; side < 2 * n; ++side)
              sorted_sides[side] = std::uint64_t{other_end(side)} << 32 | side;
            std::sort(sorted_sides.begin(), sorted_sides.end());
            for (std::size_t i = 0; i < sorted_sides.size();) {
              const auto other = static_cast<std::uint32_t>(sorted_sides[i] >> 32);
              std::size_t j = i;
              while (j < sorted_sides.size() && sorted_sides[j] >> 32 == other) ++j;
              settle_edge(other, static_cast<std::uint32_t>(j - i), static_cast<std::uint32_t>(sorted_sides[i]),
                          j - i > 1 ? static_cast<std::uint32_t>(sorted_sides[i + 1]) : 0);
              i = j;
            }
          }
          // Fans are numbered by their first corner (a set's root is its smallest slot, met before the
          // others); corner_vertex holds each corner's fan number within its vertex until number_vertices
          // replaces it by the surface vertex.
          fan_of_slot.resize(n);
          std::uint32_t fans = 0;
          for (std::uint32_t i = 0; i < n; ++i) {
            const std::uint32_t root = find(i);
            fan_of_slot[i] = root == i ? fans++ : fan_of_slot[root];
            s.corner_vertex[begin[i]] = fan_of_slot[i];
          }
          state.fan_count[v] = fans;
        }
        return c;
      },
      [](EdgeCounts x, const EdgeCounts& y) {
        return EdgeCounts{x.zero_length + y.zero_length, x.boundary + y.boundary, x.non_manifold + y.non_manifold};
      });
  s.report.zero_length_edges = counts.zero_length;
  s.report.boundary_edges = counts.boundary;
  s.report.non_manifold_edges = counts.non_manifold;
}

void number_vertices(const ParallelTeam& team, SurfaceMesh& s, BuildState& state) {
  const std::size_t corner_count = state.corner_input_vertex.size(), vertex_count = s.input_positions.size() / 3;
  const Groups& corners_of = state.corners_of_input_vertex;
  const MeshArray<std::uint32_t>& fan_count = state.fan_count;
  // Surface vertices are numbered in spatial order of their input vertices, the copies of one input vertex
  // by first corner. Only the vertices of kept faces count: an unreferenced vertex far away would stretch
  // the box. Ties of position go to the vertex met first in the faces.
  MeshArray<std::uint32_t> used(vertex_count);
  team.for_each(vertex_count, kTopologyGrain, [&](std::size_t v) { used[v] = fan_count[v] > 0; });
  const std::size_t used_count = exclusive_prefix_sum(team, used);
  MeshArray<std::uint32_t> used_vertices(used_count);
  team.for_each(vertex_count, kTopologyGrain, [&](std::size_t v) {
    if (fan_count[v] > 0) used_vertices[used[v]] = static_cast<std::uint32_t>(v);
  });
  used = {};
  MeshArray<std::uint32_t> order = spatial_order(
      team, used_count, [&](std::size_t i) { return s.input_position(used_vertices[i]); },
      [&](std::size_t i) { return corners_of.begin(used_vertices[i])[0]; });
  team.for_each(used_count, kTopologyGrain, [&](std::size_t rank) { order[rank] = used_vertices[order[rank]]; });
  used_vertices = {};
  // First surface vertex and first corner of each input vertex, in that order.
  MeshArray<std::uint32_t> first_copy(used_count), first_corner(used_count);
  team.for_each(used_count, kTopologyGrain, [&](std::size_t rank) {
    first_copy[rank] = fan_count[order[rank]];
    first_corner[rank] = static_cast<std::uint32_t>(corners_of.size(order[rank]));
  });
  s.vertex_count = static_cast<std::uint32_t>(exclusive_prefix_sum(team, first_copy));
  exclusive_prefix_sum(team, first_corner);

  s.surface_to_input.resize(s.vertex_count);
  s.vertex_corner_offsets.resize(std::size_t{s.vertex_count} + 1);
  s.vertex_corners.resize(corner_count);
  team.for_ranges(used_count, kTopologyGrain, [&](std::size_t first, std::size_t last) {
    std::vector<std::uint32_t> cursor;
    for (std::size_t rank = first; rank < last; ++rank) {
      const std::uint32_t v = order[rank], fans = fan_count[v], base = first_copy[rank];
      const std::uint32_t* begin = corners_of.begin(v);
      const std::size_t n = corners_of.size(v);
      if (fans == 1) {  // a manifold vertex, nearly all of them: its corners in order, without counting
        s.surface_to_input[base] = v;
        s.vertex_corner_offsets[base] = first_corner[rank];
        std::copy_n(begin, n, s.vertex_corners.begin() + first_corner[rank]);
        for (std::size_t i = 0; i < n; ++i) s.corner_vertex[begin[i]] = base;
        continue;
      }
      cursor.assign(fans + 1, 0);
      for (std::size_t i = 0; i < n; ++i) ++cursor[s.corner_vertex[begin[i]] + 1];
      cursor[0] = first_corner[rank];
      for (std::uint32_t fan = 0; fan < fans; ++fan) {
        cursor[fan + 1] += cursor[fan];
        s.surface_to_input[base + fan] = v;
        s.vertex_corner_offsets[base + fan] = cursor[fan];
      }
      for (std::size_t i = 0; i < n; ++i) {
        std::uint32_t& corner_vertex = s.corner_vertex[begin[i]];
        s.vertex_corners[cursor[corner_vertex]++] = begin[i];
        corner_vertex += base;
      }
    }
  });
  s.vertex_corner_offsets[s.vertex_count] = static_cast<std::uint32_t>(corner_count);

  // The copies of each input vertex: consecutive surface vertices.
  s.report.non_manifold_vertices = team.count_if(vertex_count, kTopologyGrain, [&](std::size_t v) { return fan_count[v] > 1; });
  MeshArray<std::uint32_t> copy_of_rank = std::move(first_copy);
  s.input_copies_offsets.resize(vertex_count + 1);
  team.for_each(vertex_count, kTopologyGrain, [&](std::size_t v) { s.input_copies_offsets[v] = fan_count[v]; });
  s.input_copies_offsets[vertex_count] = 0;
  exclusive_prefix_sum(team, s.input_copies_offsets);
  s.input_copies.resize(s.vertex_count);
  team.for_each(used_count, kTopologyGrain, [&](std::size_t rank) {
    const std::uint32_t v = order[rank];
    for (std::uint32_t fan = 0; fan < fan_count[v]; ++fan)
      s.input_copies[s.input_copies_offsets[v] + fan] = copy_of_rank[rank] + fan;
  });
}

void join_cut_edges_between_same_copies(SurfaceMesh& s) {
  // After splitting, two faces of a cut edge may meet again at the same surface copies of both its ends:
  // the fans at both ends already join them, so joining the edge too keeps the surface manifold and loses
  // no connection the input had. Edges that now pair up exactly two faces are joined.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  for (std::uint32_t h = 0; h < s.twin.size(); ++h) {
    if (s.twin[h] != kNone) continue;
    std::uint64_t a = s.tail(h), b = s.head(h);
    if (a > b) std::swap(a, b);
    keyed.push_back({(a << 32) | b, h});
  }
  std::sort(keyed.begin(), keyed.end());
  for (std::size_t i = 0; i < keyed.size();) {
    std::size_t j = i;
    while (j < keyed.size() && keyed[j].first == keyed[i].first) ++j;
    if (j - i == 2) {
      s.twin[keyed[i].second] = keyed[i + 1].second;
      s.twin[keyed[i + 1].second] = keyed[i].second;
    }
    i = j;
  }
}

namespace {

// The faces united across every edge: each set is then one connected piece.
ConcurrentUnionFind faces_joined_by_edges(const ParallelTeam& team, const SurfaceMesh& s) {
  ConcurrentUnionFind faces(team, s.face_count());
  team.for_each(s.twin.size(), kTopologyGrain, [&](std::size_t h) {
    if (s.twin[h] != kNone && s.twin[h] < h) faces.unite(face_of(static_cast<std::uint32_t>(h)), face_of(s.twin[h]));
  });
  return faces;
}

}  // namespace

std::size_t count_components(const ParallelTeam& team, const SurfaceMesh& s) {
  const ConcurrentUnionFind faces = faces_joined_by_edges(team, s);
  return team.count_if(s.face_count(), kTopologyGrain, [&](std::size_t f) { return faces.is_root(static_cast<std::uint32_t>(f)); });
}

std::vector<std::uint32_t> face_components(const ParallelTeam& team, const SurfaceMesh& s) {
  ConcurrentUnionFind faces = faces_joined_by_edges(team, s);
  std::vector<std::uint32_t> component(s.face_count());
  team.for_each(s.face_count(), kTopologyGrain,
                [&](std::size_t f) { component[f] = faces.find(static_cast<std::uint32_t>(f)); });
  return component;
}

}  // namespace exactgeo::detail
