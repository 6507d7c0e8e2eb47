// The nearest source of each vertex and point of a finished run: the source its shortest path starts from,
// found by following the arrivals back through the pseudo-sources (GeodesicResult::nearest_source).
#pragma once

#include <cstdint>
#include <vector>

#include "vtp_engine.hpp"

namespace exactgeo::detail {

// The source each surface vertex's path starts from (an index into the user's sources), kNoSource where the
// distance is +inf; and the same for a pseudo-source id as used in Arrival::from, given those labels.
std::vector<std::uint32_t> vertex_labels(const VtpEngine& engine);
std::uint32_t label_of(const VtpEngine& engine, std::uint32_t pseudo_source,
                       const std::vector<std::uint32_t>& vertex_labels);
// The same for one pseudo-source, by following its chain of arrivals back to a source (vertex_labels' rule,
// without labelling every vertex).
std::uint32_t label_of(const VtpEngine& engine, std::uint32_t pseudo_source);

}  // namespace exactgeo::detail
