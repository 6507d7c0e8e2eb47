// Uses the library as a consumer does: public headers only, a distance with a closed form, an error caught
// across the library boundary (the exception's type must be exported from a shared library).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string_view>
#include <vector>

#include "exactgeo/exactgeo.hpp"

int main() {
  // The unit square as two triangles: opposite corners are sqrt(2) apart, whichever diagonal is an edge.
  const std::vector<double> positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const std::vector<std::uint32_t> triangles = {0, 1, 3, 1, 2, 3};
  const exactgeo::Mesh mesh(positions, triangles);
  const double d = exactgeo::geodesic_distance(mesh, 0).distances[2];
  if (std::abs(d - std::sqrt(2.0)) > 1e-12) {
    std::printf("distance %.17g, expected sqrt(2)\n", d);
    return 1;
  }
  try {
    exactgeo::geodesic_distance(mesh, 4);
    std::printf("no error for a source vertex out of range\n");
    return 1;
  } catch (const exactgeo::Error& error) {
    if (error.code() != exactgeo::ErrorCode::invalid_argument) return 1;
  }
  std::printf("exactgeo %s (%d.%d.%d): distance %.17g\n", exactgeo::kVersion, EXACTGEO_VERSION_MAJOR,
              EXACTGEO_VERSION_MINOR, EXACTGEO_VERSION_PATCH, d);
  return std::string_view(exactgeo::kVersion).empty() ? 1 : 0;
}
