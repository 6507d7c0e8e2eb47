// Sources, targets, vertex lists and the checks of numbers on the command line.
#include "inputs.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <system_error>

#include "npy.hpp"
#include "outputs.hpp"

namespace exactgeo::cli {
namespace {

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

// A vertex index that fits the library's 32-bit type; anything else cannot name a vertex of any mesh.
std::optional<std::uint32_t> parse_vertex(std::string_view text) {
  std::uint32_t v = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || ptr != text.data() + text.size() || text.empty()) return std::nullopt;
  return v;
}

}  // namespace

void add_source_options(CLI::App& command, MeshArguments& mesh, SourceArguments& sources) {
  CLI::Option* vertices = add_list_option(command, mesh, "--source", sources.vertices,
                                          "Source vertex indices (--source 0 911, or repeated)")
                              ->type_name("I");
  CLI::Option* points = add_list_option(command, mesh, "--source-point", sources.points,
                                        "Source points on input triangle F with barycentric weights b0,b1,b2 "
                                        "(several, or repeated; numbered after the --source vertices)")
                            ->type_name("F:b0,b1,b2");
  add_list_option(command, mesh, "--source-xyz", sources.xyz,
                  "Sources at the closest surface points of points in space X,Y,Z (several, repeated, or a file "
                  "of x y z lines; numbered after the --source-point points)")
      ->type_name("X,Y,Z|FILE");
  // Syntax only, once MESH has been taken back from the lists; whether a vertex exists is up to the mesh.
  mesh.checks.push_back([&command, &sources, vertices, points] {
    if (sources.vertices.empty() && sources.points.empty() && sources.xyz.empty())
      throw CLI::RequiredError(command.get_name() + ": --source, --source-point or --source-xyz");
    for (const std::string& text : sources.vertices)
      if (!count_check()(std::string(text)).empty())
        throw CLI::ValidationError(vertices->get_name(), "'" + text + "' is not a vertex index");
    for (const std::string& text : sources.points)
      if (!parse_surface_point(text))
        throw CLI::ValidationError(points->get_name(), "'" + text + "' is not a surface point F:b0,b1,b2");
  });
}

Sources read_sources(const SourceArguments& arguments, const exactgeo::Mesh& mesh) {
  Sources sources;
  for (const std::string& text : arguments.vertices) {
    const auto v = parse_vertex(text);
    if (!v)
      throw invalid_argument("source vertex " + text + " is out of range (mesh has " +
                             std::to_string(mesh.vertex_count()) + " vertices)");
    sources.vertices.push_back(*v);
  }
  sources.as_points = !arguments.points.empty() || !arguments.xyz.empty();
  if (sources.as_points) {
    for (std::uint32_t v : sources.vertices) sources.points.push_back(exactgeo::vertex_point(mesh, v));
    for (const std::string& text : arguments.points) sources.points.push_back(*parse_surface_point(text));
    if (!arguments.xyz.empty()) {
      const exactgeo::LocateResult located = locate_listed(arguments.xyz, mesh, "--source-xyz");
      sources.points.insert(sources.points.end(), located.points.begin(), located.points.end());
    }
  }
  return sources;
}

std::string describe_sources(const SourceArguments& arguments) {
  std::string text;
  for (const auto& list : {arguments.vertices, arguments.points, arguments.xyz})
    for (const std::string& source : list) text += (text.empty() ? "" : " ") + source;
  return text;
}

const exactgeo::GeodesicResult& solve(exactgeo::GeodesicSolver& solver, const Sources& sources,
                                      std::span<const exactgeo::SurfacePoint> targets,
                                      const exactgeo::GeodesicOptions& options) {
  if (sources.as_points) return solver.solve(sources.points, targets, options);
  return solver.solve(sources.vertices, targets, options);
}

namespace {

// A token of a list, quoted for a message: bytes outside printable ASCII as \xNN, and at most 40 characters,
// so that a binary file taken for a list cannot garble the terminal.
std::string token_text(std::string_view token) {
  constexpr std::size_t kLongest = 40;
  std::string text = "'";
  for (std::size_t i = 0; i < token.size() && i < kLongest; ++i) {
    const auto byte = static_cast<unsigned char>(token[i]);
    if (byte >= 0x20 && byte < 0x7f) {
      text += static_cast<char>(byte);
    } else {
      constexpr char kHex[] = "0123456789ABCDEF";
      text += {'\\', 'x', kHex[byte >> 4], kHex[byte & 0xf]};
    }
  }
  return text + (token.size() > kLongest ? "...'" : "'");
}

// The point at vertex `v`; the library's message for a vertex out of range or used by no face gets `where`
// in front.
exactgeo::SurfacePoint listed_vertex_point(const exactgeo::Mesh& mesh, std::uint32_t v, const std::string& where) {
  try {
    return exactgeo::vertex_point(mesh, v);
  } catch (const exactgeo::Error& e) {
    throw exactgeo::Error(e.code(), where + ": " + e.what());
  }
}

}  // namespace

