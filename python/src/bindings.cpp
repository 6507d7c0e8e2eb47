// exactgeo._core: the library over numpy arrays. The package around it (python/exactgeo) turns whatever
// the caller passes (any real dtype, either memory order, lists, single values) into the exact arrays taken
// here, checking only what that conversion could lose. Every check of the values themselves happens once,
// in the library, so a bad input gets the same message from Python, C++ and the command line.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/string_view.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <future>
#include <initializer_list>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <stop_token>
#include <string>
#include <string_view>
#include <thread>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "exactgeo/exactgeo.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

// Arrays as the package hands them over: exact dtype, C order, in main memory. Arguments of these types are
// marked noconvert: nanobind's own conversion would wrap negative indices silently.
using PointArray = nb::ndarray<const double, nb::shape<-1, 3>, nb::c_contig, nb::device::cpu>;
using TriangleArray = nb::ndarray<const std::uint32_t, nb::shape<-1, 3>, nb::c_contig, nb::device::cpu>;
using IndexArray = nb::ndarray<const std::uint32_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

template <class T>
using NumpyArray = nb::ndarray<nb::numpy, T>;

template <class Array>
auto span_of(const Array& array) {
  return std::span(array.data(), array.size());
}

// Hands a vector's storage to numpy without copying it: the capsule frees the vector with the array.
template <class T>
NumpyArray<T> to_numpy(std::vector<T>&& values, std::initializer_list<std::size_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  nb::capsule owner(owned, [](void* vector) noexcept { delete static_cast<std::vector<T>*>(vector); });
  return NumpyArray<T>(owned->data(), shape, owner);
}

// Indices into sources or samples, with -1 where the library says kNoSource (unreachable): numpy code
// expects signed indices, and -1 is the usual "none".
std::vector<std::int64_t> signed_indices(std::span<const std::uint32_t> indices) {
  std::vector<std::int64_t> result(indices.size());
  for (std::size_t i = 0; i < indices.size(); ++i)
    result[i] = indices[i] == exactgeo::kNoSource ? -1 : std::int64_t{indices[i]};
  return result;
}

// A result struct as a Python class generated from the library's field table (for_each_stats_field,
// for_each_report_field): one attribute per field with its description as docstring, to_dict(), equality,
// repr and pickling. A field added to the table reaches Python without a change here.
template <class Struct, class ForEachField>
void bind_fields(nb::class_<Struct>& cls, ForEachField for_each_field) {
  // The visitors pass (name, member, [kind,] description): the description is the last argument.
  for_each_field([&](const char* name, auto member, const auto&... rest) {
    const char* description = std::get<sizeof...(rest) - 1>(std::tuple(rest...));
    cls.def_rw(name, member, description);
  });
  // The library fills these in: arguments are refused in one line, not nanobind's list of signatures.
  cls.def("__init__", [](Struct* self, const nb::args& args, const nb::kwargs& keywords) {
    if (args.size() != 0 || keywords.size() != 0)
      throw nb::type_error(("exactgeo." + nb::cast<std::string>(nb::type<Struct>().attr("__name__")) +
                            "() takes no arguments: the library fills it in")
                               .c_str());
    new (self) Struct{};
  });
  cls.def("to_dict", [for_each_field](const Struct& self) {
    nb::dict dict;
    for_each_field([&](const char* name, auto member, const auto&...) { dict[name] = self.*member; });
    return dict;
  }, "The fields as a dict, in declaration order.");
  cls.def("__eq__", [for_each_field](const Struct& self, const Struct& other) {
    bool equal = true;
    for_each_field([&](const char*, auto member, const auto&...) { equal = equal && self.*member == other.*member; });
    return equal;
  });
  cls.def("__repr__", [for_each_field](const Struct& self) {
    // Named as the package exports it: exactgeo.GeodesicStats, not exactgeo._core.GeodesicStats.
    std::string text = "exactgeo." + nb::cast<std::string>(nb::type<Struct>().attr("__name__")) + "(";
    bool first = true;
    for_each_field([&](const char* name, auto member, const auto&...) {
      text += std::string(first ? "" : ", ") + name + "=" + nb::repr(nb::cast(self.*member)).c_str();
      first = false;
    });
    return text + ")";
  });
  // Pickled as the tuple of the fields, in declaration order.
  cls.def("__getstate__", [for_each_field](const Struct& self) {
    nb::list state;
    for_each_field([&](const char*, auto member, const auto&...) { state.append(self.*member); });
    return nb::tuple(state);
  });
  cls.def("__setstate__", [for_each_field](Struct& self, const nb::tuple& state) {
    new (&self) Struct{};
    std::size_t i = 0;
    for_each_field([&](const char*, auto member, const auto&...) {
      self.*member = nb::cast<std::remove_reference_t<decltype(self.*member)>>(state[i++]);
    });
  });
}

