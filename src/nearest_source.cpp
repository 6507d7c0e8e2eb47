// The source each shortest path starts from, read off a finished run's arrivals: see nearest_source.hpp.
#include "nearest_source.hpp"

#include <algorithm>

namespace exactgeo::detail {

std::uint32_t label_of(const VtpEngine& engine, std::uint32_t pseudo_source,
                       const std::vector<std::uint32_t>& vertex_labels) {
  const std::uint32_t vertex_count = engine.mesh().vertex_count;
  if (pseudo_source == kNone) return kNoSource;
  if (pseudo_source >= vertex_count) return engine.sources()[pseudo_source - vertex_count].label;
  return vertex_labels[pseudo_source];
}

std::uint32_t label_of(const VtpEngine& engine, std::uint32_t pseudo_source) {
  const std::uint32_t vertex_count = engine.mesh().vertex_count;
  const std::span<const std::uint32_t> source_label = engine.source_labels();
  const std::span<const Arrival> arrival = engine.arrivals();
  for (std::uint32_t u = pseudo_source, steps = 0; u != kNone && steps <= vertex_count; ++steps) {
    if (u >= vertex_count) return engine.sources()[u - vertex_count].label;
    if (source_label[u] != kNone) return source_label[u];
    u = arrival[u].from;
  }
  return kNoSource;
}

// Each vertex takes the label of the pseudo-source its last straight piece starts from. Pseudo-sources are
// reached with strictly smaller distances, so resolving vertices in order of distance needs one step each.
std::vector<std::uint32_t> vertex_labels(const VtpEngine& engine) {
  const std::uint32_t vertex_count = engine.mesh().vertex_count;
  const std::span<const double> distance = engine.distances();
  const std::span<const std::uint32_t> source_label = engine.source_labels();
  const std::span<const Arrival> arrival = engine.arrivals();
  std::vector<std::uint32_t> order;
  for (std::uint32_t v = 0; v < vertex_count; ++v)
    if (engine.answers(distance[v])) order.push_back(v);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return distance[a] < distance[b] || (distance[a] == distance[b] && a < b);
  });
  std::vector<std::uint32_t> label(vertex_count, kNoSource);
  for (std::uint32_t v : order)
    label[v] = source_label[v] != kNone ? source_label[v] : label_of(engine, arrival[v].from, label);
  // A pseudo-source at exactly the same distance (across a zero-length edge) may come later in that order.
  for (std::uint32_t v : order)
    for (std::uint32_t u = v, steps = 0; label[v] == kNoSource && steps <= vertex_count; ++steps) {
      u = arrival[u].from;
      if (u == kNone) break;
      label[v] = label_of(engine, u, label);
      if (u >= vertex_count) break;
    }
  return label;
}

}  // namespace exactgeo::detail
