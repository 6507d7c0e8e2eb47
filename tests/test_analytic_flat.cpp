// Distances whose true values the test computes itself on flat domains: convex ones, where the geodesic is
// the straight line (also turned into a random plane), domains of grid cells with reflex corners (shortest
// paths in the visibility graph), and a symmetric grid where many vertices tie exactly in the wavefront queue.
// Each runs with the paper's pruning rules on and off (analytic.hpp).
#include <gtest/gtest.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "analytic.hpp"
#include "exactgeo/shapes.hpp"
#include "test_meshes.hpp"

namespace exactgeo_test::analytic {
namespace {

// ---- Flat convex domain ---------------------------------------------------------------------------------

// A random triangulation of a convex polygon: `boundary_count` points at random angles on the unit circle
// (so all in convex position), fanned from the first, then `interior_count` random points inserted one by
// one, each splitting the triangle that contains it into three. Candidates outside the polygon or too close
// to an edge are drawn again, so no triangle is degenerate; otherwise they are as skinny as chance makes them.
MeshSoup random_convex_triangulation(std::uint64_t seed, int boundary_count, int interior_count) {
  Random random(seed);
  std::vector<double> angles(boundary_count);
  for (double& a : angles) a = random.uniform(0, 2 * kPi);
  std::sort(angles.begin(), angles.end());
  std::vector<Vec2> points;
  for (double a : angles) points.push_back({std::cos(a), std::sin(a)});
  std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise
  for (std::uint32_t i = 1; i + 1 < points.size(); ++i) triangles.push_back({0, i, i + 1});

  constexpr double kMinDoubledArea = 1e-6;
  while (points.size() < std::size_t(boundary_count + interior_count)) {
    const Vec2 p = {random.uniform(-1, 1), random.uniform(-1, 1)};
    for (auto& t : triangles) {
      const Vec2 &a = points[t[0]], &b = points[t[1]], &c = points[t[2]];
      if (cross(sub(b, a), sub(p, a)) > kMinDoubledArea && cross(sub(c, b), sub(p, b)) > kMinDoubledArea &&
          cross(sub(a, c), sub(p, c)) > kMinDoubledArea) {
        const auto new_vertex = static_cast<std::uint32_t>(points.size());
        points.push_back(p);
        const std::array<std::uint32_t, 3> old = t;
        t = {old[0], old[1], new_vertex};
        triangles.push_back({old[1], old[2], new_vertex});
        triangles.push_back({old[2], old[0], new_vertex});
        break;
      }
    }
  }
  MeshSoup soup;
  for (const Vec2& p : points) add_vertex(soup, {p[0], p[1], 0.0});
  for (const auto& t : triangles) add_triangle(soup, t[0], t[1], t[2]);
  return soup;
}

// The soup moved by a random rotation (from a random unit quaternion) and translation.
MeshSoup randomly_placed(const MeshSoup& soup, std::uint64_t seed) {
  Random random(seed);
  std::array<double, 4> q;
  double length2;
  do {
    for (double& x : q) x = random.uniform(-1, 1);
    length2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
  } while (length2 > 1 || length2 < 0.01);
  for (double& x : q) x /= std::sqrt(length2);
  const auto [w, x, y, z] = q;
  const std::array<Vec3, 3> rotation = {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                                         {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                                         {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
  const Vec3 offset = {random.uniform(-5, 5), random.uniform(-5, 5), random.uniform(-5, 5)};
  MeshSoup moved = soup;
  for (std::uint32_t v = 0; v < vertex_count(soup); ++v) {
    const Vec3 p = vertex_position(soup, v);
    for (int k = 0; k < 3; ++k) moved.positions[3 * v + k] = dot(rotation[k], p) + offset[k];
  }
  return moved;
}

// ---- Flat domains made of unit grid cells ---------------------------------------------------------------

// A union of closed unit squares [i, i+1] x [j, j+1] inside [0, n]^2.
struct CellDomain {
  int n = 0;
  std::vector<std::uint8_t> kept;  // n * n, cell (i, j) at j * n + i

  bool has_cell(int i, int j) const { return i >= 0 && j >= 0 && i < n && j < n && kept[j * n + i]; }
  // Adjacent cells of grid point (i, j) that belong to the domain.
  int cells_around(int i, int j) const {
    return has_cell(i - 1, j - 1) + has_cell(i, j - 1) + has_cell(i - 1, j) + has_cell(i, j);
  }
  bool contains(const Vec2& p) const {
    for (int i = int(std::ceil(p[0])) - 1; i <= int(std::floor(p[0])); ++i)
      for (int j = int(std::ceil(p[1])) - 1; j <= int(std::floor(p[1])); ++j)
        if (has_cell(i, j)) return true;
    return false;
  }
  // Whether segment ab lies in the domain: cut at every grid line it crosses, each piece lies in one
  // closed cell (or on a grid line, between two), so the piece is in the domain iff its midpoint is.
  bool sees(const Vec2& a, const Vec2& b) const {
    std::vector<double> cuts = {0.0, 1.0};
    for (int k = 0; k < 2; ++k) {
      if (a[k] == b[k]) continue;
      for (int line = int(std::ceil(std::min(a[k], b[k]))); line <= int(std::floor(std::max(a[k], b[k]))); ++line) {
        const double t = (line - a[k]) / (b[k] - a[k]);
        if (t > 0 && t < 1) cuts.push_back(t);
      }
    }
    std::sort(cuts.begin(), cuts.end());
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
      const double t = (cuts[i] + cuts[i + 1]) / 2;
      if (!contains({a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])})) return false;
    }
    return true;
  }
  // Grid points where the domain turns by 270 degrees: the only places a shortest path bends.
  std::vector<Vec2> reflex_corners() const {
    std::vector<Vec2> corners;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        if (cells_around(i, j) == 3) corners.push_back({double(i), double(j)});
    return corners;
  }
};

CellDomain l_shape() {  // [0,12]^2 without the top-right quarter [6,12]^2
  CellDomain domain{12, std::vector<std::uint8_t>(144, 1)};
  for (int j = 6; j < 12; ++j)
    for (int i = 6; i < 12; ++i) domain.kept[j * 12 + i] = 0;
  return domain;
}

CellDomain square_with_hole() {  // [0,12]^2 without the off-centre rectangle [3,7] x [4,9]
  CellDomain domain{12, std::vector<std::uint8_t>(144, 1)};
  for (int j = 4; j < 9; ++j)
    for (int i = 3; i < 7; ++i) domain.kept[j * 12 + i] = 0;
  return domain;
}

// Shortest path inside the domain from `from` to each of `targets`: Dijkstra over `from` and the reflex
// corners joined where they see each other, then the best last corner (or none) that sees the target.
std::vector<double> visibility_graph_distances(const CellDomain& domain, const Vec2& from,
                                               const std::vector<Vec2>& targets) {
  std::vector<Vec2> nodes = domain.reflex_corners();
  nodes.insert(nodes.begin(), from);
  std::vector<double> d(nodes.size(), HUGE_VAL);
  std::vector<std::uint8_t> done(nodes.size(), 0);
  d[0] = 0;
  for (std::size_t round = 0; round < nodes.size(); ++round) {
    std::size_t u = nodes.size();
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (!done[i] && (u == nodes.size() || d[i] < d[u])) u = i;
    done[u] = 1;
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (!done[i] && domain.sees(nodes[u], nodes[i])) d[i] = std::min(d[i], d[u] + distance(nodes[u], nodes[i]));
  }
  std::vector<double> result;
  for (const Vec2& t : targets) {
    double best = HUGE_VAL;
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (d[i] + distance(nodes[i], t) < best && domain.sees(nodes[i], t)) best = d[i] + distance(nodes[i], t);
    result.push_back(best);
  }
  return result;
}

// The domain triangulated along its grid (alternating diagonals), with every grid point that is interior
// to the domain moved by up to 0.2 in x and y so that the triangles are irregular. Boundary points stay
// on the grid, so the domain itself is unchanged. Grid points outside the domain are left out.
MeshSoup cell_domain_mesh(const CellDomain& domain, std::uint64_t seed) {
  Random random(seed);
  const int n = domain.n;
  std::vector<std::uint32_t> index((n + 1) * (n + 1), exactgeo::kNoSource);
  MeshSoup soup;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const int around = domain.cells_around(i, j);
      if (around == 0) continue;
      Vec3 p = {double(i), double(j), 0.0};
      if (around == 4) {
        p[0] += random.uniform(-0.2, 0.2);
        p[1] += random.uniform(-0.2, 0.2);
      }
      index[j * (n + 1) + i] = add_vertex(soup, p);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (!domain.has_cell(i, j)) continue;
      const std::uint32_t a = index[j * (n + 1) + i], b = index[j * (n + 1) + i + 1],
                          c = index[(j + 1) * (n + 1) + i + 1], d = index[(j + 1) * (n + 1) + i];
      add_quad(soup, a, b, c, d, (i + j) % 2 != 0);
    }
  return soup;
}

std::vector<double> visibility_graph_distances(const CellDomain& domain, const MeshSoup& soup, std::uint32_t source) {
  std::vector<Vec2> targets;
  for (std::uint32_t v = 0; v < vertex_count(soup); ++v)
    targets.push_back({soup.positions[3 * v], soup.positions[3 * v + 1]});
  return visibility_graph_distances(domain, targets[source], targets);
}

// The references check themselves against values worked out by hand.
TEST(AnalyticReference, VisibilityGraphHandValues) {
  const CellDomain l = l_shape();
  const auto from_corner = visibility_graph_distances(l, {12, 6}, {{6, 12}, {0, 0}, {6, 6}});
  EXPECT_DOUBLE_EQ(from_corner[0], 12.0);  // around the reflex corner (6,6)
  EXPECT_DOUBLE_EQ(from_corner[1], std::hypot(12.0, 6.0));
  EXPECT_DOUBLE_EQ(from_corner[2], 6.0);
  EXPECT_DOUBLE_EQ(visibility_graph_distances(l, {12, 5}, {{5, 12}})[0], 2 * std::sqrt(37.0));
  EXPECT_DOUBLE_EQ(visibility_graph_distances(l, {12, 0}, {{0, 12}})[0], 12 * std::numbers::sqrt2);  // grazes (6,6)

  // Around the hole [3,7] x [4,9], past two of its corners on either side.
  const auto across = visibility_graph_distances(square_with_hole(), {5, 0}, {{5, 12}, {5, 4}, {0, 12}, {12, 12}});
  EXPECT_DOUBLE_EQ(across[0], std::sqrt(20.0) + 5 + std::sqrt(13.0));
  EXPECT_DOUBLE_EQ(across[1], 4.0);
  EXPECT_DOUBLE_EQ(across[2], std::sqrt(20.0) + std::sqrt(73.0));  // the straight line would cut the hole
  EXPECT_DOUBLE_EQ(across[3], std::hypot(7.0, 12.0));              // passes right of the hole
}

TEST_P(AnalyticDistance, FlatConvexRandomTriangulation) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const MeshSoup soup = random_convex_triangulation(seed, 40, 400);
    // Vertex 0 is on the boundary, vertex 40 is the first interior point.
    for (std::uint32_t source : {0u, 40u, 41u}) {
      SCOPED_TRACE(testing::Message() << "seed " << seed << ", source " << source);
      EXPECT_TRUE(distances_match(distances(soup, source), expected_distances(soup, source, euclidean), kExact));
    }
  }
}

