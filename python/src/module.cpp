// exactgeo._core: the library over numpy arrays. The package around it (python/exactgeo) turns whatever
// the caller passes (any real dtype, either memory order, lists, single values) into the exact arrays taken
// here, checking only what that conversion could lose. Every check of the values themselves happens once,
// in the library, so a bad input gets the same message from Python, C++ and the command line.
//
// This file defines the module: its errors, and the list of its parts (registration.hpp), each in a file of
// its own; marshalling.* converts arrays, interruption.hpp runs long work stoppably without the GIL.
#include <nanobind/nanobind.h>

#include <cstring>
#include <exception>

#include "exactgeo/exactgeo.hpp"
#include "registration.hpp"

namespace {

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
      case exactgeo::ErrorCode::cancelled:
        set_error(PyExc_KeyboardInterrupt, e.what());
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

  // The module's parts (registration.hpp): a new one is registered here, after those it uses.
  exactgeo::python::register_field_classes(m);
  exactgeo::python::register_mesh(m);
  exactgeo::python::register_solver(m);
  exactgeo::python::register_many_sources(m);
  exactgeo::python::register_files(m);
  exactgeo::python::register_store(m);
}
