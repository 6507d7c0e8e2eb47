#include "cgal_oracle.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_shortest_path.h>
#include <CGAL/boost/graph/helpers.h>

#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace exactgeo_oracle {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using ShortestPathTraits = CGAL::Surface_mesh_shortest_path_traits<Kernel, SurfaceMesh>;
using ShortestPath = CGAL::Surface_mesh_shortest_path<ShortestPathTraits>;
using Triangle = std::array<std::size_t, 3>;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// orient_polygon_soup appends a copy of a point for every extra fan around a non-manifold vertex and
// reports each copy here; the visitor is taken by value, so it extends the caller's map through a pointer.
struct RecordDuplicatedPoints : CGAL::Polygon_mesh_processing::Default_orientation_visitor {
  std::vector<std::uint32_t>* input_vertex_of_point = nullptr;

  void duplicated_vertex(std::size_t original, std::size_t copy) {
    // Copies are appended in order, so `copy` is always the next free slot.
    if (copy != input_vertex_of_point->size()) throw std::logic_error("orient_polygon_soup: unexpected point index");
    input_vertex_of_point->push_back((*input_vertex_of_point)[original]);
  }
};

// The soup after CGAL's repairs: one point per surface vertex (point i is Surface_mesh vertex i) and the
// input vertex each point stands for.
struct OrientedSoup {
  std::vector<Point> points;
  std::vector<Triangle> triangles;
  std::vector<std::size_t> triangle_of_input;  // input triangle -> kept triangle (= Surface_mesh face)
  std::vector<std::uint32_t> input_vertex_of_point;
  std::size_t duplicated_points = 0;
};

void check_input(std::span<const double> positions, std::span<const std::uint32_t> triangles,
                 std::span<const std::uint32_t> source_vertices) {
  if (positions.size() % 3 != 0 || triangles.size() % 3 != 0)
    throw std::invalid_argument("cgal_geodesic_distances: array sizes must be multiples of 3");
  const std::size_t vertex_count = positions.size() / 3;
  for (std::size_t i = 0; i < triangles.size(); ++i)
    if (triangles[i] >= vertex_count)
      throw std::invalid_argument("cgal_geodesic_distances: triangle " + std::to_string(i / 3) + " names vertex " +
                                  std::to_string(triangles[i]) + " of " + std::to_string(vertex_count));
  for (std::uint32_t source : source_vertices)
    if (source >= vertex_count)
      throw std::invalid_argument("cgal_geodesic_distances: source vertex " + std::to_string(source) + " of " +
                                  std::to_string(vertex_count));
}

OrientedSoup orient_soup(std::span<const double> positions, std::span<const std::uint32_t> triangles) {
  const std::size_t vertex_count = positions.size() / 3;
  OrientedSoup soup;

  // Only vertices of kept triangles become points: CGAL's shortest path code does not cope with isolated
  // vertices (CGAL issue #5280), and they have no distance anyway.
  constexpr std::size_t kNoPoint = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> point_of_input_vertex(vertex_count, kNoPoint);
  soup.triangle_of_input.assign(triangles.size() / 3, kNoPoint);
  for (std::size_t t = 0; t < triangles.size(); t += 3) {
    const std::uint32_t a = triangles[t], b = triangles[t + 1], c = triangles[t + 2];
    if (a == b || b == c || c == a) continue;  // repeats a vertex: not a triangle
    soup.triangle_of_input[t / 3] = soup.triangles.size();
    Triangle triangle;
    for (int corner = 0; corner < 3; ++corner) {
      const std::uint32_t v = triangles[t + corner];
      if (point_of_input_vertex[v] == kNoPoint) {
        point_of_input_vertex[v] = soup.points.size();
        soup.points.emplace_back(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
        soup.input_vertex_of_point.push_back(v);
      }
      triangle[corner] = point_of_input_vertex[v];
    }
    soup.triangles.push_back(triangle);
  }

  const std::size_t used_points = soup.points.size();
  const std::size_t kept_triangles = soup.triangles.size();
  RecordDuplicatedPoints visitor;
  visitor.input_vertex_of_point = &soup.input_vertex_of_point;
  CGAL::Polygon_mesh_processing::orient_polygon_soup(soup.points, soup.triangles,
                                                     CGAL::parameters::visitor(visitor));
  if (soup.triangles.size() != kept_triangles) throw std::logic_error("orient_polygon_soup dropped a triangle");
  soup.duplicated_points = soup.points.size() - used_points;
  if (soup.input_vertex_of_point.size() != soup.points.size())
    throw std::logic_error("orient_polygon_soup: a duplicated point was not reported");
  return soup;
}

// The CGAL face location of a point given on an input triangle. CGAL's k-th barycentric coordinate belongs
// to the source vertex of the k-th halfedge from halfedge(face); the kept triangle may have been reoriented
// and its corners split into copies, so corners are matched by the input vertex they stand for.
ShortestPath::Face_location face_location(const SurfaceMesh& mesh, const OrientedSoup& soup,
                                          std::span<const std::uint32_t> triangles, const FacePoint& point) {
  if (point.face >= soup.triangle_of_input.size() ||
      soup.triangle_of_input[point.face] == std::numeric_limits<std::size_t>::max())
    throw std::invalid_argument("cgal_geodesic_distances: point on a missing or dropped triangle");
  const SurfaceMesh::Face_index face(static_cast<SurfaceMesh::size_type>(soup.triangle_of_input[point.face]));
  std::array<double, 3> coordinates = {0, 0, 0};
  SurfaceMesh::Halfedge_index h = mesh.halfedge(face);
  for (int k = 0; k < 3; ++k, h = mesh.next(h)) {
    const std::uint32_t input_vertex = soup.input_vertex_of_point[mesh.source(h)];
    for (int corner = 0; corner < 3; ++corner)
      if (triangles[3 * point.face + corner] == input_vertex) coordinates[k] = point.barycentric[corner];
  }
  return {face, coordinates};  // Barycentric_coordinates is std::array<double, 3> for this kernel
}

}  // namespace

