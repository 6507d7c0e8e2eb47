// exactgeo: command-line front end. A thin layer over the public API: parse the arguments, read or
// generate the mesh, run the query, write the result. Exit codes are listed in kExitCodesHelp.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <new>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <unistd.h>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "exactgeo/shapes.hpp"
#include "npy.hpp"

namespace {

constexpr int kExitOk = 0;
constexpr int kExitUsage = 1;
constexpr int kExitInvalidInput = 2;
constexpr int kExitInternal = 3;

// The demo default `@torus`: 2 * 64 * 36 = 4,608 faces, small enough to run instantly, curved enough to
// show the wavefront bending around bumps and saddles.
constexpr int kDemoTorusMajorSegments = 64;
constexpr int kDemoTorusMinorSegments = 36;

constexpr const char* kMeshHelp =
    "Mesh file (.obj, .ply, .off, .stl) or a built-in mesh:\n"
    "  @torus          bumpy torus, 64 x 36 segments (4,608 faces): the demo default\n"
    "  @torus:NU:NV    bumpy torus with NU segments around the ring and NV around the tube\n"
    "  @icosphere:K    unit icosphere, icosahedron subdivided K times (20 * 4^K faces)\n"
    "  @grid:NX:NY     flat grid of NX x NY unit squares; vertex j*(NX+1)+i is at (i, j, 0)";

constexpr const char* kExitCodesHelp =
    "Exit codes: 0 ok, 1 usage error, 2 unreadable or invalid input, 3 internal error.";

// ---------------------------------------------------------------------------------------------------
// Meshes: files through load_mesh, built-in names through the generators in shapes.hpp.

enum class BuiltinShape { torus, icosphere, grid };

struct BuiltinMesh {
  BuiltinShape shape;
  std::vector<int> parameters;
};

// "@torus", "@torus:NU:NV", "@icosphere:K", "@grid:NX:NY"; nullopt for anything else. Only the syntax is
// checked here: the generators reject values out of their range.
std::optional<BuiltinMesh> parse_builtin_mesh(std::string_view name) {
  if (!name.starts_with('@')) return std::nullopt;
  name.remove_prefix(1);
  std::vector<std::string_view> fields;
  for (std::size_t start = 0;;) {
    const std::size_t colon = name.find(':', start);
    fields.push_back(name.substr(start, colon - start));
    if (colon == std::string_view::npos) break;
    start = colon + 1;
  }

  BuiltinMesh mesh;
  for (std::size_t i = 1; i < fields.size(); ++i) {
    int value = 0;
    const char* end = fields[i].data() + fields[i].size();
    const auto [ptr, ec] = std::from_chars(fields[i].data(), end, value);
    if (ec != std::errc() || ptr != end || fields[i].empty()) return std::nullopt;
    mesh.parameters.push_back(value);
  }
  const std::size_t count = mesh.parameters.size();
  if (fields[0] == "torus" && (count == 0 || count == 2)) {
    mesh.shape = BuiltinShape::torus;
  } else if (fields[0] == "icosphere" && count == 1) {
    mesh.shape = BuiltinShape::icosphere;
  } else if (fields[0] == "grid" && count == 2) {
    mesh.shape = BuiltinShape::grid;
  } else {
    return std::nullopt;
  }
  return mesh;
}

exactgeo::MeshSoup generate_builtin_mesh(const BuiltinMesh& mesh) {
  const std::vector<int>& p = mesh.parameters;
  switch (mesh.shape) {
    case BuiltinShape::torus:
      return p.empty() ? exactgeo::make_bumpy_torus(kDemoTorusMajorSegments, kDemoTorusMinorSegments)
                       : exactgeo::make_bumpy_torus(p[0], p[1]);
    case BuiltinShape::icosphere:
      return exactgeo::make_icosphere(p[0]);
    case BuiltinShape::grid:
      return exactgeo::make_grid(p[0], p[1], p[0], p[1]);
  }
  throw exactgeo::Error(exactgeo::ErrorCode::internal, "unhandled built-in mesh shape");
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct LoadedMesh {
  exactgeo::Mesh mesh;
  double read_seconds;   // reading the file or generating the shape
  double build_seconds;  // read_seconds plus validating and building the Mesh
};

LoadedMesh load_mesh(const std::string& name, bool weld) {
  const auto start = std::chrono::steady_clock::now();
  const std::optional<BuiltinMesh> builtin = parse_builtin_mesh(name);
  const exactgeo::MeshSoup soup = builtin ? generate_builtin_mesh(*builtin) : exactgeo::read_mesh_soup(name);
  const double read_seconds = seconds_since(start);
  exactgeo::Mesh mesh(soup, exactgeo::MeshOptions{.weld_duplicate_positions = weld});
  return {std::move(mesh), read_seconds, seconds_since(start)};
}

// Rejects a malformed built-in name at parse time (a usage error); file paths are checked when read.
const CLI::Validator kMeshArgument(
    [](std::string& name) -> std::string {
      if (name.starts_with('@') && !parse_builtin_mesh(name)) {
        return "unknown built-in mesh '" + name + "' (use @torus, @torus:NU:NV, @icosphere:K or @grid:NX:NY)";
      }
      return {};
    },
    "", "mesh");

// A vertex index is a plain decimal number; whether it exists is up to the mesh.
const CLI::Validator kSourceArgument(
    [](std::string& text) -> std::string {
      if (text.empty() || !std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); })) {
        return "'" + text + "' is not a vertex index";
      }
      return {};
    },
    "", "source");

