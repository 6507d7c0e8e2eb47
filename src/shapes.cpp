// Generated meshes: the demo's bumpy torus, test shapes, and 1-to-4 midpoint subdivision.
#include "exactgeo/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "exactgeo/error.hpp"

namespace exactgeo {
namespace {

constexpr std::uint64_t kMaxVertexCount = std::numeric_limits<std::uint32_t>::max();

// Generated sizes are checked up front so that a too-large request fails with a message naming the
// parameter instead of wrapping 32-bit indices.
void require_vertex_count_fits(std::uint64_t vertex_count, const char* what) {
  if (vertex_count > kMaxVertexCount) {
    throw Error(ErrorCode::invalid_argument, std::string(what) + ": " + std::to_string(vertex_count) +
                                                 " vertices do not fit 32-bit indices");
  }
}

void push_point(std::vector<double>& positions, double x, double y, double z) {
  positions.push_back(x);
  positions.push_back(y);
  positions.push_back(z);
}

void push_triangle(std::vector<std::uint32_t>& triangles, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  triangles.push_back(a);
  triangles.push_back(b);
  triangles.push_back(c);
}

void project_to_unit_sphere(std::vector<double>& positions, std::size_t first_vertex) {
  for (std::size_t i = first_vertex * 3; i < positions.size(); i += 3) {
    const double length = std::sqrt(positions[i] * positions[i] + positions[i + 1] * positions[i + 1] +
                                     positions[i + 2] * positions[i + 2]);
    positions[i] /= length;
    positions[i + 1] /= length;
    positions[i + 2] /= length;
  }
}

}  // namespace

MeshSoup make_icosphere(int subdivisions) {
  if (subdivisions < 0 || subdivisions > kMaxIcosphereSubdivisions) {
    throw Error(ErrorCode::invalid_argument,
                "icosphere subdivisions " + std::to_string(subdivisions) + " out of range (0 to " +
                    std::to_string(kMaxIcosphereSubdivisions) + ": 20 * 4^K faces must fit 32-bit face indices)");
  }

  // The icosahedron's vertices are the corners of three orthogonal golden rectangles.
  const double phi = std::numbers::phi;
  MeshSoup soup;
  soup.positions = {-1, phi, 0, 1, phi, 0, -1, -phi, 0, 1, -phi, 0,  //
                    0, -1, phi, 0, 1, phi, 0, -1, -phi, 0, 1, -phi,  //
                    phi, 0, -1, phi, 0, 1, -phi, 0, -1, -phi, 0, 1};
  // Counter-clockwise seen from outside.
  soup.triangles = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11, 4,
                    11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9,  4,  3, 4,  2,  3, 2, 6, 3, 6, 8,
                    3, 8,  9,  4, 9,  5, 2, 4, 11, 6, 2, 10, 8, 6,  7,  9, 8, 1};
  project_to_unit_sphere(soup.positions, 0);

  for (int level = 0; level < subdivisions; ++level) {
    const std::size_t old_vertex_count = soup.positions.size() / 3;
    soup = subdivide_midpoint(soup);
    // Only the new midpoints move: the original vertices are already on the sphere and keep their bits.
    project_to_unit_sphere(soup.positions, old_vertex_count);
  }
  return soup;
}

MeshSoup make_bumpy_torus(int major_segments, int minor_segments) {
  if (major_segments < 3 || minor_segments < 3) {
    throw Error(ErrorCode::invalid_argument, "bumpy torus needs at least 3 segments each way (got " +
                                                 std::to_string(major_segments) + " x " +
                                                 std::to_string(minor_segments) + ")");
  }
  const std::uint64_t vertex_count = std::uint64_t(major_segments) * std::uint64_t(minor_segments);
  require_vertex_count_fits(vertex_count, "bumpy torus");

  constexpr double kMajorRadius = 1.0;
  constexpr double kMinorRadius = 0.35;
  // Five bumps around the ring times three around the tube: the tube radius swings by +-30%, which
  // makes the surface clearly curved everywhere with saddles between the bumps (not only on the
  // inside of the ring), while staying far from self-intersection (0.35 * 1.3 < kMajorRadius).
  constexpr int kRingBumps = 5;
  constexpr int kTubeBumps = 3;
  constexpr double kBumpAmplitude = 0.3;

  const double two_pi = 2.0 * std::numbers::pi;
  MeshSoup soup;
  soup.positions.reserve(vertex_count * 3);
  for (int i = 0; i < major_segments; ++i) {
    const double u = two_pi * i / major_segments;
    for (int j = 0; j < minor_segments; ++j) {
      const double v = two_pi * j / minor_segments;
      const double tube_radius =
          kMinorRadius * (1.0 + kBumpAmplitude * std::sin(kRingBumps * u) * std::cos(kTubeBumps * v));
      const double ring_distance = kMajorRadius + tube_radius * std::cos(v);
      push_point(soup.positions, ring_distance * std::cos(u), ring_distance * std::sin(u),
                 tube_radius * std::sin(v));
    }
  }

  // Both directions wrap around, so the surface is closed (Euler characteristic 0).
  soup.triangles.reserve(vertex_count * 6);
  const auto index = [&](int i, int j) {
    return std::uint32_t((i % major_segments) * minor_segments + (j % minor_segments));
  };
  for (int i = 0; i < major_segments; ++i) {
    for (int j = 0; j < minor_segments; ++j) {
      const std::uint32_t a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1), d = index(i, j + 1);
      push_triangle(soup.triangles, a, b, c);
      push_triangle(soup.triangles, a, c, d);
    }
  }
  return soup;
}

