// Generated meshes: counts, topology, geometry, and exact midpoint subdivision.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/shapes.hpp"

namespace {

using exactgeo::MeshSoup;
using Vec3 = std::array<double, 3>;
using Edge = std::pair<std::uint32_t, std::uint32_t>;

std::size_t vertex_count(const MeshSoup& soup) { return soup.positions.size() / 3; }
std::size_t face_count(const MeshSoup& soup) { return soup.triangles.size() / 3; }

Vec3 position(const MeshSoup& soup, std::uint32_t v) {
  return {soup.positions[v * 3], soup.positions[v * 3 + 1], soup.positions[v * 3 + 2]};
}

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

// Twice the signed area vector of face f (its direction follows the winding).
Vec3 area_vector(const MeshSoup& soup, std::size_t f) {
  const Vec3 a = position(soup, soup.triangles[f * 3]);
  const Vec3 b = position(soup, soup.triangles[f * 3 + 1]);
  const Vec3 c = position(soup, soup.triangles[f * 3 + 2]);
  return cross(sub(b, a), sub(c, a));
}

double total_area(const MeshSoup& soup) {
  double area = 0.0;
  for (std::size_t f = 0; f < face_count(soup); ++f) area += norm(area_vector(soup, f)) / 2.0;
  return area;
}

// Directed edge -> number of faces using it in that direction.
std::map<Edge, int> directed_edges(const MeshSoup& soup) {
  std::map<Edge, int> edges;
  for (std::size_t f = 0; f < face_count(soup); ++f) {
    for (int k = 0; k < 3; ++k) ++edges[{soup.triangles[f * 3 + k], soup.triangles[f * 3 + (k + 1) % 3]}];
  }
  return edges;
}

// Undirected edge -> number of faces using it.
std::map<Edge, int> undirected_edges(const MeshSoup& soup) {
  std::map<Edge, int> edges;
  for (const auto& [edge, count] : directed_edges(soup)) {
    edges[{std::min(edge.first, edge.second), std::max(edge.first, edge.second)}] += count;
  }
  return edges;
}

long euler_characteristic(const MeshSoup& soup) {
  return long(vertex_count(soup)) - long(undirected_edges(soup).size()) + long(face_count(soup));
}

// Every edge is used exactly once in each direction: closed, manifold, consistently oriented.
void expect_closed_and_oriented(const MeshSoup& soup) {
  const auto directed = directed_edges(soup);
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << "edge " << edge.first << "-" << edge.second;
    EXPECT_TRUE(directed.count({edge.second, edge.first})) << "edge " << edge.first << "-" << edge.second;
  }
}

void expect_indices_in_range(const MeshSoup& soup) {
  ASSERT_EQ(soup.positions.size() % 3, 0u);
  ASSERT_EQ(soup.triangles.size() % 3, 0u);
  for (std::uint32_t v : soup.triangles) ASSERT_LT(v, vertex_count(soup));
}

// Sum of the corner angles at each vertex.
std::vector<double> angle_sums(const MeshSoup& soup) {
  std::vector<double> sums(vertex_count(soup), 0.0);
  for (std::size_t f = 0; f < face_count(soup); ++f) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = soup.triangles[f * 3 + k];
      const Vec3 to_next = sub(position(soup, soup.triangles[f * 3 + (k + 1) % 3]), position(soup, v));
      const Vec3 to_prev = sub(position(soup, soup.triangles[f * 3 + (k + 2) % 3]), position(soup, v));
      sums[v] += std::atan2(norm(cross(to_next, to_prev)), dot(to_next, to_prev));
    }
  }
  return sums;
}

TEST(ShapesIcosphere, CountsAndEulerCharacteristic) {
  for (int k = 0; k <= 3; ++k) {
    const MeshSoup soup = exactgeo::make_icosphere(k);
    expect_indices_in_range(soup);
    const std::size_t power = std::size_t(1) << (2 * k);
    EXPECT_EQ(vertex_count(soup), 10 * power + 2) << "k=" << k;
    EXPECT_EQ(face_count(soup), 20 * power) << "k=" << k;
    EXPECT_EQ(undirected_edges(soup).size(), 30 * power) << "k=" << k;
    EXPECT_EQ(euler_characteristic(soup), 2) << "k=" << k;
    expect_closed_and_oriented(soup);
  }
}

TEST(ShapesIcosphere, VerticesOnUnitSphere) {
  const MeshSoup soup = exactgeo::make_icosphere(3);
  for (std::uint32_t v = 0; v < vertex_count(soup); ++v) {
    EXPECT_NEAR(norm(position(soup, v)), 1.0, 4e-16) << "vertex " << v;
  }
}