// "F:b0,b1,b2": a point on input triangle F, with the barycentric weights of its three corners. Only the
// syntax is checked here; the library checks the values against the mesh.
std::optional<exactgeo::SurfacePoint> parse_surface_point(std::string_view text) {
  const std::size_t colon = text.find(':');
  if (colon == std::string_view::npos) return std::nullopt;
  exactgeo::SurfacePoint point;
  const char* end = text.data() + colon;
  auto [ptr, ec] = std::from_chars(text.data(), end, point.face);
  if (ec != std::errc() || ptr != end || colon == 0) return std::nullopt;
  const char* cursor = text.data() + colon + 1;
  const char* stop = text.data() + text.size();
  for (int k = 0; k < 3; ++k) {
    const auto [next, error] = std::from_chars(cursor, stop, point.barycentric[k]);
    if (error != std::errc()) return std::nullopt;
    cursor = next;
    if (k < 2) {
      if (cursor == stop || *cursor != ',') return std::nullopt;
      ++cursor;
    }
  }
  if (cursor != stop) return std::nullopt;
  return point;
}

const CLI::Validator kSurfacePointArgument(
    [](std::string& text) -> std::string {
      if (!parse_surface_point(text)) return "'" + text + "' is not a surface point F:b0,b1,b2";
      return {};
    },
    "", "surface point");

// A vertex index that fits the library's 32-bit type; anything else cannot name a vertex of any mesh.
std::optional<std::uint32_t> parse_vertex(std::string_view text) {
  std::uint32_t v = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || ptr != text.data() + text.size() || text.empty()) return std::nullopt;
  return v;
}

// Targets: entries separated by spaces, newlines or ';', each a point F:b0,b1,b2 or vertex indices
// separated by commas. `text` is a file's contents or the argument itself.
std::vector<exactgeo::SurfacePoint> parse_targets(const std::string& text, const exactgeo::Mesh& mesh,
                                                  const std::string& origin) {
  std::vector<exactgeo::SurfacePoint> targets;
  std::string entry;
  std::istringstream entries(text);
  while (entries >> entry) {
    std::istringstream parts(entry);
    for (std::string part; std::getline(parts, part, ';');) {
      if (part.empty()) continue;
      if (part.find(':') != std::string::npos) {
        const auto point = parse_surface_point(part);
        if (!point)
          throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument,
                                origin + ": target '" + part + "' is not a surface point F:b0,b1,b2");
        targets.push_back(*point);
        continue;
      }
      std::istringstream vertices(part);
      for (std::string index; std::getline(vertices, index, ',');) {
        const auto v = parse_vertex(index);
        if (!v)
          throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument,
                                origin + ": target '" + index + "' is neither a vertex index nor a point F:b0,b1,b2");
        targets.push_back(exactgeo::vertex_point(mesh, *v));
      }
    }
  }
  if (targets.empty()) throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument, origin + ": no target given");
  return targets;
}

// A list argument: the contents of the file it names if there is one, else the argument itself.
std::string list_text(const std::string& argument) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(argument, error)) {
    // A list never holds a '/': this was meant as a file.
    if (argument.find('/') != std::string::npos)
      throw exactgeo::Error(exactgeo::ErrorCode::io_error, "cannot read '" + argument + "': no such file");
    return argument;
  }
  std::ifstream file(argument, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  if (!file && !file.eof()) throw exactgeo::Error(exactgeo::ErrorCode::io_error, "cannot read '" + argument + "'");
  return text.str();
}

// Vertex indices separated by spaces, newlines, ',' or ';'.
std::vector<std::uint32_t> parse_vertex_list(const std::string& text, const std::string& origin) {
  std::vector<std::uint32_t> vertices;
  std::string entry;
  std::istringstream entries(text);
  while (entries >> entry) {
    std::replace(entry.begin(), entry.end(), ';', ',');
    std::istringstream parts(entry);
    for (std::string index; std::getline(parts, index, ',');) {
      if (index.empty()) continue;
      const auto v = parse_vertex(index);
      if (!v) throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument, origin + ": '" + index + "' is not a vertex index");
      vertices.push_back(*v);
    }
  }
  if (vertices.empty()) throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument, origin + ": no vertex given");
  return vertices;
}

// Progress of long work on stderr: shown once the work has run for a second, only when stderr is a terminal
// and --quiet is not given; the line is rewritten in place and ended when the work is done.
class Progress {
 public:
  Progress(std::string what, std::size_t total, bool quiet)
      : what_(std::move(what)), total_(total), enabled_(!quiet && ::isatty(::fileno(stderr))),
        start_(std::chrono::steady_clock::now()) {}
  ~Progress() { finish(); }
  // Ends the line, if one was shown, before anything else is printed.
  void finish() {
    if (shown_) std::fputc('\n', stderr);
    shown_ = false;
    enabled_ = false;
  }
  void update(std::size_t done) {
    if (!enabled_ || seconds_since(start_) < 1.0) return;
    std::fprintf(stderr, "\rexactgeo: %s %zu/%zu (%.0f%%)", what_.c_str(), done, total_,
                 total_ ? 100.0 * double(done) / double(total_) : 100.0);
    std::fflush(stderr);
    shown_ = true;
  }

 private:
  std::string what_;
  std::size_t total_;
  bool enabled_, shown_ = false;
  std::chrono::steady_clock::time_point start_;
};

const CLI::Validator kDistanceArgument(
    [](std::string& text) -> std::string {
      double value = 0;
      const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
      if (ec != std::errc() || ptr != text.data() + text.size() || !(value >= 0))
        return "'" + text + "' is not a non-negative distance";
      return {};
    },
    "", "distance");

// ---------------------------------------------------------------------------------------------------
// Output files.

// A file's extension in lower case (".npy"): every output format is chosen by it, whatever its case.
std::string extension_of(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return extension;
}

enum class OutputFormat { txt, csv, npy, ply };

std::optional<OutputFormat> output_format(const std::filesystem::path& path) {
  const std::string extension = extension_of(path.string());
  if (extension == ".txt") return OutputFormat::txt;
  if (extension == ".csv") return OutputFormat::csv;
  if (extension == ".npy") return OutputFormat::npy;
  if (extension == ".ply") return OutputFormat::ply;
  return std::nullopt;
}

