// The faces' bounding-volume hierarchy (face_bvh.hpp): its build on the team and the closest-point search.
#include "face_bvh.hpp"

#include <algorithm>
#include <cfloat>
#include <memory>
#include <mutex>
#include <numeric>
#include <utility>

#include "worker_pool.hpp"

namespace exactgeo::detail {
namespace {

constexpr std::size_t kBoxGrain = 1 << 12;

// A box is skipped only if its squared distance, less this fraction, still exceeds the best face's: the two
// are computed with a few roundings each (a few ulps apart at most), and a box skipped for rounding could
// hide a face that ties with the best and has a lower index.
constexpr double kSkipSlack = 1e-12;

// Deeper than a tree of 2^32 faces goes (31 levels): the search's stack, which holds a node per level at most.
constexpr int kMaxDepth = 40;

double box_squared_distance(const FaceBvhNode& node, const Vec3& point) {
  double sum = 0;
  for (int k = 0; k < 3; ++k) {
    const double gap = std::max({node.lo[k] - point[k], point[k] - node.hi[k], 0.0});
    sum += gap * gap;
  }
  return sum;
}

// Node spans are filled depth first: a node, then its first child's subtree, then its second child's. The
// split depends on the count alone, so the whole layout is known before any face is placed.
struct Layout {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> spans;  // per node: its entries [first, end)
  std::vector<std::vector<std::uint32_t>> levels;               // per depth: its nodes
};

void lay_out(FaceBvh& bvh, Layout& layout, std::uint32_t first, std::uint32_t end, std::size_t depth) {
  const auto node = static_cast<std::uint32_t>(bvh.nodes.size());
  const bool leaf = end - first <= FaceBvh::kMaxLeafFaces;
  bvh.nodes.push_back({{}, {}, first, leaf ? end - first : 0});
  layout.spans.emplace_back(first, end);
  if (layout.levels.size() <= depth) layout.levels.emplace_back();
  layout.levels[depth].push_back(node);
  if (leaf) return;
  const std::uint32_t middle = first + (end - first) / 2;
  lay_out(bvh, layout, first, middle, depth + 1);
  bvh.nodes[node].first = static_cast<std::uint32_t>(bvh.nodes.size());
  lay_out(bvh, layout, middle, end, depth + 1);
}

}  // namespace

Vec3 point_at(const std::array<Vec3, 3>& corners, const std::array<double, 3>& barycentric) {
  Vec3 p;
  for (int k = 0; k < 3; ++k)
    p[k] = barycentric[0] * corners[0][k] + barycentric[1] * corners[1][k] + barycentric[2] * corners[2][k];
  return p;
}

TrianglePoint closest_point_on_triangle(const Vec3& point, const std::array<Vec3, 3>& corners) {
  TrianglePoint best;
  const auto consider = [&](const std::array<double, 3>& barycentric) {
    const Vec3 offset = sub(point, point_at(corners, barycentric));
    const double squared_distance = dot(offset, offset);
    if (squared_distance < best.squared_distance) best = {barycentric, squared_distance};
  };
  // Edge i runs between corners i and i + 1.
  std::array<double, 3> squared_lengths;
  for (int i = 0; i < 3; ++i) {
    int from = i, to = (i + 1) % 3;
    if (corners[to] < corners[from]) std::swap(from, to);
    const Vec3 edge = sub(corners[to], corners[from]);
    squared_lengths[i] = dot(edge, edge);
    const double along = squared_lengths[i] > 0 ? dot(sub(point, corners[from]), edge) / squared_lengths[i] : 0.0;
    const double t = std::clamp(along, 0.0, 1.0);
    std::array<double, 3> barycentric = {0, 0, 0};
    barycentric[from] = 1 - t;
    barycentric[to] = t;
    consider(barycentric);
  }

  // The foot of the perpendicular, as weights s of b and t of c, in the frame of the longest edge ab, where
  // c's foot lies between a and b. p's position along ab comes out well conditioned whatever the triangle's
  // shape; only t, p's position across it towards c, depends on the apex, and on a thin triangle rounding
  // moves the foot across the triangle (less than its height), never along it. Where rounding puts the foot
  // inside when it is not, the point is still on the triangle, and its squared distance is its own.
  const int i = static_cast<int>(std::max_element(squared_lengths.begin(), squared_lengths.end()) -
                                 squared_lengths.begin());
  const Vec3 &a = corners[i], &b = corners[(i + 1) % 3], &c = corners[(i + 2) % 3];
  const Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(point, a);
  const double squared_base = dot(ab, ab);
  if (squared_base == 0) return best;  // the corners coincide
  const double apex_along = dot(ac, ab) / squared_base;  // in lengths of ab
  const Vec3 height = {ac[0] - apex_along * ab[0], ac[1] - apex_along * ab[1], ac[2] - apex_along * ab[2]};
  const double squared_height = dot(height, height);
  if (squared_height == 0) return best;  // collinear corners
  const double along = dot(ap, ab) / squared_base;
  const Vec3 across = {ap[0] - along * ab[0], ap[1] - along * ab[1], ap[2] - along * ab[2]};  // p from line ab
  const double t = dot(across, height) / squared_height;
  const double s = along - t * apex_along;
  if (s >= 0 && t >= 0 && s + t <= 1) {
    std::array<double, 3> barycentric;
    barycentric[i] = std::max(0.0, 1 - s - t);
    barycentric[(i + 1) % 3] = s;
    barycentric[(i + 2) % 3] = t;
    consider(barycentric);
  }
  return best;
}

FaceBvh build_face_bvh(const ParallelTeam& team, const SurfaceMesh& mesh) {
  const std::uint32_t face_count = mesh.face_count();
  FaceBvh bvh;
  Layout layout;
  bvh.nodes.reserve(std::size_t{face_count} + 1);  // leaves hold two faces at least (one if the mesh has one)
  lay_out(bvh, layout, 0, face_count, 0);

  const auto corners_of = [&](std::uint32_t face) {
    std::array<Vec3, 3> corners;
    for (int k = 0; k < 3; ++k) corners[k] = mesh.position(mesh.surface_to_input[mesh.corner_vertex[3 * face + k]]);
    return corners;
  };
  std::vector<Vec3> centroid_sum(face_count);  // three times the centroid: only its order matters
  team.for_each(face_count, kBoxGrain, [&](std::size_t f) {
    const std::array<Vec3, 3> corners = corners_of(static_cast<std::uint32_t>(f));
    for (int k = 0; k < 3; ++k) centroid_sum[f][k] = corners[0][k] + corners[1][k] + corners[2][k];
  });

  // Top down, a level at a time: each inner node puts the first half of its faces (by centroid along the
  // longest side of their centroids' box, ties by face) before the second, which its children then split.
  // The surface numbers faces in spatial order already, so each partition starts from nearly sorted faces.
  std::vector<std::uint32_t> order(face_count);
  std::iota(order.begin(), order.end(), 0u);
  for (const std::vector<std::uint32_t>& level : layout.levels) {
    team.for_each(level.size(), 1, [&](std::size_t i) {
      const std::uint32_t node = level[i];
      if (bvh.nodes[node].count > 0) return;
      const auto [first, end] = layout.spans[node];
      Box box;
      for (std::uint32_t e = first; e < end; ++e)
        for (int k = 0; k < 3; ++k) {
          box.lo[k] = std::min(box.lo[k], centroid_sum[order[e]][k]);
          box.hi[k] = std::max(box.hi[k], centroid_sum[order[e]][k]);
        }
      int axis = 0;
      for (int k = 1; k < 3; ++k)
        if (box.hi[k] - box.lo[k] > box.hi[axis] - box.lo[axis]) axis = k;
      const auto before = [&](std::uint32_t a, std::uint32_t b) {
        return std::pair(centroid_sum[a][axis], a) < std::pair(centroid_sum[b][axis], b);
      };
      std::nth_element(order.begin() + first, order.begin() + first + (end - first) / 2, order.begin() + end,
                       before);
    });
  }

  bvh.corners.resize(face_count);
  bvh.input_faces.resize(face_count);
  team.for_each(face_count, kBoxGrain, [&](std::size_t e) {
    bvh.corners[e] = corners_of(order[e]);
    bvh.input_faces[e] = mesh.surface_face_to_input[order[e]];
  });
  // point_at's rounding: each coordinate a sum of three weighted corners, each weight at most 1 and the
  // weights summing to 1 up to a few ulps, errs by a few ulps of the largest coordinate at most.
  const double largest = team.reduce_ranges(
      face_count, kBoxGrain, 0.0,
      [&](std::size_t first, std::size_t end) {
        double m = 0;
        for (std::size_t e = first; e < end; ++e)
          for (const Vec3& c : bvh.corners[e]) m = std::max({m, std::abs(c[0]), std::abs(c[1]), std::abs(c[2])});
        return m;
      },
      [](double a, double b) { return std::max(a, b); });
  bvh.margin = 16 * DBL_EPSILON * largest;

  // Bottom up: a leaf's box from its corners, an inner node's from its children's.
  for (auto level = layout.levels.rbegin(); level != layout.levels.rend(); ++level) {
    team.for_each(level->size(), 64, [&](std::size_t i) {
      FaceBvhNode& node = bvh.nodes[(*level)[i]];
      Box box;
      const auto add = [&](const Vec3& lo, const Vec3& hi) {
        for (int k = 0; k < 3; ++k) {
          box.lo[k] = std::min(box.lo[k], lo[k]);
          box.hi[k] = std::max(box.hi[k], hi[k]);
        }
      };
      if (node.count > 0) {
        for (std::uint32_t e = node.first; e < node.first + node.count; ++e)
          for (const Vec3& c : bvh.corners[e]) add(c, c);
        for (int k = 0; k < 3; ++k) {
          box.lo[k] -= bvh.margin;
          box.hi[k] += bvh.margin;
        }
      } else {
        const FaceBvhNode &left = bvh.nodes[(*level)[i] + 1], &right = bvh.nodes[node.first];
        add(left.lo, left.hi);
        add(right.lo, right.hi);
      }
      node.lo = box.lo;
      node.hi = box.hi;
    });
  }
  return bvh;
}

const FaceBvh& face_bvh(const SurfaceMesh& mesh, unsigned threads) {
  std::call_once(mesh.face_hierarchy_built, [&] {
    WorkerPool pool(threads_worth(threads, mesh.face_count(), kFacesPerBuildThread));
    mesh.face_hierarchy = std::make_shared<const FaceBvh>(build_face_bvh(ParallelTeam{pool}, mesh));
  });
  return *mesh.face_hierarchy;
}

SurfaceClosestPoint closest_surface_point(const FaceBvh& bvh, const Vec3& point) {
  SurfaceClosestPoint best;
  // Nodes still to search with their boxes' squared distances, the nearer child searched first: the best
  // face found early lets most boxes be skipped.
  struct Pending {
    std::uint32_t node;
    double squared_distance;
  };
  std::array<Pending, kMaxDepth + 1> stack;
  int size = 0;
  stack[size++] = {0, box_squared_distance(bvh.nodes[0], point)};
  const auto may_hold_closer = [&](double squared_distance) {
    return squared_distance * (1 - kSkipSlack) <= best.point.squared_distance;
  };
  while (size > 0) {
    const Pending pending = stack[--size];
    if (!may_hold_closer(pending.squared_distance)) continue;
    const FaceBvhNode& node = bvh.nodes[pending.node];
    if (node.count > 0) {
      for (std::uint32_t e = node.first; e < node.first + node.count; ++e) {
        const TrianglePoint candidate = closest_point_on_triangle(point, bvh.corners[e]);
        const double d = candidate.squared_distance, best_d = best.point.squared_distance;
        if (d < best_d || (d == best_d && bvh.input_faces[e] < best.input_face)) best = {bvh.input_faces[e], candidate};
      }
      continue;
    }
    Pending nearer = {pending.node + 1, box_squared_distance(bvh.nodes[pending.node + 1], point)};
    Pending farther = {node.first, box_squared_distance(bvh.nodes[node.first], point)};
    if (farther.squared_distance < nearer.squared_distance) std::swap(nearer, farther);
    if (may_hold_closer(farther.squared_distance)) stack[size++] = farther;
    if (may_hold_closer(nearer.squared_distance)) stack[size++] = nearer;
  }
  return best;
}

}  // namespace exactgeo::detail