// Surface points travel as two arrays: faces (n) and barycentric coordinates (n x 3). The package pairs
// them; the check keeps a direct call of the module from reading past the shorter one.
std::vector<exactgeo::SurfacePoint> surface_points(const IndexArray& faces, const PointArray& barycentric) {
  if (faces.shape(0) != barycentric.shape(0))
    throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument,
                          std::to_string(faces.shape(0)) + " faces but " + std::to_string(barycentric.shape(0)) +
                              " rows of barycentric coordinates");
  std::vector<exactgeo::SurfacePoint> points(faces.shape(0));
  for (std::size_t i = 0; i < points.size(); ++i)
    points[i] = {faces(i), {barycentric(i, 0), barycentric(i, 1), barycentric(i, 2)}};
  return points;
}

std::tuple<NumpyArray<std::uint32_t>, NumpyArray<double>> point_arrays(std::span<const exactgeo::SurfacePoint> points) {
  std::vector<std::uint32_t> faces(points.size());
  std::vector<double> barycentric(3 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    faces[i] = points[i].face;
    std::copy(points[i].barycentric.begin(), points[i].barycentric.end(), barycentric.begin() + 3 * i);
  }
  return {to_numpy(std::move(faces), {points.size()}), to_numpy(std::move(barycentric), {points.size(), 3})};
}