const CLI::Validator kOutputArgument(
    [](std::string& path) -> std::string {
      if (!output_format(path)) {
        return "unsupported output file '" + path + "': the extension must be .txt, .csv, .npy or .ply";
      }
      return {};
    },
    "", "output");

// Opens `path` for writing, lets `write` fill it, and turns any failure into an io_error naming the file.
void write_file(const std::string& path, const std::function<void(std::FILE*)>& write) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) {
    throw exactgeo::Error(exactgeo::ErrorCode::io_error, "cannot write '" + path + "': " + std::strerror(errno));
  }
  write(file);
  const bool failed = std::ferror(file) != 0;
  if (std::fclose(file) != 0 || failed) {
    throw exactgeo::Error(exactgeo::ErrorCode::io_error, "error writing '" + path + "': " + std::strerror(errno));
  }
}

// %.17g round-trips every double; unreachable vertices are written as "inf" on every platform.
void print_distance(std::FILE* file, double distance) {
  if (std::isinf(distance)) {
    std::fputs("inf", file);
  } else {
    std::fprintf(file, "%.17g", distance);
  }
}

// One value per row; with labels, each row also gives the nearest source (-1 where there is none).
struct Column {
  std::span<const double> distances;
  std::span<const std::uint32_t> labels;  // empty: no label column
};

long long label_value(std::uint32_t label) { return label == exactgeo::kNoSource ? -1 : static_cast<long long>(label); }

void write_txt(std::FILE* file, const Column& column) {
  for (std::size_t i = 0; i < column.distances.size(); ++i) {
    print_distance(file, column.distances[i]);
    if (!column.labels.empty()) std::fprintf(file, " %lld", label_value(column.labels[i]));
    std::fputc('\n', file);
  }
}

void write_csv(std::FILE* file, const Column& column, const char* row_name) {
  std::fprintf(file, "%s,distance%s\n", row_name, column.labels.empty() ? "" : ",nearest_source");
  for (std::size_t i = 0; i < column.distances.size(); ++i) {
    std::fprintf(file, "%zu,", i);
    print_distance(file, column.distances[i]);
    if (!column.labels.empty()) std::fprintf(file, ",%lld", label_value(column.labels[i]));
    std::fputc('\n', file);
  }
}

// .npy: with labels the array has two columns, distance and nearest source (-1 where there is none).
void write_npy(std::FILE* file, const Column& column) {
  const std::size_t rows = column.distances.size();
  std::vector<double> values;
  values.reserve(rows * 2);
  for (std::size_t i = 0; i < rows; ++i) {
    values.push_back(column.distances[i]);
    if (!column.labels.empty()) values.push_back(static_cast<double>(label_value(column.labels[i])));
  }
  const std::vector<std::size_t> shape =
      column.labels.empty() ? std::vector<std::size_t>{rows} : std::vector<std::size_t>{rows, 2};
  const std::string header = exactgeo_cli::npy_header("<f8", shape);
  const std::vector<unsigned char> data = exactgeo_cli::little_endian_bytes(values);
  std::fwrite(header.data(), 1, header.size(), file);
  std::fwrite(data.data(), 1, data.size(), file);
}

// A colour for t in [0, 1]: a blue-green-yellow ramp like viridis, from a few of its stops.
std::array<std::uint8_t, 3> ramp_colour(double t) {
  static constexpr std::array<std::array<double, 3>, 5> kStops = {{
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};
  const double x = std::clamp(t, 0.0, 1.0) * (kStops.size() - 1);
  const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(x), kStops.size() - 2);
  const double f = x - static_cast<double>(i);
  std::array<std::uint8_t, 3> colour{};
  for (int k = 0; k < 3; ++k) colour[k] = std::uint8_t(std::lround(kStops[i][k] + f * (kStops[i + 1][k] - kStops[i][k])));
  return colour;
}

// The mesh as ASCII PLY with the distance as a per-vertex scalar (and the nearest source with labels) and a
// colour ramp from 0 to the largest finite distance; unreachable vertices are grey with distance inf.
void write_ply(std::FILE* file, const exactgeo::Mesh& mesh, const Column& column) {
  const auto positions = mesh.positions();
  const auto triangles = mesh.triangles();
  double largest = 0;
  for (double d : column.distances)
    if (std::isfinite(d)) largest = std::max(largest, d);
  std::fprintf(file, "ply\nformat ascii 1.0\ncomment written by exactgeo: geodesic distance per vertex\n");
  std::fprintf(file, "element vertex %zu\nproperty double x\nproperty double y\nproperty double z\n",
               mesh.vertex_count());
  std::fprintf(file, "property double distance\n%s", column.labels.empty() ? "" : "property int nearest_source\n");
  std::fprintf(file, "property uchar red\nproperty uchar green\nproperty uchar blue\n");
  std::fprintf(file, "element face %zu\nproperty list uchar int vertex_indices\nend_header\n", mesh.face_count());
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const double d = column.distances[v];
    const std::array<std::uint8_t, 3> colour =
        std::isfinite(d) ? ramp_colour(largest > 0 ? d / largest : 0) : std::array<std::uint8_t, 3>{128, 128, 128};
    std::fprintf(file, "%.17g %.17g %.17g ", positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
    print_distance(file, d);
    if (!column.labels.empty()) std::fprintf(file, " %lld", label_value(column.labels[v]));
    std::fprintf(file, " %u %u %u\n", colour[0], colour[1], colour[2]);
  }
  for (std::size_t f = 0; f < mesh.face_count(); ++f)
    std::fprintf(file, "3 %u %u %u\n", triangles[3 * f], triangles[3 * f + 1], triangles[3 * f + 2]);
}

