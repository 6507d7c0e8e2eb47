// Shortest paths traced back from the engine's arrivals: each point's last straight piece is unfolded face
// by face back to the pseudo-source it starts from, then that pseudo-source's own piece, and so on to a
// source.
#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "assert.hpp"
#include "exactgeo/error.hpp"
#include "exactgeo/geodesic.hpp"
#include "face_windows.hpp"
#include "nearest_source.hpp"
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

// How far p, given in h's frame, lies from h's face (0 inside it).
double distance_to_face(const SurfaceMesh& mesh, std::uint32_t h, Vec2 p) {
  const std::array<Vec2, 3> c = corners_in_frame(mesh, h);
  const double area = cross(c[1] - c[0], c[2] - c[0]);
  if (area > 0 && cross(p - c[0], c[2] - c[0]) >= 0 && cross(c[1] - c[0], p - c[0]) >= 0 &&
      cross(c[2] - c[1], p - c[1]) >= 0)
    return 0;
  // Outside the face (or the face has no area): the distance to the nearest of its sides.
  double nearest = HUGE_VAL;
  for (int k = 0; k < 3; ++k) {
    const Vec2 from = c[k], side = c[(k + 1) % 3] - c[k];
    const double squared = dot(side, side);
    const double t = squared > 0 ? std::clamp(dot(p - from, side) / squared, 0.0, 1.0) : 0;
    nearest = std::min(nearest, norm(p - Vec2{from.x + t * side.x, from.y + t * side.y}));
  }
  return nearest;
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
  GeodesicPath trace(std::array<double, 3> start, const PathPointLocation& location, const Arrival& arrival) {
    add(start, location);
    if (arrival.halfedge == kNone) return finish();
    return finish_from(trace_piece(arrival));
  }

  // From surface vertex v back to a source.
  GeodesicPath trace_vertex(std::uint32_t v) {
    add(vertex_position(v), vertex_location(v));
    return finish_from(leave(v));
  }

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
  // Goes on from vertex `reached` (kNone: the path is at a source), vertex by vertex, to a source.
  GeodesicPath finish_from(std::uint32_t reached) {
    for (std::uint32_t pieces = 0; reached != kNone; ++pieces) {
      if (pieces > surface_.vertex_count) fail("the chain of pseudo-sources does not end at a source");
      add_vertex(reached);
      reached = leave(reached);
    }
    return finish();
  }

  // The path, traced from its end back to a source, turned around and measured.
  GeodesicPath finish() {
    std::reverse(path_.points.begin(), path_.points.end());
    std::reverse(path_.locations.begin(), path_.locations.end());
    path_.length = surface_.to_input_length(engine_length(0));
    return std::move(path_);
  }

  // The length of the path from its point `first` on, and on to the position `end` if given. Measured in the
  // engine's frame, where squared lengths neither underflow nor overflow.
  double engine_length(std::size_t first, const std::array<double, 3>* end = nullptr) const {
    const auto step = [&](const std::array<double, 3>& a, const std::array<double, 3>& b) {
      double squared = 0;
      for (int k = 0; k < 3; ++k)
        squared += std::pow(surface_.to_engine_length(b[k]) - surface_.to_engine_length(a[k]), 2);
      return std::sqrt(squared);
    };
    double length = 0;
    for (std::size_t i = first + 1; i < path_.points.size(); ++i) length += step(path_.points[i - 1], path_.points[i]);
    if (end) length += step(path_.points.back(), *end);
    return length;
  }

  // From vertex v, where the path is, the next piece, as v's arrival says; returns the vertex it ends at, or
  // kNone at a source.
  std::uint32_t leave(std::uint32_t v) {
    if (has_coincident_neighbour(v)) return leave_coincident(v);
    const Arrival& arrival = engine_.arrivals()[v];
    return arrival.halfedge == kNone ? kNone : trace_piece(arrival);
  }

  // Whether an edge at v is shorter than the snapping distance: a neighbour at v's place.
  bool has_coincident_neighbour(std::uint32_t v) const {
    for (std::uint32_t i = surface_.vertex_corner_offsets[v]; i < surface_.vertex_corner_offsets[v + 1]; ++i) {
      const std::uint32_t c = surface_.vertex_corners[i];  // leaves v; prev(c) comes back to it
      if (surface_.halfedges[c].length <= eps_ || surface_.halfedges[prev_halfedge(c)].length <= eps_) return true;
    }
    return false;
  }

  // v and the vertices joined to it by edges shorter than the snapping distance, and to those in turn: one
  // point of the surface. Ordered by distance, then number.
  std::vector<std::uint32_t> coincident_with(std::uint32_t v) const {
    std::vector<std::uint32_t> together = {v};
    for (std::size_t next = 0; next < together.size(); ++next) {
      const std::uint32_t u = together[next];
      for (std::uint32_t i = surface_.vertex_corner_offsets[u]; i < surface_.vertex_corner_offsets[u + 1]; ++i) {
        const std::uint32_t c = surface_.vertex_corners[i];
        for (const auto& [edge, other] :
             {std::pair{c, surface_.head(c)}, std::pair{prev_halfedge(c), surface_.apex(c)}})
          if (surface_.halfedges[edge].length <= eps_ &&
              std::find(together.begin(), together.end(), other) == together.end())
            together.push_back(other);
      }
    }
    const std::span<const double> d = engine_.distances();
    std::sort(together.begin(), together.end(),
              [&](std::uint32_t a, std::uint32_t b) { return d[a] < d[b] || (d[a] == d[b] && a < b); });
    return together;
  }

  // Issue 34: vertices at one place (a zero-length edge) have equal distances up to rounding, and the engine
  // may have reached each of them from another: a ray through one reaches the other, and rounding a unit in the
  // last place lower then lowers the first from the second across the zero-length edge. Their arrivals then
  // lead from one to the other and back. The path leaves the place by the first of them, in order of distance,
  // that is a source or whose own piece leads away (through the others where its ray runs through them, and
  // around them into the face it goes on in) and is as long as the distances at its ends say; it reaches that
  // one along the zero-length edges. A piece that cannot be traced, or that comes back, is no way out.
  std::uint32_t leave_coincident(std::uint32_t v) {
    const std::vector<std::uint32_t> together = coincident_with(v);
    const std::span<const double> d = engine_.distances();
    const std::size_t before = path_.points.size();
    for (const std::uint32_t w : together) {
      if (!(d[w] < HUGE_VAL)) break;  // not reached (beyond a cut-off), nor are those after it
      add_vertex(w);
      const Arrival& arrival = engine_.arrivals()[w];
      if (arrival.halfedge == kNone) return kNone;  // reached, without a piece: a source vertex
      const std::size_t start = path_.points.size() - 1;  // w's place
      try {
        const std::uint32_t end = trace_piece(arrival, together);
        const std::array<double, 3> end_position = end != kNone ? vertex_position(end) : path_.points.back();
        const double through_end = (end != kNone ? d[end] : 0) + engine_length(start, &end_position);
        if (std::find(together.begin(), together.end(), end) == together.end() &&
            through_end <= d[w] + kPathPieceTolerance * surface_.length_scale)
          return end;
      } catch (const Error&) {
        // A piece that cannot be traced: no way out, try the next.
      }
      path_.points.resize(before);
      path_.locations.resize(before);
    }
    fail("no piece leads away from the " + std::to_string(together.size()) + " vertices at the place of vertex " +
         std::to_string(surface_.surface_to_input[v]));
  }

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
    piece_edge_points_.push_back({e, x});
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

  // The source point numbered `id` as Arrival::from counts (from the surface's vertex count on), as given.
  const LocatedPoint& source_point(std::uint32_t id) const {
    return engine_.sources()[id - surface_.vertex_count].point;
  }

  // The source point numbered `id`, where it is given: not where the piece's unfolding puts it, which may be
  // off by the snapping distance (and in a face the point lies beside: in a sliver narrower than that, the
  // point of its neighbour's side beside it).
  void add_source_point(std::uint32_t id) {
    const LocatedPoint& source = source_point(id);
    PathPointLocation location;
    location.kind = PathPointLocation::Kind::face;
    location.face_point = {surface_.surface_face_to_input[source.face], source.barycentric};
    const std::array<double, 3> position = point_position(mesh_, location.face_point);
    if (!path_.points.empty() && path_.points.back() == position) {  // the edge point the piece crossed last
      path_.points.pop_back();
      path_.locations.pop_back();
    }
    add(position, location);
  }

  // Whether the source point numbered `id` lies in face f: f is the face it was given in or another that holds
  // it (on a side or at a corner).
  bool source_in_face(std::uint32_t id, std::uint32_t f) const {
    const LocatedPoint& source = source_point(id);
    bool holds = source.face == f;
    if (!holds)
      for_each_placement(surface_, source,
                         [&](const LocatedPoint& placement) { holds = holds || placement.face == f; });
    return holds;
  }

  // Whether vertex v lies on a side of face f (a T-junction's vertex, SurfaceMesh::vertices_on_sides).
  bool vertex_on_side(std::uint32_t v, std::uint32_t f) const {
    const auto on_sides = vertices_on_sides(surface_, f);
    return std::any_of(on_sides.begin(), on_sides.end(), [&](const VertexOnSide& on) { return on.vertex == v; });
  }

  // Whether h's face holds the pseudo-source numbered `id` as Arrival::from counts: a vertex at one of its
  // corners or on one of its sides, or a source point in it.
  bool face_holds(std::uint32_t h, std::uint32_t id) const {
    if (id >= surface_.vertex_count) return source_in_face(id, face_of(h));
    return id == surface_.tail(h) || id == surface_.head(h) || id == surface_.apex(h) || vertex_on_side(id, face_of(h));
  }

  // The corner of h's face within the snapping distance of p (in h's frame), if any.
  std::uint32_t corner_at(std::uint32_t h, Vec2 p) const {
    const std::array<Vec2, 3> c = corners_in_frame(surface_, h);
    const std::array<std::uint32_t, 3> vertex = {surface_.tail(h), surface_.head(h), surface_.apex(h)};
    for (int k = 0; k < 3; ++k)
      if (norm(p - c[k]) <= eps_) return vertex[k];
    return kNone;
  }

  // The end of a piece at vertex v, come to in `face` (which holds the piece's last point). A piece whose
  // pseudo-source (numbered `from` as Arrival::from counts) is a source point beside v (passes_beside) held by
  // `face` ends at that point instead, the edge points near v that the walk past v added kept: through v the path
  // would be longer by up to twice their distance. Otherwise the edge points just before v on edges at v, a few
  // snapping distances from v or less, go: they come from rounding in the pseudo-source's unfolded position, which
  // lies beside v by up to about 1e-10 of the mesh's size after many faces (an offset across the ray, which changes
  // the distance by its square only), and tips the ray across an edge at v just short of it. Such a point is a kink
  // that made the path longer than its distance by up to its offset (4e-11 on a height field whose ray ran along a
  // row of vertices, tests/test_fuzz.cpp). Without it the path goes straight on to v, inside the face that holds
  // both the point before and v (it has the dropped point's edge, which is at v).
  std::uint32_t end_piece_at(std::uint32_t v, std::uint32_t from, std::uint32_t face) {
    if (passes_beside(from, v) && source_in_face(from, face)) {
      add_source_point(from);
      return kNone;
    }
    const double near = kPathPieceTolerance * surface_.length_scale;
    while (!piece_edge_points_.empty()) {
      const auto [e, x] = piece_edge_points_.back();
      const double gap = surface_.tail(e) == v   ? x
                         : surface_.head(e) == v ? surface_.halfedges[e].length - x
                                                 : HUGE_VAL;
      if (!(gap <= near)) break;
      piece_edge_points_.pop_back();
      path_.points.pop_back();
      path_.locations.pop_back();
    }
    return v;
  }

  // Whether a piece heading for pseudo-source `from` (numbered as Arrival::from counts) at vertex v goes on past v:
  // `from` is a source point within a few snapping distances of v, where the rounding of unfolded positions leaves
  // it hard to tell from v, and the ray reaches it past v. Snapped to v, the path would bend there: longer than the
  // distance by up to twice their distance where v is the bend, and where the line to the point was then drawn
  // straight from before v, it cut across the faces at v, shorter than the distance (by 3.6e-10 at a nearness of
  // 5.8e-10, tests/test_fuzz.cpp).
  bool passes_beside(std::uint32_t from, std::uint32_t v) const {
    if (v == kNone || from < surface_.vertex_count) return false;
    const LocatedPoint& source = source_point(from);
    const std::array<double, 3> p =
        face_point_position(surface_, source.face, source.barycentric, PositionFrame::engine);
    const std::array<double, 3> q = surface_.position(surface_.surface_to_input[v]);
    return std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]) <= kPathPieceTolerance * surface_.length_scale;
  }

  // One straight piece: from the point the arrival reaches back towards the arrival's pseudo-source, adding
  // every point where it crosses an edge, and the pseudo-source itself when it is a point source. Returns the
  // vertex where the piece ends (kNone at a point source): the pseudo-source, or the first vertex the piece
  // runs through on the way. A piece of a window's ray runs through a vertex where the window was cut there
  // (along a line of symmetry, say, every vertex of it): the surface is unfolded differently on either side
  // of the vertex, so the straight line beyond it, and the face sequence the window took, are not known here.
  // The vertex's own path is no longer than the rest of the ray (it was reached through that window too, and
  // its distance is the smallest), so the path continues with it, and stays as short as the distance.
  // Vertices in `pass` (those at the place the piece starts from, see leave_coincident) are no such end: the
  // piece goes on through them, and around them where it grazes one, into the face where the ray goes on.
  std::uint32_t trace_piece(const Arrival& arrival, std::span<const std::uint32_t> pass = {}) {
    const std::uint32_t pseudo_source = arrival.from < surface_.vertex_count ? arrival.from : kNone;
    const auto ends_at = [&](std::uint32_t v) {
      return v != kNone && std::find(pass.begin(), pass.end(), v) == pass.end();
    };
    // The piece ends at its pseudo-source: a vertex, which finish_from adds next, or a source point, added here.
    const auto end_at_pseudo_source = [&] {
      if (pseudo_source == kNone) add_source_point(arrival.from);
      return pseudo_source;
    };
    piece_edge_points_.clear();
    std::uint32_t h = arrival.halfedge;
    Vec2 source = {arrival.px, arrival.py};
    if (std::isnan(arrival.crossing))
      return end_at_pseudo_source();  // straight from a corner, a vertex on a side, or a source point
    // The vertex a crossing at x of edge e snaps to, unless the piece goes on past it.
    const auto snapped = [&](std::uint32_t e, double x) {
      const std::uint32_t v = vertex_at(e, x);
      return passes_beside(arrival.from, v) ? kNone : v;
    };
    if (const std::uint32_t v = snapped(h, arrival.crossing); ends_at(v))
      return end_piece_at(v, arrival.from, face_of(h));
    else if (v == kNone)
      add_edge_point(h, arrival.crossing);
    Vec2 entry = {arrival.crossing, 0};
    // The pseudo-source where the piece crosses, in a face of the edge crossed. One that near but in neither face
    // lies across a fold thinner than the snapping distance (a near-sliver folded over that edge, its far layer
    // holding the pseudo-source): the walk below goes through the fold to it, as the path must.
    if (norm(source - entry) <= eps_ &&
        (surface_.twin[h] == kNone || face_holds(h, arrival.from) || face_holds(surface_.twin[h], arrival.from))) {
      if (pseudo_source != kNone) return end_piece_at(pseudo_source, arrival.from, face_of(h));
      add_source_point(arrival.from);
      return kNone;
    }
    // Walk face by face: enter the face across h at `entry`, heading for `source` beyond it.
    const std::size_t limit = 2 * surface_.halfedges.size() + 8;
    // Where the walk first came within the snapping distance of its pseudo-source, in a face that does not hold it.
    struct NearSource {
      std::size_t step, points, edge_points;
    };
    std::optional<NearSource> near_since;
    const auto straight_from = [&](const NearSource& near) {
      path_.points.resize(near.points);
      path_.locations.resize(near.points);
      piece_edge_points_.resize(near.edge_points);
      return end_at_pseudo_source();
    };
    constexpr std::size_t kNearFaces = 8;
    for (std::size_t step = 0; step < limit; ++step) {
      if (surface_.twin[h] == kNone) fail("a piece leaves the surface through a boundary edge");
      source = to_twin(surface_, h, source);
      entry = to_twin(surface_, h, entry);
      h = surface_.twin[h];
      const std::array<Vec2, 3> c = corners_in_frame(surface_, h);  // entry lies on c[0] c[1]
      // At a corner, unless the pseudo-source is a point beside it in another face (the walk goes on to it).
      if (const std::uint32_t corner = corner_at(h, source);
          corner != kNone && (!passes_beside(arrival.from, corner) || source_in_face(arrival.from, face_of(h))))
        return end_piece_at(corner, arrival.from, face_of(h));
      // Inside the face (or on its far edges, up to the snapping distance): a pseudo-source the face holds (a
      // source point in it, a vertex on its side or at a corner rounding put farther away). A distance, not weights
      // with a slack: in a face narrower than the slack, slack on the weights holds every point near the face's line,
      // far beyond its ends too.
      if (distance_to_face(surface_, h, source) <= eps_) {
        if (face_holds(h, arrival.from)) return end_at_pseudo_source();
        // The pseudo-source lies just beyond this face, a vertex not on its sides or a point in another face
        // (across a sliver thinner than the snapping distance, say): the walk goes on into a face that holds
        // it, so that the path does not cut across the sliver.
        if (!near_since) near_since = NearSource{step, path_.points.size(), piece_edge_points_.size()};
      }
      // No face holding it within a few faces more: the piece goes straight to it from where it first came that near.
      if (near_since && step - near_since->step >= kNearFaces) return straight_from(*near_since);
      // Leave through the side from the tail to the apex if the source lies left of entry -> apex, else through
      // the side from the head to the apex.
      const bool via_tail_side = cross(c[2] - entry, source - entry) > 0;
      std::uint32_t side = via_tail_side ? prev_halfedge(h) : next_halfedge(h);  // apex->tail or head->apex
      // A side of zero length is a point, whose frame says nothing of directions: the ray leaves a face with one
      // (a face with no area, whose other sides coincide) by its other side, at the same place.
      if (!(surface_.halfedges[side].length > 0)) side = via_tail_side ? next_halfedge(h) : prev_halfedge(h);
      const Vec2 s = to_sibling_frame(surface_, h, side, source);
      const Vec2 e = to_sibling_frame(surface_, h, side, entry);
      // Where the line e -> s meets the side's line (y = 0), as a fraction of the way from e to s.
      const double reach = s.y != e.y ? e.y / (e.y - s.y) : 0.0;
      // After the walk came within the snapping distance of the pseudo-source, a side met beyond it means that the walk
      // went past it, around a vertex on the wrong side of a fold thinner than that (the fold's layers unfolded over
      // each other): the piece goes straight to it from where it first came that near, not on to the border or to a
      // vertex beyond.
      if (near_since && reach > 1) return straight_from(*near_since);
      // A shortest path cannot leave the surface: a piece that seems to cross a boundary side runs along it
      // (a ray grazing the border, tipped out by rounding), through the side's end in the direction it goes,
      // which is the first vertex it runs through.
      if (surface_.twin[side] == kNone)
        return end_piece_at(s.x >= e.x ? surface_.head(side) : surface_.tail(side), arrival.from, face_of(h));
      const double along = e.x + (s.x - e.x) * reach;
      const double x = std::clamp(along, 0.0, surface_.halfedges[side].length);
      // At a vertex to pass (which a ray grazing it leaves this face at), on across the side, around the vertex.
      if (const std::uint32_t v = snapped(side, x); ends_at(v))
        return end_piece_at(v, arrival.from, face_of(h));
      else if (v == kNone)
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
  // The edge points the piece being traced added (halfedge, place along it), last at the back.
  std::vector<std::pair<std::uint32_t, double>> piece_edge_points_;
};

// The path to `point`, a point of the last run's surface inside a face or on an edge, whose last straight
// piece `arrival` describes.
GeodesicPath trace_to_point(const Mesh& mesh, const VtpEngine& engine, const LocatedPoint& point,
                            const Arrival& arrival) {
  PathPointLocation location;
  location.kind = PathPointLocation::Kind::face;
  location.face_point = {mesh.surface().surface_face_to_input[point.face], point.barycentric};
  return PathBuilder(mesh, engine).trace(point_position(mesh, location.face_point), location, arrival);
}

}  // namespace

