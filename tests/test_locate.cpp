// exactgeo::locate, the closest surface point of points in space: against a search of every kept face with an
// independent formula in long double, on generated meshes (with zero-area and needle triangles) and on every
// shared mesh for 10,000 seeded random points on, near and far from the surface; closed forms, points exactly
// at corners and on edges, ties, dropped faces, threads, scale, far points, errors, and the located points as
// sources and targets.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "face_bvh.hpp"
#include "test_meshes.hpp"

namespace {

using exactgeo::LocateResult;
using exactgeo::Mesh;
using exactgeo::MeshSoup;
using exactgeo::SurfacePoint;
using exactgeo_test::Random;
using exactgeo_test::Vec3;
using exactgeo_test::vertex_position;

// The distance agrees with the reference to this, relative to the distance, or to this times a thousandth of
// the mesh's diagonal for points on or very near the surface (where rounding of the coordinates dominates).
constexpr double kDistanceTolerance = 1e-12;
// Located points agree with the reference's to this times the diagonal, unless the reference finds another
// point as close (a tie between distinct points, where either is right).
constexpr double kPositionTolerance = 1e-9;

#ifdef EXACTGEO_TESTS_SANITIZED
constexpr std::size_t kSharedMeshPoints = 1'000;
constexpr std::size_t kMaxSharedFaces = 13'000;
#else
constexpr std::size_t kSharedMeshPoints = 10'000;
constexpr std::size_t kMaxSharedFaces = std::numeric_limits<std::size_t>::max();
#endif

using Real = long double;
using RealVec = std::array<Real, 3>;

RealVec real(const Vec3& v) { return {v[0], v[1], v[2]}; }
RealVec minus(const RealVec& a, const RealVec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Real dot(const RealVec& a, const RealVec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
RealVec along(const RealVec& from, const RealVec& direction, Real t) {
  return {from[0] + t * direction[0], from[1] + t * direction[1], from[2] + t * direction[2]};
}
Vec3 to_double(const RealVec& v) { return {double(v[0]), double(v[1]), double(v[2])}; }
double length(const RealVec& v) { return double(std::sqrt(dot(v, v))); }

struct Reference {
  double distance = HUGE_VAL;
  Vec3 position{};
};

// The closest point of the triangle to p, written differently from the library's: the nearest of the three
// edges, and the orthogonal projection onto the plane where it falls inside the triangle, decided by 2D
// orientation tests in an orthonormal frame of the plane (the longest edge, and the apex's offset from it,
// orthogonalised twice, which keeps the frame accurate on triangles a billion times longer than wide).
Reference closest_on_triangle(const RealVec& p, const std::array<RealVec, 3>& corner) {
  Reference best;
  const auto consider = [&](const RealVec& q) {
    const double d = length(minus(p, q));
    if (d < best.distance) best = {d, to_double(q)};
  };
  std::array<Real, 3> squared_lengths;
  for (int i = 0; i < 3; ++i) {
    const RealVec& a = corner[i];
    const RealVec edge = minus(corner[(i + 1) % 3], a);
    squared_lengths[i] = dot(edge, edge);
    const Real t = squared_lengths[i] > 0 ? dot(minus(p, a), edge) / squared_lengths[i] : Real(0);
    consider(along(a, edge, std::clamp(t, Real(0), Real(1))));
  }
  const int i = static_cast<int>(std::max_element(squared_lengths.begin(), squared_lengths.end()) -
                                 squared_lengths.begin());
  const RealVec &a = corner[i], &b = corner[(i + 1) % 3], &c = corner[(i + 2) % 3];
  if (squared_lengths[i] == 0) return best;
  const auto unit = [](const RealVec& v) {
    const Real n = std::sqrt(dot(v, v));
    return RealVec{v[0] / n, v[1] / n, v[2] / n};
  };
  const RealVec x_axis = unit(minus(b, a));
  RealVec offset = minus(c, a);
  for (int pass = 0; pass < 2; ++pass) offset = along(offset, x_axis, -dot(offset, x_axis));
  if (dot(offset, offset) == 0) return best;
  const RealVec y_axis = unit(offset);
  const auto in_plane = [&](const RealVec& v) {
    return std::array<Real, 2>{dot(minus(v, a), x_axis), dot(minus(v, a), y_axis)};
  };
  const std::array<std::array<Real, 2>, 3> flat = {in_plane(a), in_plane(b), in_plane(c)};
  const std::array<Real, 2> q = in_plane(p);
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    const auto& from = flat[k];
    const auto& to = flat[(k + 1) % 3];
    inside = inside && (to[0] - from[0]) * (q[1] - from[1]) - (to[1] - from[1]) * (q[0] - from[0]) >= 0;
  }
  if (inside) consider(along(along(a, x_axis, q[0]), y_axis, q[1]));
  return best;
}

// The faces the mesh policy keeps: not repeating a vertex, not the same three vertices as an earlier face.
std::vector<bool> kept_faces(const MeshSoup& soup) {
  std::vector<std::pair<std::array<std::uint32_t, 3>, std::uint32_t>> sorted;  // corners in order, face
  for (std::uint32_t f = 0; f < exactgeo_test::face_count(soup); ++f) {
    std::array<std::uint32_t, 3> corners;
    std::copy_n(soup.triangles.begin() + 3 * f, 3, corners.begin());
    std::sort(corners.begin(), corners.end());
    sorted.emplace_back(corners, f);
  }
  std::sort(sorted.begin(), sorted.end());
  std::vector<bool> kept(sorted.size(), false);
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    const auto& [corners, face] = sorted[i];
    const bool repeats_a_vertex = corners[0] == corners[1] || corners[1] == corners[2];
    const bool repeats_a_face = i > 0 && sorted[i - 1].first == corners;  // the earliest comes first
    kept[face] = !repeats_a_vertex && !repeats_a_face;
  }
  return kept;
}

// The closest point over every kept face. A face is skipped only where its bounding sphere lies farther than
// the best distance so far (which starts at the nearest used vertex), so every face that could be closer is
// measured.
class BruteForce {
 public:
  explicit BruteForce(const MeshSoup& soup) : soup_(soup), kept_(kept_faces(soup)) {
    for (std::uint32_t f = 0; f < kept_.size(); ++f) {
      if (!kept_[f]) continue;
      const std::array<Vec3, 3> c = corners(f);
      Vec3 center;
      for (int k = 0; k < 3; ++k) center[k] = (c[0][k] + c[1][k] + c[2][k]) / 3;
      double radius = 0;
      for (const Vec3& corner : c) radius = std::max(radius, exactgeo_test::distance(center, corner));
      faces_.push_back(f);
      centers_.push_back(center);
      radii_.push_back(radius * (1 + 1e-9));
      for (std::uint32_t v : {soup.triangles[3 * f], soup.triangles[3 * f + 1], soup.triangles[3 * f + 2]})
        used_vertices_.push_back(v);
    }
    std::sort(used_vertices_.begin(), used_vertices_.end());
    used_vertices_.erase(std::unique(used_vertices_.begin(), used_vertices_.end()), used_vertices_.end());
  }