// A path as flat arrays: every point is a convex combination of up to three input vertices, so the
// locations are the vertices (n x 3, -1 where unused) and their weights (n x 3), plus the kind of place and,
// for points inside a triangle, the face (-1 otherwise).
nb::tuple path_arrays(const exactgeo::GeodesicPath& path, const exactgeo::Mesh& mesh) {
  using Kind = exactgeo::PathPointLocation::Kind;
  const std::size_t n = path.points.size();
  std::vector<double> points(3 * n), weights(3 * n, 0.0);
  std::vector<std::int64_t> vertices(3 * n, -1), faces(n, -1);
  std::vector<std::string> kinds(n);
  const auto triangles = mesh.triangles();
  for (std::size_t i = 0; i < n; ++i) {
    std::copy(path.points[i].begin(), path.points[i].end(), points.begin() + 3 * i);
    const exactgeo::PathPointLocation& location = path.locations[i];
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
  const std::int64_t source = path.source == exactgeo::kNoSource ? -1 : std::int64_t{path.source};
  return nb::make_tuple(to_numpy(std::move(points), {n, 3}), std::move(kinds), to_numpy(std::move(vertices), {n, 3}),
                        to_numpy(std::move(weights), {n, 3}), to_numpy(std::move(faces), {n}), path.length, source);
}

// A generated or subdivided mesh as (vertices n x 3, faces m x 3), the arrays handed over without a copy.
std::tuple<NumpyArray<double>, NumpyArray<std::uint32_t>> soup_arrays(exactgeo::MeshSoup&& soup) {
  const std::size_t vertices = soup.positions.size() / 3, faces = soup.triangles.size() / 3;
  return {to_numpy(std::move(soup.positions), {vertices, 3}), to_numpy(std::move(soup.triangles), {faces, 3})};
}

// A solver bound to Python. It keeps its own handle on the mesh (a shared pointer inside exactgeo::Mesh), so
// the Python mesh may be dropped first. The GIL is released while it runs, so two Python threads could call
// the same solver at once: the mutex makes the second one wait. Runs are numbered, so that a path query can
// tell that another thread ran the solver since the run the caller means.
struct Solver {
  explicit Solver(const exactgeo::Mesh& mesh_) : mesh(mesh_), solver(mesh) {}
  exactgeo::Mesh mesh;
  exactgeo::GeodesicSolver solver;
  std::mutex busy;
  std::uint64_t runs = 0;
};

// What `query` answers about run `run` (the caller's last), refused if the solver has run again since.
auto ask(Solver& self, std::uint64_t run, const auto& query) {
  nb::gil_scoped_release release;
  const std::lock_guard lock(self.busy);
  if (run != self.runs)
    throw std::runtime_error(
        "this GeodesicSolver has run again since this thread's solve() (from another thread): its answers "
        "would belong to that run. Use one GeodesicSolver per thread.");
  return query(self.solver);
}

// A path of run `run`, as ask() gets it.
nb::tuple trace(Solver& self, std::uint64_t run, const auto& query) {
  return path_arrays(ask(self, run, query), self.mesh);
}

// Progress of long work as the worker reports it: units done out of a total (rows, samples, vertices).
struct ProgressCounter {
  std::atomic<std::size_t> done{0};
  std::atomic<std::size_t> total{0};
};

// Runs `work(stop, progress)` on a worker thread. This thread waits without the GIL, taking it every 50 ms to
// let Python handle signals and to pass the progress to `on_progress(done, total)` (None: nobody listens).
// Ctrl-C stops the work (GeodesicOptions::stop ends it within milliseconds) and raises KeyboardInterrupt once
// the worker has returned; an exception from `on_progress` stops it the same way.
template <class Work>
auto run_interruptibly(const nb::object& on_progress, Work&& work) {
  using Result = decltype(work(std::stop_token{}, std::declval<ProgressCounter&>()));
  std::stop_source stop;
  ProgressCounter progress;
  std::optional<Result> result;
  std::exception_ptr failure;
  bool python_raised = false;
  {
    nb::gil_scoped_release release;
    std::promise<void> finished;
    std::future<void> done = finished.get_future();
    std::jthread worker([&] {
      try {
        result.emplace(work(stop.get_token(), progress));
      } catch (...) {
        failure = std::current_exception();
      }
      finished.set_value();
    });
    std::size_t reported = 0;
    while (done.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
      nb::gil_scoped_acquire acquire;
      bool raised = PyErr_CheckSignals() != 0;
      const std::size_t now = progress.done.load();
      if (!raised && !on_progress.is_none() && now != reported) {
        reported = now;
        try {
          on_progress(now, progress.total.load());
        } catch (nb::python_error& e) {
          e.restore();
          raised = true;
        }
      }
      if (raised) {
        python_raised = true;
        stop.request_stop();
        break;
      }
    }
  }  // the worker is joined here, without the GIL
  if (python_raised) throw nb::python_error();
  if (failure) std::rethrow_exception(failure);
  return std::move(*result);
}

// Single runs on meshes this large take long enough (tens of milliseconds and more) to be worth a worker
// thread that Ctrl-C can stop; smaller ones run on the calling thread, where that overhead would show.
constexpr std::size_t kInterruptibleVertices = 20000;

// What a run returns to Python: per vertex distance and nearest source, per target the same, statistics.
// `run(solver, options)` starts the run with the options it is given.
nb::tuple solve(Solver& self, exactgeo::GeodesicOptions options, const nb::object& progress, const auto& run) {
  std::vector<double> distances, target_distances;
  std::vector<std::int64_t> nearest, target_nearest;
  exactgeo::GeodesicStats stats;
  std::uint64_t run_number = 0;
  const auto copy_result = [&](const exactgeo::GeodesicResult& result) {
    // Copies: the solver keeps its result for path queries.
    distances = result.distances;
    target_distances = result.target_distances;
    nearest = signed_indices(result.nearest_source);
    target_nearest = signed_indices(result.target_nearest_source);
    stats = result.stats;
  };
  if (progress.is_none() && self.mesh.vertex_count() < kInterruptibleVertices) {
    nb::gil_scoped_release release;
    const std::lock_guard lock(self.busy);
    run_number = ++self.runs;  // before the run: a failed run invalidates the paths of the one before
    copy_result(run(self.solver, options));
  } else {
    run_interruptibly(progress, [&](std::stop_token stop, ProgressCounter& counter) {
      const std::lock_guard lock(self.busy);
      run_number = ++self.runs;
      // Progress in thousandths of the vertices the wavefront has passed.
      counter.total = 1000;
      self.solver.set_progress([&](double fraction) { counter.done = static_cast<std::size_t>(1000 * fraction); });
      options.stop = stop;
      try {
        copy_result(run(self.solver, options));
      } catch (...) {
        self.solver.set_progress({});
        throw;
      }
      self.solver.set_progress({});
      return true;
    });
  }
  const std::size_t vertices = distances.size(), targets = target_distances.size();
  return nb::make_tuple(to_numpy(std::move(distances), {vertices}), to_numpy(std::move(nearest), {vertices}),
                        to_numpy(std::move(target_distances), {targets}),
                        to_numpy(std::move(target_nearest), {targets}), nb::cast(stats), run_number);
}

// Meshes this large take long enough to build (tens of milliseconds and more) to be worth a worker thread
// that Ctrl-C can stop; smaller ones are built on the calling thread (without the GIL).
constexpr std::size_t kInterruptibleFaces = 40000;
// About the bytes a face takes in a mesh file (an OBJ's `f` line and half a `v` line).
constexpr std::uintmax_t kFileBytesPerFace = 40;

// A mesh built by `build(options)`: on a worker thread that Ctrl-C stops (with progress in thousandths of
// the build) when it is large or progress is asked for, else here.
template <class Build>
exactgeo::Mesh build_mesh(const nb::object& progress, std::size_t faces, exactgeo::MeshOptions options, Build&& build) {
  if (progress.is_none() && faces < kInterruptibleFaces) {
    nb::gil_scoped_release release;
    return build(options);
  }
  return run_interruptibly(progress, [&](std::stop_token stop, ProgressCounter& counter) {
    counter.total = 1000;
    options.stop = stop;
    options.progress = [&](double fraction) { counter.done = static_cast<std::size_t>(1000 * fraction); };
    return build(options);
  });
}

// A message may quote a file name that is not UTF-8: its bytes are shown as \xNN escapes, where decoding the
// message as UTF-8 would fail and raise an error about the message instead of the error itself.
void set_error(PyObject* type, const char* message) {
  const nb::object text =
      nb::steal(PyUnicode_DecodeUTF8(message, Py_ssize_t(std::strlen(message)), "backslashreplace"));
  PyErr_SetObject(type, text.ptr());
}

void translate_error(const std::exception_ptr& error, void*) {
  try {
    std::rethrow_exception(error);
  } catch (const exactgeo::Error& e) {
    switch (e.code()) {
      case exactgeo::ErrorCode::invalid_argument:
      case exactgeo::ErrorCode::invalid_mesh:
        set_error(PyExc_ValueError, e.what());
        return;
      case exactgeo::ErrorCode::io_error:
        set_error(PyExc_OSError, e.what());
        return;
      case exactgeo::ErrorCode::internal:
        set_error(PyExc_RuntimeError, e.what());
        return;
    }
  }
}

}  // namespace

