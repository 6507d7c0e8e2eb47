// The files of a mesh with a value per vertex (exactgeo/value_files.hpp), as bytes for save_vtk and save_ply:
// the command's writers, so that both write the same files; and the command's colour ramp, the package's
// built-in one, so that both colour alike.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "marshalling.hpp"
#include "registration.hpp"

using namespace nb::literals;

namespace exactgeo::python {
namespace {

using ValueArray = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using ColourArray = nb::ndarray<const std::uint8_t, nb::shape<-1, 3>, nb::c_contig, nb::device::cpu>;

nb::bytes as_bytes(const std::vector<unsigned char>& bytes) {
  return nb::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

}  // namespace

void register_files(nb::module_& m) {
  m.def(
      "vtk_file_bytes",
      [](const Mesh& mesh, const ValueArray& values, const std::string& value_name) {
        return as_bytes(vtk_file_bytes(mesh, {span_of(values), value_name, {}}));
      },
      "mesh"_a, "values"_a.noconvert(), "value_name"_a);
  m.def(
      "ply_file_bytes",
      [](const Mesh& mesh, const ValueArray& values, const std::string& value_name, const ColourArray& colours) {
        return as_bytes(ply_file_bytes(mesh, {span_of(values), value_name, {}}, span_of(colours)));
      },
      "mesh"_a, "values"_a.noconvert(), "value_name"_a, "colours"_a.noconvert());
  m.def(
      "ramp_colour",
      [](const ValueArray& t) {
        std::vector<double> colours;
        colours.reserve(3 * t.size());
        for (const double at : span_of(t))
          for (const double channel : ramp_colour(at)) colours.push_back(channel);
        return to_numpy(std::move(colours), {t.size(), 3});
      },
      "t"_a.noconvert());
  m.attr("no_value_colour") = nb::make_tuple(kNoValueColour[0], kNoValueColour[1], kNoValueColour[2]);
}

}  // namespace exactgeo::python
