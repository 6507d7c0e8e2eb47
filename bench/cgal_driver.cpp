// The CGAL peer of the benchmark: geodesic distances from CGAL's Surface_mesh_shortest_path on a mesh file,
// with mesh construction and propagation timed apart, N times.
//
//   exactgeo_cgal_driver MESH --source I [--source J ...] [--out distances.txt] [--stats stats.json] [--repeat N]
//
// distances.txt: one line per input vertex, %.17g, "inf" where unreachable or used by no face.
// stats.json: vertices, faces, sources, build_seconds and query_seconds (one entry per run),
// loaded_as_manifold, duplicated_points.
// Exit codes: 0 ok, 1 usage, 2 bad input (unreadable mesh, source out of range, or a soup CGAL cannot
// turn into a valid polygon mesh).
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "cgal_oracle.hpp"
#include "exactgeo/error.hpp"
#include "exactgeo/io.hpp"

namespace {

constexpr const char* kUsage =
    "usage: exactgeo_cgal_driver MESH --source I [--source J ...] [--out distances.txt] [--stats stats.json] "
    "[--repeat N]\n";

struct Arguments {
  std::string mesh_path;
  std::vector<std::uint32_t> sources;
  std::string distances_path;  // empty: not written
  std::string stats_path;      // empty: not written
  unsigned repeat = 1;
};

template <typename Integer>
bool parse_integer(std::string_view text, Integer& value) {
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size();
}

// Returns false (after saying why) on anything it does not understand.
bool parse_arguments(int argc, char** argv, Arguments& arguments) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view option = argv[i];
    const bool takes_value = option == "--source" || option == "--out" || option == "--stats" || option == "--repeat";
    if (!takes_value) {
      if (option.starts_with("-") || !arguments.mesh_path.empty()) {
        std::fprintf(stderr, "unexpected argument '%s'\n", argv[i]);
        return false;
      }
      arguments.mesh_path = option;
      continue;
    }
    if (i + 1 == argc) {
      std::fprintf(stderr, "%s needs a value\n", argv[i]);
      return false;
    }
    const std::string_view value = argv[++i];
    if (option == "--source") {
      std::uint32_t source = 0;
      if (!parse_integer(value, source)) {
        std::fprintf(stderr, "--source: '%s' is not a vertex index\n", argv[i]);
        return false;
      }
      arguments.sources.push_back(source);
    } else if (option == "--repeat") {
      if (!parse_integer(value, arguments.repeat) || arguments.repeat == 0) {
        std::fprintf(stderr, "--repeat: '%s' is not a positive count\n", argv[i]);
        return false;
      }
    } else if (option == "--out") {
      arguments.distances_path = value;
    } else {
      arguments.stats_path = value;
    }
  }
  if (arguments.mesh_path.empty() || arguments.sources.empty()) {
    std::fprintf(stderr, "a mesh and at least one --source are required\n");
    return false;
  }
  return true;
}

// Opens for writing or throws exactgeo::Error(io_error) naming the file.
std::FILE* open_for_writing(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr)
    throw exactgeo::Error(exactgeo::ErrorCode::io_error, path + ": cannot open for writing: " + std::strerror(errno));
  return file;
}

void close_written(std::FILE* file, const std::string& path) {
  const bool failed = std::ferror(file) != 0;
  if (std::fclose(file) != 0 || failed)
    throw exactgeo::Error(exactgeo::ErrorCode::io_error, path + ": write failed");
}

void write_distances(const std::string& path, const std::vector<double>& distances) {
  std::FILE* file = open_for_writing(path);
  for (double distance : distances) std::fprintf(file, "%.17g\n", distance);  // glibc prints +inf as "inf"
  close_written(file, path);
}

void write_json_list(std::FILE* file, const char* name, const std::vector<double>& values) {
  std::fprintf(file, "  \"%s\": [", name);
  for (std::size_t i = 0; i < values.size(); ++i) std::fprintf(file, "%s%.9g", i == 0 ? "" : ", ", values[i]);
  std::fprintf(file, "],\n");
}

void write_stats(const std::string& path, const exactgeo::MeshSoup& soup, const std::vector<std::uint32_t>& sources,
                 const std::vector<double>& build_seconds, const std::vector<double>& query_seconds,
                 const exactgeo_oracle::OracleResult& result) {
  std::FILE* file = open_for_writing(path);
  std::fprintf(file, "{\n  \"vertices\": %zu,\n  \"faces\": %zu,\n  \"sources\": [", soup.positions.size() / 3,
               soup.triangles.size() / 3);
  for (std::size_t i = 0; i < sources.size(); ++i) std::fprintf(file, "%s%u", i == 0 ? "" : ", ", sources[i]);
  std::fprintf(file, "],\n");
  write_json_list(file, "build_seconds", build_seconds);
  write_json_list(file, "query_seconds", query_seconds);
  std::fprintf(file, "  \"loaded_as_manifold\": %s,\n  \"duplicated_points\": %zu\n}\n",
               result.loaded_as_manifold ? "true" : "false", result.duplicated_points);
  close_written(file, path);
}

int run(const Arguments& arguments) {
  const exactgeo::MeshSoup soup = exactgeo::read_mesh_soup(arguments.mesh_path);
  const std::size_t vertex_count = soup.positions.size() / 3;
  for (std::uint32_t source : arguments.sources)
    if (source >= vertex_count)
      throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument,
                            "--source " + std::to_string(source) + " out of range (" + arguments.mesh_path + " has " +
                                std::to_string(vertex_count) + " vertices)");

  exactgeo_oracle::OracleResult result;
  std::vector<double> build_seconds, query_seconds;
  for (unsigned run_index = 0; run_index < arguments.repeat; ++run_index) {
    result = exactgeo_oracle::cgal_geodesic_distances(soup.positions, soup.triangles, arguments.sources);
    build_seconds.push_back(result.build_seconds);
    query_seconds.push_back(result.query_seconds);
    std::printf("run %u: build %.6f s, query %.6f s\n", run_index + 1, result.build_seconds, result.query_seconds);
  }

  if (!arguments.stats_path.empty())
    write_stats(arguments.stats_path, soup, arguments.sources, build_seconds, query_seconds, result);
  if (!result.loaded_as_manifold)
    throw exactgeo::Error(exactgeo::ErrorCode::invalid_mesh,
                          arguments.mesh_path + ": CGAL cannot turn this soup into a valid polygon mesh");
  if (!arguments.distances_path.empty()) write_distances(arguments.distances_path, result.distances);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  Arguments arguments;
  if (!parse_arguments(argc, argv, arguments)) {
    std::fputs(kUsage, stderr);
    return 1;
  }
  try {
    return run(arguments);
  } catch (const exactgeo::Error& error) {
    std::fprintf(stderr, "error: %s\n", error.what());
    return 2;
  }
}
