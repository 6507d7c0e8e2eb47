#include "outputs.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "npy.hpp"

namespace exactgeo::cli {
namespace {

// nlohmann::json's error id for a string that is not UTF-8.
constexpr int kJsonInvalidUtf8 = 316;

// --- Values per vertex or per target -------------------------------------------------------------------

void write_values_txt(std::FILE* file, const Values& values) {
  for (std::size_t i = 0; i < values.distances.size(); ++i) {
    print_distance(file, values.distances[i]);
    if (!values.labels.empty()) std::fprintf(file, " %lld", label_value(values.labels[i]));
    std::fputc('\n', file);
  }
}

void write_values_csv(std::FILE* file, const Values& values) {
  std::fprintf(file, "%s,distance%s\n", values.row_name, values.labels.empty() ? "" : ",nearest_source");
  for (std::size_t i = 0; i < values.distances.size(); ++i) {
    std::fprintf(file, "%zu,", i);
    print_distance(file, values.distances[i]);
    if (!values.labels.empty()) std::fprintf(file, ",%lld", label_value(values.labels[i]));
    std::fputc('\n', file);
  }
}

// With labels the array has two columns, distance and nearest source (-1 where there is none).
void write_values_npy(std::FILE* file, const Values& values) {
  const std::size_t rows = values.distances.size();
  std::vector<double> data;
  data.reserve(rows * 2);
  for (std::size_t i = 0; i < rows; ++i) {
    data.push_back(values.distances[i]);
    if (!values.labels.empty()) data.push_back(static_cast<double>(label_value(values.labels[i])));
  }
  const std::vector<std::size_t> shape =
      values.labels.empty() ? std::vector<std::size_t>{rows} : std::vector<std::size_t>{rows, 2};
  write_npy(file, "<f8", shape, little_endian_bytes(data));
}

// The mesh as ASCII PLY (.ascii.ply) with the distance as a per-vertex scalar (and the nearest source with
// labels) and the colour ramp (exactgeo::ramp_colours); every value as written by .txt, so the doubles
// round-trip.
void write_values_ascii_ply(std::FILE* file, const Values& values) {
  const exactgeo::Mesh& mesh = *values.mesh;
  const auto positions = mesh.positions();
  const auto triangles = mesh.triangles();
  const std::vector<std::uint8_t> colours = exactgeo::ramp_colours(values.distances);
  std::fprintf(file, "ply\nformat ascii 1.0\ncomment written by exactgeo\n");
  std::fprintf(file, "element vertex %zu\nproperty double x\nproperty double y\nproperty double z\n",
               mesh.vertex_count());
  std::fprintf(file, "property double distance\n%s", values.labels.empty() ? "" : "property int nearest_source\n");
  std::fprintf(file, "property uchar red\nproperty uchar green\nproperty uchar blue\n");
  std::fprintf(file, "element face %zu\nproperty list uchar int vertex_indices\nend_header\n", mesh.face_count());
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    std::fprintf(file, "%.17g %.17g %.17g ", positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
    print_distance(file, values.distances[v]);
    if (!values.labels.empty()) std::fprintf(file, " %lld", label_value(values.labels[v]));
    std::fprintf(file, " %u %u %u\n", colours[3 * v], colours[3 * v + 1], colours[3 * v + 2]);
  }
  for (std::size_t f = 0; f < mesh.face_count(); ++f)
    std::fprintf(file, "3 %u %u %u\n", triangles[3 * f], triangles[3 * f + 1], triangles[3 * f + 2]);
}

// The library's binary PLY (.ply), coloured by exactgeo::ramp_colours: per vertex float x, y, z, double
// distance (exactly the .npy's value, inf where unreachable), with labels int nearest_source, then the colour; a
// third of the ASCII size. The layout exactgeo.save_ply writes too.
void write_values_ply(std::FILE* file, const Values& values) {
  const std::vector<unsigned char> bytes = exactgeo::ply_file_bytes(
      *values.mesh, {values.distances, "distance", values.labels}, exactgeo::ramp_colours(values.distances));
  std::fwrite(bytes.data(), 1, bytes.size(), file);
}

// The library's legacy VTK file (.vtk), binary, for ParaView, VisIt, pyvista and meshio: VTK's PLY reader keeps
// only positions, normals, texture coordinates and colours, so a .ply's distance never reaches them. The file
// exactgeo.save_vtk writes, byte for byte.
void write_values_vtk(std::FILE* file, const Values& values) {
  const std::vector<unsigned char> bytes =
      exactgeo::vtk_file_bytes(*values.mesh, {values.distances, "distance", values.labels});
  std::fwrite(bytes.data(), 1, bytes.size(), file);
}

constexpr std::array<Format<ValuesWriter>, 6> kVertexValueFormatTable = {{
    {".txt", write_values_txt},
    {".csv", write_values_csv},
    {".npy", write_values_npy},
    {".ascii.ply", write_values_ascii_ply},  // before .ply, which it ends with
    {".ply", write_values_ply},
    {".vtk", write_values_vtk},
}};
// Per-target values have no mesh to colour, so no .ply.
constexpr std::array<Format<ValuesWriter>, 3> kTargetValueFormatTable = {{
    {".txt", write_values_txt},
    {".csv", write_values_csv},
    {".npy", write_values_npy},
}};

// --- Paths ---------------------------------------------------------------------------------------------

using Kind = exactgeo::PathPointLocation::Kind;

// x,y,z,kind,a,b,t: the vertex, the edge's two vertices and parameter, or the face and its barycentric weights.
void write_path_csv(std::FILE* file, const exactgeo::GeodesicPath& path) {
  std::fprintf(file, "x,y,z,kind,a,b,t\n");
  for (std::size_t i = 0; i < path.points.size(); ++i) {
    const auto& p = path.points[i];
    const auto& location = path.locations[i];
    std::fprintf(file, "%.17g,%.17g,%.17g,", p[0], p[1], p[2]);
    if (location.kind == Kind::vertex)
      std::fprintf(file, "vertex,%u,,\n", location.vertex);
    else if (location.kind == Kind::edge)
      std::fprintf(file, "edge,%u,%u,%.17g\n", location.from, location.to, location.t);
    else
      std::fprintf(file, "face,%u,,%.17g;%.17g;%.17g\n", location.face_point.face, location.face_point.barycentric[0],
                   location.face_point.barycentric[1], location.face_point.barycentric[2]);
  }
}

// A polyline that MeshLab, Blender and ParaView draw over the mesh.
void write_path_obj(std::FILE* file, const exactgeo::GeodesicPath& path) {
  std::fprintf(file, "# geodesic path, length %.17g\n", path.length);
  for (const auto& p : path.points) std::fprintf(file, "v %.17g %.17g %.17g\n", p[0], p[1], p[2]);
  if (path.points.size() > 1) {
    std::fputc('l', file);
    for (std::size_t i = 1; i <= path.points.size(); ++i) std::fprintf(file, " %zu", i);
    std::fputc('\n', file);
  }
}

void write_path_json(std::FILE* file, const exactgeo::GeodesicPath& path) {
  nlohmann::ordered_json json;
  json["length"] = path.length;
  json["source"] = label_value(path.source);
  json["points"] = path.points;
  nlohmann::ordered_json locations = nlohmann::ordered_json::array();
  for (const auto& location : path.locations) {
    nlohmann::ordered_json item;
    if (location.kind == Kind::vertex) {
      item["vertex"] = location.vertex;
    } else if (location.kind == Kind::edge) {
      item["edge"] = {location.from, location.to};
      item["t"] = location.t;
    } else {
      item["face"] = location.face_point.face;
      item["barycentric"] = location.face_point.barycentric;
    }
    locations.push_back(item);
  }
  json["locations"] = locations;
  const std::string text = json_text(json) + "\n";
  std::fwrite(text.data(), 1, text.size(), file);
}

constexpr std::array<Format<PathWriter>, 3> kPathFormatTable = {{
    {".csv", write_path_csv},
    {".obj", write_path_obj},
    {".json", write_path_json},
}};

// --- Samples -------------------------------------------------------------------------------------------

void write_samples_txt(std::FILE* file, const exactgeo::Sampling& sampling) {
  for (std::uint32_t sample : sampling.samples) std::fprintf(file, "%u\n", sample);
}

// sample,vertex,radius: the radius is the distance to the samples before.
void write_samples_csv(std::FILE* file, const exactgeo::Sampling& sampling) {
  std::fputs("sample,vertex,radius\n", file);
  for (std::size_t i = 0; i < sampling.samples.size(); ++i) {
    std::fprintf(file, "%zu,%u,", i, sampling.samples[i]);
    print_distance(file, sampling.radii[i]);
    std::fputc('\n', file);
  }
}

// The sample vertices as a 1-D int64 array.
void write_samples_npy(std::FILE* file, const exactgeo::Sampling& sampling) {
  const std::vector<std::int64_t> samples(sampling.samples.begin(), sampling.samples.end());
  write_npy(file, "<i8", std::vector<std::size_t>{samples.size()}, little_endian_bytes(samples));
}

constexpr std::array<Format<SamplesWriter>, 3> kSamplesFormatTable = {{
    {".txt", write_samples_txt},
    {".csv", write_samples_csv},
    {".npy", write_samples_npy},
}};

// --- Located points ------------------------------------------------------------------------------------

// One point F:b0,b1,b2 per line: what --targets reads.
void write_located_txt(std::FILE* file, const LocatedPoints& located) {
  for (const exactgeo::SurfacePoint& p : located.points)
    std::fprintf(file, "%u:%.17g,%.17g,%.17g\n", p.face, p.barycentric[0], p.barycentric[1], p.barycentric[2]);
}

// point,face,b0,b1,b2,x,y,z,distance: the surface point, where it lies, and the distance to it.
void write_located_csv(std::FILE* file, const LocatedPoints& located) {
  std::fputs("point,face,b0,b1,b2,x,y,z,distance\n", file);
  for (std::size_t i = 0; i < located.points.size(); ++i) {
    const exactgeo::SurfacePoint& p = located.points[i];
    const std::array<double, 3>& x = located.positions[i];
    std::fprintf(file, "%zu,%u,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", i, p.face, p.barycentric[0],
                 p.barycentric[1], p.barycentric[2], x[0], x[1], x[2], located.distances[i]);
  }
}

constexpr std::array<Format<LocatedWriter>, 2> kLocatedFormatTable = {{
    {".txt", write_located_txt},
    {".csv", write_located_csv},
}};

}  // namespace

const std::span<const Format<ValuesWriter>> kVertexValueFormats = kVertexValueFormatTable;
const std::span<const Format<ValuesWriter>> kTargetValueFormats = kTargetValueFormatTable;
const std::span<const Format<PathWriter>> kPathFormats = kPathFormatTable;
const std::span<const Format<SamplesWriter>> kSamplesFormats = kSamplesFormatTable;
const std::span<const Format<LocatedWriter>> kLocatedFormats = kLocatedFormatTable;

bool has_extension(const std::string& path, std::string_view extension) {
  if (path.size() <= extension.size()) return false;
  const std::string_view ending = std::string_view(path).substr(path.size() - extension.size());
  return std::equal(ending.begin(), ending.end(), extension.begin(),
                    [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; });
}


void write_values(const std::string& path, std::span<const Format<ValuesWriter>> formats, const Values& values) {
  const ValuesWriter write = find_format(formats, path)->write;
  write_file(path, [&](std::FILE* file) { write(file, values); });
}

void print_distance(std::FILE* file, double distance) { std::fputs(format_distance(distance).c_str(), file); }

std::string format_distance(double distance) {
  return std::isinf(distance) ? "inf" : format_number("%.17g", distance);
}

std::string format_number(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

long long label_value(std::uint32_t label) { return label == exactgeo::kNoSource ? -1 : static_cast<long long>(label); }

void print_table(const Rows& rows) {
  std::size_t width = 0;
  for (const auto& row : rows) width = std::max(width, row.first.size());
  for (const auto& [name, value] : rows) std::printf("%-*s  %s\n", int(width), name.c_str(), value.c_str());
}

std::string json_text(const nlohmann::ordered_json& json) {
  try {
    return json.dump(2);
  } catch (const nlohmann::ordered_json::type_error& e) {
    if (e.id != kJsonInvalidUtf8) throw;
  }
  std::fprintf(stderr,
               "exactgeo: warning: JSON output: a name that is not UTF-8 has U+FFFD in place of its invalid bytes\n");
  return json.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

void write_json(const std::string& path, const nlohmann::ordered_json& json) {
  const std::string text = json_text(json) + "\n";
  write_file(path, [&](std::FILE* file) { std::fwrite(text.data(), 1, text.size(), file); });
}

bool same_output(const std::string& first, const std::string& second) {
  if (first == second) return true;
  if (first == kStdout || second == kStdout) return false;
  const std::filesystem::path a = output_target(first).path, b = output_target(second).path;
  std::error_code error_a, error_b;
  if (std::filesystem::equivalent(a, b, error_a)) return true;  // both exist: one file
  const std::filesystem::path canonical_a = std::filesystem::weakly_canonical(a, error_a),
                              canonical_b = std::filesystem::weakly_canonical(b, error_b);
  return !error_a && !error_b && canonical_a == canonical_b;
}

}  // namespace exactgeo::cli
