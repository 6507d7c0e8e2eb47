// Marshalling between numpy and the library's flat arrays: the array types the package hands over (exact
// dtype, C order), vectors handed to numpy without a copy, and the conversions of surface points, paths and
// meshes. Python objects are touched only here and in the bindings that call these.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include "exactgeo/exactgeo.hpp"

namespace nb = nanobind;

namespace exactgeo::python {

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
std::vector<std::int64_t> signed_indices(std::span<const std::uint32_t> indices);

// Surface points travel as two arrays: faces (n) and barycentric coordinates (n x 3). The package pairs
// them; the check keeps a direct call of the module from reading past the shorter one.
std::vector<SurfacePoint> surface_points(const IndexArray& faces, const PointArray& barycentric);
std::tuple<NumpyArray<std::uint32_t>, NumpyArray<double>> point_arrays(std::span<const SurfacePoint> points);

// A path as flat arrays: every point is a convex combination of up to three input vertices, so the
// locations are the vertices (n x 3, -1 where unused) and their weights (n x 3), plus the kind of place and,
// for points inside a triangle, the face (-1 otherwise).
nb::tuple path_arrays(const GeodesicPath& path, const Mesh& mesh);

// A generated or subdivided mesh as (vertices n x 3, faces m x 3), the arrays handed over without a copy.
std::tuple<NumpyArray<double>, NumpyArray<std::uint32_t>> soup_arrays(MeshSoup&& soup);

}  // namespace exactgeo::python
