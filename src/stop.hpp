// Stopping on request (GeodesicOptions::stop): the engine checks between batches of wavefront pops, the
// many-source loops between runs, so a stop takes effect within milliseconds whatever the mesh size.
#pragma once

#include <stop_token>

#include "exactgeo/error.hpp"

namespace exactgeo::detail {

inline void throw_if_stopped(const std::stop_token& stop) {
  if (stop.stop_requested()) throw Error(ErrorCode::cancelled, "the run was stopped on request");
}

}  // namespace exactgeo::detail