TEST(ShapesIcosphere, IcosahedronIsRegularAndFacesPointOutward) {
  const MeshSoup soup = exactgeo::make_icosphere(0);
  // Circumradius 1 gives edge length 4 / sqrt(10 + 2 sqrt 5).
  const double edge_length = 4.0 / std::sqrt(10.0 + 2.0 * std::sqrt(5.0));
  for (const auto& [edge, count] : undirected_edges(soup)) {
    EXPECT_EQ(count, 2);
    EXPECT_NEAR(norm(sub(position(soup, edge.first), position(soup, edge.second))), edge_length, 1e-15);
  }
  for (std::size_t f = 0; f < face_count(soup); ++f) {
    const Vec3 centroid = position(soup, soup.triangles[f * 3]);
    EXPECT_GT(dot(area_vector(soup, f), centroid), 0.0) << "face " << f;
  }
}

TEST(ShapesIcosphere, AreaApproachesTheSphere) {
  double previous = total_area(exactgeo::make_icosphere(0));
  for (int k = 1; k <= 4; ++k) {
    const double area = total_area(exactgeo::make_icosphere(k));
    EXPECT_GT(area, previous);
    EXPECT_LT(area, 4.0 * std::numbers::pi);
    previous = area;
  }
  EXPECT_NEAR(previous, 4.0 * std::numbers::pi, 0.02);
}

TEST(ShapesIcosphere, RejectsNegativeSubdivisions) {
  try {
    exactgeo::make_icosphere(-1);
    FAIL() << "expected exactgeo::Error";
  } catch (const exactgeo::Error& e) {
    EXPECT_EQ(e.code(), exactgeo::ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find("-1"), std::string::npos) << e.what();
  }
}

// Level 14 was accepted: its 5.4 billion faces do not fit 32-bit face indices, and it ran until memory ran out.
TEST(ShapesIcosphere, RejectsLevelsWhoseFacesDoNotFit32BitIndices) {
  try {
    exactgeo::make_icosphere(exactgeo::kMaxIcosphereSubdivisions + 1);
    FAIL() << "expected exactgeo::Error";
  } catch (const exactgeo::Error& e) {
    EXPECT_EQ(e.code(), exactgeo::ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find("icosphere subdivisions 14 out of range (0 to 13"), std::string::npos)
        << e.what();
  }
}

TEST(ShapesTorus, CountsAndEulerCharacteristic) {
  for (const auto& [nu, nv] : {std::pair{3, 3}, std::pair{64, 36}, std::pair{10, 7}}) {
    const MeshSoup soup = exactgeo::make_bumpy_torus(nu, nv);
    expect_indices_in_range(soup);
    EXPECT_EQ(vertex_count(soup), std::size_t(nu * nv));
    EXPECT_EQ(face_count(soup), std::size_t(2 * nu * nv));
    EXPECT_EQ(euler_characteristic(soup), 0);
    expect_closed_and_oriented(soup);
  }
}

TEST(ShapesTorus, DemoResolutionHasAFewThousandFaces) {
  const MeshSoup soup = exactgeo::make_bumpy_torus(64, 36);
  EXPECT_GE(face_count(soup), 4000u);
  EXPECT_LE(face_count(soup), 5000u);
}

TEST(ShapesTorus, TubeRadiusStaysWithinTheBumps) {
  const MeshSoup soup = exactgeo::make_bumpy_torus(64, 36);
  double smallest = 1e300, largest = 0.0;
  for (std::uint32_t v = 0; v < vertex_count(soup); ++v) {
    const Vec3 p = position(soup, v);
    const double ring = std::hypot(p[0], p[1]);  // major radius 1 around the z axis
    const double tube = std::hypot(ring - 1.0, p[2]);
    smallest = std::min(smallest, tube);
    largest = std::max(largest, tube);
  }
  // Minor radius 0.35; bumps must change it visibly but never reach the axis of the ring.
  EXPECT_GT(largest - smallest, 0.1);
  EXPECT_GT(smallest, 0.1);
  EXPECT_LT(largest, 0.6);
}

TEST(ShapesTorus, IsCurvedWithSaddles) {
  const MeshSoup soup = exactgeo::make_bumpy_torus(64, 36);
  const std::vector<double> sums = angle_sums(soup);
  // Gaussian curvature at a vertex is 2 pi minus its angle sum; it must be far from flat both ways.
  std::size_t saddles = 0, domes = 0;
  for (double sum : sums) {
    saddles += sum > 2.0 * std::numbers::pi + 1e-3;
    domes += sum < 2.0 * std::numbers::pi - 1e-3;
  }
  EXPECT_GT(saddles, sums.size() / 5);
  EXPECT_GT(domes, sums.size() / 5);
  // Total curvature of a torus is 0 (Gauss-Bonnet), which also checks that faces tile the surface.
  double total_curvature = 0.0;
  for (double sum : sums) total_curvature += 2.0 * std::numbers::pi - sum;
  EXPECT_NEAR(total_curvature, 0.0, 1e-9);
}

