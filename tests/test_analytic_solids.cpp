// Distances whose true values the test computes itself on solids: the cube and the regular tetrahedron
// (unfolding), a cone whose apex is a saddle, and an icosphere whose symmetry makes many vertices tie exactly
// in the wavefront queue. Each runs with the paper's pruning rules on and off (analytic.hpp).
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
#include "exactgeo/surface_point.hpp"
#include "test_meshes.hpp"

namespace exactgeo_test::analytic {
namespace {

// ---- Convex polyhedra by unfolding ----------------------------------------------------------------------

// A convex polyhedron given by its faces (planar convex polygons, corners in order around each face; faces
// that share an edge list its two corners with identical coordinates).
//
// The geodesic distance between two surface points, by brute force: a shortest path on a convex polyhedron
// crosses each face at most once, so it runs through a simple sequence of faces; unfolding that sequence
// into the plane, edge by edge, makes the path straight. Every simple sequence from a face holding one
// point to a face holding the other is unfolded; where the straight segment between the two unfolded points
// crosses each shared edge in turn, it is a path on the surface. The shortest of those is the distance.
class ConvexPolyhedron {
 public:
  explicit ConvexPolyhedron(std::vector<std::vector<Vec3>> faces) : faces_(std::move(faces)) {
    for (std::size_t f = 0; f < faces_.size(); ++f) unfold_from(f);
  }

  double surface_distance(const Vec3& p, const Vec3& q) const {
    double best = HUGE_VAL;
    for (const Unfolding& u : unfoldings_) {
      if (!on_face(u.faces.front(), p) || !on_face(u.faces.back(), q)) continue;
      const Vec2 a = u.placements.front().image(p), b = u.placements.back().image(q);
      if (crosses_every_edge(a, b, u.edges)) best = std::min(best, distance(a, b));
    }
    return best;
  }

 private:
  // Maps the points of one face rigidly into the plane of the unfolding.
  struct Placement {
    Vec3 origin3, u3, v3;  // a point of the face and an orthonormal frame of its plane
    Vec2 origin2, u2, v2;  // their images
    Vec2 image(const Vec3& p) const {
      const Vec3 d = sub(p, origin3);
      const double a = dot(d, u3), b = dot(d, v3);
      return {origin2[0] + a * u2[0] + b * v2[0], origin2[1] + a * u2[1] + b * v2[1]};
    }
  };
  struct Unfolding {
    std::vector<std::size_t> faces;
    std::vector<Placement> placements;       // one per face
    std::vector<std::array<Vec2, 2>> edges;  // the images of the shared edges, in order
  };

  Vec3 centroid(std::size_t f) const {
    Vec3 c = {0, 0, 0};
    for (const Vec3& p : faces_[f]) c = add(c, p);
    return scaled(c, 1.0 / double(faces_[f].size()));
  }
  Vec3 normal(std::size_t f) const {
    const auto& c = faces_[f];
    return normalized(cross(sub(c[1], c[0]), sub(c[2], c[0])));
  }
  bool on_face(std::size_t f, const Vec3& p) const {
    constexpr double kSlack = 1e-12;
    const auto& c = faces_[f];
    const Vec3 n = normal(f);
    if (std::abs(dot(sub(p, c[0]), n)) > kSlack) return false;
    for (std::size_t i = 0; i < c.size(); ++i)
      if (dot(cross(sub(c[(i + 1) % c.size()], c[i]), sub(p, c[i])), n) < -kSlack) return false;
    return true;
  }
  // The edge (two corners) that faces f and g share, if any.
  std::optional<std::array<Vec3, 2>> shared_edge(std::size_t f, std::size_t g) const {
    const auto &a = faces_[f], &b = faces_[g];
    for (std::size_t i = 0; i < a.size(); ++i)
      for (std::size_t j = 0; j < b.size(); ++j) {
        const Vec3 &p = a[i], &q = a[(i + 1) % a.size()];
        const Vec3 &r = b[j], &s = b[(j + 1) % b.size()];
        if ((p == r && q == s) || (p == s && q == r)) return std::array<Vec3, 2>{p, q};
      }
    return std::nullopt;
  }

  void unfold_from(std::size_t first) {
    const auto& c = faces_[first];
    const Vec3 u3 = normalized(sub(c[1], c[0]));
    Unfolding u;
    u.faces = {first};
    u.placements = {Placement{c[0], u3, cross(normal(first), u3), {0, 0}, {1, 0}, {0, 1}}};
    extend(u);
  }