// Per-vertex values go to any format; `mesh` is needed for .ply only (per-target values have no mesh).
void write_column(const std::string& path, const Column& column, const char* row_name,
                  const exactgeo::Mesh* mesh = nullptr) {
  switch (*output_format(path)) {
    case OutputFormat::txt:
      return write_file(path, [&](std::FILE* file) { write_txt(file, column); });
    case OutputFormat::csv:
      return write_file(path, [&](std::FILE* file) { write_csv(file, column, row_name); });
    case OutputFormat::npy:
      return write_file(path, [&](std::FILE* file) { write_npy(file, column); });
    case OutputFormat::ply:
      if (!mesh)
        throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument,
                              "'" + path + "': per-target values cannot be written as a mesh (.ply)");
      return write_file(path, [&](std::FILE* file) { write_ply(file, *mesh, column); });
  }
}

// ---------------------------------------------------------------------------------------------------
// Reports: one list of (name, value) rows feeds both the aligned text and the JSON.

std::vector<std::pair<std::string, std::size_t>> report_fields(const exactgeo::MeshReport& report) {
  return {
      {"vertices", report.vertices},
      {"faces", report.faces},
      {"faces_used", report.faces_used},
      {"faces_repeating_a_vertex", report.faces_repeating_a_vertex},
      {"degenerate_faces", report.degenerate_faces},
      {"zero_length_edges", report.zero_length_edges},
      {"unreferenced_vertices", report.unreferenced_vertices},
      {"duplicate_positions", report.duplicate_positions},
      {"welded_vertices", report.welded_vertices},
      {"boundary_edges", report.boundary_edges},
      {"non_manifold_edges", report.non_manifold_edges},
      {"non_manifold_vertices", report.non_manifold_vertices},
      {"surface_vertices", report.surface_vertices},
      {"components", report.components},
      {"saddle_vertices", report.saddle_vertices},
  };
}

nlohmann::ordered_json report_json(const exactgeo::MeshReport& report) {
  nlohmann::ordered_json json = nlohmann::ordered_json::object();
  for (const auto& [name, value] : report_fields(report)) json[name] = value;
  return json;
}

void print_table(const std::vector<std::pair<std::string, std::string>>& rows) {
  std::size_t width = 0;
  for (const auto& row : rows) width = std::max(width, row.first.size());
  for (const auto& [name, value] : rows) std::printf("%-*s  %s\n", int(width), name.c_str(), value.c_str());
}

void write_json(const std::string& path, const nlohmann::ordered_json& json) {
  const std::string text = json.dump(2) + "\n";
  write_file(path, [&](std::FILE* file) { std::fwrite(text.data(), 1, text.size(), file); });
}

// ---------------------------------------------------------------------------------------------------
// Subcommands.

struct SourceArguments {
  std::vector<std::string> vertices;  // checked by kSourceArgument, converted after loading
  std::vector<std::string> points;    // checked by kSurfacePointArgument
};

struct DistanceArguments {
  std::string mesh;
  SourceArguments sources;
  double max_distance = std::numeric_limits<double>::infinity();
  std::string targets;
  bool labels = false;
  std::string out;
  std::string target_out;
  std::string stats;
  std::string algorithm = "vtp";
  bool no_rule1 = false;
  bool no_rule23 = false;
  bool timers = false;
  bool quiet = false;
  bool weld = false;
};

struct PathArguments {
  std::string mesh;
  SourceArguments sources;
  std::string target;
  std::string out;
  bool weld = false;
};

struct SampleArguments {
  std::string mesh;
  std::size_t count = 0;
  std::uint32_t first = 0;
  std::string out;
  bool quiet = false;
  bool weld = false;
};

struct MatrixArguments {
  std::string mesh;
  std::string sources;
  double max_distance = std::numeric_limits<double>::infinity();
  unsigned threads = 0;
  std::string out;
  bool quiet = false;
  bool weld = false;
};

struct InfoArguments {
  std::string mesh;
  bool json = false;
  bool weld = false;
};

// The sources as the library takes them: vertex indices alone keep the vertex-source semantics (every copy
// of a split vertex is a source); with points, vertices become points too. Vertices are numbered first.
struct Sources {
  std::vector<std::uint32_t> vertices;
  std::vector<exactgeo::SurfacePoint> points;
  bool as_points = false;
};

Sources read_sources(const SourceArguments& arguments, const exactgeo::Mesh& mesh) {
  Sources sources;
  for (const std::string& text : arguments.vertices) {
    const auto v = parse_vertex(text);
    if (!v)
      throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument,
                            "source vertex " + text + " is out of range (mesh has " +
                                std::to_string(mesh.vertex_count()) + " vertices)");
    sources.vertices.push_back(*v);
  }
  sources.as_points = !arguments.points.empty();
  if (sources.as_points) {
    for (std::uint32_t v : sources.vertices) sources.points.push_back(exactgeo::vertex_point(mesh, v));
    for (const std::string& text : arguments.points) sources.points.push_back(*parse_surface_point(text));
  }
  return sources;
}

const exactgeo::GeodesicResult& solve(exactgeo::GeodesicSolver& solver, const Sources& sources,
                                      std::span<const exactgeo::SurfacePoint> targets,
                                      const exactgeo::GeodesicOptions& options) {
  if (sources.as_points) return solver.solve(sources.points, targets, options);
  return solver.solve(sources.vertices, targets, options);
}

std::string describe_sources(const SourceArguments& arguments) {
  std::string text;
  for (const auto& list : {arguments.vertices, arguments.points})
    for (const std::string& source : list) text += (text.empty() ? "" : " ") + source;
  return text;
}

