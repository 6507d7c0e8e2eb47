// Validation of the input arrays and construction of the manifold surface (see include/exactgeo/mesh.hpp
// for the policy and src/surface_mesh.hpp for the layout).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <numeric>
#include <string>
#include <unordered_map>

#include "exactgeo/error.hpp"
#include "exactgeo/mesh.hpp"
#include "surface_mesh.hpp"
#include "tolerances.hpp"

namespace exactgeo {
namespace detail {
namespace {

using Vec3 = std::array<double, 3>;

Vec3 position(const std::vector<double>& positions, std::uint32_t v) {
  return {positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]};
}
Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

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

// The indices of `points` in Morton (Z-curve) order over their bounding box, ties in index order.
// The engine numbers faces and vertices this way: a propagation touches the faces and vertices around the
// wavefront, and near each other in space they are then near each other in memory. On the scans we hold
// that is 9-15% of a propagation against their files' own order; a mesh stored in random order ran 29%
// slower than in its file's.
std::vector<std::uint32_t> spatial_order(const std::vector<Vec3>& points) {
  Vec3 lo = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  constexpr double kCells = (1 << 21) - 1;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(points.size());
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    std::uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      // Halved, so that no difference overflows; a flat box side (0 / 0) gives NaN, taken as 0.
      const double t = (0.5 * points[i][k] - 0.5 * lo[k]) / (0.5 * hi[k] - 0.5 * lo[k]);
      const double cell = t > 0 ? std::min(t, 1.0) * kCells : 0.0;
      code |= spread_bits(static_cast<std::uint64_t>(cell)) << k;
    }
    keyed[i] = {code, i};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> order(points.size());
  for (std::uint32_t i = 0; i < points.size(); ++i) order[i] = keyed[i].second;
  return order;
}

// Renumbers the kept faces in spatial order of their centroids (see spatial_order): their corners, and the
// maps between input and surface faces.
void order_faces_in_space(SurfaceMesh& s, std::vector<std::uint32_t>& input_vertex_of_corner) {
  const std::size_t face_count = input_vertex_of_corner.size() / 3;
  std::vector<Vec3> centroids(face_count);
  for (std::size_t f = 0; f < face_count; ++f)
    for (int k = 0; k < 3; ++k)
      for (std::size_t corner = 3 * f; corner < 3 * f + 3; ++corner)  // thirds summed: no overflow
        centroids[f][k] += s.input_positions[3 * std::size_t{input_vertex_of_corner[corner]} + k] / 3;
  const std::vector<std::uint32_t> order = spatial_order(centroids);
  std::vector<std::uint32_t> corners(input_vertex_of_corner.size()), face_to_input(face_count), renumbered(face_count);
  for (std::uint32_t f = 0; f < face_count; ++f) {
    const std::uint32_t old = order[f];
    std::copy_n(input_vertex_of_corner.begin() + 3 * std::ptrdiff_t{old}, 3, corners.begin() + 3 * std::ptrdiff_t{f});
    face_to_input[f] = s.surface_face_to_input[old];
    renumbered[old] = f;
  }
  input_vertex_of_corner = std::move(corners);
  s.surface_face_to_input = std::move(face_to_input);
  for (std::uint32_t& f : s.input_face_to_surface)
    if (f != kNone) f = renumbered[f];
}

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// Hash of an exact position; -0.0 and +0.0 are the same position.
struct PositionKey {
  Vec3 p;
  bool operator==(const PositionKey& o) const { return p[0] == o.p[0] && p[1] == o.p[1] && p[2] == o.p[2]; }
};
struct PositionHash {
  std::size_t operator()(const PositionKey& k) const {
    std::size_t h = 0;
    for (double c : k.p) {
      double normalized = c + 0.0;  // maps -0.0 to +0.0
      std::uint64_t bits;
      static_assert(sizeof bits == sizeof normalized);
      __builtin_memcpy(&bits, &normalized, sizeof bits);
      h ^= std::hash<std::uint64_t>{}(bits) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    }
    return h;
  }
};

struct VertexSetHash {
  std::size_t operator()(const std::array<std::uint32_t, 3>& v) const {
    const std::uint64_t h = (std::uint64_t{v[0]} * 0x9e3779b97f4a7c15ull ^ v[1]) * 0xbf58476d1ce4e5b9ull ^ v[2];
    return std::hash<std::uint64_t>{}(h * 0x94d049bb133111ebull);
  }
};

void validate_arrays(std::span<const double> positions, std::span<const std::uint32_t> triangles) {
  if (positions.size() % 3 != 0)
    throw Error(ErrorCode::invalid_mesh, "positions array has " + std::to_string(positions.size()) +
                                             " values, not a multiple of 3");
  if (triangles.size() % 3 != 0)
    throw Error(ErrorCode::invalid_mesh, "triangles array has " + std::to_string(triangles.size()) +
                                             " indices, not a multiple of 3");
  const std::size_t vertex_count = positions.size() / 3;
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (!std::isfinite(positions[i]))
      throw Error(ErrorCode::invalid_mesh, "vertex " + std::to_string(i / 3) + " has a non-finite coordinate");
  for (std::size_t i = 0; i < triangles.size(); ++i)
    if (triangles[i] >= vertex_count)
      throw Error(ErrorCode::invalid_mesh, "face " + std::to_string(i / 3) + " names vertex " +
                                               std::to_string(triangles[i]) + ", but the mesh has " +
                                               std::to_string(vertex_count) + " vertices");
  if (triangles.empty()) throw Error(ErrorCode::invalid_mesh, "mesh has no faces");
}

// Representative of each vertex: itself, or the first vertex at the same position. Counts duplicates.
std::vector<std::uint32_t> find_duplicate_positions(const std::vector<double>& positions, std::size_t& duplicates) {
  const auto n = static_cast<std::uint32_t>(positions.size() / 3);
  std::vector<std::uint32_t> representative(n);
  std::unordered_map<PositionKey, std::uint32_t, PositionHash> first;
  first.reserve(n);
  duplicates = 0;
  for (std::uint32_t v = 0; v < n; ++v) {
    auto [it, inserted] = first.try_emplace(PositionKey{position(positions, v)}, v);
    representative[v] = it->second;
    duplicates += !inserted;
  }
  return representative;
}

// Pair up halfedges along undirected edges: two halfedges become twins; edges with one halfedge are
// boundary, edges with three or more are cut (every halfedge on them becomes boundary).
void match_twins(SurfaceMesh& s, const std::vector<std::uint32_t>& input_vertex_of_corner) {
  const std::size_t halfedge_count = input_vertex_of_corner.size();
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(halfedge_count);
  for (std::uint32_t h = 0; h < halfedge_count; ++h) {
    std::uint64_t a = input_vertex_of_corner[h], b = input_vertex_of_corner[next_halfedge(h)];
    if (a > b) std::swap(a, b);
    keyed[h] = {(a << 32) | b, h};
  }
  std::sort(keyed.begin(), keyed.end());
  const auto& P = s.input_positions;
  s.twin.assign(halfedge_count, kNone);
  for (std::size_t i = 0; i < keyed.size();) {
    std::size_t j = i;
    while (j < keyed.size() && keyed[j].first == keyed[i].first) ++j;
    const std::size_t count = j - i;
    const auto a = static_cast<std::uint32_t>(keyed[i].first >> 32), b = static_cast<std::uint32_t>(keyed[i].first);
    if (position(P, a) == position(P, b)) ++s.report.zero_length_edges;
    if (count == 1) {
      ++s.report.boundary_edges;
    } else if (count == 2) {
      s.twin[keyed[i].second] = keyed[i + 1].second;
      s.twin[keyed[i + 1].second] = keyed[i].second;
    } else {
      ++s.report.non_manifold_edges;
    }
    i = j;
  }
}

// The corner of `h`'s face at the end of `h` that is vertex `v` (v is the tail or head of h).
std::uint32_t corner_at(const std::vector<std::uint32_t>& input_vertex_of_corner, std::uint32_t h,
                        std::uint32_t v) {
  return input_vertex_of_corner[h] == v ? h : next_halfedge(h);
}

// Split every input vertex into one surface vertex per fan of faces connected across twin edges.
void split_into_fans(SurfaceMesh& s, const std::vector<std::uint32_t>& input_vertex_of_corner,
                     std::size_t input_vertex_count) {
  const auto corner_count = static_cast<std::uint32_t>(input_vertex_of_corner.size());
  UnionFind fans(corner_count);
  for (std::uint32_t h = 0; h < corner_count; ++h) {
    const std::uint32_t t = s.twin[h];
    if (t == kNone || t < h) continue;
    for (std::uint32_t v : {input_vertex_of_corner[h], input_vertex_of_corner[next_halfedge(h)]})
      fans.unite(corner_at(input_vertex_of_corner, h, v), corner_at(input_vertex_of_corner, t, v));
  }
  // Number surface vertices in spatial order of their input vertices (see spatial_order), the copies of one
  // input vertex by first corner.
  // Only the vertices of kept faces count: an unreferenced vertex far away would stretch the box.
  std::vector<std::uint32_t> rank(input_vertex_count, kNone), used;
  for (const std::uint32_t v : input_vertex_of_corner)
    if (rank[v] == kNone) {
      rank[v] = 0;
      used.push_back(v);
    }
  std::vector<Vec3> positions(used.size());
  for (std::size_t i = 0; i < used.size(); ++i) positions[i] = position(s.input_positions, used[i]);
  const std::vector<std::uint32_t> order = spatial_order(positions);
  for (std::uint32_t i = 0; i < order.size(); ++i) rank[used[order[i]]] = i;
  std::vector<std::uint32_t> corners_by_vertex(corner_count);
  std::iota(corners_by_vertex.begin(), corners_by_vertex.end(), 0u);
  std::stable_sort(corners_by_vertex.begin(), corners_by_vertex.end(), [&](std::uint32_t a, std::uint32_t b) {
    return rank[input_vertex_of_corner[a]] < rank[input_vertex_of_corner[b]];
  });
  std::vector<std::uint32_t> surface_of_root(corner_count, kNone);
  s.corner_vertex.assign(corner_count, kNone);
  s.input_copies_offsets.assign(input_vertex_count + 1, 0);
  for (std::uint32_t c : corners_by_vertex) {
    const std::uint32_t root = fans.find(c);
    if (surface_of_root[root] == kNone) {
      surface_of_root[root] = s.vertex_count++;
      s.surface_to_input.push_back(input_vertex_of_corner[c]);
      ++s.input_copies_offsets[input_vertex_of_corner[c] + 1];
    }
    s.corner_vertex[c] = surface_of_root[root];
  }
  for (std::size_t v = 0; v < input_vertex_count; ++v) {
    if (s.input_copies_offsets[v + 1] > 1) ++s.report.non_manifold_vertices;
    s.input_copies_offsets[v + 1] += s.input_copies_offsets[v];
  }
  s.input_copies.resize(s.vertex_count);
  {
    std::vector<std::uint32_t> fill(s.input_copies_offsets.begin(), s.input_copies_offsets.end() - 1);
    for (std::uint32_t v = 0; v < s.vertex_count; ++v) s.input_copies[fill[s.surface_to_input[v]]++] = v;
  }

  s.vertex_corner_offsets.assign(s.vertex_count + 1, 0);
  for (std::uint32_t c = 0; c < corner_count; ++c) ++s.vertex_corner_offsets[s.corner_vertex[c] + 1];
  for (std::uint32_t v = 0; v < s.vertex_count; ++v) s.vertex_corner_offsets[v + 1] += s.vertex_corner_offsets[v];
  s.vertex_corners.resize(corner_count);
  std::vector<std::uint32_t> fill(s.vertex_corner_offsets.begin(), s.vertex_corner_offsets.end() - 1);
  for (std::uint32_t c = 0; c < corner_count; ++c) s.vertex_corners[fill[s.corner_vertex[c]]++] = c;
}

// Edge lengths, apex positions in each halfedge frame, angle sums and pseudo-source classification.
void compute_geometry(SurfaceMesh& s, const std::vector<std::uint32_t>& input_vertex_of_corner) {
  const std::uint32_t face_count = s.face_count();
  s.halfedges.resize(3 * std::size_t{face_count});
  s.corner_angle.resize(3 * std::size_t{face_count});
  std::vector<double> angle_sum(s.vertex_count, 0.0);
  std::vector<std::uint8_t> on_boundary(s.vertex_count, 0);
  std::vector<std::uint8_t> near_degenerate(s.vertex_count, 0);
  double total_length = 0;
  for (std::uint32_t f = 0; f < face_count; ++f) {
    const std::array<Vec3, 3> corner = {s.position(input_vertex_of_corner[3 * f]),
                                        s.position(input_vertex_of_corner[3 * f + 1]),
                                        s.position(input_vertex_of_corner[3 * f + 2])};
    double longest = 0;
    for (int i = 0; i < 3; ++i) {
      const Vec3 ab = sub(corner[(i + 1) % 3], corner[i]);
      const Vec3 ac = sub(corner[(i + 2) % 3], corner[i]);
      const double length = norm(ab);
      longest = std::max(longest, length);
      total_length += length;
      HalfedgeGeometry& g = s.halfedges[3 * f + i];
      g.length = length;
      if (length > 0) {
        g.apex_x = dot(ac, ab) / length;
        g.apex_y = norm(cross(ac, ab)) / length;
      } else {  // A and B coincide: place C straight above them, which keeps the unfolding consistent
        g.apex_x = 0;
        g.apex_y = norm(ac);
      }
    }
    const double doubled_area = norm(cross(sub(corner[1], corner[0]), sub(corner[2], corner[0])));
    const bool degenerate = doubled_area <= kDegenerateAreaRatio * longest * longest;
    s.report.degenerate_faces += degenerate;
    for (int i = 0; i < 3; ++i) {
      const HalfedgeGeometry& g = s.halfedges[3 * f + i];
      const std::uint32_t v = s.corner_vertex[3 * f + i];
      s.corner_angle[3 * f + i] = std::atan2(g.apex_y, g.apex_x);
      angle_sum[v] += s.corner_angle[3 * f + i];
      if (degenerate) near_degenerate[v] = 1;
    }
  }
  s.mean_edge_length = total_length / std::max(1.0, 3.0 * face_count);
  for (std::uint32_t h = 0; h < s.twin.size(); ++h) {
    if (s.twin[h] != kNone) continue;
    on_boundary[s.tail(h)] = 1;
    on_boundary[s.head(h)] = 1;
  }
  s.fan_angles_reliable.assign(s.vertex_count, 1);
  for (std::uint32_t v = 0; v < s.vertex_count; ++v) s.fan_angles_reliable[v] = !near_degenerate[v];
  s.is_pseudo_source.assign(s.vertex_count, 0);
  for (std::uint32_t v = 0; v < s.vertex_count; ++v) {
    const double full = on_boundary[v] ? std::numbers::pi : 2 * std::numbers::pi;
    // A shortest path through a vertex leaves it at an angle of at least pi on both sides (interior) or on
    // the surface side (boundary), so it bends only where the angle sum exceeds 2*pi or pi.
    const bool bends = angle_sum[v] > full + kSaddleAngleTolerance;
    s.is_pseudo_source[v] = bends || near_degenerate[v];
    if (!on_boundary[v] && angle_sum[v] > full + kSaddleAngleTolerance) ++s.report.saddle_vertices;
  }
}

// After splitting, two faces of a cut edge may meet again at the same surface copies of both its ends:
// the fans at both ends already join them, so joining the edge too keeps the surface manifold and loses
// no connection the input had. Edges that now pair up exactly two faces are joined.
void join_cut_edges_between_same_copies(SurfaceMesh& s) {
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

// Orders each vertex's corners around it (see SurfaceMesh::fan_angle_start).
void walk_fans(SurfaceMesh& s) {
  const std::size_t corner_count = s.corner_vertex.size();
  s.fan_angle_start.assign(corner_count, 0.0);
  s.corner_enters_forward.assign(corner_count, 1);
  s.fan_total_angle.assign(s.vertex_count, 0.0);
  s.fan_closed.assign(s.vertex_count, 1);
  for (std::uint32_t v = 0; v < s.vertex_count; ++v) {
    const std::uint32_t begin = s.vertex_corner_offsets[v], end = s.vertex_corner_offsets[v + 1];
    // Start where the fan has a free edge, entering through it; a closed fan starts anywhere.
    std::uint32_t start = s.vertex_corners[begin];
    bool forward = true;
    for (std::uint32_t i = begin; i < end; ++i) {
      const std::uint32_t c = s.vertex_corners[i];
      if (s.twin[c] == kNone) { start = c; forward = true; s.fan_closed[v] = 0; break; }
      if (s.twin[prev_halfedge(c)] == kNone) { start = c; forward = false; s.fan_closed[v] = 0; break; }
    }
    double walked = 0;
    std::uint32_t c = start;
    for (std::uint32_t step = begin; step < end; ++step) {
      s.fan_angle_start[c] = walked;
      s.corner_enters_forward[c] = forward;
      walked += s.corner_angle[c];
      const std::uint32_t exit = forward ? prev_halfedge(c) : c;  // the corner's other edge at v
      const std::uint32_t across = s.twin[exit];
      if (across == kNone) break;
      // The corner of v beyond that edge is entered through it: forward if v is the twin's tail.
      forward = s.tail(across) == v;
      c = forward ? across : next_halfedge(across);
      if (c == start) break;
    }
    s.fan_total_angle[v] = walked;
  }
}

std::size_t count_components(const SurfaceMesh& s) {
  UnionFind faces(s.face_count());
  for (std::uint32_t h = 0; h < s.twin.size(); ++h)
    if (s.twin[h] != kNone) faces.unite(face_of(h), face_of(s.twin[h]));
  std::size_t components = 0;
  for (std::uint32_t f = 0; f < s.face_count(); ++f) components += faces.find(f) == f;
  return components;
}

// The power of two the engine scales positions by (see kOrdinaryScaleExponent), and the length scale of the
// tolerances: the bounding-box diagonal of the used vertices in the engine's frame.
void choose_scale(SurfaceMesh& s, const std::vector<std::uint32_t>& input_vertex_of_corner) {
  const auto& P = s.input_positions;
  Vec3 lo = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (std::uint32_t v : input_vertex_of_corner)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], P[3 * v + k]);
      hi[k] = std::max(hi[k], P[3 * v + k]);
    }
  // Half of each side: hi - lo itself may overflow (coordinates of both signs near the largest double).
  double half_extent = 0;
  for (int k = 0; k < 3; ++k) half_extent = std::max(half_extent, 0.5 * hi[k] - 0.5 * lo[k]);
  const int exponent = half_extent > 0 ? std::ilogb(half_extent) + 1 : 0;  // extent in [2^e, 2^(e+1)), about
  s.scale_exponent = std::abs(exponent) <= kOrdinaryScaleExponent ? 0 : -exponent;
  const Vec3 scaled_lo = {std::ldexp(lo[0], s.scale_exponent), std::ldexp(lo[1], s.scale_exponent),
                          std::ldexp(lo[2], s.scale_exponent)};
  const Vec3 scaled_hi = {std::ldexp(hi[0], s.scale_exponent), std::ldexp(hi[1], s.scale_exponent),
                          std::ldexp(hi[2], s.scale_exponent)};
  const double diagonal =
      std::hypot(scaled_hi[0] - scaled_lo[0], scaled_hi[1] - scaled_lo[1], scaled_hi[2] - scaled_lo[2]);
  s.length_scale = diagonal > 0 ? diagonal : 1.0;
}

}  // namespace

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

