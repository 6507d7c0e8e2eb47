// Shortest paths traced back from the engine's arrivals: each point's last straight piece is unfolded face
// by face back to the pseudo-source it starts from, then that pseudo-source's own piece, and so on to a
// source.
#include <algorithm>
#include <cmath>
#include <string>

#include "exactgeo/error.hpp"
#include "exactgeo/geodesic.hpp"
#include "assert.hpp"
#include "surface_point.hpp"
#include "tolerances.hpp"
#include "vtp_engine.hpp"

namespace exactgeo {
namespace detail {
namespace {

struct Vec2 {
  double x, y;
};
Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
double norm(Vec2 a) { return std::sqrt(dot(a, a)); }

// The corners of h's face in h's frame: tail, head, apex.
std::array<Vec2, 3> corners_in_frame(const SurfaceMesh& mesh, std::uint32_t h) {
  const HalfedgeGeometry& g = mesh.halfedges[h];
  return {Vec2{0, 0}, Vec2{g.length, 0}, Vec2{g.apex_x, g.apex_y}};
}

// A point given in the frame of halfedge h, re-expressed in the frame of halfedge e of the same face.
Vec2 to_sibling_frame(const SurfaceMesh& mesh, std::uint32_t h, std::uint32_t e, Vec2 p) {
  const std::array<Vec2, 3> c = corners_in_frame(mesh, h);
  // Corner k of h's frame is h's tail, head, apex: e's tail is corner (e - h) mod 3 of that list.
  const std::uint32_t shift = (e % 3 + 3 - h % 3) % 3;
  const Vec2 tail = c[shift], head = c[(shift + 1) % 3];
  const Vec2 axis = head - tail;
  const double axis_length = norm(axis);
  if (!(axis_length > 0)) return p - tail;  // a zero-length edge: any direction will do
  const Vec2 u = {axis.x / axis_length, axis.y / axis_length};
  return {dot(p - tail, u), cross(u, p - tail)};
}

// A point in the frame of halfedge e, re-expressed in the frame of its twin (the face across the edge).
Vec2 to_twin(const SurfaceMesh& mesh, std::uint32_t e, Vec2 p) {
  const std::uint32_t t = mesh.twin[e];
  const bool reversed = mesh.tail(t) != mesh.tail(e);
  return {reversed ? mesh.halfedges[e].length - p.x : p.x, -p.y};
}

class PathBuilder {
 public:
  PathBuilder(const Mesh& mesh, const VtpEngine& engine)
      : mesh_(mesh), surface_(mesh.surface()), engine_(engine),
        eps_(kPathSnapTolerance * surface_.length_scale) {}

  // From the point at `start` (described by `location`) back to a source, as the arrival says.
  GeodesicPath trace(std::array<double, 3> start, const PathPointLocation& location, Arrival arrival) {
    add(start, location);
    const std::uint32_t n = surface_.vertex_count;
    for (std::uint32_t pieces = 0; arrival.halfedge != kNone; ++pieces) {
      if (pieces > n) fail("the chain of pseudo-sources does not end at a source");
      const std::uint32_t reached = trace_piece(arrival);
      if (reached == kNone) break;  // a source point: the piece ended on it
      add_vertex(reached);
      arrival = engine_.arrivals()[reached];  // kNone at a source vertex
    }
    std::reverse(path_.points.begin(), path_.points.end());
    std::reverse(path_.locations.begin(), path_.locations.end());
    // Measured in the engine's frame, where squared lengths neither underflow nor overflow.
    double length = 0;
    for (std::size_t i = 1; i < path_.points.size(); ++i) {
      double squared = 0;
      for (int k = 0; k < 3; ++k)
        squared += std::pow(surface_.to_engine_length(path_.points[i][k]) -
                                surface_.to_engine_length(path_.points[i - 1][k]),
                            2);
      length += std::sqrt(squared);
    }
    path_.length = surface_.to_input_length(length);
    return std::move(path_);
  }

  // From surface vertex v back to a source.
  GeodesicPath trace_vertex(std::uint32_t v) { return trace(vertex_position(v), vertex_location(v), engine_.arrivals()[v]); }

  std::array<double, 3> vertex_position(std::uint32_t surface_vertex) const {
    const std::uint32_t v = surface_.surface_to_input[surface_vertex];
    return {surface_.input_positions[3 * v], surface_.input_positions[3 * v + 1], surface_.input_positions[3 * v + 2]};
  }
  PathPointLocation vertex_location(std::uint32_t surface_vertex) const {
    PathPointLocation location;
    location.kind = PathPointLocation::Kind::vertex;
    location.vertex = surface_.surface_to_input[surface_vertex];
    return location;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw Error(ErrorCode::internal, "path tracing failed: " + why);
  }