TEST(ShapesTorus, RejectsTooFewSegments) {
  EXPECT_THROW(exactgeo::make_bumpy_torus(2, 36), exactgeo::Error);
  EXPECT_THROW(exactgeo::make_bumpy_torus(64, 0), exactgeo::Error);
}

TEST(ShapesGrid, CountsAndEulerCharacteristic) {
  const MeshSoup soup = exactgeo::make_grid(5, 3, 2.0, 1.0);
  expect_indices_in_range(soup);
  EXPECT_EQ(vertex_count(soup), 6u * 4u);
  EXPECT_EQ(face_count(soup), 2u * 5u * 3u);
  EXPECT_EQ(euler_characteristic(soup), 1);  // a disk
  std::size_t boundary_edges = 0;
  for (const auto& [edge, count] : undirected_edges(soup)) {
    EXPECT_LE(count, 2);
    boundary_edges += count == 1;
  }
  EXPECT_EQ(boundary_edges, 2u * (5u + 3u));
}

TEST(ShapesGrid, FlatWithTheRightAreaAndCorners) {
  const double width = 3.0, height = 0.7;
  const MeshSoup soup = exactgeo::make_grid(7, 4, width, height);
  double min_x = 1e300, max_x = -1e300, min_y = 1e300, max_y = -1e300;
  for (std::uint32_t v = 0; v < vertex_count(soup); ++v) {
    const Vec3 p = position(soup, v);
    EXPECT_EQ(p[2], 0.0);
    min_x = std::min(min_x, p[0]), max_x = std::max(max_x, p[0]);
    min_y = std::min(min_y, p[1]), max_y = std::max(max_y, p[1]);
  }
  EXPECT_EQ(min_x, 0.0);
  EXPECT_EQ(max_x, width);
  EXPECT_EQ(min_y, 0.0);
  EXPECT_EQ(max_y, height);
  for (std::size_t f = 0; f < face_count(soup); ++f) {
    EXPECT_GT(area_vector(soup, f)[2], 0.0) << "face " << f << " is degenerate or faces down";
  }
  EXPECT_NEAR(total_area(soup), width * height, 1e-14);
}

TEST(ShapesGrid, RejectsEmptyOrInvalidSizes) {
  EXPECT_THROW(exactgeo::make_grid(0, 4, 1.0, 1.0), exactgeo::Error);
  EXPECT_THROW(exactgeo::make_grid(4, 4, -1.0, 1.0), exactgeo::Error);
  EXPECT_THROW(exactgeo::make_grid(4, 4, 1.0, std::nan("")), exactgeo::Error);
}

// Checks that `fine` is the 1-to-4 midpoint subdivision of `coarse` without relying on the order in
// which new vertices or faces are produced.
void expect_midpoint_subdivision(const MeshSoup& coarse, const MeshSoup& fine) {
  expect_indices_in_range(fine);
  const auto coarse_edges = undirected_edges(coarse);
  ASSERT_EQ(vertex_count(fine), vertex_count(coarse) + coarse_edges.size());
  ASSERT_EQ(face_count(fine), 4 * face_count(coarse));

  // Original vertices keep their index and their bits.
  for (std::size_t i = 0; i < coarse.positions.size(); ++i) {
    ASSERT_EQ(std::bit_cast<std::uint64_t>(fine.positions[i]), std::bit_cast<std::uint64_t>(coarse.positions[i]))
        << "coordinate " << i;
  }

  // Each new vertex touches exactly the two ends of one original edge and sits exactly at its midpoint;
  // together the new vertices cover every original edge once.
  const auto original = std::uint32_t(vertex_count(coarse));
  std::vector<std::set<std::uint32_t>> original_neighbours(vertex_count(fine));
  for (std::size_t f = 0; f < face_count(fine); ++f) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = fine.triangles[f * 3 + k], b = fine.triangles[f * 3 + (k + 1) % 3];
      if (a >= original && b < original) original_neighbours[a].insert(b);
      if (b >= original && a < original) original_neighbours[b].insert(a);
      EXPECT_FALSE(a < original && b < original) << "original edge " << a << "-" << b << " survived";
    }
  }
  std::set<Edge> covered;
  for (std::uint32_t m = original; m < vertex_count(fine); ++m) {
    ASSERT_EQ(original_neighbours[m].size(), 2u) << "new vertex " << m;
    const std::uint32_t a = *original_neighbours[m].begin(), b = *original_neighbours[m].rbegin();
    EXPECT_TRUE(coarse_edges.count({a, b})) << "new vertex " << m << " is not on an original edge";
    EXPECT_TRUE(covered.insert({a, b}).second) << "edge " << a << "-" << b << " has two midpoints";
    const Vec3 pa = position(coarse, a), pb = position(coarse, b), pm = position(fine, m);
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_EQ(std::bit_cast<std::uint64_t>(pm[axis]), std::bit_cast<std::uint64_t>((pa[axis] + pb[axis]) / 2.0))
          << "new vertex " << m << " axis " << axis;
    }
  }
  EXPECT_EQ(covered.size(), coarse_edges.size());
  EXPECT_EQ(euler_characteristic(fine), euler_characteristic(coarse));
}