  void extend(Unfolding& u) {
    unfoldings_.push_back(u);
    const std::size_t f = u.faces.back();
    const Placement at = u.placements.back();  // a copy: extending u below reallocates
    for (std::size_t g = 0; g < faces_.size(); ++g) {
      if (std::find(u.faces.begin(), u.faces.end(), g) != u.faces.end()) continue;
      const auto edge = shared_edge(f, g);
      if (!edge) continue;
      // g turns about the shared edge into the plane, on the far side of the edge from f.
      const Vec3 u3 = normalized(sub((*edge)[1], (*edge)[0]));
      const Vec3 to_centre = sub(centroid(g), (*edge)[0]);
      const Vec3 v3 = normalized(sub(to_centre, scaled(u3, dot(to_centre, u3))));
      const Vec2 e0 = at.image((*edge)[0]), e1 = at.image((*edge)[1]);
      const double length = distance(e0, e1);
      const Vec2 u2 = {(e1[0] - e0[0]) / length, (e1[1] - e0[1]) / length};
      Vec2 v2 = {-u2[1], u2[0]};
      const Vec2 f_centre = sub(at.image(centroid(f)), e0);
      if (f_centre[0] * v2[0] + f_centre[1] * v2[1] > 0) v2 = {-v2[0], -v2[1]};
      u.faces.push_back(g);
      u.placements.push_back(Placement{(*edge)[0], u3, v3, e0, u2, v2});
      u.edges.push_back({e0, e1});
      extend(u);
      u.faces.pop_back();
      u.placements.pop_back();
      u.edges.pop_back();
    }
  }

  // Whether segment ab crosses each edge, in order along ab.
  static bool crosses_every_edge(const Vec2& a, const Vec2& b, const std::vector<std::array<Vec2, 2>>& edges) {
    constexpr double kSlack = 1e-12;
    const Vec2 d = sub(b, a);
    double previous = -kSlack;
    for (const auto& [e0, e1] : edges) {
      const Vec2 e = sub(e1, e0);
      const double denominator = cross(d, e);
      if (std::abs(denominator) < kSlack) return false;
      const double t = cross(sub(e0, a), e) / denominator;  // along ab
      const double s = cross(sub(e0, a), d) / denominator;  // along the edge
      if (t < previous - kSlack || t > 1 + kSlack || s < -kSlack || s > 1 + kSlack) return false;
      previous = t;
    }
    return true;
  }