GeodesicPath trace_to_target(const Mesh& mesh, const VtpEngine& engine, std::size_t target) {
  const LocatedPoint& point = engine.targets()[target];
  const SurfaceMesh& surface = mesh.surface();
  if (point.vertex != kNone)  // that input vertex, through the copy that has its distance
    return PathBuilder(mesh, engine)
        .trace_vertex(surface.nearest_copy(surface.surface_to_input[point.vertex], engine.distances()));
  return trace_to_point(mesh, engine, point, engine.target_arrivals()[target]);
}

}  // namespace detail

GeodesicPath GeodesicSolver::path_to_vertex(std::uint32_t vertex) const {
  if (vertex >= mesh_->vertex_count())
    throw Error(ErrorCode::invalid_argument, "vertex " + std::to_string(vertex) + " is out of range (mesh has " +
                                                 std::to_string(mesh_->vertex_count()) + " vertices)");
  if (result_.distances.empty()) throw Error(ErrorCode::invalid_argument, "no run to trace a path in: solve first");
  if (std::isinf(result_.distances[vertex])) return {};
  const std::uint32_t copy = mesh_->surface().nearest_copy(vertex, engine_->distances());  // carries its distance
  EXACTGEO_ASSERT(copy != detail::kNone);
  GeodesicPath path = detail::PathBuilder(*mesh_, *engine_).trace_vertex(copy);
  path.source = result_.nearest_source[vertex];
  return path;
}