std::string format_number(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

int run_distance(const DistanceArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh, arguments.weld);
  const exactgeo::Mesh& mesh = loaded.mesh;
  const Sources sources = read_sources(arguments.sources, mesh);
  const std::vector<exactgeo::SurfacePoint> targets =
      arguments.targets.empty() ? std::vector<exactgeo::SurfacePoint>()
                                : parse_targets(list_text(arguments.targets), mesh, "--targets");

  exactgeo::GeodesicSolver solver(mesh);
  Progress progress("vertices", mesh.vertex_count(), arguments.quiet);
  solver.set_progress([&](double fraction) {
    progress.update(static_cast<std::size_t>(fraction * static_cast<double>(mesh.vertex_count())));
  });
  const exactgeo::GeodesicOptions options{.algorithm = exactgeo::parse_algorithm(arguments.algorithm),
                                          .rule1 = !arguments.no_rule1,
                                          .rule23 = !arguments.no_rule23,
                                          .max_distance = arguments.max_distance,
                                          .collect_timings = arguments.timers};
  const exactgeo::GeodesicResult& result = solve(solver, sources, targets, options);
  progress.finish();
  const exactgeo::GeodesicStats& stats = result.stats;

  double max_distance = 0.0;
  std::size_t unreachable = 0;
  for (double distance : result.distances) {
    if (std::isinf(distance)) {
      ++unreachable;
    } else {
      max_distance = std::max(max_distance, distance);
    }
  }

  const auto labels_if_asked = [&](const std::vector<std::uint32_t>& labels) {
    return arguments.labels ? std::span<const std::uint32_t>(labels) : std::span<const std::uint32_t>();
  };
  if (!arguments.out.empty())
    write_column(arguments.out, {result.distances, labels_if_asked(result.nearest_source)}, "vertex", &mesh);
  if (!arguments.target_out.empty())
    write_column(arguments.target_out, {result.target_distances, labels_if_asked(result.target_nearest_source)},
                 "target");

  if (!arguments.stats.empty()) {
    nlohmann::ordered_json json;
    json["mesh"] = arguments.mesh;
    json["vertices"] = mesh.vertex_count();
    json["faces"] = mesh.face_count();
    json["source"] = sources.vertices;
    json["source_points"] = arguments.sources.points;
    json["targets"] = targets.size();
    json["max_distance_cutoff"] =
        std::isinf(arguments.max_distance) ? nlohmann::ordered_json() : nlohmann::ordered_json(arguments.max_distance);
    json["algorithm"] = exactgeo::algorithm_name(options.algorithm);
    json["rule1"] = options.rule1;
    json["rule23"] = options.rule23;
    json["read_seconds"] = loaded.read_seconds;
    json["build_seconds"] = loaded.build_seconds;
    json["propagation_seconds"] = stats.propagation_seconds;
    const auto timer = [&](double seconds) { return arguments.timers ? nlohmann::ordered_json(seconds) : nlohmann::ordered_json(); };
    json["window_propagation_seconds"] = timer(stats.window_propagation_seconds);
    json["pruning_seconds"] = timer(stats.pruning_seconds);
    json["queue_seconds"] = timer(stats.queue_seconds);
    json["window_propagations"] = stats.window_propagations;
    json["prime_propagations"] = stats.prime_propagations;
    json["secondary_propagations"] = stats.secondary_propagations;
    json["prime_merges"] = stats.prime_merges;
    json["secondary_merges"] = stats.secondary_merges;
    json["peak_windows"] = stats.peak_windows;
    json["peak_window_bytes"] = stats.peak_window_bytes;
    json["vertex_pops"] = stats.vertex_pops;
    json["face_pops"] = stats.face_pops;
    json["pseudo_source_emissions"] = stats.pseudo_source_emissions;
    json["max_distance"] = max_distance;
    json["unreachable"] = unreachable;
    json["mesh_report"] = report_json(mesh.report());
    json["version"] = exactgeo::kVersion;
    write_json(arguments.stats, json);
  }

  if (arguments.out.empty()) {
    const std::size_t source_count = sources.vertices.size() + arguments.sources.points.size();
    const bool cut_off = !targets.empty() || !std::isinf(arguments.max_distance);
    std::vector<std::pair<std::string, std::string>> rows = {
        {"mesh", arguments.mesh},
        {"vertices", std::to_string(mesh.vertex_count())},
        {"faces", std::to_string(mesh.face_count())},
        {source_count == 1 ? "source" : "sources", describe_sources(arguments.sources)},
        {"max distance", format_number("%.12g", max_distance)},
        {cut_off ? "unreachable or beyond" : "unreachable", std::to_string(unreachable)},
        {"window propagations", std::to_string(stats.window_propagations)},
        {"peak windows", std::to_string(stats.peak_windows)},
        {"build", format_number("%.4f s", loaded.build_seconds)},
        {"propagation", format_number("%.4f s", stats.propagation_seconds)},
    };
    if (!std::isinf(arguments.max_distance)) rows.insert(rows.begin() + 4, {"cut-off", format_number("%.12g", arguments.max_distance)});
    if (options.algorithm != exactgeo::Algorithm::vtp || !options.rule1 || !options.rule23) {
      std::string variant(exactgeo::algorithm_name(options.algorithm));
      if (!options.rule1) variant += ", Rule 1 off";
      if (!options.rule23) variant += ", Rules 2 and 3 off";
      rows.insert(rows.begin() + 4, {"algorithm", variant});
    }
    if (arguments.timers) {
      rows.push_back({"  window propagation", format_number("%.4f s", stats.window_propagation_seconds)});
      rows.push_back({"  pruning", format_number("%.4f s", stats.pruning_seconds)});
      rows.push_back({"  queue", format_number("%.4f s", stats.queue_seconds)});
    }
    if (arguments.target_out.empty())
      for (std::size_t t = 0; t < targets.size(); ++t) {
        std::string value = std::isinf(result.target_distances[t]) ? "inf" : format_number("%.17g", result.target_distances[t]);
        if (arguments.labels) value += " (source " + std::to_string(label_value(result.target_nearest_source[t])) + ")";
        rows.push_back({"target " + std::to_string(t), value});
      }
    print_table(rows);
  }
  return kExitOk;
}