std::vector<exactgeo::SurfacePoint> parse_targets(const std::string& text, const exactgeo::Mesh& mesh,
                                                  const std::string& origin, std::string_view element) {
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
          throw invalid_argument(origin + ": " + std::string(element) + " " + token_text(part) +
                                 " is not a surface point F:b0,b1,b2");
        targets.push_back(*point);
        continue;
      }
      std::istringstream vertices(part);
      for (std::string index; std::getline(vertices, index, ',');) {
        const auto v = parse_vertex(index);
        if (!v)
          throw invalid_argument(origin + ": " + std::string(element) + " " + token_text(index) +
                                 " is neither a vertex index nor a point F:b0,b1,b2");
        targets.push_back(listed_vertex_point(mesh, *v, origin));
      }
    }
  }
  if (targets.empty()) throw invalid_argument(origin + ": no " + std::string(element) + " given");
  return targets;
}

std::vector<double> parse_xyz_list(const std::string& text, const std::string& origin) {
  std::vector<double> xyz;
  std::string entries = text;
  std::replace(entries.begin(), entries.end(), ';', '\n');
  std::istringstream lines(entries);
  bool first = true;
  for (std::string entry; std::getline(lines, entry);) {
    std::string fields_text = entry;
    std::replace(fields_text.begin(), fields_text.end(), ',', ' ');
    std::istringstream fields(fields_text);
    std::vector<std::string> parts;
    for (std::string field; fields >> field;) parts.push_back(field);
    if (parts.empty()) continue;
    const bool may_be_header = first;
    first = false;
    std::array<double, 3> point;
    std::size_t numbers = 0;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      double value = 0;
      const auto [ptr, ec] = std::from_chars(parts[k].data(), parts[k].data() + parts[k].size(), value);
      if (ec != std::errc() || ptr != parts[k].data() + parts[k].size()) continue;
      if (k < 3) point[k] = value;
      ++numbers;
    }
    if (numbers == 0 && may_be_header) continue;  // x,y,z
    if (numbers != 3 || parts.size() != 3)
      throw invalid_argument(origin + ": '" + entry + "' is not a point X,Y,Z");
    xyz.insert(xyz.end(), point.begin(), point.end());
  }
  if (xyz.empty()) throw invalid_argument(origin + ": no point given");
  return xyz;
}

