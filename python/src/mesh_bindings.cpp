// Meshes (built from arrays or read from files, interruptibly when large), surface points and their
// positions, the closest surface points of points in space, and the generated meshes.
#include <nanobind/nanobind.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "interruption.hpp"
#include "marshalling.hpp"
#include "registration.hpp"

using namespace nb::literals;

namespace exactgeo::python {

void register_mesh(nb::module_& m) {
  nb::class_<exactgeo::Mesh>(m, "Mesh")
      .def(
          "__init__",
          [](exactgeo::Mesh* self, const PointArray& positions, const TriangleArray& triangles, bool weld,
             unsigned threads, const nb::object& progress) {
            const exactgeo::MeshOptions options{.weld_duplicate_positions = weld, .threads = threads};
            new (self)
                exactgeo::Mesh(build_mesh(progress, triangles.shape(0), options, [&](const exactgeo::MeshOptions& o) {
                  return exactgeo::Mesh(span_of(positions), span_of(triangles), o);
                }));
          },
          "positions"_a.noconvert(), "triangles"_a.noconvert(), "weld_duplicate_positions"_a, "threads"_a,
          "progress"_a.none())
      .def_prop_ro("vertex_count", &exactgeo::Mesh::vertex_count)
      .def_prop_ro("face_count", &exactgeo::Mesh::face_count)
      // Views of the mesh's own storage, read-only; each keeps the mesh alive.
      .def_prop_ro(
          "positions",
          [](const exactgeo::Mesh& mesh) {
            return nb::ndarray<nb::numpy, const double, nb::shape<-1, 3>>(mesh.positions().data(),
                                                                          {mesh.vertex_count(), 3});
          },
          nb::rv_policy::reference_internal)
      .def_prop_ro(
          "triangles",
          [](const exactgeo::Mesh& mesh) {
            return nb::ndarray<nb::numpy, const std::uint32_t, nb::shape<-1, 3>>(mesh.triangles().data(),
                                                                                 {mesh.face_count(), 3});
          },
          nb::rv_policy::reference_internal)
      .def_prop_ro("report", [](const exactgeo::Mesh& mesh) -> exactgeo::MeshReport { return mesh.report(); });

  // The path as bytes (os.fsencode): a file name that is not UTF-8 cannot travel as a str.
  m.def(
      "load_mesh",
      [](const nb::bytes& name, bool weld, unsigned threads, const nb::object& progress) {
        const std::string path(name.c_str(), name.size());
        const exactgeo::MeshOptions options{.weld_duplicate_positions = weld, .threads = threads};
        // The file's size stands in for its faces until they are known: a big file is read interruptibly.
        std::error_code size_error;
        const std::uintmax_t bytes = std::filesystem::file_size(path, size_error);
        return build_mesh(progress, size_error ? 0 : bytes / kFileBytesPerFace, options,
                          [&](const exactgeo::MeshOptions& o) { return exactgeo::load_mesh(path, o); });
      },
      "path"_a, "weld_duplicate_positions"_a, "threads"_a, "progress"_a.none());

  // `what` names the points in messages: "target" gives "target 3: vertex 99 is out of range (...)"; empty,
  // the library's message as it is.
  m.def(
      "vertex_points",
      [](const exactgeo::Mesh& mesh, const IndexArray& vertices, const std::string& what) {
        std::vector<exactgeo::SurfacePoint> points;
        points.reserve(vertices.shape(0));
        for (std::uint32_t v : span_of(vertices)) {
          try {
            points.push_back(exactgeo::vertex_point(mesh, v));
          } catch (const exactgeo::Error& e) {
            if (what.empty()) throw;
            throw exactgeo::Error(e.code(), what + " " + std::to_string(points.size()) + ": " + e.what());
          }
        }
        return point_arrays(points);
      },
      "mesh"_a, "vertices"_a.noconvert(), "what"_a);
  m.def(
      "edge_point",
      [](const exactgeo::Mesh& mesh, std::uint32_t from, std::uint32_t to, double t) {
        const exactgeo::SurfacePoint point = exactgeo::edge_point(mesh, from, to, t);
        return std::make_tuple(point.face, point.barycentric);
      },
      "mesh"_a, "from_vertex"_a, "to_vertex"_a, "t"_a);
  m.def(
      "point_positions",
      [](const exactgeo::Mesh& mesh, const IndexArray& faces, const PointArray& barycentric) {
        const std::vector<exactgeo::SurfacePoint> points = surface_points(faces, barycentric);
        std::vector<double> positions(3 * points.size());
        for (std::size_t i = 0; i < points.size(); ++i) {
          const std::array<double, 3> p = exactgeo::point_position(mesh, points[i]);
          std::copy(p.begin(), p.end(), positions.begin() + 3 * i);
        }
        return to_numpy(std::move(positions), {points.size(), 3});
      },
      "mesh"_a, "faces"_a.noconvert(), "barycentric"_a.noconvert());

  // The closest surface points of an (n, 3) array, without the GIL: (faces, barycentric, distances).
  m.def(
      "locate",
      [](const exactgeo::Mesh& mesh, const PointArray& xyz, unsigned threads) {
        exactgeo::LocateResult located;
        {
          nb::gil_scoped_release release;
          located = exactgeo::locate(mesh, span_of(xyz), {.threads = threads});
        }
        auto [faces, barycentric] = point_arrays(located.points);
        const std::size_t n = located.distances.size();
        return std::make_tuple(std::move(faces), std::move(barycentric), to_numpy(std::move(located.distances), {n}));
      },
      "mesh"_a, "xyz"_a.noconvert(), "threads"_a);

  m.def(
      "make_icosphere", [](int subdivisions) { return soup_arrays(exactgeo::make_icosphere(subdivisions)); },
      "subdivisions"_a);
  m.def(
      "make_bumpy_torus",
      [](int major_segments, int minor_segments) {
        return soup_arrays(exactgeo::make_bumpy_torus(major_segments, minor_segments));
      },
      "major_segments"_a, "minor_segments"_a);
  m.def(
      "make_grid",
      [](int nx, int ny, double width, double height) {
        return soup_arrays(exactgeo::make_grid(nx, ny, width, height));
      },
      "nx"_a, "ny"_a, "width"_a, "height"_a);
  m.def(
      "subdivide_midpoint",
      [](const PointArray& positions, const TriangleArray& triangles) {
        exactgeo::MeshSoup soup{{positions.data(), positions.data() + positions.size()},
                                {triangles.data(), triangles.data() + triangles.size()}};
        return soup_arrays(exactgeo::subdivide_midpoint(soup));
      },
      "positions"_a.noconvert(), "triangles"_a.noconvert());
}

}  // namespace exactgeo::python