// A path as CSV (x,y,z,kind,a,b,t: the vertex, the edge's two vertices and parameter, or the face and two
// of its barycentric weights), OBJ (a polyline) or JSON.
void write_path(const std::string& path_file, const exactgeo::GeodesicPath& path) {
  const std::string extension = extension_of(path_file);
  using Kind = exactgeo::PathPointLocation::Kind;
  if (extension == ".json") {
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
    return write_json(path_file, json);
  }
  write_file(path_file, [&](std::FILE* file) {
    if (extension == ".obj") {
      std::fprintf(file, "# geodesic path, length %.17g\n", path.length);
      for (const auto& p : path.points) std::fprintf(file, "v %.17g %.17g %.17g\n", p[0], p[1], p[2]);
      if (path.points.size() > 1) {
        std::fputc('l', file);
        for (std::size_t i = 1; i <= path.points.size(); ++i) std::fprintf(file, " %zu", i);
        std::fputc('\n', file);
      }
      return;
    }
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
  });
}

int run_path(const PathArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh, arguments.weld);
  const exactgeo::Mesh& mesh = loaded.mesh;
  const Sources sources = read_sources(arguments.sources, mesh);
  const std::vector<exactgeo::SurfacePoint> targets = parse_targets(arguments.target, mesh, "--target");
  if (targets.size() != 1)
    throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument, "--target takes one vertex or point, not " +
                                                                     std::to_string(targets.size()));
  exactgeo::GeodesicSolver solver(mesh);
  const exactgeo::GeodesicResult& result = solve(solver, sources, targets, {});
  const exactgeo::GeodesicPath path = solver.path_to_target(0);
  if (!arguments.out.empty()) write_path(arguments.out, path);
  if (path.points.empty()) {
    std::printf("target unreachable from every source\n");
    return kExitOk;
  }
  if (arguments.out.empty()) {
    print_table({{"mesh", arguments.mesh},
                 {"distance", format_number("%.17g", result.target_distances[0])},
                 {"path length", format_number("%.17g", path.length)},
                 {"points", std::to_string(path.points.size())},
                 {"nearest source", std::to_string(path.source)}});
    for (const auto& p : path.points) std::printf("%.17g %.17g %.17g\n", p[0], p[1], p[2]);
  }
  return kExitOk;
}

// Samples one per line (.txt), or with the distance to the samples before each (.csv: sample,vertex,radius).
int run_sample(const SampleArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh, arguments.weld);
  const exactgeo::Mesh& mesh = loaded.mesh;
  Progress progress("samples", arguments.count, arguments.quiet);
  const exactgeo::Sampling sampling = exactgeo::farthest_point_sampling(
      mesh, arguments.count, arguments.first, {}, [&](std::size_t done) { progress.update(done); });
  const auto write = [&](std::FILE* file, bool csv) {
    if (csv) std::fputs("sample,vertex,radius\n", file);
    for (std::size_t i = 0; i < sampling.samples.size(); ++i) {
      if (csv) {
        std::fprintf(file, "%zu,%u,", i, sampling.samples[i]);
        print_distance(file, sampling.radii[i]);
        std::fputc('\n', file);
      } else {
        std::fprintf(file, "%u\n", sampling.samples[i]);
      }
    }
  };
  if (arguments.out.empty()) {
    write(stdout, false);
  } else {
    const bool csv = output_format(arguments.out) == OutputFormat::csv;
    write_file(arguments.out, [&](std::FILE* file) { write(file, csv); });
  }
  return kExitOk;
}

// Rows are sources, columns vertices. .npy: dense float64 (inf beyond the cut-off), written block by block;
// .npz: scipy.sparse CSR of the finite entries; .csv: source,vertex,distance for the finite entries.
int run_matrix(const MatrixArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh, arguments.weld);
  const exactgeo::Mesh& mesh = loaded.mesh;
  const std::vector<std::uint32_t> sources = parse_vertex_list(list_text(arguments.sources), "--sources");
  exactgeo::MatrixOptions options;
  options.geodesic.max_distance = arguments.max_distance;
  options.threads = arguments.threads;
  Progress progress("rows", sources.size(), arguments.quiet);
  const std::size_t columns = mesh.vertex_count();
  const std::string extension = extension_of(arguments.out);
  if (extension == ".npz") {
    std::vector<double> data;
    std::vector<std::int32_t> indices;
    std::vector<std::int64_t> indptr = {0};
    exactgeo::for_each_distance_block(mesh, sources, options, [&](std::size_t first, std::span<const double> rows) {
      for (std::size_t r = 0; r < rows.size() / columns; ++r) {
        for (std::size_t v = 0; v < columns; ++v) {
          const double d = rows[r * columns + v];
          if (std::isinf(d)) continue;
          data.push_back(d);
          indices.push_back(static_cast<std::int32_t>(v));
        }
        indptr.push_back(static_cast<std::int64_t>(data.size()));
      }
      progress.update(first + rows.size() / columns);
    });
    const std::vector<std::int64_t> shape = {static_cast<std::int64_t>(sources.size()), static_cast<std::int64_t>(columns)};
    const std::vector<exactgeo_cli::NpzMember> members = {
        {"indices", "<i4", {indices.size()}, exactgeo_cli::little_endian_bytes(indices)},
        {"indptr", "<i8", {indptr.size()}, exactgeo_cli::little_endian_bytes(indptr)},
        {"format", "|S3", {}, {'c', 's', 'r'}},
        {"shape", "<i8", {2}, exactgeo_cli::little_endian_bytes(shape)},
        {"data", "<f8", {data.size()}, exactgeo_cli::little_endian_bytes(data)},
    };
    exactgeo_cli::write_npz(arguments.out, members);
    return kExitOk;
  }
  const bool csv = extension == ".csv";
  write_file(arguments.out, [&](std::FILE* file) {
    if (csv) {
      std::fputs("source,vertex,distance\n", file);
    } else {
      const std::string header = exactgeo_cli::npy_header("<f8", std::vector<std::size_t>{sources.size(), columns});
      std::fwrite(header.data(), 1, header.size(), file);
    }
    exactgeo::for_each_distance_block(mesh, sources, options, [&](std::size_t first, std::span<const double> rows) {
      if (csv) {
        for (std::size_t i = 0; i < rows.size(); ++i) {
          if (std::isinf(rows[i])) continue;
          std::fprintf(file, "%zu,%zu,%.17g\n", first + i / columns, i % columns, rows[i]);
        }
      } else {
        const std::vector<unsigned char> bytes = exactgeo_cli::little_endian_bytes(rows);
        std::fwrite(bytes.data(), 1, bytes.size(), file);
      }
      progress.update(first + rows.size() / columns);
    });
  });
  return kExitOk;
}