TEST(ShapesSubdivide, IcosphereTorusAndGrid) {
  for (const MeshSoup& coarse :
       {exactgeo::make_icosphere(1), exactgeo::make_bumpy_torus(12, 8), exactgeo::make_grid(4, 3, 1.0, 2.0)}) {
    expect_midpoint_subdivision(coarse, exactgeo::subdivide_midpoint(coarse));
  }
}

TEST(ShapesSubdivide, PreservesTotalArea) {
  for (const MeshSoup& coarse : {exactgeo::make_icosphere(2), exactgeo::make_bumpy_torus(20, 9),
                                 exactgeo::make_grid(5, 5, 1.0, 1.0)}) {
    const double area = total_area(coarse);
    EXPECT_NEAR(total_area(exactgeo::subdivide_midpoint(coarse)), area, 1e-13 * area);
  }
}

TEST(ShapesSubdivide, KeepsWindingAndSharesMidpointsAcrossOppositeWinding) {
  // Two triangles sharing edge 1-2, the second wound against the first; on that edge a + (b - a) / 2
  // would round differently from b + (a - b) / 2, so only a symmetric formula gives one exact midpoint.
  MeshSoup coarse;
  coarse.positions = {0.1, 0.0, 0.0, 1.0, 0.3, 0.0, 0.7, 1.0, 0.2, 2.0, 1.1, 0.0};
  coarse.triangles = {0, 1, 2, 1, 2, 3};
  const MeshSoup fine = exactgeo::subdivide_midpoint(coarse);
  expect_midpoint_subdivision(coarse, fine);

  // A small face belongs to the coarse face whose corners and edge midpoints hold all its corners;
  // it must keep that face's winding.
  std::array<std::set<Vec3>, 2> points_of_parent;
  for (std::size_t f = 0; f < 2; ++f) {
    for (int k = 0; k < 3; ++k) {
      const Vec3 a = position(coarse, coarse.triangles[f * 3 + k]);
      const Vec3 b = position(coarse, coarse.triangles[f * 3 + (k + 1) % 3]);
      points_of_parent[f].insert(a);
      points_of_parent[f].insert({(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, (a[2] + b[2]) / 2.0});
    }
  }
  std::array<int, 2> children{};
  for (std::size_t f = 0; f < face_count(fine); ++f) {
    for (std::size_t parent = 0; parent < 2; ++parent) {
      bool inside = true;
      for (int k = 0; k < 3; ++k) inside = inside && points_of_parent[parent].count(position(fine, fine.triangles[f * 3 + k]));
      if (!inside) continue;
      ++children[parent];
      EXPECT_GT(dot(area_vector(fine, f), area_vector(coarse, parent)), 0.0) << "face " << f;
    }
  }
  EXPECT_EQ(children, (std::array<int, 2>{4, 4}));
}

TEST(ShapesSubdivide, KeepsUnreferencedVertices) {
  MeshSoup coarse;
  coarse.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5};
  coarse.triangles = {0, 1, 2};
  const MeshSoup fine = exactgeo::subdivide_midpoint(coarse);
  expect_midpoint_subdivision(coarse, fine);
  EXPECT_EQ(position(fine, 3), (Vec3{5, 5, 5}));
}

TEST(ShapesSubdivide, RejectsIndexOutOfRange) {
  MeshSoup coarse;
  coarse.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  coarse.triangles = {0, 1, 3};
  try {
    exactgeo::subdivide_midpoint(coarse);
    FAIL() << "expected exactgeo::Error";
  } catch (const exactgeo::Error& e) {
    EXPECT_EQ(e.code(), exactgeo::ErrorCode::invalid_mesh);
    EXPECT_NE(std::string(e.what()).find("index 3"), std::string::npos) << e.what();
  }
}

}  // namespace
