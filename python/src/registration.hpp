// The parts of exactgeo._core, each defined by a register_... function in a file of its own and registered on
// the module by module.cpp, in this order. A new part: a file of its own (python/CMakeLists.txt lists it), its
// function declared here and called in module.cpp.
#pragma once

#include <nanobind/nanobind.h>

namespace nb = nanobind;

namespace exactgeo::python {

void register_field_classes(nb::module_& m);  // field_classes.cpp: statistics, report, options, algorithm names
void register_mesh(nb::module_& m);           // mesh_bindings.cpp: meshes, files, surface points, shapes
void register_solver(nb::module_& m);         // solver_bindings.cpp: GeodesicSolver, its runs and queries
void register_many_sources(nb::module_& m);   // many_sources_bindings.cpp: matrices, pairs, sampling
void register_files(nb::module_& m);          // file_bindings.cpp: a mesh with values as VTK and PLY files
void register_store(nb::module_& m);          // store_bindings.cpp: the distance matrix store of store/

}  // namespace exactgeo::python
