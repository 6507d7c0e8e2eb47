// The reference that exactgeo::locate is tested against (test_locate.cpp): the closest point of every kept
// face to a point in space, by an independent formula in long double, searched over all faces; the checks
// of a locate result against it; and seeded points on, near and far from a mesh.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "test_meshes.hpp"

namespace exactgeo_test::closest_point {

using exactgeo::LocateResult;
using exactgeo::MeshSoup;
using exactgeo::SurfacePoint;

// The distance agrees with the reference to this, relative to the distance, or to this times a thousandth of
// the mesh's diagonal for points on or very near the surface (where rounding of the coordinates dominates).
inline constexpr double kDistanceTolerance = 1e-12;
// Located points agree with the reference's to this times the diagonal, unless the reference finds another
// point as close (a tie between distinct points, where either is right).
inline constexpr double kPositionTolerance = 1e-9;

using Real = long double;
using RealVec = std::array<Real, 3>;

inline RealVec real(const Vec3& v) { return {v[0], v[1], v[2]}; }
inline RealVec minus(const RealVec& a, const RealVec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Real dot(const RealVec& a, const RealVec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline RealVec along(const RealVec& from, const RealVec& direction, Real t) {
  return {from[0] + t * direction[0], from[1] + t * direction[1], from[2] + t * direction[2]};
}
inline Vec3 to_double(const RealVec& v) { return {double(v[0]), double(v[1]), double(v[2])}; }
inline Real real_length(const RealVec& v) { return std::sqrt(dot(v, v)); }
inline double length(const RealVec& v) { return double(real_length(v)); }
// |a - b|, without the underflow of squares of doubles (lengths below 1e-154) or their overflow (above 1e154).
inline double distance_apart(const Vec3& a, const Vec3& b) { return length(minus(real(a), real(b))); }

struct Reference {
  double distance = HUGE_VAL;
  Vec3 position{};
};

// The closest point of the triangle to p, written differently from the library's: the nearest of the three
// edges, and the orthogonal projection onto the plane where it falls inside the triangle, decided by 2D
// orientation tests in an orthonormal frame of the plane (the longest edge, and the apex's offset from it,
// orthogonalised twice, which keeps the frame accurate on triangles a billion times longer than wide).
inline Reference closest_on_triangle(const RealVec& p, const std::array<RealVec, 3>& corner) {
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
  const int i =
      static_cast<int>(std::max_element(squared_lengths.begin(), squared_lengths.end()) - squared_lengths.begin());
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
inline std::vector<bool> kept_faces(const MeshSoup& soup) {
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
      RealVec center;
      for (int k = 0; k < 3; ++k) center[k] = (Real(c[0][k]) + Real(c[1][k]) + Real(c[2][k])) / 3;
      Real radius = 0;
      for (const Vec3& corner : c) radius = std::max(radius, real_length(minus(center, real(corner))));
      faces_.push_back(f);
      centers_.push_back(center);
      radii_.push_back(radius * (1 + 1e-9L));
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
    Real bound = HUGE_VALL;
    for (std::uint32_t v : used_vertices_)
      bound = std::min(bound, real_length(minus(real(p), real(vertex_position(soup_, v)))));
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
      tie = tie || (candidate.distance <= distance + tolerance && distance_apart(candidate.position, position) > apart);
    });
    return tie;
  }

 private:
  Reference measure(const Vec3& p, std::uint32_t f) const {
    const std::array<Vec3, 3> c = corners(f);
    return closest_on_triangle(real(p), {real(c[0]), real(c[1]), real(c[2])});
  }
  // In long double, whose range squares lengths of 1e-300 and 1e300 (in double, a mesh at 1e-162 has its squares
  // underflow, and faces that hold the closest point were skipped).
  template <class Visit>
  void for_faces_within(const Vec3& p, Real bound, Visit&& visit) const {
    for (std::size_t i = 0; i < faces_.size(); ++i) {
      const RealVec offset = minus(real(p), centers_[i]);
      const Real reach = bound * (1 + 1e-12L) + radii_[i];
      if (dot(offset, offset) <= reach * reach) visit(faces_[i]);
    }
  }

  const MeshSoup& soup_;
  std::vector<bool> kept_;
  std::vector<std::uint32_t> faces_;
  std::vector<RealVec> centers_;
  std::vector<Real> radii_;
  std::vector<std::uint32_t> used_vertices_;
};

struct Bounds {
  Vec3 lo = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  double diagonal() const { return distance_apart(lo, hi); }
};

inline Bounds bounds_of(const MeshSoup& soup) {
  Bounds bounds;
  for (std::size_t v = 0; v < exactgeo_test::vertex_count(soup); ++v)
    for (int k = 0; k < 3; ++k) {
      bounds.lo[k] = std::min(bounds.lo[k], soup.positions[3 * v + k]);
      bounds.hi[k] = std::max(bounds.hi[k], soup.positions[3 * v + k]);
    }
  return bounds;
}

// The located point in space, as the barycentric combination of its face's corners, in long double.
inline RealVec located_position(const BruteForce& brute, const SurfacePoint& point) {
  const std::array<Vec3, 3> c = brute.corners(point.face);
  RealVec q = {0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (int axis = 0; axis < 3; ++axis) q[axis] += Real(point.barycentric[k]) * Real(c[k][axis]);
  return q;
}

// What a locate result found against the reference: the first fault ("" if none), the ties between distinct
// points, and the largest distance error relative to the distance (or to a thousandth of the diagonal).
struct LocateCheck {
  std::string fault;
  std::size_t ties = 0;
  double worst_relative = 0;
};

// Every point of `xyz` located on a kept face, with valid barycentric coordinates, at the reference's distance
// (kDistanceTolerance), the located point at that distance from it, and at the reference's closest point
// (kPositionTolerance) unless the reference finds a tie. Stops at the first fault.
inline LocateCheck check_against_brute_force(const MeshSoup& soup, const std::vector<double>& xyz,
                                             const LocateResult& located) {
  const BruteForce brute(soup);
  const double scale = bounds_of(soup).diagonal();
  LocateCheck check;
  if (located.points.size() != xyz.size() / 3 || located.distances.size() != xyz.size() / 3) {
    check.fault = "located " + std::to_string(located.points.size()) + " points and " +
                  std::to_string(located.distances.size()) + " distances for " + std::to_string(xyz.size() / 3);
    return check;
  }
  const auto number = [](long double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17Lg", value);
    return std::string(text);
  };
  const auto fail = [&](std::size_t i, const std::string& what) {
    check.fault = "point " + std::to_string(i) + " (" + number(xyz[3 * i]) + " " + number(xyz[3 * i + 1]) + " " +
                  number(xyz[3 * i + 2]) + "): " + what;
    return check;
  };
  for (std::size_t i = 0; i < located.points.size(); ++i) {
    const Vec3 p = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
    const SurfacePoint& point = located.points[i];
    if (!brute.kept(point.face)) return fail(i, "on face " + std::to_string(point.face) + ", not a kept face");
    const auto& b = point.barycentric;
    if (!(b[0] >= 0 && b[1] >= 0 && b[2] >= 0 && b[0] <= 1 && b[1] <= 1 && b[2] <= 1) ||
        !(std::abs(b[0] + b[1] + b[2] - 1) <= 1e-15))
      return fail(i, "barycentric " + number(b[0]) + " " + number(b[1]) + " " + number(b[2]));

    const Reference reference = brute.closest(p);
    const double tolerance = kDistanceTolerance * std::max(reference.distance, 1e-3 * scale);
    if (!(std::abs(located.distances[i] - reference.distance) <= tolerance))
      return fail(i, "distance " + number(located.distances[i]) + ", the reference's " + number(reference.distance));
    const RealVec q = located_position(brute, point);
    const double apart = length(minus(real(p), q));
    if (!(std::abs(apart - located.distances[i]) <= tolerance))
      return fail(i, "at " + number(apart) + " from the point located, its distance " + number(located.distances[i]));
    check.worst_relative = std::max(check.worst_relative, std::abs(located.distances[i] - reference.distance) /
                                                              std::max(reference.distance, 1e-3 * scale));
    if (distance_apart(to_double(q), reference.position) > kPositionTolerance * scale) {
      if (!brute.ties_elsewhere(p, reference.distance, to_double(q), tolerance, kPositionTolerance * scale))
        return fail(i, "located at " + number(q[0]) + " " + number(q[1]) + " " + number(q[2]) + ", the closest is " +
                           number(reference.position[0]) + " " + number(reference.position[1]) + " " +
                           number(reference.position[2]));
      ++check.ties;
    }
  }
  return check;
}

// check_against_brute_force as a test expectation, with a line saying how close the answers came.
inline void expect_matches_brute_force(const MeshSoup& soup, const std::vector<double>& xyz,
                                       const LocateResult& located, const std::string& label) {
  const LocateCheck check = check_against_brute_force(soup, xyz, located);
  EXPECT_EQ(check.fault, "") << label;
  std::printf(
      "  %s: %zu points, distance errors up to %.2g (of the distance, or of a thousandth of the diagonal), "
      "%zu ties between distinct points\n",
      label.c_str(), located.points.size(), check.worst_relative, check.ties);
}

// A random point of a random kept face.
inline Vec3 random_surface_point(const MeshSoup& soup, const std::vector<bool>& kept, Random& random) {
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
inline std::vector<double> random_points(const MeshSoup& soup, std::size_t count, std::uint64_t seed) {
  Random random(seed);
  const std::vector<bool> kept = kept_faces(soup);
  const auto [lo, hi] = bounds_of(soup);
  const double scale = distance_apart(lo, hi);
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

inline std::vector<double> flat(const std::vector<Vec3>& points) {
  std::vector<double> xyz;
  for (const Vec3& p : points) xyz.insert(xyz.end(), p.begin(), p.end());
  return xyz;
}

}  // namespace exactgeo_test::closest_point