NB_MODULE(_core, m) {
  m.doc() = "exactgeo's compiled core. Use the exactgeo package, which converts and checks the arguments.";
  m.attr("version") = exactgeo::kVersion;
  nb::register_exception_translator(translate_error);

  // The library's own table of names: a new Algorithm value reaches Python without a change here.
  m.def("recommended_threads", &exactgeo::recommended_threads, "mesh"_a,
        "Threads worth giving one run on this mesh: one per 10,000 faces, up to one per core.");
  m.def("algorithm_names", [] {
    std::vector<std::string> names;
    for (const auto& [algorithm, name] : exactgeo::kAlgorithmNames) names.emplace_back(name);
    return names;
  });

  nb::class_<exactgeo::GeodesicStats> stats(m, "GeodesicStats",
                                            "What a run did: the paper's counts (Section 6.2) and the time.");
  bind_fields(stats, [](auto&& visit) { exactgeo::for_each_stats_field(visit); });
  nb::class_<exactgeo::MeshReport> report(m, "MeshReport", "What validation found in a mesh.");
  bind_fields(report, [](auto&& visit) { exactgeo::for_each_report_field(visit); });

  // Options from keyword arguments named as in the library's table (for_each_option_field), the algorithm by
  // its name; read-only attributes of the same names, and `fields`, the names in order.
  nb::class_<exactgeo::GeodesicOptions> options(m, "GeodesicOptions", "How a run goes (C++: exactgeo::GeodesicOptions).");
  std::vector<std::string> option_names;
  exactgeo::for_each_option_field([&](const char* name, auto member, const char* description) {
    option_names.emplace_back(name);
    using Value = std::remove_cvref_t<decltype(std::declval<exactgeo::GeodesicOptions>().*member)>;
    if constexpr (std::is_same_v<Value, exactgeo::Algorithm>) {
      options.def_prop_ro(
          name, [member](const exactgeo::GeodesicOptions& o) { return std::string(exactgeo::algorithm_name(o.*member)); },
          description);
    } else {
      options.def_ro(name, member, description);
    }
  });
  options.attr("fields") = nb::tuple(nb::cast(option_names));
  options.def("__init__", [option_names](exactgeo::GeodesicOptions* self, const nb::kwargs& settings) {
    for (const auto& [key, value] : settings) {
      const std::string name = nb::cast<std::string>(key);
      if (std::find(option_names.begin(), option_names.end(), name) == option_names.end())
        throw nb::type_error(("unknown option '" + name + "'").c_str());
    }
    new (self) exactgeo::GeodesicOptions{};
    exactgeo::for_each_option_field([&](const char* name, auto member, const char*) {
      if (!settings.contains(name)) return;
      using Value = std::remove_cvref_t<decltype(self->*member)>;
      if constexpr (std::is_same_v<Value, exactgeo::Algorithm>) {
        self->*member = exactgeo::parse_algorithm(nb::cast<std::string>(settings[name]));
      } else {
        self->*member = nb::cast<Value>(settings[name]);
      }
    });
  });

  nb::class_<exactgeo::Mesh>(m, "Mesh")
      .def(
          "__init__",
          [](exactgeo::Mesh* self, const PointArray& positions, const TriangleArray& triangles, bool weld,
             unsigned threads, const nb::object& progress) {
            const exactgeo::MeshOptions options{.weld_duplicate_positions = weld, .threads = threads};
            new (self) exactgeo::Mesh(build_mesh(progress, triangles.shape(0), options, [&](const exactgeo::MeshOptions& o) {
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
      [](int nx, int ny, double width, double height) { return soup_arrays(exactgeo::make_grid(nx, ny, width, height)); },
      "nx"_a, "ny"_a, "width"_a, "height"_a);
  m.def(
      "subdivide_midpoint",
      [](const PointArray& positions, const TriangleArray& triangles) {
        exactgeo::MeshSoup soup{{positions.data(), positions.data() + positions.size()},
                                {triangles.data(), triangles.data() + triangles.size()}};
        return soup_arrays(exactgeo::subdivide_midpoint(soup));
      },
      "positions"_a.noconvert(), "triangles"_a.noconvert());

  nb::class_<Solver>(m, "GeodesicSolver")
      .def(nb::init<const exactgeo::Mesh&>(), "mesh"_a)
      .def(
          "solve_from_vertices",
          [](Solver& self, const IndexArray& sources, const IndexArray& target_faces,
             const PointArray& target_barycentric, const exactgeo::GeodesicOptions& options, const nb::object& progress) {
            const std::vector<exactgeo::SurfacePoint> targets = surface_points(target_faces, target_barycentric);
            return solve(self, options, progress,
                         [&](exactgeo::GeodesicSolver& solver,
                             const exactgeo::GeodesicOptions& run_options) -> const exactgeo::GeodesicResult& {
                           return solver.solve(span_of(sources), targets, run_options);
                         });
          },
          "sources"_a.noconvert(), "target_faces"_a.noconvert(), "target_barycentric"_a.noconvert(), "options"_a,
          "progress"_a.none())
      .def(
          "solve_from_points",
          [](Solver& self, const IndexArray& source_faces, const PointArray& source_barycentric,
             const IndexArray& target_faces, const PointArray& target_barycentric,
             const exactgeo::GeodesicOptions& options, const nb::object& progress) {
            const std::vector<exactgeo::SurfacePoint> sources = surface_points(source_faces, source_barycentric);
            const std::vector<exactgeo::SurfacePoint> targets = surface_points(target_faces, target_barycentric);
            return solve(self, options, progress,
                         [&](exactgeo::GeodesicSolver& solver,
                             const exactgeo::GeodesicOptions& run_options) -> const exactgeo::GeodesicResult& {
                           return solver.solve(sources, targets, run_options);
                         });
          },
          "source_faces"_a.noconvert(), "source_barycentric"_a.noconvert(), "target_faces"_a.noconvert(),
          "target_barycentric"_a.noconvert(), "options"_a, "progress"_a.none())
      .def(
          "path_to_vertex",
          [](Solver& self, std::uint32_t vertex, std::uint64_t run) {
            return trace(self, run, [&](const exactgeo::GeodesicSolver& solver) { return solver.path_to_vertex(vertex); });
          },
          "vertex"_a, "run"_a)
      .def(
          "path_to_target",
          [](Solver& self, std::size_t target, std::uint64_t run) {
            return trace(self, run, [&](const exactgeo::GeodesicSolver& solver) { return solver.path_to_target(target); });
          },
          "target"_a, "run"_a)
      .def(
          "distance_at",
          [](Solver& self, const IndexArray& faces, const PointArray& barycentric, std::uint64_t run) {
            const std::vector<exactgeo::SurfacePoint> points = surface_points(faces, barycentric);
            std::vector<double> distances =
                ask(self, run, [&](const exactgeo::GeodesicSolver& solver) { return solver.distance_at(points); });
            return to_numpy(std::move(distances), {points.size()});
          },
          "faces"_a.noconvert(), "barycentric"_a.noconvert(), "run"_a)
      .def(
          "path_to_point",
          [](Solver& self, const IndexArray& faces, const PointArray& barycentric, std::uint64_t run) {
            const std::vector<exactgeo::SurfacePoint> points = surface_points(faces, barycentric);
            if (points.size() != 1)
              throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument, "path_to_point takes one point");
            return trace(self, run, [&](const exactgeo::GeodesicSolver& solver) { return solver.path_to_point(points[0]); });
          },
          "faces"_a.noconvert(), "barycentric"_a.noconvert(), "run"_a);

  // Matrix options from the arguments: columns are the targets when has_targets, else every vertex.
  const auto matrix_options = [](const exactgeo::GeodesicOptions& options, unsigned threads, const IndexArray& targets,
                                 bool has_targets) {
    exactgeo::MatrixOptions matrix{.geodesic = options, .threads = threads};
    if (has_targets) matrix.target_vertices.emplace(span_of(targets).begin(), span_of(targets).end());
    return matrix;
  };

  // The dense matrix written into `out` (sources x columns, float64, or float32: each distance rounded to
  // nearest) as the library hands over its blocks of a few rows: no other copy of the matrix is made, so a
  // float32 matrix never exists as float64 in full.
  using MatrixArray = nb::ndarray<nb::ndim<2>, nb::c_contig, nb::device::cpu>;
  m.def(
      "fill_distance_matrix",
      [matrix_options](const exactgeo::Mesh& mesh, const IndexArray& sources, const IndexArray& targets,
                       bool has_targets, exactgeo::GeodesicOptions options, unsigned threads, const MatrixArray& out,
                       const nb::object& progress) {
        const std::size_t columns = has_targets ? targets.shape(0) : mesh.vertex_count();
        if (out.shape(0) != sources.shape(0) || out.shape(1) != columns)
          throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument,
                                "out has shape (" + std::to_string(out.shape(0)) + ", " + std::to_string(out.shape(1)) +
                                    "), not (" + std::to_string(sources.shape(0)) + ", " + std::to_string(columns) + ")");
        const auto fill = [&](auto* values) {
          run_interruptibly(progress, [&](std::stop_token stop, ProgressCounter& counter) {
            options.stop = stop;
            counter.total = sources.shape(0);
            exactgeo::for_each_distance_block(
                mesh, span_of(sources), matrix_options(options, threads, targets, has_targets),
                [&](std::size_t first, std::span<const double> block) {
                  using Value = std::remove_pointer_t<decltype(values)>;
                  std::transform(block.begin(), block.end(), values + first * columns,
                                 [](double distance) { return static_cast<Value>(distance); });
                  counter.done = first + (columns ? block.size() / columns : 0);
                });
            return true;
          });
        };
        if (out.dtype() == nb::dtype<double>())
          fill(static_cast<double*>(out.data()));
        else if (out.dtype() == nb::dtype<float>())
          fill(static_cast<float*>(out.data()));
        else
          throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument, "out must hold float64 or float32 values");
      },
      "mesh"_a, "sources"_a.noconvert(), "targets"_a.noconvert(), "has_targets"_a, "options"_a, "threads"_a,
      "out"_a.noconvert(), "progress"_a.none());

  // The finite entries as compressed sparse rows: values, column indices and row offsets.
  m.def(
      "sparse_distance_matrix",
      [matrix_options](const exactgeo::Mesh& mesh, const IndexArray& sources, const IndexArray& targets,
                       bool has_targets, exactgeo::GeodesicOptions options, unsigned threads,
                       const nb::object& progress) {
        const std::size_t rows = sources.shape(0), columns = has_targets ? targets.shape(0) : mesh.vertex_count();
        std::vector<double> values;
        std::vector<std::uint32_t> column_indices;
        std::vector<std::int64_t> row_offsets = {0};
        run_interruptibly(progress, [&](std::stop_token stop, ProgressCounter& counter) {
          options.stop = stop;
          counter.total = rows;
          if (columns == 0) row_offsets.assign(rows + 1, 0);  // no entries, and no block to count rows in
          exactgeo::for_each_distance_block(mesh, span_of(sources), matrix_options(options, threads, targets, has_targets),
                                            [&](std::size_t first, std::span<const double> block) {
                                              for (std::size_t i = 0; i < block.size(); ++i) {
                                                if (!std::isinf(block[i])) {
                                                  values.push_back(block[i]);
                                                  column_indices.push_back(static_cast<std::uint32_t>(i % columns));
                                                }
                                                if ((i + 1) % columns == 0) row_offsets.push_back(std::int64_t(values.size()));
                                              }
                                              counter.done = first + (columns ? block.size() / columns : 0);
                                            });
          return true;
        });
        const std::size_t entries = values.size();
        return std::make_tuple(to_numpy(std::move(values), {entries}), to_numpy(std::move(column_indices), {entries}),
                               to_numpy(std::move(row_offsets), {rows + 1}));
      },
      "mesh"_a, "sources"_a.noconvert(), "targets"_a.noconvert(), "has_targets"_a, "options"_a, "threads"_a,
      "progress"_a.none());

  // Distances (and paths) between pairs of points, each from a search of its own, on `threads` threads.
  m.def(
      "pair_distances",
      [](const exactgeo::Mesh& mesh, const IndexArray& a_faces, const PointArray& a_barycentric,
         const IndexArray& b_faces, const PointArray& b_barycentric, exactgeo::GeodesicOptions options,
         unsigned threads, bool return_paths) {
        const std::vector<exactgeo::SurfacePoint> a = surface_points(a_faces, a_barycentric);
        const std::vector<exactgeo::SurfacePoint> b = surface_points(b_faces, b_barycentric);
        exactgeo::PairResult result = run_interruptibly(nb::none(), [&](std::stop_token stop, ProgressCounter&) {
          options.stop = stop;
          return exactgeo::pair_distances(mesh, a, b, {.geodesic = options, .threads = threads, .return_paths = return_paths});
        });
        nb::list paths;
        for (const exactgeo::GeodesicPath& path : result.paths) paths.append(path_arrays(path, mesh));
        const std::size_t n = result.distances.size();
        return std::make_tuple(to_numpy(std::move(result.distances), {n}), paths);
      },
      "mesh"_a, "a_faces"_a.noconvert(), "a_barycentric"_a.noconvert(), "b_faces"_a.noconvert(),
      "b_barycentric"_a.noconvert(), "options"_a, "threads"_a, "return_paths"_a);

  m.def(
      "farthest_point_sampling",
      [](const exactgeo::Mesh& mesh, std::size_t count, const IndexArray& first, exactgeo::GeodesicOptions options,
         const nb::object& progress) {
        exactgeo::Sampling sampling = run_interruptibly(progress, [&](std::stop_token stop, ProgressCounter& counter) {
          options.stop = stop;
          counter.total = count;
          return exactgeo::farthest_point_sampling(mesh, count, span_of(first), options,
                                                   [&](std::size_t taken) { counter.done = taken; });
        });
        std::vector<std::int64_t> samples(sampling.samples.begin(), sampling.samples.end());
        std::vector<std::int64_t> nearest = signed_indices(sampling.nearest_sample);
        const std::size_t taken = samples.size(), vertices = nearest.size();
        return std::make_tuple(to_numpy(std::move(samples), {taken}), to_numpy(std::move(sampling.radii), {taken}),
                               to_numpy(std::move(sampling.distances), {vertices}),
                               to_numpy(std::move(nearest), {vertices}));
      },
      "mesh"_a, "count"_a, "first"_a.noconvert(), "options"_a, "progress"_a.none());

  void register_store(nb::module_&);  // the distance matrix store: store_bindings.cpp
  register_store(m);
}