  bool kept(std::uint32_t face) const { return face < kept_.size() && kept_[face]; }
  std::array<Vec3, 3> corners(std::uint32_t f) const {
    return {vertex_position(soup_, soup_.triangles[3 * f]), vertex_position(soup_, soup_.triangles[3 * f + 1]),
            vertex_position(soup_, soup_.triangles[3 * f + 2])};
  }

  Reference closest(const Vec3& p) const {
    double bound = HUGE_VAL;
    for (std::uint32_t v : used_vertices_)
      bound = std::min(bound, exactgeo_test::distance(p, vertex_position(soup_, v)));
    Reference best;
    for_faces_within(p, bound, [&](std::uint32_t f) {
      const Reference candidate = measure(p, f);
      if (candidate.distance < best.distance) best = candidate;
    });
    return best;
  }

  // Whether some face holds a point within `tolerance` of `distance` from p and farther than `apart` from
  // `position`: p is as close to two distinct points of the surface, and either is a right answer.
  bool ties_elsewhere(const Vec3& p, double distance, const Vec3& position, double tolerance, double apart) const {
    bool tie = false;
    for_faces_within(p, distance + tolerance, [&](std::uint32_t f) {
      const Reference candidate = measure(p, f);
      tie = tie || (candidate.distance <= distance + tolerance &&
                    exactgeo_test::distance(candidate.position, position) > apart);
    });
    return tie;
  }

 private:
  Reference measure(const Vec3& p, std::uint32_t f) const {
    const std::array<Vec3, 3> c = corners(f);
    return closest_on_triangle(real(p), {real(c[0]), real(c[1]), real(c[2])});
  }
  template <class Visit>
  void for_faces_within(const Vec3& p, double bound, Visit&& visit) const {
    for (std::size_t i = 0; i < faces_.size(); ++i) {
      const Vec3& c = centers_[i];
      const double dx = p[0] - c[0], dy = p[1] - c[1], dz = p[2] - c[2];
      const double reach = bound * (1 + 1e-12) + radii_[i];
      if (dx * dx + dy * dy + dz * dz <= reach * reach) visit(faces_[i]);
    }
  }