OracleResult cgal_geodesic_distances(std::span<const double> positions, std::span<const std::uint32_t> triangles,
                                     std::span<const std::uint32_t> source_vertices,
                                     std::span<const FacePoint> source_points, std::span<const FacePoint> target_points) {
  check_input(positions, triangles, source_vertices);
  OracleResult result;

  const auto build_start = std::chrono::steady_clock::now();
  OrientedSoup soup = orient_soup(positions, triangles);
  result.duplicated_points = soup.duplicated_points;
  // polygon_soup_to_polygon_mesh only asserts its precondition, so check it here; an empty soup is "valid"
  // for CGAL but has nothing to measure on.
  if (soup.triangles.empty() || !CGAL::Polygon_mesh_processing::is_polygon_soup_a_polygon_mesh(soup.triangles)) {
    result.build_seconds = seconds_since(build_start);
    return result;
  }
  SurfaceMesh mesh;
  CGAL::Polygon_mesh_processing::polygon_soup_to_polygon_mesh(soup.points, soup.triangles, mesh);
  result.build_seconds = seconds_since(build_start);
  if (!CGAL::is_valid_polygon_mesh(mesh) || mesh.number_of_vertices() != soup.points.size()) return result;
  result.loaded_as_manifold = true;

  const std::size_t vertex_count = positions.size() / 3;
  result.distances.assign(vertex_count, kInfinity);

  // A split vertex seeds every one of its copies: they are the same point of the input.
  std::vector<bool> is_source(vertex_count, false);
  for (std::uint32_t source : source_vertices) is_source[source] = true;
  std::vector<SurfaceMesh::Vertex_index> source_vertex_points;
  for (std::size_t point = 0; point < soup.points.size(); ++point)
    if (is_source[soup.input_vertex_of_point[point]])
      source_vertex_points.emplace_back(static_cast<SurfaceMesh::size_type>(point));
  result.target_distances.assign(target_points.size(), kInfinity);
  std::vector<ShortestPath::Face_location> located_sources;
  for (const FacePoint& point : source_points) located_sources.push_back(face_location(mesh, soup, triangles, point));
  if (source_vertex_points.empty() && located_sources.empty()) return result;  // nothing is reachable

  const auto query_start = std::chrono::steady_clock::now();
  ShortestPath shortest_path(mesh);
  shortest_path.add_source_points(source_vertex_points.begin(), source_vertex_points.end());
  shortest_path.add_source_points(located_sources.begin(), located_sources.end());
  shortest_path.build_sequence_tree();
  for (std::size_t point = 0; point < soup.points.size(); ++point) {
    const SurfaceMesh::Vertex_index vertex(static_cast<SurfaceMesh::size_type>(point));
    const double distance = shortest_path.shortest_distance_to_source_points(vertex).first;
    if (distance < 0) continue;  // CGAL's answer for "no source reachable"
    // A NaN is kept (no later copy replaces it) so that a test comparing against it fails loudly.
    double& best = result.distances[soup.input_vertex_of_point[point]];
    if (std::isnan(distance) || distance < best) best = distance;
  }
  for (std::size_t t = 0; t < target_points.size(); ++t) {
    const auto location = face_location(mesh, soup, triangles, target_points[t]);
    const double distance = shortest_path.shortest_distance_to_source_points(location.first, location.second).first;
    if (!(distance < 0)) result.target_distances[t] = distance;
  }
  result.query_seconds = seconds_since(query_start);
  return result;
}

}  // namespace exactgeo_oracle
