// Validation of surface points against the mesh, and the convenience constructors.
#include "surface_point.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "exactgeo/error.hpp"

namespace exactgeo {
namespace detail {
namespace {

std::string coordinates_text(const std::array<double, 3>& b) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.17g, %.17g, %.17g)", b[0], b[1], b[2]);
  return text;
}

}  // namespace

LocatedPoint locate_checked(const SurfaceMesh& mesh, const SurfacePoint& point, const std::string& what) {
  const std::size_t input_faces = mesh.input_face_to_surface.size();
  if (point.face >= input_faces)
    throw Error(ErrorCode::invalid_argument, what + ": face " + std::to_string(point.face) +
                                                 " is out of range (mesh has " + std::to_string(input_faces) +
                                                 " faces)");
  LocatedPoint located;
  located.face = mesh.input_face_to_surface[point.face];
  if (located.face == kNone)
    throw Error(ErrorCode::invalid_argument, what + ": face " + std::to_string(point.face) +
                                                 " repeats a vertex and was dropped from the mesh");
  // A dropped duplicate of the kept face lists the same corners in another order: weights follow corners.
  std::array<double, 3> b = point.barycentric;
  const std::uint32_t kept = mesh.surface_face_to_input[located.face];
  if (kept != point.face) {
    const auto corner = [&](std::uint32_t face, int k) {
      return mesh.canonical(mesh.input_triangles[3 * face + k]);
    };
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j)
        if (corner(kept, k) == corner(point.face, j)) b[k] = point.barycentric[j];
  }
  const double sum = b[0] + b[1] + b[2];
  const bool finite = std::isfinite(b[0]) && std::isfinite(b[1]) && std::isfinite(b[2]);
  if (!finite || std::min({b[0], b[1], b[2]}) < -kBarycentricSlack || std::abs(sum - 1) > kBarycentricSlack)
    throw Error(ErrorCode::invalid_argument,
                what + ": " + coordinates_text(b) + " are not barycentric coordinates on face " +
                    std::to_string(point.face) + " (each must be >= 0 and their sum 1)");

  // Clamp rounding noise, snap what is left of it to the edges and corners, and rescale to sum to 1.
  std::array<double, 3> clean;
  for (int k = 0; k < 3; ++k) clean[k] = std::clamp(b[k], 0.0, 1.0);
  for (int pass = 0; pass < 2; ++pass) {
    const double total = clean[0] + clean[1] + clean[2];
    for (double& c : clean) c = c / total < kBarycentricSnap ? 0.0 : c / total;
  }
  located.barycentric = clean;
  const int zeros = (clean[0] == 0) + (clean[1] == 0) + (clean[2] == 0);
  if (zeros == 2) {
    const int k = clean[0] != 0 ? 0 : (clean[1] != 0 ? 1 : 2);
    located.vertex = mesh.corner_vertex[3 * located.face + k];
  } else if (zeros == 1) {
    // Halfedge i runs from corner i to corner i + 1: the edge without the zero corner.
    const int zero = clean[0] == 0 ? 0 : (clean[1] == 0 ? 1 : 2);
    located.edge = 3 * located.face + (zero + 1) % 3;
  }
  return located;
}

std::array<double, 3> face_point_position(const SurfaceMesh& mesh, std::uint32_t face,
                                          const std::array<double, 3>& barycentric, PositionFrame frame) {
  std::array<double, 3> sum = {0, 0, 0};
  for (std::uint32_t k = 0; k < 3; ++k) {
    const std::uint32_t v = mesh.surface_to_input[mesh.corner_vertex[3 * face + k]];
    const std::array<double, 3> corner = frame == PositionFrame::input ? mesh.input_position(v) : mesh.position(v);
    for (std::uint32_t axis = 0; axis < 3; ++axis) sum[axis] += barycentric[k] * corner[axis];
  }
  return sum;
}

std::span<const std::uint32_t> source_vertex_copies(const SurfaceMesh& mesh, std::uint32_t vertex) {
  const std::size_t vertex_count = mesh.input_positions.size() / 3;
  if (vertex >= vertex_count)
    throw Error(ErrorCode::invalid_argument, "source vertex " + std::to_string(vertex) +
                                                 " is out of range (mesh has " + std::to_string(vertex_count) +
                                                 " vertices)");
  const auto copies = mesh.copies_of(vertex);
  if (copies.empty())
    throw Error(ErrorCode::invalid_argument, "source vertex " + std::to_string(vertex) + " is used by no face");
  return copies;
}

bool lies_on_side(const SurfaceMesh& mesh, const LocatedPoint& point, std::uint32_t h) {
  const double length = mesh.halfedges[h].length, near = on_side_tolerance(mesh);
  // A side of no length holds a point only at its ends: the point is at a vertex's place, which the face's
  // other sides hold (across it, its place along the side would be 0 / 0).
  if (!(length > 0)) return false;
  if (h == point.edge) return true;
  const auto [x, y] = position_in_frame(mesh, point, h);
  return y <= near && x >= -near && x <= length + near;
}