  const MeshSoup& soup_;
  std::vector<bool> kept_;
  std::vector<std::uint32_t> faces_;
  std::vector<Vec3> centers_;
  std::vector<double> radii_;
  std::vector<std::uint32_t> used_vertices_;
};

struct Bounds {
  Vec3 lo = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  double diagonal() const { return exactgeo_test::distance(lo, hi); }
};

Bounds bounds_of(const MeshSoup& soup) {
  Bounds bounds;
  for (std::size_t v = 0; v < exactgeo_test::vertex_count(soup); ++v)
    for (int k = 0; k < 3; ++k) {
      bounds.lo[k] = std::min(bounds.lo[k], soup.positions[3 * v + k]);
      bounds.hi[k] = std::max(bounds.hi[k], soup.positions[3 * v + k]);
    }
  return bounds;
}

// The located point in space, as the barycentric combination of its face's corners, in long double.
RealVec located_position(const BruteForce& brute, const SurfacePoint& point) {
  const std::array<Vec3, 3> c = brute.corners(point.face);
  RealVec q = {0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (int axis = 0; axis < 3; ++axis) q[axis] += Real(point.barycentric[k]) * Real(c[k][axis]);
  return q;
}

// Every point of `xyz` located on a kept face, with valid barycentric coordinates, at the reference's distance
// (kDistanceTolerance), the located point at that distance from it, and at the reference's closest point
// (kPositionTolerance) unless the reference finds a tie.
void expect_matches_brute_force(const MeshSoup& soup, const std::vector<double>& xyz, const LocateResult& located,
                                const std::string& label) {
  const BruteForce brute(soup);
  const double scale = bounds_of(soup).diagonal();
  ASSERT_EQ(located.points.size(), xyz.size() / 3);
  ASSERT_EQ(located.distances.size(), xyz.size() / 3);
  std::size_t ties = 0;
  double worst_relative = 0;
  for (std::size_t i = 0; i < located.points.size(); ++i) {
    const Vec3 p = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
    const SurfacePoint& point = located.points[i];
    ASSERT_TRUE(brute.kept(point.face)) << label << ": point " << i << " on face " << point.face << ", not a kept face";
    const auto& b = point.barycentric;
    ASSERT_TRUE(b[0] >= 0 && b[1] >= 0 && b[2] >= 0 && b[0] <= 1 && b[1] <= 1 && b[2] <= 1)
        << label << ": point " << i << " barycentric " << b[0] << " " << b[1] << " " << b[2];
    ASSERT_NEAR(b[0] + b[1] + b[2], 1.0, 1e-15) << label << ": point " << i;

    const Reference reference = brute.closest(p);
    const double tolerance = kDistanceTolerance * std::max(reference.distance, 1e-3 * scale);
    ASSERT_NEAR(located.distances[i], reference.distance, tolerance) << label << ": point " << i;
    const RealVec q = located_position(brute, point);
    ASSERT_NEAR(length(minus(real(p), q)), located.distances[i], tolerance)
        << label << ": point " << i << " is not at its distance from the point located";
    worst_relative = std::max(worst_relative, std::abs(located.distances[i] - reference.distance) /
                                                  std::max(reference.distance, 1e-3 * scale));
    if (exactgeo_test::distance(to_double(q), reference.position) > kPositionTolerance * scale) {
      ASSERT_TRUE(brute.ties_elsewhere(p, reference.distance, to_double(q), tolerance, kPositionTolerance * scale))
          << label << ": point " << i << " located at " << q[0] << " " << q[1] << " " << q[2] << ", the closest is "
          << reference.position[0] << " " << reference.position[1] << " " << reference.position[2];
      ++ties;
    }
  }
  std::printf("  %s: %zu points, distance errors up to %.2g (of the distance, or of a thousandth of the diagonal), "
              "%zu ties between distinct points\n",
              label.c_str(), located.points.size(), worst_relative, ties);
}

// A random point of a random kept face.
Vec3 random_surface_point(const MeshSoup& soup, const std::vector<bool>& kept, Random& random) {
  std::uint32_t f;
  do f = random.below(kept.size());
  while (!kept[f]);
  const double u = random.uniform(0, 1), v = random.uniform(0, 1);
  const double a = std::min(u, v), b = std::max(u, v);
  const std::array<double, 3> w = {a, b - a, 1 - b};
  Vec3 p = {0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (int axis = 0; axis < 3; ++axis) p[axis] += w[k] * soup.positions[3 * soup.triangles[3 * f + k] + axis];
  return p;
}

// Seeded points: a quarter on the surface, a third just off it (at 1e-7 to 1e-1 of the diagonal, in a
// random direction), the rest spread over the bounding box grown by half, and a tenth up to five boxes away.
std::vector<double> random_points(const MeshSoup& soup, std::size_t count, std::uint64_t seed) {
  Random random(seed);
  const std::vector<bool> kept = kept_faces(soup);
  const auto [lo, hi] = bounds_of(soup);
  const double scale = exactgeo_test::distance(lo, hi);
  std::vector<double> xyz;
  for (std::size_t i = 0; i < count; ++i) {
    Vec3 p;
    const double kind = random.uniform(0, 1);
    if (kind < 0.25) {
      p = random_surface_point(soup, kept, random);
    } else if (kind < 0.6) {
      p = random_surface_point(soup, kept, random);
      Vec3 direction = {random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
      const double offset =
          scale * std::pow(10.0, random.uniform(-7, -1)) / exactgeo_test::distance(direction, {0, 0, 0});
      for (int k = 0; k < 3; ++k) p[k] += offset * direction[k];
    } else {
      const double grow = kind < 0.9 ? 0.5 : 5.0;
      for (int k = 0; k < 3; ++k) p[k] = random.uniform(lo[k] - grow * (hi[k] - lo[k]), hi[k] + grow * (hi[k] - lo[k]));
    }
    xyz.insert(xyz.end(), p.begin(), p.end());
  }
  return xyz;
}

std::vector<double> flat(const std::vector<Vec3>& points) {
  std::vector<double> xyz;
  for (const Vec3& p : points) xyz.insert(xyz.end(), p.begin(), p.end());
  return xyz;
}

// ---- Closed forms -------------------------------------------------------------------------------------

MeshSoup right_triangle() {
  MeshSoup soup;
  exactgeo_test::add_vertex(soup, {0, 0, 0});
  exactgeo_test::add_vertex(soup, {1, 0, 0});
  exactgeo_test::add_vertex(soup, {0, 1, 0});
  exactgeo_test::add_triangle(soup, 0, 1, 2);
  return soup;
}

TEST(Locate, ClosedFormsOnOneTriangle) {
  const Mesh mesh(right_triangle());
  const LocateResult r = exactgeo::locate(mesh, flat({{0.25, 0.25, 2}, {2, -1, 0}, {0.5, -3, 4}, {-1, 3, 0}}));
  // Above the inside: the foot of the perpendicular.
  EXPECT_EQ(r.points[0].face, 0u);
  EXPECT_NEAR(r.points[0].barycentric[0], 0.5, 1e-15);
  EXPECT_NEAR(r.points[0].barycentric[1], 0.25, 1e-15);
  EXPECT_NEAR(r.points[0].barycentric[2], 0.25, 1e-15);
  EXPECT_DOUBLE_EQ(r.distances[0], 2);
  // Beyond corner 1: that corner, exactly.
  EXPECT_EQ(r.points[1].barycentric, (std::array<double, 3>{0, 1, 0}));
  EXPECT_DOUBLE_EQ(r.distances[1], std::sqrt(2.0));
  // Beside edge 01: its midpoint.
  EXPECT_EQ(r.points[2].barycentric, (std::array<double, 3>{0.5, 0.5, 0}));
  EXPECT_DOUBLE_EQ(r.distances[2], 5);
  // Beyond corner 2, off to the side: corner 2.
  EXPECT_EQ(r.points[3].barycentric, (std::array<double, 3>{0, 0, 1}));
  EXPECT_DOUBLE_EQ(r.distances[3], std::sqrt(5.0));
}

TEST(Locate, EmptyInputGivesEmptyResult) {
  const LocateResult r = exactgeo::locate(Mesh(right_triangle()), {});
  EXPECT_TRUE(r.points.empty());
  EXPECT_TRUE(r.distances.empty());
}

// ---- Corners, edges and ties ----------------------------------------------------------------------------

// A flat 8 x 8 grid of cells an eighth wide: corners and edge midpoints are exact in binary.
MeshSoup eighths_grid() { return exactgeo::make_grid(8, 8, 1.0, 1.0); }

// The lowest input face with a corner at vertex v.
std::uint32_t lowest_face_at(const MeshSoup& soup, std::uint32_t v) {
  for (std::uint32_t f = 0; f < exactgeo_test::face_count(soup); ++f)
    for (int k = 0; k < 3; ++k)
      if (soup.triangles[3 * f + k] == v) return f;
  return exactgeo::kNoSource;
}

TEST(Locate, PointsAtCornersAreTheCornersOnTheLowestFace) {
  const MeshSoup soup = eighths_grid();
  const Mesh mesh(soup);
  std::vector<Vec3> points;
  for (std::uint32_t v = 0; v < exactgeo_test::vertex_count(soup); ++v) points.push_back(vertex_position(soup, v));
  const LocateResult r = exactgeo::locate(mesh, flat(points));
  for (std::uint32_t v = 0; v < points.size(); ++v) {
    EXPECT_EQ(r.distances[v], 0.0) << "vertex " << v;
    EXPECT_EQ(r.points[v].face, lowest_face_at(soup, v)) << "vertex " << v;
    EXPECT_EQ(exactgeo::point_position(mesh, r.points[v]), points[v]) << "vertex " << v;
  }
}

TEST(Locate, PointsAboveCornersTieExactlyAndTakeTheLowestFace) {
  const MeshSoup soup = eighths_grid();
  std::vector<Vec3> points;
  for (std::uint32_t v = 0; v < exactgeo_test::vertex_count(soup); ++v) {
    Vec3 p = vertex_position(soup, v);
    p[2] = 0.75;
    points.push_back(p);
  }
  const LocateResult r = exactgeo::locate(Mesh(soup), flat(points));
  for (std::uint32_t v = 0; v < points.size(); ++v) {
    EXPECT_EQ(r.distances[v], 0.75) << "vertex " << v;
    EXPECT_EQ(r.points[v].face, lowest_face_at(soup, v)) << "vertex " << v;
  }
}

TEST(Locate, PointsOnEdgesLieOnTheLowestFaceOfTheEdge) {
  const MeshSoup soup = eighths_grid();
  const Mesh mesh(soup);
  const std::vector<exactgeo_test::MeshEdge> edges = exactgeo_test::unique_edges(soup);
  std::vector<Vec3> points;
  for (const auto& edge : edges) {
    const Vec3 a = vertex_position(soup, edge.low), b = vertex_position(soup, edge.high);
    points.push_back({(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
  }
  const LocateResult r = exactgeo::locate(mesh, flat(points));
  for (std::size_t i = 0; i < edges.size(); ++i) {
    std::uint32_t lowest = exactgeo::kNoSource;
    for (std::uint32_t f = 0; f < exactgeo_test::face_count(soup) && lowest == exactgeo::kNoSource; ++f) {
      const auto t = std::span(soup.triangles).subspan(3 * f, 3);
      if (std::count(t.begin(), t.end(), edges[i].low) && std::count(t.begin(), t.end(), edges[i].high)) lowest = f;
    }
    EXPECT_EQ(r.distances[i], 0.0) << "edge " << edges[i].low << "-" << edges[i].high;
    EXPECT_EQ(r.points[i].face, lowest) << "edge " << edges[i].low << "-" << edges[i].high;
    EXPECT_EQ(exactgeo::point_position(mesh, r.points[i]), points[i]);
  }
}

TEST(Locate, NeverOnADroppedFace) {
  // Face 0 repeats a vertex and face 2 repeats face 1 reversed: both dropped, face 2 in favour of face 1.
  MeshSoup soup;
  for (const Vec3& p : std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}})
    exactgeo_test::add_vertex(soup, p);
  exactgeo_test::add_triangle(soup, 0, 0, 1);
  exactgeo_test::add_triangle(soup, 0, 1, 2);
  exactgeo_test::add_triangle(soup, 2, 1, 0);
  exactgeo_test::add_triangle(soup, 0, 2, 3);
  const std::vector<double> xyz =
      flat({{0, 0, 0}, {0.5, 0, 0}, {0.5, -1, 0}, {0.7, 0.3, 1}, {0.2, 0.6, -1}, {1, 1, 0}});
  const LocateResult r = exactgeo::locate(Mesh(soup), xyz);
  const std::vector<std::uint32_t> expected = {1, 1, 1, 1, 3, 1};
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(r.points[i].face, expected[i]) << "point " << i;
  expect_matches_brute_force(soup, xyz, r, "dropped faces");
}

// ---- Generated meshes, degenerate triangles -------------------------------------------------------------

// Triangles of zero area (collinear corners, two or three coincident corners) and needles down to 1e-9 wide,
// some sharing edges with ordinary triangles, turned at random so that nothing is axis-aligned.
MeshSoup degenerate_soup(Random& random) {
  MeshSoup soup;
  const auto add = [&](const Vec3& a, const Vec3& b, const Vec3& c) {
    const std::uint32_t i = exactgeo_test::add_vertex(soup, a), j = exactgeo_test::add_vertex(soup, b),
                        k = exactgeo_test::add_vertex(soup, c);
    exactgeo_test::add_triangle(soup, i, j, k);
  };
  add({0, 0, 0}, {1, 0, 0}, {2, 0, 0});            // collinear
  add({0, 1, 0}, {0, 1, 0}, {1, 1, 0});            // two corners coincide
  add({2, 2, 2}, {2, 2, 2}, {2, 2, 2});            // a point
  add({0, 3, 0}, {1, 3, 0}, {0.5, 3 + 1e-9, 0});   // a needle across
  add({0, 4, 0}, {1e-9, 4, 0}, {0.5, 5, 0.25});    // a needle along
  add({3, 0, 0}, {4, 0, 0}, {3.5, 1e-12, 1e-12});  // thinner still
  for (int i = 0; i < 20; ++i) {
    const Vec3 a = {random.uniform(-1, 5), random.uniform(-1, 5), random.uniform(-1, 1)};
    const Vec3 b = {random.uniform(-1, 5), random.uniform(-1, 5), random.uniform(-1, 1)};
    const double t = random.uniform(-0.5, 1.5), lift = std::pow(10.0, random.uniform(-14, -3));
    add(a, b, {a[0] + t * (b[0] - a[0]) + lift, a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]) - lift});
  }
  // A fan of ordinary triangles around a needle, sharing its edges.
  const std::uint32_t hub = exactgeo_test::add_vertex(soup, {6, 6, 0});
  const std::uint32_t tip = exactgeo_test::add_vertex(soup, {8, 6, 0});
  const std::uint32_t side = exactgeo_test::add_vertex(soup, {7, 6 + 1e-10, 0});
  const std::uint32_t top = exactgeo_test::add_vertex(soup, {7, 8, 1});
  exactgeo_test::add_triangle(soup, hub, side, tip);
  exactgeo_test::add_triangle(soup, hub, top, side);
  exactgeo_test::add_triangle(soup, side, top, tip);
  return exactgeo_test::randomly_rotated(soup, random);
}

struct NamedSoup {
  std::string name;
  MeshSoup soup;
};

std::vector<NamedSoup> generated_meshes() {
  using namespace exactgeo_test;
  Random random(35);
  std::vector<std::uint32_t> stands_for;
  const MeshSoup torus = exactgeo::make_bumpy_torus(24, 10);
  return {{"icosphere", exactgeo::make_icosphere(3)},
          {"bumpy torus", exactgeo::make_bumpy_torus(40, 16)},
          {"grid", exactgeo::make_grid(12, 9, 3.0, 2.0)},
          {"noisy height field", random_height_field(random, 16, 12, 0.4, false)},
          {"smooth height field", random_height_field(random, 16, 12, 0.4, true)},
          {"grid with holes", random_grid_with_holes(random, 14, 10, 3)},
          {"convex polygon", random_convex_polygon(random, 9, 3)},
          {"sheet with fin", random_sheet_with_fin(random)},
          {"degenerate triangles", degenerate_soup(random)},
          {"coincident vertices", with_coincident_vertices(torus, random, 12, stands_for)}};
}

TEST(Locate, GeneratedMeshesMatchBruteForce) {
  std::uint64_t seed = 1;
  for (const NamedSoup& mesh : generated_meshes()) {
    const std::vector<double> xyz = random_points(mesh.soup, 2000, seed++);
    expect_matches_brute_force(mesh.soup, xyz, exactgeo::locate(Mesh(mesh.soup), xyz), mesh.name);
  }
}

TEST(Locate, DegenerateTrianglesAlone) {
  // Only zero-area faces: every answer lies on their edges.
  MeshSoup soup;
  for (const Vec3& p : std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 0, 0}, {2, 3, 0}})
    exactgeo_test::add_vertex(soup, p);
  exactgeo_test::add_triangle(soup, 0, 1, 2);
  exactgeo_test::add_triangle(soup, 2, 3, 4);
  const std::vector<double> xyz = random_points(soup, 500, 7);
  expect_matches_brute_force(soup, xyz, exactgeo::locate(Mesh(soup), xyz), "zero-area faces");
}

// ---- Threads, concurrency, scale, far points, errors -----------------------------------------------------

void expect_same(const LocateResult& a, const LocateResult& b) {
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    ASSERT_EQ(a.points[i].face, b.points[i].face) << "point " << i;
    ASSERT_EQ(a.points[i].barycentric, b.points[i].barycentric) << "point " << i;
    ASSERT_EQ(a.distances[i], b.distances[i]) << "point " << i;
  }
}