  std::vector<std::vector<Vec3>> faces_;
  std::vector<Unfolding> unfoldings_;
};

ConvexPolyhedron unit_cube() {
  std::vector<std::vector<Vec3>> faces;
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {0.0, 1.0}) {
      const int b = (axis + 1) % 3, c = (axis + 2) % 3;
      constexpr double kSquare[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      std::vector<Vec3> face;
      for (const auto& corner : kSquare) {
        Vec3 p;
        p[axis] = side;
        p[b] = corner[0];
        p[c] = corner[1];
        face.push_back(p);
      }
      faces.push_back(face);
    }
  return ConvexPolyhedron(faces);
}

// The surface of the unit cube, each face an n-by-n grid of squares split along alternating diagonals.
// Vertices are the lattice points k/n on the surface, each once.
MeshSoup cube_surface_mesh(int n) {
  MeshSoup soup;
  std::map<std::array<int, 3>, std::uint32_t> index;
  const auto vertex = [&](std::array<int, 3> lattice) {
    auto [it, inserted] = index.try_emplace(lattice, static_cast<std::uint32_t>(vertex_count(soup)));
    if (inserted) add_vertex(soup, {double(lattice[0]) / n, double(lattice[1]) / n, double(lattice[2]) / n});
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {0, n}) {
      const int b = (axis + 1) % 3, c = (axis + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          std::array<std::array<int, 3>, 4> corner;
          for (int k = 0; k < 4; ++k) {
            corner[k][axis] = side;
            corner[k][b] = i + (k == 1 || k == 2);
            corner[k][c] = j + (k >= 2);
          }
          const std::uint32_t p = vertex(corner[0]), q = vertex(corner[1]), r = vertex(corner[2]),
                              s = vertex(corner[3]);
          add_quad(soup, p, q, r, s, (i + j) % 2 != 0);
        }
    }
  return soup;
}

const std::array<Vec3, 4> kTetrahedronCorners = {{{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}};
const std::array<std::array<std::uint32_t, 3>, 4> kTetrahedronFaces = {{{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}}};
const double kTetrahedronEdge = 2 * std::numbers::sqrt2;

MeshSoup tetrahedron_mesh() {
  MeshSoup soup;
  for (const Vec3& p : kTetrahedronCorners) add_vertex(soup, p);
  for (const auto& f : kTetrahedronFaces) add_triangle(soup, f[0], f[1], f[2]);
  return soup;
}

ConvexPolyhedron tetrahedron() {
  std::vector<std::vector<Vec3>> faces;
  for (const auto& f : kTetrahedronFaces)
    faces.push_back({kTetrahedronCorners[f[0]], kTetrahedronCorners[f[1]], kTetrahedronCorners[f[2]]});
  return ConvexPolyhedron(faces);
}

// ---- A cone with a saddle apex --------------------------------------------------------------------------

// `rays` planar sectors around an apex whose angles add up to `total_angle` > 2*pi, cut by rings at radii
// 1..rings into a triangle mesh. In 3D the rays zigzag up and down so that consecutive rays meet at the
// sector angle; each sector is planar, so intrinsically the surface is a flat cone of the given total angle.
// Vertex 0 is the apex; ring k (1-based) on ray i is vertex 1 + (k - 1) * rays + i.
struct SaddleCone {
  int rays = 20;
  int rings = 4;
  double total_angle = 2.5 * kPi;

  double sector_angle() const { return total_angle / rays; }

  MeshSoup mesh() const {
    // Rays at azimuth 2*pi*i/rays and elevation +-beta meet at sector_angle when
    // cos(sector) = cos^2(beta) cos(step) - sin^2(beta).
    const double step = 2 * kPi / rays;
    const double beta = std::asin(std::sqrt((std::cos(step) - std::cos(sector_angle())) / (1 + std::cos(step))));
    MeshSoup soup;
    add_vertex(soup, {0, 0, 0});
    for (int k = 1; k <= rings; ++k)
      for (int i = 0; i < rays; ++i) {
        const double elevation = i % 2 == 0 ? beta : -beta;
        add_vertex(soup, {k * std::cos(elevation) * std::cos(step * i), k * std::cos(elevation) * std::sin(step * i),
                          k * std::sin(elevation)});
      }
    for (int i = 0; i < rays; ++i) {
      const int next = (i + 1) % rays;
      add_triangle(soup, 0, vertex(1, i), vertex(1, next));
      for (int k = 1; k < rings; ++k) {
        if ((i + k) % 2 == 0) {
          add_triangle(soup, vertex(k, i), vertex(k + 1, i), vertex(k + 1, next));
          add_triangle(soup, vertex(k, i), vertex(k + 1, next), vertex(k, next));
        } else {
          add_triangle(soup, vertex(k, i), vertex(k + 1, i), vertex(k, next));
          add_triangle(soup, vertex(k + 1, i), vertex(k + 1, next), vertex(k, next));
        }
      }
    }
    return soup;
  }

  std::uint32_t vertex(int ring, int ray) const { return static_cast<std::uint32_t>(1 + (ring - 1) * rays + ray); }

  // Intrinsic distance between two vertices: unroll the cone around the apex. Within an angle below pi the
  // straight segment stays on the surface; at pi or more the shortest path runs through the apex.
  double distance(std::uint32_t a, std::uint32_t b) const {
    const auto radius = [&](std::uint32_t v) { return v == 0 ? 0.0 : double((v - 1) / rays + 1); };
    const auto ray = [&](std::uint32_t v) { return v == 0 ? 0 : int((v - 1) % rays); };
    const int apart = std::abs(ray(a) - ray(b));
    const double angle = std::min(apart, rays - apart) * sector_angle();
    const double ra = radius(a), rb = radius(b);
    if (angle >= kPi) return ra + rb;
    return std::hypot(ra - rb * std::cos(angle), rb * std::sin(angle));
  }
};

INSTANTIATE_TEST_SUITE_P(Analytic, AnalyticDistance, testing::ValuesIn(exactgeo_test::kAllVariants),
                         exactgeo_test::variant_name);
INSTANTIATE_TEST_SUITE_P(AnalyticThreads, AnalyticDistance, testing::ValuesIn(exactgeo_test::kParallelVariants),
                         exactgeo_test::variant_name);

TEST(AnalyticReference, UnfoldingHandValues) {
  // Unit cube: two faces unfolded side by side make a 2 x 1 rectangle (corner to opposite corner: sqrt(5));
  // a far face's centre sits at (1.5, 0.5) from the corner; centre to opposite centre is 0.5 + 1 + 0.5.
  const ConvexPolyhedron cube = unit_cube();
  EXPECT_DOUBLE_EQ(cube.surface_distance({0, 0, 0}, {1, 1, 1}), std::sqrt(5.0));
  EXPECT_DOUBLE_EQ(cube.surface_distance({0, 0, 0}, {1, 0.5, 0.5}), std::sqrt(2.5));
  EXPECT_DOUBLE_EQ(cube.surface_distance({0, 0, 0}, {0.5, 0.5, 0}), std::sqrt(0.5));
  EXPECT_DOUBLE_EQ(cube.surface_distance({0.5, 0.5, 0}, {0.5, 0.5, 1}), 2.0);
  EXPECT_DOUBLE_EQ(cube.surface_distance({0.5, 0.5, 0}, {1, 0.5, 0.5}), 1.0);
  EXPECT_DOUBLE_EQ(cube.surface_distance({0.5, 0.5, 0}, {1, 1, 1}), std::sqrt(2.5));

  // Regular tetrahedron, edge a = 2*sqrt(2): a vertex to another, to the midpoint of edge v1v2 (the height
  // of face v0v1v2, h = a*sqrt(3)/2), and to the point 1/4 v1 + 1/4 v2 + 1/2 v3 of the opposite face: with
  // that face unfolded across edge v1v3 the point lies a/8 along and 5h/4 across from v0, so at a*sqrt(19)/4.
  const ConvexPolyhedron tetra = tetrahedron();
  const double a = kTetrahedronEdge;
  EXPECT_DOUBLE_EQ(tetra.surface_distance(kTetrahedronCorners[0], kTetrahedronCorners[2]), a);
  EXPECT_DOUBLE_EQ(tetra.surface_distance(kTetrahedronCorners[0], {0, 0, -1}), a * std::sqrt(3.0) / 2);
  EXPECT_DOUBLE_EQ(tetra.surface_distance(kTetrahedronCorners[0], {-0.5, -0.5, 0}), a * std::sqrt(19.0) / 4);
}

TEST_P(AnalyticDistance, CubeSurface) {
  const MeshSoup soup = cube_surface_mesh(6);
  ASSERT_EQ(vertex_count(soup), 6u * 36 + 2);
  const ConvexPolyhedron cube = unit_cube();
  const auto on_cube = [&](const Vec3& p, const Vec3& q) { return cube.surface_distance(p, q); };
  for (const Vec3& source_position : {Vec3{0, 0, 0}, Vec3{0.5, 0.5, 0}, Vec3{1, 0.5, 1. / 3}}) {
    const std::uint32_t source = vertex_at(soup, source_position);
    SCOPED_TRACE(testing::Message() << "source " << source);
    const std::vector<double> d = distances(soup, source);
    EXPECT_TRUE(distances_match(d, expected_distances(soup, source, on_cube), kExact));
    if (source_position == Vec3{0, 0, 0}) {
      // Cycling the coordinates maps the lattice onto itself and fixes the corner: equal distances.
      for (std::uint32_t v = 0; v < vertex_count(soup); ++v) {
        const Vec3 p = vertex_position(soup, v);
        EXPECT_NEAR(d[v], d[vertex_at(soup, {p[1], p[2], p[0]})], 1e-15 * 3) << "vertex " << v;
      }
    }
  }
}

TEST_P(AnalyticDistance, CubeSurfacePointsAndTheirPaths) {
  const MeshSoup soup = cube_surface_mesh(4);
  const exactgeo::Mesh mesh(soup);
  const ConvexPolyhedron cube = unit_cube();
  Random random(8);
  const auto random_point = [&] {
    const double u = random.uniform(0, 1), v = random.uniform(0, 1);
    return exactgeo::SurfacePoint{random.below(exactgeo_test::face_count(soup)),
                                  {std::min(u, v), std::max(u, v) - std::min(u, v), 1 - std::max(u, v)}};
  };
  exactgeo::GeodesicSolver solver(mesh);
  for (int trial = 0; trial < 6; ++trial) {
    const exactgeo::SurfacePoint source = random_point();
    std::vector<exactgeo::SurfacePoint> targets;
    for (int i = 0; i < 10; ++i) targets.push_back(random_point());
    const auto& result = solver.solve(std::span(&source, 1), targets, GetParam());
    const Vec3 s = exactgeo::point_position(mesh, source);
    for (std::size_t t = 0; t < targets.size(); ++t) {
      const double expected = cube.surface_distance(s, exactgeo::point_position(mesh, targets[t]));
      EXPECT_NEAR(result.target_distances[t], expected, kExact * 3) << "trial " << trial << " target " << t;
      EXPECT_NEAR(solver.path_to_target(t).length, expected, 1e-9 * 3) << "trial " << trial << " target " << t;
    }
  }
}

TEST_P(AnalyticDistance, RegularTetrahedron) {
  const MeshSoup soup = tetrahedron_mesh();
  for (std::uint32_t source = 0; source < 4; ++source) {
    const std::vector<double> d = distances(soup, source);
    for (std::uint32_t v = 0; v < 4; ++v) EXPECT_NEAR(d[v], v == source ? 0.0 : kTetrahedronEdge, kExact);
  }
}

TEST_P(AnalyticDistance, SubdividedTetrahedron) {
  const ConvexPolyhedron tetra = tetrahedron();
  const auto on_tetrahedron = [&](const Vec3& p, const Vec3& q) { return tetra.surface_distance(p, q); };
  MeshSoup soup = tetrahedron_mesh();
  for (int level = 1; level <= 3; ++level) {
    soup = exactgeo::subdivide_midpoint(soup);
    SCOPED_TRACE(testing::Message() << "subdivided " << level << " times");
    const std::vector<double> d = distances(soup, 0);
    const double a = kTetrahedronEdge;
    EXPECT_NEAR(d[1], a, a * kExact);
    EXPECT_NEAR(d[vertex_at(soup, {1, 0, 0})], a / 2, a * kExact);                    // midpoint of edge v0v1
    EXPECT_NEAR(d[vertex_at(soup, {0, 0, -1})], a * std::sqrt(3.0) / 2, a * kExact);  // of edge v1v2
    if (level >= 2) {
      EXPECT_NEAR(d[vertex_at(soup, {-0.5, -0.5, 0})], a * std::sqrt(19.0) / 4, a * kExact);
    }
    EXPECT_TRUE(distances_match(d, expected_distances(soup, 0, on_tetrahedron), kExact));
  }
  // A source on the opposite face, away from any vertex of the original tetrahedron.
  const std::uint32_t source = vertex_at(soup, {-0.5, -0.5, 0});
  EXPECT_TRUE(distances_match(distances(soup, source), expected_distances(soup, source, on_tetrahedron), kExact));
}

TEST_P(AnalyticDistance, SaddleConeBendsPathsAtTheApex) {
  const SaddleCone cone;
  const MeshSoup soup = cone.mesh();
  // Sources on ring 2, on the rim, and at the apex.
  for (std::uint32_t source : {cone.vertex(2, 0), cone.vertex(4, 3), 0u}) {
    SCOPED_TRACE(testing::Message() << "source " << source);
    const std::vector<double> d = distances(soup, source);
    std::vector<double> expected(vertex_count(soup));
    for (std::uint32_t v = 0; v < expected.size(); ++v) expected[v] = cone.distance(source, v);
    EXPECT_TRUE(distances_match(d, expected, kExact));
  }
  // Rays 9 to 11 are at least 9 sectors (202.5 degrees) around the apex from ray 0 either way: in the shadow
  // of a source on ray 0, reached through the apex, d = d(apex) + |apex - point|.
  const std::uint32_t source = cone.vertex(2, 0);
  const std::vector<double> d = distances(soup, source);
  for (int ray : {9, 10, 11})
    for (int ring = 1; ring <= cone.rings; ++ring) {
      const std::uint32_t v = cone.vertex(ring, ray);
      EXPECT_NEAR(d[v], d[0] + exactgeo_test::distance_between(soup, 0, v), kExact * 2 * cone.rings) << "vertex " << v;
    }
}

TEST_P(AnalyticDistance, ExactTiesOnAnIcosphere) {
  const MeshSoup soup = exactgeo::make_icosphere(3);
  const std::vector<double> d = distances(soup, 0);
  // A turn by 2*pi/5 about the axis through vertex 0 maps the icosphere onto itself.
  const Vec3 axis = vertex_position(soup, 0);
  const double c = std::cos(2 * kPi / 5), s = std::sin(2 * kPi / 5);
  for (std::uint32_t v = 0; v < vertex_count(soup); ++v) {
    ASSERT_TRUE(std::isfinite(d[v]));
    const Vec3 p = vertex_position(soup, v);
    const Vec3 turned = add(add(scaled(p, c), scaled(cross(axis, p), s)), scaled(axis, dot(axis, p) * (1 - c)));
    std::uint32_t partner = 0;
    for (std::uint32_t w = 1; w < vertex_count(soup); ++w)
      if (distance(vertex_position(soup, w), turned) < distance(vertex_position(soup, partner), turned)) partner = w;
    ASSERT_LT(distance(vertex_position(soup, partner), turned), 1e-9);
    EXPECT_NEAR(d[v], d[partner], 1e-14) << "vertex " << v << " and its turned partner " << partner;
  }
}

}  // namespace
}  // namespace exactgeo_test::analytic