  void add(const std::array<double, 3>& p, const PathPointLocation& location) {
    path_.points.push_back(p);
    path_.locations.push_back(location);
  }
  void add_vertex(std::uint32_t surface_vertex) {
    if (!path_.locations.empty() && path_.locations.back().kind == PathPointLocation::Kind::vertex &&
        path_.locations.back().vertex == surface_.surface_to_input[surface_vertex])
      return;  // the walk already ended on it
    add(vertex_position(surface_vertex), vertex_location(surface_vertex));
  }

  // The end of halfedge e within the snapping distance of x, if any.
  std::uint32_t vertex_at(std::uint32_t e, double x) const {
    if (x <= eps_) return surface_.tail(e);
    if (x >= surface_.halfedges[e].length - eps_) return surface_.head(e);
    return kNone;
  }

  // The point at x on halfedge e, away from its ends.
  void add_edge_point(std::uint32_t e, double x) {
    const double t = x / surface_.halfedges[e].length;
    PathPointLocation location;
    location.kind = PathPointLocation::Kind::edge;
    location.from = surface_.surface_to_input[surface_.tail(e)];
    location.to = surface_.surface_to_input[surface_.head(e)];
    location.t = t;
    // In the engine's frame, where b - a cannot overflow, then back.
    const std::array<double, 3> a = surface_.position(location.from), b = surface_.position(location.to);
    std::array<double, 3> p;
    for (int k = 0; k < 3; ++k) p[k] = std::ldexp(a[k] + t * (b[k] - a[k]), -surface_.scale_exponent);
    add(p, location);
  }

  // The point p of face(h), given in h's frame, as a surface point.
  void add_face_point(std::uint32_t h, Vec2 p) {
    const std::array<Vec2, 3> c = corners_in_frame(surface_, h);
    const double area = cross(c[1] - c[0], c[2] - c[0]);
    std::array<double, 3> weight = {1, 0, 0};  // by corner of h's frame: tail, head, apex
    if (area > 0) {
      weight[1] = cross(p - c[0], c[2] - c[0]) / area;
      weight[2] = cross(c[1] - c[0], p - c[0]) / area;
      weight[0] = 1 - weight[1] - weight[2];
    }
    const std::uint32_t f = face_of(h);
    SurfacePoint point{surface_.surface_face_to_input[f], {0, 0, 0}};
    for (int k = 0; k < 3; ++k) point.barycentric[(h % 3 + k) % 3] = weight[k];
    PathPointLocation location;
    location.kind = PathPointLocation::Kind::face;
    location.face_point = point;
    add(point_position(mesh_, point), location);
  }

  // The corner of h's face within the snapping distance of p (in h's frame), if any.
  std::uint32_t corner_at(std::uint32_t h, Vec2 p) const {
    const std::array<Vec2, 3> c = corners_in_frame(surface_, h);
    const std::array<std::uint32_t, 3> vertex = {surface_.tail(h), surface_.head(h), surface_.apex(h)};
    for (int k = 0; k < 3; ++k)
      if (norm(p - c[k]) <= eps_) return vertex[k];
    return kNone;
  }