TEST(Locate, SameResultOnAnyThreadCount) {
  const MeshSoup soup = exactgeo::make_bumpy_torus(200, 60);  // 24,000 faces: the hierarchy's build is shared too
  const std::vector<double> xyz = random_points(soup, 20000, 11);
  const LocateResult one = exactgeo::locate(Mesh(soup), xyz, {.threads = 1});
  expect_same(one, exactgeo::locate(Mesh(soup), xyz, {.threads = 3}));
  expect_same(one, exactgeo::locate(Mesh(soup), xyz, {.threads = 0}));
}

TEST(Locate, HierarchyIsTheSameOnAnyTeam) {
  // Three threads and ranges of one item, whatever the cores and the mesh's size: the parallel build, which
  // locate only uses on large meshes with cores to spare, gives the one-thread hierarchy bit for bit.
  using exactgeo::detail::FaceBvh;
  const Mesh mesh(exactgeo::make_bumpy_torus(60, 24));
  exactgeo::detail::WorkerPool one(1), three(3);
  const FaceBvh a = exactgeo::detail::build_face_bvh({one}, mesh.surface());
  const FaceBvh b = exactgeo::detail::build_face_bvh({three, {}, 1}, mesh.surface());
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (std::size_t i = 0; i < a.nodes.size(); ++i) {
    EXPECT_EQ(a.nodes[i].lo, b.nodes[i].lo) << "node " << i;
    EXPECT_EQ(a.nodes[i].hi, b.nodes[i].hi) << "node " << i;
    EXPECT_EQ(a.nodes[i].first, b.nodes[i].first) << "node " << i;
    EXPECT_EQ(a.nodes[i].count, b.nodes[i].count) << "node " << i;
  }
  EXPECT_EQ(a.corners, b.corners);
  EXPECT_EQ(a.input_faces, b.input_faces);
  EXPECT_EQ(a.margin, b.margin);
}

