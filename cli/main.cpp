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
#include <functional>
#include <limits>
#include <new>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "exactgeo/shapes.hpp"

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

// ---------------------------------------------------------------------------------------------------
// Output files.

enum class OutputFormat { txt, csv, npy };

std::optional<OutputFormat> output_format(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (extension == ".txt") return OutputFormat::txt;
  if (extension == ".csv") return OutputFormat::csv;
  if (extension == ".npy") return OutputFormat::npy;
  return std::nullopt;
}

const CLI::Validator kOutputArgument(
    [](std::string& path) -> std::string {
      if (!output_format(path)) {
        return "unsupported output file '" + path + "': the extension must be .txt, .csv or .npy";
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

void write_txt(std::FILE* file, std::span<const double> distances) {
  for (double distance : distances) {
    print_distance(file, distance);
    std::fputc('\n', file);
  }
}

void write_csv(std::FILE* file, std::span<const double> distances) {
  std::fputs("vertex,distance\n", file);
  for (std::size_t v = 0; v < distances.size(); ++v) {
    std::fprintf(file, "%zu,", v);
    print_distance(file, distances[v]);
    std::fputc('\n', file);
  }
}

// NumPy .npy format version 1.0: magic, version, little-endian header length, a Python dict literal
// padded with spaces to a multiple of 64 bytes, then the raw little-endian doubles.
void write_npy(std::FILE* file, std::span<const double> distances) {
  std::string header =
      "{'descr': '<f8', 'fortran_order': False, 'shape': (" + std::to_string(distances.size()) + ",), }";
  constexpr std::size_t kPreambleBytes = 10;  // magic (6) + version (2) + header length (2)
  constexpr std::size_t kAlignment = 64;
  const std::size_t unpadded = kPreambleBytes + header.size() + 1;  // + the closing newline
  header.append((kAlignment - unpadded % kAlignment) % kAlignment, ' ');
  header += '\n';

  const auto header_bytes = std::uint16_t(header.size());
  const unsigned char preamble[kPreambleBytes] = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0,
                                                  std::uint8_t(header_bytes & 0xff), std::uint8_t(header_bytes >> 8)};
  std::fwrite(preamble, 1, sizeof preamble, file);
  std::fwrite(header.data(), 1, header.size(), file);

  std::vector<unsigned char> data(distances.size() * 8);
  for (std::size_t i = 0; i < distances.size(); ++i) {
    const auto bits = std::bit_cast<std::uint64_t>(distances[i]);
    for (std::size_t byte = 0; byte < 8; ++byte) data[i * 8 + byte] = std::uint8_t(bits >> (8 * byte));
  }
  std::fwrite(data.data(), 1, data.size(), file);
}

void write_distances(const std::string& path, std::span<const double> distances) {
  switch (*output_format(path)) {
    case OutputFormat::txt:
      return write_file(path, [&](std::FILE* file) { write_txt(file, distances); });
    case OutputFormat::csv:
      return write_file(path, [&](std::FILE* file) { write_csv(file, distances); });
    case OutputFormat::npy:
      return write_file(path, [&](std::FILE* file) { write_npy(file, distances); });
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

struct DistanceArguments {
  std::string mesh;
  std::vector<std::string> sources;  // checked by kSourceArgument, converted after loading
  std::string out;
  std::string stats;
  bool weld = false;
};

struct InfoArguments {
  std::string mesh;
  bool json = false;
  bool weld = false;
};

int run_distance(const DistanceArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh, arguments.weld);
  const exactgeo::Mesh& mesh = loaded.mesh;

  // The library checks sources against the mesh; only indices too wide for its 32-bit type stop here.
  std::vector<std::uint32_t> sources;
  for (const std::string& text : arguments.sources) {
    std::uint32_t source = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), source);
    if (ec != std::errc() || ptr != text.data() + text.size()) {
      const std::string vertices = std::to_string(mesh.vertex_count());
      throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument,
                            "source vertex " + text + " is out of range (mesh has " + vertices + " vertices)");
    }
    sources.push_back(source);
  }

  const exactgeo::GeodesicResult result = exactgeo::geodesic_distance(mesh, sources);
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

  if (!arguments.out.empty()) write_distances(arguments.out, result.distances);

  if (!arguments.stats.empty()) {
    nlohmann::ordered_json json;
    json["mesh"] = arguments.mesh;
    json["vertices"] = mesh.vertex_count();
    json["faces"] = mesh.face_count();
    json["source"] = sources;
    json["algorithm"] = "vtp";
    json["read_seconds"] = loaded.read_seconds;
    json["build_seconds"] = loaded.build_seconds;
    json["propagation_seconds"] = stats.propagation_seconds;
    json["window_propagations"] = stats.window_propagations;
    json["peak_windows"] = stats.peak_windows;
    json["peak_window_bytes"] = stats.peak_window_bytes;
    json["vertex_pops"] = stats.vertex_pops;
    json["pseudo_source_emissions"] = stats.pseudo_source_emissions;
    json["max_distance"] = max_distance;
    json["unreachable"] = unreachable;
    json["mesh_report"] = report_json(mesh.report());
    json["version"] = exactgeo::kVersion;
    write_json(arguments.stats, json);
  }

  if (arguments.out.empty()) {
    std::string source_list;
    for (std::uint32_t source : sources) source_list += (source_list.empty() ? "" : " ") + std::to_string(source);
    char max_text[32], build_text[32], propagation_text[32];
    std::snprintf(max_text, sizeof max_text, "%.12g", max_distance);
    std::snprintf(build_text, sizeof build_text, "%.4f s", loaded.build_seconds);
    std::snprintf(propagation_text, sizeof propagation_text, "%.4f s", stats.propagation_seconds);
    print_table({
        {"mesh", arguments.mesh},
        {"vertices", std::to_string(mesh.vertex_count())},
        {"faces", std::to_string(mesh.face_count())},
        {sources.size() == 1 ? "source" : "sources", source_list},
        {"max distance", max_text},
        {"unreachable", std::to_string(unreachable)},
        {"window propagations", std::to_string(stats.window_propagations)},
        {"peak windows", std::to_string(stats.peak_windows)},
        {"build", build_text},
        {"propagation", propagation_text},
    });
  }
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

  DistanceArguments distance;
  CLI::App* distance_command =
      app.add_subcommand("distance", "Geodesic distance from source vertices to every vertex");
  distance_command->add_option("MESH", distance.mesh, kMeshHelp)->required()->check(kMeshArgument)->type_name("");
  distance_command->add_option("--source", distance.sources, "Source vertex index (repeat for several sources)")
      ->required()
      ->check(kSourceArgument)
      ->allow_extra_args(false)  // one index per --source, so MESH may follow it
      ->type_name("I");
  distance_command
      ->add_option("--out", distance.out,
                   "Write one distance per vertex in input order: .txt (%.17g, 'inf' if unreachable), "
                   ".csv (vertex,distance) or .npy (float64)")
      ->check(kOutputArgument)
      ->type_name("FILE.{txt,csv,npy}");
  distance_command->add_option("--stats", distance.stats, "Write statistics as JSON")->type_name("FILE.json");
  distance_command->add_flag("--weld", distance.weld, "Merge vertices with identical positions");
  distance_command->footer(kExitCodesHelp);

  InfoArguments info;
  CLI::App* info_command = app.add_subcommand("info", "What validation found in a mesh");
  info_command->add_option("MESH", info.mesh, kMeshHelp)->required()->check(kMeshArgument)->type_name("");
  info_command->add_flag("--json", info.json, "Print JSON instead of aligned text");
  info_command->add_flag("--weld", info.weld, "Merge vertices with identical positions");
  info_command->footer(kExitCodesHelp);

  // CLI11 reports a mistyped command only as "A subcommand is required"; name it instead.
  if (argc > 1 && argv[1][0] != '-' && argv[1] != distance_command->get_name() &&
      argv[1] != info_command->get_name()) {
    return usage_error(std::string("unknown command '") + argv[1] + "' (use distance or info)");
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    return usage_error(e.what());
  }

  try {
    if (*distance_command) return run_distance(distance);
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