int run_info(const InfoArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh, arguments.weld);
  const exactgeo::MeshReport& report = loaded.mesh.report();
  if (arguments.json) {
    nlohmann::ordered_json json;
    json["mesh"] = arguments.mesh;
    json.update(report_json(report));
    std::printf("%s\n", json.dump(2).c_str());
  } else {
    std::vector<std::pair<std::string, std::string>> rows = {{"mesh", arguments.mesh}};
    for (const auto& [name, value] : report_fields(report)) rows.emplace_back(name, std::to_string(value));
    print_table(rows);
  }
  return kExitOk;
}

void print_error(std::string_view message) {
  std::fprintf(stderr, "exactgeo: %.*s\n", int(message.size()), message.data());
}

int usage_error(std::string_view message) {
  print_error(message);
  std::fprintf(stderr, "Run 'exactgeo --help' for usage.\n");
  return kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"exactgeo: exact geodesic distances on triangle meshes (VTP algorithm)", "exactgeo"};
  app.set_version_flag("--version", std::string("exactgeo ") + exactgeo::kVersion);
  app.require_subcommand(1);
  app.footer(kExitCodesHelp);

  // --source and --source-point, shared by the commands that take sources.
  const auto add_sources = [](CLI::App* command, SourceArguments& sources) {
    CLI::Option* vertices = command->add_option("--source", sources.vertices,
                                                "Source vertex index (repeat for several sources)")
                                ->check(kSourceArgument)
                                ->allow_extra_args(false)  // one index per --source, so MESH may follow it
                                ->type_name("I");
    CLI::Option* points = command->add_option("--source-point", sources.points,
                                              "Source point on input triangle F with barycentric weights b0,b1,b2 "
                                              "(repeat for several; numbered after the --source vertices)")
                              ->check(kSurfacePointArgument)
                              ->allow_extra_args(false)
                              ->type_name("F:b0,b1,b2");
    // At least one source of either kind.
    command->callback([command, vertices, points] {
      if (vertices->count() == 0 && points->count() == 0)
        throw CLI::RequiredError(command->get_name() + ": --source or --source-point");
    });
  };

  DistanceArguments distance;
  CLI::App* distance_command =
      app.add_subcommand("distance", "Geodesic distance from sources to every vertex (and to targets)");
  distance_command->add_option("MESH", distance.mesh, kMeshHelp)->required()->check(kMeshArgument)->type_name("");
  add_sources(distance_command, distance.sources);
  distance_command
      ->add_option("--max-distance", distance.max_distance,
                   "Stop the wavefront at this distance; vertices farther away get inf")
      ->check(kDistanceArgument)
      ->type_name("R");
  distance_command
      ->add_option("--targets", distance.targets,
                   "Targets, as a file or a list: vertex indices (3,17,42) or points F:b0,b1,b2, separated by "
                   "spaces, newlines or ';'. Propagation stops once they are final; vertex distances are then "
                   "exact up to the farthest target and inf beyond")
      ->type_name("FILE|LIST");
  distance_command->add_flag("--labels", distance.labels,
                             "Add the nearest source (index in the order given, vertices first; -1 if none) to "
                             "each output row");
  distance_command
      ->add_option("--out", distance.out,
                   "Write one distance per vertex in input order: .txt (%.17g, 'inf' if unreachable), "
                   ".csv (vertex,distance), .npy (float64) or .ply (the mesh with a distance property and "
                   "colours)")
      ->check(kOutputArgument)
      ->type_name("FILE.{txt,csv,npy,ply}");
  distance_command
      ->add_option("--target-out", distance.target_out,
                   "Write one distance per target: .txt, .csv (target,distance) or .npy; without it the "
                   "summary lists them")
      ->check(kOutputArgument)
      ->type_name("FILE.{txt,csv,npy}");
  distance_command->add_option("--stats", distance.stats, "Write statistics as JSON")->type_name("FILE.json");
  std::vector<std::string> algorithm_names;
  for (const auto& [value, name] : exactgeo::kAlgorithmNames) algorithm_names.emplace_back(name);
  distance_command
      ->add_option("--algorithm", distance.algorithm,
                   "Variant (paper Section 5): vtp (default), opvtp (order-preserving merges), ftp (face-sorted "
                   "wavefront), opftp. All give the same distances")
      ->check(CLI::IsMember(algorithm_names))
      ->type_name("NAME");
  distance_command->add_flag("--no-rule1", distance.no_rule1,
                             "Ablation: split every window at the opposite vertex instead of pruning with Rule 1");
  distance_command->add_flag("--no-rule23", distance.no_rule23,
                             "Ablation: no pairwise pruning of neighbouring windows (Rules 2 and 3)");
  distance_command->add_flag("--timers", distance.timers,
                             "Split the propagation time into window propagation, pruning and queue (in --stats; "
                             "the clock reads slow the run down by up to 60%)");
  distance_command->add_flag("--quiet", distance.quiet, "No progress line on stderr");
  distance_command->add_flag("--weld", distance.weld, "Merge vertices with identical positions");
  distance_command->footer(kExitCodesHelp);

  PathArguments path;
  CLI::App* path_command = app.add_subcommand("path", "Shortest path from the nearest source to a target");
  path_command->add_option("MESH", path.mesh, kMeshHelp)->required()->check(kMeshArgument)->type_name("");
  add_sources(path_command, path.sources);
  path_command->add_option("--target", path.target, "Target vertex index or point F:b0,b1,b2")
      ->required()
      ->type_name("I|F:b0,b1,b2");
  path_command
      ->add_option("--out", path.out,
                   "Write the path: .csv (x,y,z and where each point lies), .obj (a polyline) or .json; "
                   "without it the points are printed")
      ->check(CLI::Validator(
          [](std::string& file) -> std::string {
            const std::string extension = extension_of(file);
            if (extension == ".csv" || extension == ".obj" || extension == ".json") return {};
            return "unsupported path file '" + file + "': the extension must be .csv, .obj or .json";
          },
          "", "path output"))
      ->type_name("FILE.{csv,obj,json}");
  path_command->add_flag("--weld", path.weld, "Merge vertices with identical positions");
  path_command->footer(kExitCodesHelp);

  SampleArguments sample;
  CLI::App* sample_command = app.add_subcommand("sample", "Geodesic farthest-point sampling of the vertices");
  sample_command->add_option("MESH", sample.mesh, kMeshHelp)->required()->check(kMeshArgument)->type_name("");
  sample_command->add_option("-k,--count", sample.count, "Number of samples")->required()->type_name("N");
  sample_command->add_option("--first", sample.first, "The first sample (default 0)")->type_name("I");
  sample_command
      ->add_option("--out", sample.out,
                   "Write the samples: .txt (one vertex per line) or .csv (sample,vertex,radius: the distance "
                   "to the samples before); without it they are printed")
      ->check(kOutputArgument)
      ->type_name("FILE.{txt,csv}");
  sample_command->add_flag("--quiet", sample.quiet, "No progress line on stderr");
  sample_command->add_flag("--weld", sample.weld, "Merge vertices with identical positions");
  sample_command->footer(kExitCodesHelp);

  MatrixArguments matrix;
  CLI::App* matrix_command =
      app.add_subcommand("matrix", "Distances from many source vertices to every vertex, in parallel");
  matrix_command->add_option("MESH", matrix.mesh, kMeshHelp)->required()->check(kMeshArgument)->type_name("");
  matrix_command
      ->add_option("--sources", matrix.sources,
                   "Source vertices, as a file or a list, separated by spaces, newlines, ',' or ';'")
      ->required()
      ->type_name("FILE|LIST");
  matrix_command->add_option("--max-distance", matrix.max_distance, "Cut-off: entries beyond it are inf (or left out)")
      ->check(kDistanceArgument)
      ->type_name("R");
  matrix_command->add_option("--threads", matrix.threads, "Worker threads (default: one per core)")->type_name("T");
  matrix_command
      ->add_option("--out", matrix.out,
                   "Write the matrix (rows: sources, columns: vertices): .npy (dense float64), .npz "
                   "(scipy.sparse CSR of the finite entries) or .csv (source,vertex,distance, finite entries)")
      ->required()
      ->check(CLI::Validator(
          [](std::string& file) -> std::string {
            const std::string extension = extension_of(file);
            if (extension == ".npy" || extension == ".npz" || extension == ".csv") return {};
            return "unsupported matrix file '" + file + "': the extension must be .npy, .npz or .csv";
          },
          "", "matrix output"))
      ->type_name("FILE.{npy,npz,csv}");
  matrix_command->add_flag("--quiet", matrix.quiet, "No progress line on stderr");
  matrix_command->add_flag("--weld", matrix.weld, "Merge vertices with identical positions");
  matrix_command->footer(kExitCodesHelp);

  InfoArguments info;
  CLI::App* info_command = app.add_subcommand("info", "What validation found in a mesh");
  info_command->add_option("MESH", info.mesh, kMeshHelp)->required()->check(kMeshArgument)->type_name("");
  info_command->add_flag("--json", info.json, "Print JSON instead of aligned text");
  info_command->add_flag("--weld", info.weld, "Merge vertices with identical positions");
  info_command->footer(kExitCodesHelp);

  // CLI11 reports a mistyped command only as "A subcommand is required"; name it instead.
  const auto is_command = [&](const char* name) {
    for (const CLI::App* command : {distance_command, path_command, sample_command, matrix_command, info_command})
      if (command->get_name() == name) return true;
    return false;
  };
  if (argc > 1 && argv[1][0] != '-' && !is_command(argv[1])) {
    return usage_error(std::string("unknown command '") + argv[1] + "' (use distance, path, sample, matrix or info)");
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    return usage_error(e.what());
  }

  try {
    if (*distance_command) return run_distance(distance);
    if (*path_command) return run_path(path);
    if (*sample_command) return run_sample(sample);
    if (*matrix_command) return run_matrix(matrix);
    return run_info(info);
  } catch (const exactgeo::Error& e) {
    if (e.code() == exactgeo::ErrorCode::internal) {
      print_error(std::string("internal error: ") + e.what());
      return kExitInternal;
    }
    print_error(e.what());
    return kExitInvalidInput;
  } catch (const std::bad_alloc&) {
    print_error("out of memory");
    return kExitInternal;
  } catch (const std::exception& e) {
    print_error(std::string("internal error: ") + e.what());
    return kExitInternal;
  }
}
