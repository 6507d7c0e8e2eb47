// What the analytic suites share (test_analytic_flat.cpp: flat domains against straight lines and visibility
// graphs; test_analytic_solids.cpp: polyhedra by unfolding, a saddle cone, exact ties): small vector algebra,
// the tolerance against closed forms, distances expected from a closed form, and the fixture that runs every
// distance test with the paper's pruning rules on and off, on one thread and on several.
#pragma once

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

#include "exactgeo/geodesic.hpp"
#include "exactgeo/mesh.hpp"
#include "test_meshes.hpp"

namespace exactgeo_test::analytic {

using exactgeo::MeshSoup;
using exactgeo_test::distance;  // of two points in space, beside the one in the plane below
using Vec2 = std::array<double, 2>;

inline constexpr double kPi = std::numbers::pi;
// Distances must match the closed forms to this fraction of the largest distance.
inline constexpr double kExact = 1e-12;

inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 scaled(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline Vec3 normalized(const Vec3& a) { return scaled(a, 1.0 / std::sqrt(dot(a, a))); }

inline Vec2 sub(const Vec2& a, const Vec2& b) { return {a[0] - b[0], a[1] - b[1]}; }
inline double cross(const Vec2& a, const Vec2& b) { return a[0] * b[1] - a[1] * b[0]; }
inline double distance(const Vec2& a, const Vec2& b) { return std::hypot(a[0] - b[0], a[1] - b[1]); }

// Expected distances from `source` given a function of the two positions.
inline std::vector<double> expected_distances(const MeshSoup& soup, std::uint32_t source,
                                              const std::function<double(const Vec3&, const Vec3&)>& truth) {
  std::vector<double> d(vertex_count(soup));
  for (std::uint32_t v = 0; v < d.size(); ++v) d[v] = truth(vertex_position(soup, source), vertex_position(soup, v));
  return d;
}

inline double euclidean(const Vec3& a, const Vec3& b) { return distance(a, b); }

// The quad a, b, c, d (in order around it) as two triangles, split along a-c, or along b-d with
// `other_diagonal`: alternating the diagonal from cell to cell keeps a grid's triangulation symmetric.
inline void add_quad(MeshSoup& soup, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d,
                     bool other_diagonal) {
  if (!other_diagonal) {
    add_triangle(soup, a, b, c);
    add_triangle(soup, a, c, d);
  } else {
    add_triangle(soup, a, b, d);
    add_triangle(soup, b, c, d);
  }
}

// Instantiated in test_analytic_solids.cpp, for the tests of both files.
class AnalyticDistance : public testing::TestWithParam<exactgeo::GeodesicOptions> {
 protected:
  std::vector<double> distances(const MeshSoup& soup, std::uint32_t source) const {
    return exactgeo::geodesic_distance(exactgeo::Mesh(soup), source, GetParam()).distances;
  }
};

}  // namespace exactgeo_test::analytic