  // One straight piece: from the point the arrival reaches back towards the arrival's pseudo-source, adding
  // every point where it crosses an edge, and the pseudo-source itself when it is a point source. Returns the
  // vertex where the piece ends (kNone at a point source): the pseudo-source, or the first vertex the piece
  // runs through on the way. A piece of a window's ray runs through a vertex where the window was cut there
  // (along a line of symmetry, say, every vertex of it): the surface is unfolded differently on either side
  // of the vertex, so the straight line beyond it, and the face sequence the window took, are not known here.
  // The vertex's own path is no longer than the rest of the ray (it was reached through that window too, and
  // its distance is the smallest), so the path continues with it, and stays as short as the distance.
  std::uint32_t trace_piece(const Arrival& arrival) {
    const std::uint32_t pseudo_source = arrival.from < surface_.vertex_count ? arrival.from : kNone;
    std::uint32_t h = arrival.halfedge;
    Vec2 source = {arrival.px, arrival.py};
    if (std::isnan(arrival.crossing)) {  // straight to a corner or a source inside the face
      if (corner_at(h, source) == kNone) add_face_point(h, source);
      return pseudo_source;
    }
    if (const std::uint32_t v = vertex_at(h, arrival.crossing); v != kNone) return v;
    add_edge_point(h, arrival.crossing);
    Vec2 entry = {arrival.crossing, 0};
    if (norm(source - entry) <= eps_) return pseudo_source;  // the pseudo-source is where the piece crosses
    // Walk face by face: enter the face across h at `entry`, heading for `source` beyond it.
    const std::size_t limit = 2 * surface_.halfedges.size() + 8;
    for (std::size_t step = 0; step < limit; ++step) {
      if (surface_.twin[h] == kNone) fail("a piece leaves the surface through a boundary edge");
      source = to_twin(surface_, h, source);
      entry = to_twin(surface_, h, entry);
      h = surface_.twin[h];
      const std::array<Vec2, 3> c = corners_in_frame(surface_, h);  // entry lies on c[0] c[1]
      if (const std::uint32_t corner = corner_at(h, source); corner != kNone) return corner;
      // Inside the face (or on its far edges): a source point.
      const double area = cross(c[1] - c[0], c[2] - c[0]);
      const double w_head = cross(source - c[0], c[2] - c[0]), w_apex = cross(c[1] - c[0], source - c[0]);
      const double tolerance = eps_ * std::max(norm(c[1] - c[0]), norm(c[2] - c[0]));
      if (w_head >= -tolerance && w_apex >= -tolerance && w_head + w_apex <= area + tolerance) {
        add_face_point(h, source);
        return pseudo_source;
      }
      // Leave through the side from the tail to the apex if the source lies left of entry -> apex, else through
      // the side from the head to the apex.
      const bool via_tail_side = cross(c[2] - entry, source - entry) > 0;
      const std::uint32_t side = via_tail_side ? prev_halfedge(h) : next_halfedge(h);  // apex->tail or head->apex
      const Vec2 s = to_sibling_frame(surface_, h, side, source);
      const Vec2 e = to_sibling_frame(surface_, h, side, entry);
      // A shortest path cannot leave the surface: a piece that seems to cross a boundary side runs along it
      // (a ray grazing the border, tipped out by rounding), through the side's end in the direction it goes,
      // which is the first vertex it runs through.
      if (surface_.twin[side] == kNone) return s.x >= e.x ? surface_.head(side) : surface_.tail(side);
      // Where the segment e -> s meets the side's line (y = 0).
      const double along = s.y != e.y ? e.x + (s.x - e.x) * (e.y / (e.y - s.y)) : e.x;
      const double x = std::clamp(along, 0.0, surface_.halfedges[side].length);
      if (const std::uint32_t v = vertex_at(side, x); v != kNone) return v;
      add_edge_point(side, x);
      entry = {x, 0};
      source = s;
      h = side;
    }
    fail("a piece does not reach its pseudo-source");
  }

  const Mesh& mesh_;
  const SurfaceMesh& surface_;
  const VtpEngine& engine_;
  const double eps_;
  GeodesicPath path_;
};

}  // namespace
}  // namespace detail

GeodesicPath GeodesicSolver::path_to_vertex(std::uint32_t vertex) const {
  if (vertex >= mesh_->vertex_count())
    throw Error(ErrorCode::invalid_argument, "vertex " + std::to_string(vertex) + " is out of range (mesh has " +
                                                 std::to_string(mesh_->vertex_count()) + " vertices)");
  if (result_.distances.empty()) throw Error(ErrorCode::invalid_argument, "no run to trace a path in: solve first");
  if (std::isinf(result_.distances[vertex])) return {};
  // The surface copy of the vertex that carries its distance: the nearest.
  std::uint32_t copy = detail::kNone;
  for (std::uint32_t s : mesh_->surface().copies_of(vertex))
    if (copy == detail::kNone || engine_->distances()[s] < engine_->distances()[copy]) copy = s;
  EXACTGEO_ASSERT(copy != detail::kNone);
  GeodesicPath path = detail::PathBuilder(*mesh_, *engine_).trace_vertex(copy);
  path.source = result_.nearest_source[vertex];
  return path;
}

GeodesicPath GeodesicSolver::path_to_target(std::size_t target) const {
  if (target >= result_.target_distances.size())
    throw Error(ErrorCode::invalid_argument, "target " + std::to_string(target) + " is out of range (the last run had " +
                                                 std::to_string(result_.target_distances.size()) + " targets)");
  if (std::isinf(result_.target_distances[target])) return {};
  const detail::LocatedPoint& point = engine_->targets()[target];
  detail::PathBuilder builder(*mesh_, *engine_);
  GeodesicPath path;
  if (point.vertex != detail::kNone) {
    path = builder.trace_vertex(point.vertex);
  } else {
    PathPointLocation location;
    location.kind = PathPointLocation::Kind::face;
    location.face_point = {mesh_->surface().surface_face_to_input[point.face], point.barycentric};
    path = builder.trace(point_position(*mesh_, location.face_point), location, engine_->target_arrivals()[target]);
  }
  path.source = result_.target_nearest_source[target];
  return path;
}

}  // namespace exactgeo