TEST(Locate, ConcurrentFirstCallsShareOneHierarchy) {
  const MeshSoup soup = exactgeo::make_bumpy_torus(60, 24);
  const Mesh mesh(soup);
  const std::vector<double> xyz = random_points(soup, 3000, 12);
  std::vector<LocateResult> results(4);
  {
    std::vector<std::jthread> threads;
    for (LocateResult& result : results)
      threads.emplace_back([&] { result = exactgeo::locate(mesh, xyz, {.threads = 2}); });
  }
  for (const LocateResult& result : results) expect_same(results[0], result);
  expect_same(results[0], exactgeo::locate(Mesh(soup), xyz, {.threads = 1}));
}

TEST(Locate, ScaledMeshesLocateTheSamePoints) {
  // A power of two scales exactly: the same faces and weights, distances scaled (to rounding of the norm).
  const MeshSoup soup = exactgeo::make_bumpy_torus(30, 12);
  const std::vector<double> xyz = random_points(soup, 1000, 13);
  const LocateResult unscaled = exactgeo::locate(Mesh(soup), xyz);
  for (const int exponent : {-1000, -700, 700, 960}) {
    MeshSoup scaled = soup;
    std::vector<double> scaled_xyz = xyz;
    for (double& c : scaled.positions) c = std::ldexp(c, exponent);
    for (double& c : scaled_xyz) c = std::ldexp(c, exponent);
    const LocateResult r = exactgeo::locate(Mesh(scaled), scaled_xyz);
    for (std::size_t i = 0; i < r.points.size(); ++i) {
      ASSERT_EQ(r.points[i].face, unscaled.points[i].face) << "2^" << exponent << ", point " << i;
      ASSERT_EQ(r.points[i].barycentric, unscaled.points[i].barycentric) << "2^" << exponent << ", point " << i;
      // At 2^-1000 the offsets of points on the surface are subnormal: a few of their steps, scaled back.
      const double subnormal_step = std::ldexp(1.0, -1074 - exponent);
      ASSERT_NEAR(std::ldexp(r.distances[i], -exponent), unscaled.distances[i],
                  1e-15 * unscaled.distances[i] + 8 * subnormal_step)
          << "2^" << exponent << ", point " << i;
    }
  }
}

