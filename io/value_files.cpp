// The files of a mesh with a value per vertex: see value_files.hpp.
#include "exactgeo/value_files.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <string>
#include <type_traits>

#include "exactgeo/error.hpp"

namespace exactgeo {
namespace {

// Throws unless `values` fits `mesh`: one value (and label, if any) per vertex, and a name that the formats'
// headers can carry.
void check_values(const Mesh& mesh, const VertexValues& values) {
  const auto per_vertex = [&](std::size_t count, const char* what) {
    if (count != mesh.vertex_count())
      throw Error(ErrorCode::invalid_argument, "got " + std::to_string(count) + " " + what + ", but the mesh has " +
                                                   std::to_string(mesh.vertex_count()) + " vertices");
  };
  per_vertex(values.values.size(), "values");
  if (!values.labels.empty()) per_vertex(values.labels.size(), "labels");
  const std::string& name = values.value_name;
  const auto plain = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0])) ||
      !std::all_of(name.begin(), name.end(), plain))
    throw Error(ErrorCode::invalid_argument,
                "value_name must be a plain name (ASCII letters, digits and _, not "
                "starting with a digit) for the file's header, not '" +
                    name + "'");
}

// The nearest-source label as written: -1 for kNoSource.
std::int32_t label_value(std::uint32_t label) { return label == kNoSource ? -1 : static_cast<std::int32_t>(label); }

// The bytes of a 32- or 64-bit value, least (PLY) or most (VTK) significant first.
template <class T>
void append_little_endian(std::vector<unsigned char>& bytes, T value) {
  using Bits = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
  const auto bits = std::bit_cast<Bits>(value);
  for (std::size_t byte = 0; byte < sizeof(T); ++byte) bytes.push_back(static_cast<unsigned char>(bits >> (8 * byte)));
}
template <class T>
void append_big_endian(std::vector<unsigned char>& bytes, T value) {
  using Bits = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
  const auto bits = std::bit_cast<Bits>(value);
  for (int byte = sizeof(T) - 1; byte >= 0; --byte) bytes.push_back(static_cast<unsigned char>(bits >> (8 * byte)));
}

void append_text(std::vector<unsigned char>& bytes, const std::string& text) {
  bytes.insert(bytes.end(), text.begin(), text.end());
}

}  // namespace

std::vector<unsigned char> vtk_file_bytes(const Mesh& mesh, const VertexValues& values) {
  check_values(mesh, values);
  const auto positions = mesh.positions();
  const auto triangles = mesh.triangles();
  const std::size_t n = mesh.vertex_count(), m = mesh.face_count();
  std::vector<unsigned char> bytes;
  bytes.reserve(300 + 24 * n + 16 * m + 12 * n);
  append_text(bytes, "# vtk DataFile Version 3.0\nwritten by exactgeo\nBINARY\nDATASET POLYDATA\n");
  append_text(bytes, "POINTS " + std::to_string(n) + " double\n");
  for (const double coordinate : positions) append_big_endian(bytes, coordinate);
  append_text(bytes, "\nPOLYGONS " + std::to_string(m) + " " + std::to_string(4 * m) + "\n");
  for (std::size_t f = 0; f < m; ++f) {
    append_big_endian(bytes, std::int32_t{3});
    for (int k = 0; k < 3; ++k) append_big_endian(bytes, triangles[3 * f + k]);
  }
  append_text(bytes, "\nPOINT_DATA " + std::to_string(n) + "\nSCALARS " + values.value_name +
                         " double 1\nLOOKUP_TABLE default\n");
  for (const double value : values.values) append_big_endian(bytes, value);
  append_text(bytes, "\n");
  if (!values.labels.empty()) {
    append_text(bytes, "SCALARS nearest_source int 1\nLOOKUP_TABLE default\n");
    for (const std::uint32_t label : values.labels) append_big_endian(bytes, label_value(label));
    append_text(bytes, "\n");
  }
  return bytes;
}

std::vector<unsigned char> ply_file_bytes(const Mesh& mesh, const VertexValues& values,
                                          std::span<const std::uint8_t> colours) {
  check_values(mesh, values);
  const std::size_t n = mesh.vertex_count(), m = mesh.face_count();
  if (colours.size() != 3 * n)
    throw Error(ErrorCode::invalid_argument, "got " + std::to_string(colours.size()) +
                                                 " colour bytes, but the mesh has " + std::to_string(n) +
                                                 " vertices (3 each)");
  const auto positions = mesh.positions();
  const auto triangles = mesh.triangles();
  std::vector<unsigned char> bytes;
  bytes.reserve(400 + 27 * n + 13 * m);
  append_text(bytes, "ply\nformat binary_little_endian 1.0\ncomment written by exactgeo\nelement vertex " +
                         std::to_string(n) +
                         "\nproperty float x\nproperty float y\nproperty float z\nproperty double " +
                         values.value_name + "\n" + (values.labels.empty() ? "" : "property int nearest_source\n") +
                         "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face " +
                         std::to_string(m) + "\nproperty list uchar int vertex_indices\nend_header\n");
  for (std::size_t v = 0; v < n; ++v) {
    for (int k = 0; k < 3; ++k) append_little_endian(bytes, static_cast<float>(positions[3 * v + k]));
    append_little_endian(bytes, values.values[v]);
    if (!values.labels.empty()) append_little_endian(bytes, label_value(values.labels[v]));
    bytes.insert(bytes.end(), colours.begin() + 3 * v, colours.begin() + 3 * v + 3);
  }
  for (std::size_t f = 0; f < m; ++f) {
    bytes.push_back(3);
    for (int k = 0; k < 3; ++k) append_little_endian(bytes, triangles[3 * f + k]);
  }
  return bytes;
}

std::array<double, 3> ramp_colour(double t) {
  static constexpr std::array<std::array<double, 3>, 5> kStops = {
      {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};
  if (std::isnan(t)) return {kNoValueColour[0], kNoValueColour[1], kNoValueColour[2]};
  const double x = std::clamp(t, 0.0, 1.0) * (kStops.size() - 1);
  const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(x), kStops.size() - 2);
  const double f = x - static_cast<double>(i);
  std::array<double, 3> colour;
  for (std::size_t k = 0; k < 3; ++k) colour[k] = kStops[i][k] + f * (kStops[i + 1][k] - kStops[i][k]);
  return colour;
}

std::vector<std::uint8_t> ramp_colours(std::span<const double> values) {
  double largest = 0;
  for (const double value : values)
    if (std::isfinite(value)) largest = std::max(largest, value);
  std::vector<std::uint8_t> colours;
  colours.reserve(3 * values.size());
  for (const double value : values) {
    const double t = std::isfinite(value) ? (largest > 0 ? value / largest : 0.0) : std::nan("");
    for (const double channel : ramp_colour(t)) colours.push_back(static_cast<std::uint8_t>(std::lround(channel)));
  }
  return colours;
}

}  // namespace exactgeo