Mesh::Mesh(std::span<const double> positions, std::span<const std::uint32_t> triangles, const MeshOptions& options) {
  using namespace detail;
  validate_arrays(positions, triangles);
  auto s = std::make_shared<SurfaceMesh>();
  s->input_positions.assign(positions.begin(), positions.end());
  s->input_triangles.assign(triangles.begin(), triangles.end());
  const std::size_t vertex_count = positions.size() / 3;
  MeshReport& report = s->report;
  report.vertices = vertex_count;
  report.faces = triangles.size() / 3;

  const std::vector<std::uint32_t> same_position = find_duplicate_positions(s->input_positions,
                                                                            report.duplicate_positions);
  // Corners of the kept faces, as input vertices (after welding, if asked).
  std::vector<std::uint32_t> input_vertex_of_corner;
  input_vertex_of_corner.reserve(triangles.size());
  std::vector<std::uint8_t> used(vertex_count, 0);
  s->input_face_to_surface.assign(triangles.size() / 3, kNone);
  // A face with the same three vertices as a kept one (a double-sided export, say) would make each of its
  // edges an edge of four faces, which the policy cuts: it is dropped instead, and points on it are located
  // on the kept face.
  std::unordered_map<std::array<std::uint32_t, 3>, std::uint32_t, VertexSetHash> kept_face_of;
  kept_face_of.reserve(triangles.size() / 3);
  for (std::size_t f = 0; f < triangles.size() / 3; ++f) {
    std::array<std::uint32_t, 3> v = {triangles[3 * f], triangles[3 * f + 1], triangles[3 * f + 2]};
    if (options.weld_duplicate_positions)
      for (auto& x : v) x = same_position[x];
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
      ++report.faces_repeating_a_vertex;
      continue;
    }
    std::array<std::uint32_t, 3> vertex_set = v;
    std::sort(vertex_set.begin(), vertex_set.end());
    const auto [kept, first] =
        kept_face_of.try_emplace(vertex_set, static_cast<std::uint32_t>(input_vertex_of_corner.size() / 3));
    if (!first) {
      ++report.duplicate_faces;
      s->input_face_to_surface[f] = kept->second;
      continue;
    }
    s->input_face_to_surface[f] = kept->second;
    s->surface_face_to_input.push_back(static_cast<std::uint32_t>(f));
    input_vertex_of_corner.insert(input_vertex_of_corner.end(), v.begin(), v.end());
    for (std::uint32_t x : {triangles[3 * f], triangles[3 * f + 1], triangles[3 * f + 2]}) used[x] = 1;
  }
  report.faces_used = input_vertex_of_corner.size() / 3;
  if (report.faces_used == 0)
    throw Error(ErrorCode::invalid_mesh, "mesh has no usable face: all " + std::to_string(report.faces) +
                                             " faces repeat a vertex");
  if (options.weld_duplicate_positions)
    for (std::size_t v = 0; v < vertex_count; ++v) report.welded_vertices += same_position[v] != v;
  for (std::size_t v = 0; v < vertex_count; ++v) report.unreferenced_vertices += !used[v];

  s->canonical_input.resize(vertex_count);
  for (std::size_t v = 0; v < vertex_count; ++v)
    s->canonical_input[v] = options.weld_duplicate_positions ? same_position[v] : static_cast<std::uint32_t>(v);
  order_faces_in_space(*s, input_vertex_of_corner);
  match_twins(*s, input_vertex_of_corner);
  split_into_fans(*s, input_vertex_of_corner, vertex_count);
  if (report.non_manifold_edges > 0) join_cut_edges_between_same_copies(*s);
  choose_scale(*s, input_vertex_of_corner);
  compute_geometry(*s, input_vertex_of_corner);
  walk_fans(*s);
  report.surface_vertices = s->vertex_count;
  report.components = count_components(*s);
  surface_ = std::move(s);
}

std::size_t Mesh::vertex_count() const noexcept { return surface_->report.vertices; }
std::size_t Mesh::face_count() const noexcept { return surface_->report.faces; }
std::span<const double> Mesh::positions() const noexcept { return surface_->input_positions; }
std::span<const std::uint32_t> Mesh::triangles() const noexcept { return surface_->input_triangles; }
const MeshReport& Mesh::report() const noexcept { return surface_->report; }

}  // namespace exactgeo