MeshSoup make_grid(int nx, int ny, double width, double height) {
  if (nx < 1 || ny < 1) {
    throw Error(ErrorCode::invalid_argument,
                "grid needs at least 1 x 1 squares (got " + std::to_string(nx) + " x " + std::to_string(ny) + ")");
  }
  if (!(width > 0.0 && std::isfinite(width) && height > 0.0 && std::isfinite(height))) {
    throw Error(ErrorCode::invalid_argument, "grid width and height must be positive and finite (got " +
                                                 std::to_string(width) + " x " + std::to_string(height) + ")");
  }
  const std::uint64_t columns = std::uint64_t(nx) + 1;
  const std::uint64_t vertex_count = columns * (std::uint64_t(ny) + 1);
  require_vertex_count_fits(vertex_count, "grid");

  MeshSoup soup;
  soup.positions.reserve(vertex_count * 3);
  for (int j = 0; j <= ny; ++j) {
    // Dividing first makes the far edges land exactly on width and height.
    const double y = height * (double(j) / ny);
    for (int i = 0; i <= nx; ++i) push_point(soup.positions, width * (double(i) / nx), y, 0.0);
  }

  soup.triangles.reserve(std::size_t(nx) * std::size_t(ny) * 6);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const auto a = std::uint32_t(j * columns + i);  // (i, j)
      const std::uint32_t b = a + 1;                   // (i+1, j)
      const auto d = std::uint32_t(a + columns);       // (i, j+1)
      const std::uint32_t c = d + 1;                   // (i+1, j+1)
      // Alternating diagonals keep the triangulation symmetric, so no direction is favoured.
      if ((i + j) % 2 == 0) {
        push_triangle(soup.triangles, a, b, c);
        push_triangle(soup.triangles, a, c, d);
      } else {
        push_triangle(soup.triangles, a, b, d);
        push_triangle(soup.triangles, b, c, d);
      }
    }
  }
  return soup;
}

MeshSoup subdivide_midpoint(const MeshSoup& soup) {
  if (soup.positions.size() % 3 != 0 || soup.triangles.size() % 3 != 0) {
    throw Error(ErrorCode::invalid_mesh, "subdivide_midpoint: array sizes must be multiples of 3 (positions " +
                                             std::to_string(soup.positions.size()) + ", triangles " +
                                             std::to_string(soup.triangles.size()) + ")");
  }
  const std::size_t vertex_count = soup.positions.size() / 3;
  const std::size_t face_count = soup.triangles.size() / 3;
  for (std::size_t k = 0; k < soup.triangles.size(); ++k) {
    if (soup.triangles[k] >= vertex_count) {
      throw Error(ErrorCode::invalid_mesh, "subdivide_midpoint: face " + std::to_string(k / 3) + " vertex index " +
                                               std::to_string(soup.triangles[k]) + " out of range (" +
                                               std::to_string(vertex_count) + " vertices)");
    }
  }

  // One midpoint per undirected edge: sort the 3F corner edges by their (low, high) key, then every run
  // of equal keys shares one new vertex. New vertices come in key order, independent of face order.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> edge_of_corner(soup.triangles.size());
  for (std::size_t f = 0; f < face_count; ++f) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint64_t a = soup.triangles[f * 3 + k];
      const std::uint64_t b = soup.triangles[f * 3 + (k + 1) % 3];
      edge_of_corner[f * 3 + k] = {(std::min(a, b) << 32) | std::max(a, b), std::uint32_t(f * 3 + k)};
    }
  }
  std::sort(edge_of_corner.begin(), edge_of_corner.end());

  std::size_t edge_count = 0;
  for (std::size_t k = 0; k < edge_of_corner.size(); ++k) {
    edge_count += (k == 0 || edge_of_corner[k].first != edge_of_corner[k - 1].first);
  }
  require_vertex_count_fits(vertex_count + edge_count, "subdivide_midpoint");

  MeshSoup out;
  out.positions.reserve((vertex_count + edge_count) * 3);
  out.positions.insert(out.positions.end(), soup.positions.begin(), soup.positions.end());
  // midpoint_of_corner[f*3+k]: the new vertex on the edge from corner k to corner k+1 of face f.
  std::vector<std::uint32_t> midpoint_of_corner(soup.triangles.size());
  auto next_vertex = std::uint32_t(vertex_count);
  for (std::size_t k = 0; k < edge_of_corner.size(); ++k) {
    const std::uint64_t key = edge_of_corner[k].first;
    if (k == 0 || key != edge_of_corner[k - 1].first) {
      // Always (low + high) / 2 from the key, so the midpoint's bits do not depend on which face or
      // which direction the edge was met in.
      const std::size_t low = key >> 32, high = key & 0xffffffffu;
      for (std::size_t axis = 0; axis < 3; ++axis) {
        out.positions.push_back((soup.positions[low * 3 + axis] + soup.positions[high * 3 + axis]) / 2.0);
      }
      ++next_vertex;
    }
    midpoint_of_corner[edge_of_corner[k].second] = next_vertex - 1;
  }

  // Each triangle (a, b, c) becomes three corner triangles and the middle one, all with its winding.
  out.triangles.reserve(soup.triangles.size() * 4);
  for (std::size_t f = 0; f < face_count; ++f) {
    const std::uint32_t a = soup.triangles[f * 3], b = soup.triangles[f * 3 + 1], c = soup.triangles[f * 3 + 2];
    const std::uint32_t ab = midpoint_of_corner[f * 3], bc = midpoint_of_corner[f * 3 + 1],
                        ca = midpoint_of_corner[f * 3 + 2];
    push_triangle(out.triangles, a, ab, ca);
    push_triangle(out.triangles, ab, b, bc);
    push_triangle(out.triangles, ca, bc, c);
    push_triangle(out.triangles, ab, bc, ca);
  }
  return out;
}

}  // namespace exactgeo