TEST_P(AnalyticDistance, FlatConvexInARandomPlane) {
  for (std::uint64_t seed : {4, 5}) {
    const MeshSoup soup = randomly_placed(random_convex_triangulation(seed, 30, 300), seed);
    for (std::uint32_t source : {0u, 30u}) {
      SCOPED_TRACE(testing::Message() << "seed " << seed << ", source " << source);
      EXPECT_TRUE(distances_match(distances(soup, source), expected_distances(soup, source, euclidean), kExact));
    }
  }
}

// T-junctions closed by slivers (faces of no area whose third corner lies on their long side): a vertex at
// a junction lies on its sliver's long side, and its rays run straight on across that side into the faces
// beyond. They were dropped (seen from the side's line, a window has no width), so that every distance
// through there bent at the side's ends: from a junction vertex of a flat 4 x 3 grid, 0.0107 too long.
TEST_P(AnalyticDistance, FlatConvexWithTJunctions) {
  for (std::uint64_t seed : {7, 8}) {
    Random random(seed);
    const MeshSoup whole = random_convex_triangulation(seed, 12, 40);
    const std::size_t before = exactgeo_test::vertex_count(whole);
    const MeshSoup soup = exactgeo_test::with_t_junctions(whole, random, 24);
    for (std::uint32_t source = 0; source < exactgeo_test::vertex_count(soup); source += 3) {
      SCOPED_TRACE(testing::Message() << "seed " << seed << ", source " << source
                                      << (source >= before ? " (at a junction)" : ""));
      EXPECT_TRUE(distances_match(distances(soup, source), expected_distances(soup, source, euclidean), kExact));
    }
  }
}