GeodesicPath GeodesicSolver::path_to_target(std::size_t target) const {
  if (target >= result_.target_distances.size())
    throw Error(ErrorCode::invalid_argument, "target " + std::to_string(target) + " is out of range (the last run had " +
                                                 std::to_string(result_.target_distances.size()) + " targets)");
  const detail::LocatedPoint& point = engine_->targets()[target];
  // A point at a vertex (or at a corner of a face) is that input vertex: its path goes to the copy that has
  // its distance.
  if (point.vertex != detail::kNone) return path_to_vertex(mesh_->surface().surface_to_input[point.vertex]);
  if (std::isinf(result_.target_distances[target])) return {};
  GeodesicPath path = detail::trace_to_target(*mesh_, *engine_, target);
  path.source = result_.target_nearest_source[target];
  return path;
}

GeodesicPath GeodesicSolver::path_to_point(const SurfacePoint& surface_point) const {
  const detail::FaceWindows& kept = kept_windows("path_to_point");
  const detail::SurfaceMesh& surface = mesh_->surface();
  const detail::LocatedPoint point = detail::locate_checked(surface, surface_point, "point");
  if (point.vertex != detail::kNone) return path_to_vertex(surface.surface_to_input[point.vertex]);
  detail::Arrival arrival;
  const double d = kept.reach(surface, engine_->distances(), point, arrival);
  if (!engine_->answers(d)) return {};  // unreached, or beyond the cut-off
  GeodesicPath path = detail::trace_to_point(*mesh_, *engine_, point, arrival);
  path.source = detail::label_of(*engine_, arrival.from);
  return path;
}

}  // namespace exactgeo