namespace {

// One value of a list option, read: a file's bytes (standard input's for "-"), or the value itself.
struct ListInput {
  std::string bytes;
  std::string origin;  // in messages: "--sources 's.npy'", "--sources (standard input)" or "--sources"
  bool npy;            // a .npy array, by its first bytes (or its name, so that a damaged one says so)
};

std::string standard_input() {
  std::string bytes;
  std::array<char, 1 << 16> buffer;
  for (std::size_t n; (n = std::fread(buffer.data(), 1, buffer.size(), stdin)) > 0;) bytes.append(buffer.data(), n);
  if (std::ferror(stdin))
    throw exactgeo::Error(exactgeo::ErrorCode::io_error,
                          std::string("cannot read standard input: ") + std::strerror(errno));
  return bytes;
}

// A list never holds a '/' nor ends in a file's extension: such a value was meant as a file.
bool names_a_file(const std::string& argument) {
  return argument.find('/') != std::string::npos ||
         std::ranges::any_of(std::array{".npy", ".txt", ".csv"},
                             [&](const char* extension) { return has_extension(argument, extension); });
}

// Text as lists are written: no control characters but white space, so that a binary file other than a .npy
// is refused as a whole rather than token by token.
bool is_text(std::string_view bytes) {
  return std::ranges::none_of(bytes, [](char c) {
    const auto byte = static_cast<unsigned char>(c);
    return (byte < 0x20 && !std::isspace(byte)) || byte == 0x7f;
  });
}

ListInput read_list_input(const std::string& argument, const std::string& option) {
  ListInput input;
  std::error_code error;
  if (argument == kStandardInput) {
    input.bytes = standard_input();
    input.origin = option + " (standard input)";
  } else if (std::filesystem::is_regular_file(argument, error)) {
    std::ifstream file(argument, std::ios::binary);
    std::ostringstream bytes;
    bytes << file.rdbuf();
    if (!file && !file.eof()) throw exactgeo::Error(exactgeo::ErrorCode::io_error, "cannot read '" + argument + "'");
    input.bytes = bytes.str();
    input.origin = option + " '" + argument + "'";
  } else if (names_a_file(argument)) {
    const bool exists = std::filesystem::exists(argument, error);
    throw exactgeo::Error(exactgeo::ErrorCode::io_error, option + ": cannot read '" + argument + "': " +
                                                             (exists ? "not a regular file" : "no such file"));
  } else {
    input.bytes = argument;
    input.origin = option;
  }
  input.npy = is_npy(input.bytes) || (input.origin != option && has_extension(argument, ".npy"));
  if (input.npy) return input;
  // A byte order mark, as spreadsheet programs begin their CSV files with, is no part of the list.
  constexpr std::string_view kUtf8ByteOrderMark = "\xEF\xBB\xBF";
  if (input.bytes.starts_with(kUtf8ByteOrderMark)) input.bytes.erase(0, kUtf8ByteOrderMark.size());
  if (!is_text(input.bytes))
    throw invalid_argument(input.origin +
                           ": binary data, not a list (a .npy array of integers, text, or CSV with a vertex column)");
  return input;
}

std::string element_origin(const ListInput& input, std::size_t element) {
  return input.origin + ": element [" + std::to_string(element) + "]";
}

// The position of the "vertex" column if the first line is a CSV header naming one (as `sample --out s.csv`
// writes: sample,vertex,radius).
std::optional<std::size_t> vertex_column(const std::string& text) {
  std::istringstream header(text.substr(0, text.find_first_of("\r\n")));
  std::size_t position = 0;
  for (std::string name; std::getline(header, name, ','); ++position)
    if (name == "vertex") return position;
  return std::nullopt;
}

// The `column` field of each row after the header line.
std::vector<std::uint32_t> csv_column_vertices(const std::string& text, std::size_t column, const std::string& origin) {
  std::vector<std::uint32_t> vertices;
  std::istringstream lines(text);
  std::string line;
  std::getline(lines, line);  // the header
  for (std::size_t row = 2; std::getline(lines, line); ++row) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::vector<std::string> fields;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) fields.push_back(cell);
    const std::string field = column < fields.size() ? fields[column] : "";
    const auto v = parse_vertex(field);
    if (!v)
      throw invalid_argument(origin + ": line " + std::to_string(row) + ": " + token_text(field) +
                             " is not a vertex index");
    vertices.push_back(*v);
  }
  return vertices;
}

// Indices separated by spaces, newlines, ',' or ';'.
std::vector<std::uint32_t> listed_vertices(const std::string& text, const std::string& origin) {
  std::vector<std::uint32_t> vertices;
  std::string entry;
  std::istringstream entries(text);
  while (entries >> entry) {
    std::replace(entry.begin(), entry.end(), ';', ',');
    std::istringstream parts(entry);
    for (std::string index; std::getline(parts, index, ',');) {
      if (index.empty()) continue;
      const auto v = parse_vertex(index);
      if (!v) throw invalid_argument(origin + ": " + token_text(index) + " is not a vertex index");
      vertices.push_back(*v);
    }
  }
  return vertices;
}

}  // namespace

std::vector<std::uint32_t> parse_vertex_list(const std::string& text, const std::string& origin) {
  const std::optional<std::size_t> column = vertex_column(text);
  std::vector<std::uint32_t> vertices =
      column ? csv_column_vertices(text, *column, origin) : listed_vertices(text, origin);
  if (vertices.empty()) throw invalid_argument(origin + ": no vertex given");
  return vertices;
}

namespace {

// The vertices of a value holding vertices only (a .npy array, a list or CSV file of indices), each checked
// against the mesh (in range; used by a face unless `check` is in_range); a message names the value, and the
// element of a .npy array.
std::vector<std::uint32_t> checked_vertices(const ListInput& input, const exactgeo::Mesh& mesh, VertexCheck check) {
  const std::vector<std::uint32_t> vertices =
      input.npy ? read_npy_indices(input.bytes, input.origin) : parse_vertex_list(input.bytes, input.origin);
  if (vertices.empty()) throw invalid_argument(input.origin + ": no vertex given");
  for (std::size_t i = 0; i < vertices.size(); ++i)
    if (check == VertexCheck::used_by_a_face || vertices[i] >= mesh.vertex_count())
      listed_vertex_point(mesh, vertices[i], input.npy ? element_origin(input, i) : input.origin);
  return vertices;
}

}  // namespace

std::vector<std::uint32_t> read_vertex_list(const std::vector<std::string>& arguments, const exactgeo::Mesh& mesh,
                                            const std::string& option, VertexCheck check) {
  std::vector<std::uint32_t> vertices;
  for (const std::string& argument : arguments) {
    const std::vector<std::uint32_t> listed = checked_vertices(read_list_input(argument, option), mesh, check);
    vertices.insert(vertices.end(), listed.begin(), listed.end());
  }
  return vertices;
}

