// Marshalling between numpy and the library's flat arrays: see marshalling.hpp.
#include "marshalling.hpp"

#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <string>

namespace exactgeo::python {

std::vector<std::int64_t> signed_indices(std::span<const std::uint32_t> indices) {
  std::vector<std::int64_t> result(indices.size());
  for (std::size_t i = 0; i < indices.size(); ++i) result[i] = indices[i] == kNoSource ? -1 : std::int64_t{indices[i]};
  return result;
}

std::vector<SurfacePoint> surface_points(const IndexArray& faces, const PointArray& barycentric) {
  if (faces.shape(0) != barycentric.shape(0))
    throw Error(ErrorCode::invalid_argument, std::to_string(faces.shape(0)) + " faces but " +
                                                 std::to_string(barycentric.shape(0)) +
                                                 " rows of barycentric coordinates");
  std::vector<SurfacePoint> points(faces.shape(0));
  for (std::size_t i = 0; i < points.size(); ++i)
    points[i] = {faces(i), {barycentric(i, 0), barycentric(i, 1), barycentric(i, 2)}};
  return points;
}

std::tuple<NumpyArray<std::uint32_t>, NumpyArray<double>> point_arrays(std::span<const SurfacePoint> points) {
  std::vector<std::uint32_t> faces(points.size());
  std::vector<double> barycentric(3 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    faces[i] = points[i].face;
    std::copy(points[i].barycentric.begin(), points[i].barycentric.end(), barycentric.begin() + 3 * i);
  }
  return {to_numpy(std::move(faces), {points.size()}), to_numpy(std::move(barycentric), {points.size(), 3})};
}

nb::tuple path_arrays(const GeodesicPath& path, const Mesh& mesh) {
  using Kind = PathPointLocation::Kind;
  const std::size_t n = path.points.size();
  std::vector<double> points(3 * n), weights(3 * n, 0.0);
  std::vector<std::int64_t> vertices(3 * n, -1), faces(n, -1);
  std::vector<std::string> kinds(n);
  const auto triangles = mesh.triangles();
  for (std::size_t i = 0; i < n; ++i) {
    std::copy(path.points[i].begin(), path.points[i].end(), points.begin() + 3 * i);
    const PathPointLocation& location = path.locations[i];
    switch (location.kind) {
      case Kind::vertex:
        kinds[i] = "vertex";
        vertices[3 * i] = location.vertex;
        weights[3 * i] = 1;
        break;
      case Kind::edge:
        kinds[i] = "edge";
        vertices[3 * i] = location.from;
        vertices[3 * i + 1] = location.to;
        weights[3 * i] = 1 - location.t;
        weights[3 * i + 1] = location.t;
        break;
      case Kind::face:
        kinds[i] = "face";
        faces[i] = location.face_point.face;
        for (int k = 0; k < 3; ++k) {
          vertices[3 * i + k] = triangles[3 * location.face_point.face + k];
          weights[3 * i + k] = location.face_point.barycentric[k];
        }
        break;
    }
  }
  const std::int64_t source = path.source == kNoSource ? -1 : std::int64_t{path.source};
  return nb::make_tuple(to_numpy(std::move(points), {n, 3}), std::move(kinds), to_numpy(std::move(vertices), {n, 3}),
                        to_numpy(std::move(weights), {n, 3}), to_numpy(std::move(faces), {n}), path.length, source);
}

std::tuple<NumpyArray<double>, NumpyArray<std::uint32_t>> soup_arrays(MeshSoup&& soup) {
  const std::size_t vertices = soup.positions.size() / 3, faces = soup.triangles.size() / 3;
  return {to_numpy(std::move(soup.positions), {vertices, 3}), to_numpy(std::move(soup.triangles), {faces, 3})};
}

}  // namespace exactgeo::python