TEST_P(AnalyticDistance, FlatLShape) {
  const CellDomain domain = l_shape();
  const MeshSoup soup = cell_domain_mesh(domain, 7);
  // The outer corner, the reflex corner itself, the tip of each arm, and a jittered interior vertex.
  const std::vector<std::uint32_t> sources = {vertex_at(soup, {0, 0, 0}), vertex_at(soup, {6, 6, 0}),
                                              vertex_at(soup, {12, 3, 0}), vertex_at(soup, {2, 12, 0}),
                                              exactgeo_test::random_source_vertex(soup, 3)};
  for (std::uint32_t source : sources) {
    SCOPED_TRACE(testing::Message() << "source " << source);
    EXPECT_TRUE(distances_match(distances(soup, source), visibility_graph_distances(domain, soup, source), kExact));
  }
}

TEST_P(AnalyticDistance, FlatSquareWithAHole) {
  const CellDomain domain = square_with_hole();
  const MeshSoup soup = cell_domain_mesh(domain, 8);
  // Below the hole, on its rim, at an outer corner, and a jittered interior vertex.
  const std::vector<std::uint32_t> sources = {vertex_at(soup, {5, 0, 0}), vertex_at(soup, {7, 6, 0}),
                                              vertex_at(soup, {12, 12, 0}),
                                              exactgeo_test::random_source_vertex(soup, 4)};
  for (std::uint32_t source : sources) {
    SCOPED_TRACE(testing::Message() << "source " << source);
    EXPECT_TRUE(distances_match(distances(soup, source), visibility_graph_distances(domain, soup, source), kExact));
  }
}

// Vertices at exactly equal distances must all come out, and equal (ENGINE-NOTES, "Ties").
TEST_P(AnalyticDistance, ExactTiesOnASymmetricGrid) {
  constexpr int n = 16;  // a power of two: grid coordinates are exact integers
  const MeshSoup soup = exactgeo::make_grid(n, n, n, n);
  const auto index = [&](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  const std::uint32_t centre = index(n / 2, n / 2);
  ASSERT_EQ(vertex_position(soup, centre), (Vec3{n / 2.0, n / 2.0, 0}));
  const std::vector<double> d = distances(soup, centre);
  EXPECT_TRUE(distances_match(d, expected_distances(soup, centre, euclidean), kExact));
  // The alternating diagonals make the mesh symmetric under the square's eight symmetries about the centre.
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double here = d[index(i, j)];
      ASSERT_TRUE(std::isfinite(here));
      for (std::uint32_t partner : {index(n - i, j), index(i, n - j), index(j, i), index(n - j, n - i)})
        EXPECT_NEAR(here, d[partner], 1e-15 * n) << "(" << i << ", " << j << ")";
    }
}

}  // namespace
}  // namespace exactgeo_test::analytic