std::vector<LocatedPoint> placements_of(const SurfaceMesh& mesh, const LocatedPoint& point) {
  std::vector<LocatedPoint> placements = {point};
  for (std::size_t next = 0; next < placements.size(); ++next) {
    const LocatedPoint here = placements[next];  // a copy: the vector grows below
    for (std::uint32_t h = 3 * here.face; h < 3 * here.face + 3; ++h) {
      const std::uint32_t g = mesh.twin[h];
      if (g == kNone || !lies_on_side(mesh, here, h)) continue;
      if (std::ranges::any_of(placements, [&](const LocatedPoint& p) { return p.face == face_of(g); })) continue;
      // The point's place along the side, from h's tail; g runs the other way unless the edge was cut reversed.
      const double length = mesh.halfedges[h].length;
      const double t = std::clamp(position_in_frame(mesh, here, h)[0] / length, 0.0, 1.0);
      const double t_g = mesh.tail(g) == mesh.tail(h) ? t : 1 - t;
      LocatedPoint across;
      across.face = face_of(g);
      across.barycentric = {0, 0, 0};
      across.barycentric[g % 3] = 1 - t_g;
      across.barycentric[(g + 1) % 3] = t_g;
      across.edge = g;
      placements.push_back(across);
    }
  }
  return placements;
}

void list_vertices_on_sides(const ParallelTeam& team, SurfaceMesh& mesh) {
  // The corners whose vertex lies on the side opposite them: few, found in one pass over the corners.
  using Corners = std::vector<std::uint32_t>;
  const Corners on_opposite_side = team.reduce_ranges(
      mesh.corner_vertex.size(), std::size_t{1} << 14, Corners{},
      [&](std::size_t begin, std::size_t end) {
        Corners found;
        for (auto c = static_cast<std::uint32_t>(begin); c < end; ++c)
          if (lies_on_opposite_side(mesh, c)) found.push_back(c);
        return found;
      },
      [](Corners all, const Corners& part) {
        all.insert(all.end(), part.begin(), part.end());
        return all;
      });
  std::vector<VertexOnSide> found;
  for (const std::uint32_t corner : on_opposite_side) {
    const std::uint32_t v = mesh.tail(corner);
    for (const LocatedPoint& at : placements_of(mesh, tail_as_point(corner)))
      if (!mesh.has_corner(at.face, v)) found.push_back({at.face, v, at.edge, at.barycentric});
  }
  // A vertex on two sides of its own faces (a sliver of slivers) is found from each: keep one of each place.
  std::ranges::sort(found, [](const VertexOnSide& a, const VertexOnSide& b) {
    return a.face != b.face ? a.face < b.face : a.vertex < b.vertex;
  });
  found.erase(std::unique(found.begin(), found.end(),
                          [](const VertexOnSide& a, const VertexOnSide& b) {
                            return a.face == b.face && a.vertex == b.vertex;
                          }),
              found.end());
  mesh.vertices_on_sides = std::move(found);
}

std::array<double, 2> position_in_frame(const SurfaceMesh& mesh, const LocatedPoint& point, std::uint32_t h) {
  const int i = static_cast<int>(h % 3);  // h runs from corner i (at the origin) to corner i + 1
  const HalfedgeGeometry& g = mesh.halfedges[h];
  const double to_head = point.barycentric[(i + 1) % 3], to_apex = point.barycentric[(i + 2) % 3];
  return {to_head * g.length + to_apex * g.apex_x, to_apex * g.apex_y};
}

}  // namespace detail

SurfacePoint vertex_point(const Mesh& mesh, std::uint32_t vertex) {
  const detail::SurfaceMesh& s = mesh.surface();
  if (vertex >= mesh.vertex_count())
    throw Error(ErrorCode::invalid_argument, "vertex " + std::to_string(vertex) + " is out of range (mesh has " +
                                                 std::to_string(mesh.vertex_count()) + " vertices)");
  const auto copies = s.copies_of(vertex);
  if (copies.empty())
    throw Error(ErrorCode::invalid_argument, "vertex " + std::to_string(vertex) + " is used by no face");
  const std::uint32_t corner = s.vertex_corners[s.vertex_corner_offsets[copies.front()]];
  SurfacePoint point{s.surface_face_to_input[detail::face_of(corner)], {0, 0, 0}};
  point.barycentric[corner % 3] = 1;
  return point;
}

SurfacePoint edge_point(const Mesh& mesh, std::uint32_t from, std::uint32_t to, double t) {
  const detail::SurfaceMesh& s = mesh.surface();
  const std::string edge = "edge (" + std::to_string(from) + ", " + std::to_string(to) + ")";
  if (!(t >= 0 && t <= 1))
    throw Error(ErrorCode::invalid_argument, edge + ": parameter " + std::to_string(t) + " is outside [0, 1]");
  if (from >= mesh.vertex_count() || to >= mesh.vertex_count())
    throw Error(ErrorCode::invalid_argument, edge + " names a vertex out of range (mesh has " +
                                                 std::to_string(mesh.vertex_count()) + " vertices)");
  const std::uint32_t target = s.canonical(to);
  for (std::uint32_t copy : s.copies_of(from)) {
    for (std::uint32_t i = s.vertex_corner_offsets[copy]; i < s.vertex_corner_offsets[copy + 1]; ++i) {
      const std::uint32_t corner = s.vertex_corners[i];
      for (std::uint32_t other : {detail::next_halfedge(corner), detail::prev_halfedge(corner)}) {
        if (s.surface_to_input[s.corner_vertex[other]] != target) continue;
        SurfacePoint point{s.surface_face_to_input[detail::face_of(corner)], {0, 0, 0}};
        point.barycentric[corner % 3] = 1 - t;
        point.barycentric[other % 3] = t;
        return point;
      }
    }
  }
  throw Error(ErrorCode::invalid_argument, edge + " is not an edge of any face");
}

std::array<double, 3> point_position(const Mesh& mesh, const SurfacePoint& point) {
  const detail::SurfaceMesh& s = mesh.surface();
  const detail::LocatedPoint located = detail::locate_checked(s, point, "point");
  return detail::face_point_position(s, located.face, located.barycentric, detail::PositionFrame::input);
}

}  // namespace exactgeo
