// Errors thrown by exactgeo: one exception type carrying a code and a message that names the element at fault.
#pragma once

#include <stdexcept>
#include <string>

#include "exactgeo/export.hpp"

namespace exactgeo {

enum class ErrorCode {
  invalid_argument,  // a caller-supplied value is out of range (source index, option value)
  invalid_mesh,      // arrays or file contents that do not describe a usable triangle mesh
  io_error,          // a file that cannot be opened, read or written
  cancelled,         // the caller stopped the run (GeodesicOptions::stop)
  internal,          // a broken invariant inside the library: a bug, please report it
};

class EXACTGEO_API Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const noexcept { return code_; }

 private:
  ErrorCode code_;
};

}  // namespace exactgeo