std::vector<exactgeo::SurfacePoint> read_targets(const std::vector<std::string>& arguments,
                                                 const exactgeo::Mesh& mesh, const std::string& option,
                                                 std::string_view element) {
  std::vector<exactgeo::SurfacePoint> targets;
  for (const std::string& argument : arguments) {
    const ListInput input = read_list_input(argument, option);
    if (input.npy || vertex_column(input.bytes)) {
      for (std::uint32_t v : checked_vertices(input, mesh, VertexCheck::used_by_a_face))
        targets.push_back(exactgeo::vertex_point(mesh, v));
    } else {
      const std::vector<exactgeo::SurfacePoint> listed = parse_targets(input.bytes, mesh, input.origin, element);
      targets.insert(targets.end(), listed.begin(), listed.end());
    }
  }
  return targets;
}

Pairs read_pairs(const std::vector<std::string>& arguments, const exactgeo::Mesh& mesh, const std::string& option) {
  Pairs pairs;
  for (const std::string& argument : arguments) {
    const ListInput input = read_list_input(argument, option);
    if (input.npy) {
      const std::vector<std::uint32_t> vertices = read_npy_indices(input.bytes, input.origin, 2);
      for (std::size_t i = 0; i < vertices.size(); ++i) {
        const std::string element =
            input.origin + ": element [" + std::to_string(i / 2) + ", " + std::to_string(i % 2) + "]";
        (i % 2 == 0 ? pairs.a : pairs.b).push_back(listed_vertex_point(mesh, vertices[i], element));
      }
      continue;
    }
    std::string text = input.bytes;
    std::replace(text.begin(), text.end(), ';', '\n');
    std::istringstream lines(text);
    bool first = true;
    std::size_t row = 0;
    for (std::string line; std::getline(lines, line);) {
      ++row;
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      const bool header = first && std::ranges::none_of(line, [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
      first = false;
      if (header) continue;
      const std::string where = input.origin + ": line " + std::to_string(row);
      const std::vector<exactgeo::SurfacePoint> points = parse_targets(line, mesh, where);
      if (points.size() != 2)
        throw invalid_argument(where + ": " + token_text(line) +
                               " is not a pair (two vertex indices or points F:b0,b1,b2)");
      pairs.a.push_back(points[0]);
      pairs.b.push_back(points[1]);
    }
  }
  if (pairs.a.empty()) throw invalid_argument(option + ": no pair given");
  return pairs;
}

exactgeo::LocateResult locate_listed(const std::vector<std::string>& arguments, const exactgeo::Mesh& mesh,
                                     const std::string& origin, unsigned threads) {
  std::vector<double> xyz;
  for (const std::string& argument : arguments) {
    const ListInput input = read_list_input(argument, origin);
    if (input.npy) throw invalid_argument(input.origin + ": points in space are text (X,Y,Z per line), not .npy");
    const std::vector<double> listed = parse_xyz_list(input.bytes, input.origin);
    xyz.insert(xyz.end(), listed.begin(), listed.end());
  }
  try {
    return exactgeo::locate(mesh, xyz, {.threads = threads});
  } catch (const exactgeo::Error& e) {
    throw exactgeo::Error(e.code(), origin + ": " + e.what());
  }
}

const CLI::Validator& distance_check() {
  static const CLI::Validator check(
      [](std::string& text) -> std::string {
        double value = 0;
        const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (ec != std::errc() || ptr != text.data() + text.size() || !(value >= 0))
          return "'" + text + "' is not a non-negative distance";
        return {};
      },
      "", "distance");
  return check;
}

void add_threads_option(CLI::App& command, std::optional<unsigned>& threads) {
  command
      .add_option("--threads", threads,
                  "Threads sharing the propagation (0: one per core; default: one per 10,000 faces, up to one per "
                  "core), and reading and building the mesh (default: one per core). The distances agree with one "
                  "thread's to 1e-14 of the largest; the mesh is the same on any count")
      ->check(count_check(std::numeric_limits<unsigned>::max()))
      ->type_name("N");
}

unsigned threads_for(const std::optional<unsigned>& threads, const exactgeo::Mesh& mesh) {
  return threads ? *threads : exactgeo::recommended_threads(mesh);
}

CLI::Validator count_check(std::uint64_t maximum) {
  return CLI::Validator(
      [maximum](std::string& text) -> std::string {
        std::uint64_t value = 0;
        // Digits only: from_chars takes no sign for an unsigned type.
        const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (ec != std::errc() || ptr != text.data() + text.size() || value > maximum)
          return "'" + text + "' is not a whole number from 0 to " + std::to_string(maximum);
        return {};
      },
      "", "count");
}

}  // namespace exactgeo::cli