TEST(Locate, FarPointsFindTheSupportingPoint) {
  // Seen from far along a direction, the closest point of a convex mesh is the one farthest out that way (to
  // about extent^2 / distance): here a vertex. Its distance is exact to rounding, even where squaring it would
  // overflow.
  const MeshSoup soup = exactgeo::make_icosphere(2);
  const Mesh mesh(soup);
  const std::array<Vec3, 4> directions = {{{1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {0.48, -0.6, 0.64}}};
  for (const double far : {1e3, 1e6, 1e9, 1e20, 1e160, 1e300}) {
    std::vector<double> xyz;
    for (const Vec3& u : directions)
      for (double c : u) xyz.push_back(far * c);
    const LocateResult r = exactgeo::locate(mesh, xyz);
    for (std::size_t i = 0; i < directions.size(); ++i) {
      const Vec3& u = directions[i];
      double support = -HUGE_VAL;
      for (std::size_t v = 0; v < exactgeo_test::vertex_count(soup); ++v) {
        const Vec3 p = vertex_position(soup, static_cast<std::uint32_t>(v));
        support = std::max(support, p[0] * u[0] + p[1] * u[1] + p[2] * u[2]);
      }
      const std::array<double, 3> q = exactgeo::point_position(mesh, r.points[i]);
      EXPECT_NEAR(q[0] * u[0] + q[1] * u[1] + q[2] * u[2], support, 1e-7 + 4 / far) << far << ", direction " << i;
      EXPECT_NEAR(r.distances[i], far - support, 1e-15 * far + 4 / far) << far << ", direction " << i;
    }
  }
}

TEST(Locate, FarPointsOfAFarMeshMatchBruteForce) {
  // A mesh 1e6 from the origin, points 1e4 diagonals away.
  MeshSoup soup = exactgeo::make_bumpy_torus(24, 10);
  for (std::size_t v = 0; v < exactgeo_test::vertex_count(soup); ++v) soup.positions[3 * v] += 1e6;
  Random random(14);
  std::vector<double> xyz;
  for (int i = 0; i < 300; ++i)
    for (int k = 0; k < 3; ++k) xyz.push_back((k == 0 ? 1e6 : 0) + random.uniform(-3e4, 3e4));
  expect_matches_brute_force(soup, xyz, exactgeo::locate(Mesh(soup), xyz), "far from the origin");
}

void expect_error(const Mesh& mesh, const std::vector<double>& xyz, const std::string& message) {
  try {
    exactgeo::locate(mesh, xyz);
    ADD_FAILURE() << "no error; expected: " << message;
  } catch (const exactgeo::Error& e) {
    EXPECT_EQ(e.code(), exactgeo::ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
}

TEST(Locate, ErrorsNameThePoint) {
  const Mesh mesh(right_triangle());
  expect_error(mesh, {0, 0, 0, 1, 2, 3, 4}, "xyz has 7 values, not a multiple of 3");
  expect_error(mesh, {0, 0, 0, 1, 2, 3, 4, NAN, 5}, "point 2 has a non-finite coordinate");
  expect_error(mesh, {0, 0, 0, 1, 2, 3, 4, 5, -INFINITY}, "point 2 has a non-finite coordinate");
  MeshSoup far = right_triangle();
  for (double& c : far.positions) c = 1e308 - c * 1e300;
  expect_error(Mesh(far), {1e308, 1e308, 1e308, -1e308, 0, 0},
               "point 1 is farther from the surface than the largest double");
}

// ---- The located points as sources and targets ------------------------------------------------------------

TEST(Locate, LocatedPointsAreSourcesAndTargets) {
  const MeshSoup soup = exactgeo::make_bumpy_torus(40, 16);
  const Mesh mesh(soup);
  // Points at the vertices locate to the vertices: as targets, the vertices' own distances.
  std::vector<double> at_vertices(soup.positions.begin(), soup.positions.begin() + 3 * 50);
  const LocateResult vertices = exactgeo::locate(mesh, at_vertices);
  exactgeo::GeodesicSolver solver(mesh);
  const std::vector<std::uint32_t> source = {123};
  const exactgeo::GeodesicResult& to_vertices = solver.solve(source, vertices.points);
  for (std::uint32_t v = 0; v < 50; ++v)
    EXPECT_EQ(to_vertices.target_distances[v], to_vertices.distances[v]) << "vertex " << v;
  // Points off the surface as sources and as targets: the distance between two of them is the same both ways.
  const std::vector<double> xyz = random_points(soup, 10, 15);
  const std::vector<SurfacePoint> points = exactgeo::locate(mesh, xyz).points;
  std::vector<std::vector<double>> between;
  for (const SurfacePoint& point : points)
    between.push_back(solver.solve(std::span(&point, 1), points).target_distances);
  const double largest = exactgeo_test::max_finite(between[0]);
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(between[i][i], 0.0) << "point " << i;
    for (std::size_t j = 0; j < i; ++j) EXPECT_NEAR(between[i][j], between[j][i], 1e-12 * largest) << i << ", " << j;
  }
}

// ---- Every shared mesh ------------------------------------------------------------------------------------

class LocateOnSharedMesh : public testing::TestWithParam<std::string> {};

TEST_P(LocateOnSharedMesh, MatchesBruteForceAtRandomPoints) {
  const MeshSoup soup = *exactgeo_test::load_shared_mesh(GetParam());
  if (exactgeo_test::face_count(soup) > kMaxSharedFaces) GTEST_SKIP() << "left to the unsanitized build";
  const std::vector<double> xyz = random_points(soup, kSharedMeshPoints, 35);
  expect_matches_brute_force(soup, xyz, exactgeo::locate(Mesh(soup), xyz), GetParam());
}

TEST_P(LocateOnSharedMesh, VerticesLocateExactly) {
  const MeshSoup soup = *exactgeo_test::load_shared_mesh(GetParam());
  const Mesh mesh(soup);
  const std::vector<bool> kept = kept_faces(soup);
  Random random(36);
  std::vector<std::uint32_t> vertices;
  for (int i = 0; i < 200; ++i) {
    const std::uint32_t f = random.below(kept.size());
    if (kept[f]) vertices.push_back(soup.triangles[3 * f + random.below(3)]);
  }
  std::vector<double> xyz;
  for (std::uint32_t v : vertices) {
    const Vec3 p = vertex_position(soup, v);
    xyz.insert(xyz.end(), p.begin(), p.end());
  }
  const LocateResult r = exactgeo::locate(mesh, xyz);
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const Vec3 p = vertex_position(soup, vertices[i]);
    EXPECT_EQ(r.distances[i], 0.0) << GetParam() << ", vertex " << vertices[i];
    // The lowest kept face with a corner at that position, or a lower one whose edge passes exactly through it.
    std::uint32_t lowest = exactgeo::kNoSource;
    for (std::uint32_t f = 0; f < kept.size() && lowest == exactgeo::kNoSource; ++f)
      for (int k = 0; k < 3; ++k)
        if (kept[f] && vertex_position(soup, soup.triangles[3 * f + k]) == p) lowest = f;
    EXPECT_LE(r.points[i].face, lowest) << GetParam() << ", vertex " << vertices[i];
  }
}

TEST(LocateOnSharedMeshes, Available) { EXACTGEO_SKIP_IF_NO_SHARED_MESHES(); }

// "stanford-bunny.obj" as "stanford_bunny": test names take letters, digits and underscores.
std::string mesh_test_name(const testing::TestParamInfo<std::string>& mesh) {
  std::string name = mesh.param.substr(0, mesh.param.find('.'));
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

INSTANTIATE_TEST_SUITE_P(Locate, LocateOnSharedMesh, testing::ValuesIn(exactgeo_test::shared_mesh_names()),
                         mesh_test_name);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(LocateOnSharedMesh);

}  // namespace
