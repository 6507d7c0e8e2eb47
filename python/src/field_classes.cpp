// The library's structs with field tables as Python classes (GeodesicStats, MeshReport, GeodesicOptions) and
// its table of algorithm names: a field or an algorithm added to a table reaches Python without a change here.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "registration.hpp"

using namespace nb::literals;

namespace exactgeo::python {

namespace {

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
  cls.def(
      "to_dict",
      [for_each_field](const Struct& self) {
        nb::dict dict;
        for_each_field([&](const char* name, auto member, const auto&...) { dict[name] = self.*member; });
        return dict;
      },
      "The fields as a dict, in declaration order.");
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

}  // namespace

void register_field_classes(nb::module_& m) {
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
  nb::class_<exactgeo::GeodesicOptions> options(m, "GeodesicOptions",
                                                "How a run goes (C++: exactgeo::GeodesicOptions).");
  std::vector<std::string> option_names;
  exactgeo::for_each_option_field([&](const char* name, auto member, const char* description) {
    option_names.emplace_back(name);
    using Value = std::remove_cvref_t<decltype(std::declval<exactgeo::GeodesicOptions>().*member)>;
    if constexpr (std::is_same_v<Value, exactgeo::Algorithm>) {
      options.def_prop_ro(
          name,
          [member](const exactgeo::GeodesicOptions& o) { return std::string(exactgeo::algorithm_name(o.*member)); },
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
}

}  // namespace exactgeo::python
