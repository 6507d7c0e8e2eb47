// The exactgeo command end to end: exit codes, messages, output formats, and distances on meshes whose
// answer is known in closed form.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "exactgeo/exactgeo.hpp"
#include "exactgeo/shapes.hpp"
#include "exactgeo/version.hpp"

namespace {

namespace fs = std::filesystem;

constexpr double kInf = std::numeric_limits<double>::infinity();

struct RunResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

std::string read_file(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

void write_file(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

std::vector<double> parse_txt(const fs::path& path) {
  std::vector<double> values;
  std::istringstream lines(read_file(path));
  for (std::string line; std::getline(lines, line);) values.push_back(std::strtod(line.c_str(), nullptr));
  return values;
}

// Checks the "vertex,distance" header and that rows come in vertex order.
std::vector<double> parse_csv(const fs::path& path) {
  std::vector<double> values;
  std::istringstream lines(read_file(path));
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "vertex,distance");
  while (std::getline(lines, line)) {
    const std::size_t comma = line.find(',');
    EXPECT_NE(comma, std::string::npos) << line;
    EXPECT_EQ(line.substr(0, comma), std::to_string(values.size()));
    values.push_back(std::strtod(line.c_str() + comma + 1, nullptr));
  }
  return values;
}

// Validates the NumPy v1.0 header of a 1-D little-endian float64 array and returns its values.
std::vector<double> parse_npy(const fs::path& path) {
  const std::string bytes = read_file(path);
  if (bytes.size() < 10) {
    ADD_FAILURE() << "npy file too short";
    return {};
  }
  EXPECT_EQ(bytes.substr(0, 6), "\x93NUMPY");
  EXPECT_EQ(bytes[6], 1);  // format version 1.0
  EXPECT_EQ(bytes[7], 0);
  const std::size_t header_length = std::uint8_t(bytes[8]) | std::size_t(std::uint8_t(bytes[9])) << 8;
  const std::size_t data_offset = 10 + header_length;
  EXPECT_EQ(data_offset % 16, 0u) << "the format requires the data to be aligned";
  const std::string header = bytes.substr(10, header_length);
  EXPECT_EQ(header.back(), '\n');
  EXPECT_NE(header.find("'descr': '<f8'"), std::string::npos) << header;
  EXPECT_NE(header.find("'fortran_order': False"), std::string::npos) << header;
  const std::size_t shape = header.find("'shape': (");
  EXPECT_NE(shape, std::string::npos) << header;
  const std::size_t count = std::strtoull(header.c_str() + shape + 10, nullptr, 10);
  EXPECT_NE(header.find("'shape': (" + std::to_string(count) + ",)"), std::string::npos) << header;
  EXPECT_EQ(bytes.size(), data_offset + count * 8);

  std::vector<double> values(count);
  for (std::size_t i = 0; i < count && data_offset + i * 8 + 8 <= bytes.size(); ++i) {
    std::uint64_t bits = 0;
    for (std::size_t byte = 0; byte < 8; ++byte) {
      bits |= std::uint64_t(std::uint8_t(bytes[data_offset + i * 8 + byte])) << (8 * byte);
    }
    values[i] = std::bit_cast<double>(bits);
  }
  return values;
}

void expect_bitwise_equal(const std::vector<double>& a, const std::vector<double>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a[i]), std::bit_cast<std::uint64_t>(b[i])) << "vertex " << i;
  }
}

// Each test gets its own scratch directory, removed afterwards.
class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("exactgeo_cli_" + std::string(test->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path path(const std::string& name) const { return dir_ / name; }

  // Runs `exactgeo ARGUMENTS` through the shell; ARGUMENTS must already be quoted where needed.
  RunResult run(const std::string& arguments) const {
    const fs::path out = path("stdout"), err = path("stderr");
    const std::string command =
        "'" EXACTGEO_CLI_PATH "' " + arguments + " >'" + out.string() + "' 2>'" + err.string() + "'";
    const int status = std::system(command.c_str());
    RunResult result;
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    result.out = read_file(out);
    result.err = read_file(err);
    return result;
  }

  // Quoted path of a scratch file, for use in arguments.
  std::string arg(const std::string& name) const { return "'" + path(name).string() + "'"; }

  // An error: the given exit code, nothing on stdout, one "exactgeo: " message on stderr naming `expected`.
  static void expect_error(const RunResult& result, int exit_code, const std::string& expected) {
    EXPECT_EQ(result.exit_code, exit_code) << result.err;
    EXPECT_EQ(result.out, "");
    EXPECT_EQ(result.err.rfind("exactgeo: ", 0), 0u) << result.err;
    EXPECT_NE(result.err.find(expected), std::string::npos) << result.err;
    EXPECT_LE(std::count(result.err.begin(), result.err.end(), '\n'), 2) << result.err;
  }

 private:
  fs::path dir_;
};

TEST_F(Cli, DistanceOnIcospherePrintsSummary) {
  const RunResult result = run("distance @icosphere:2 --source 0");
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.err, "");
  for (const char* expected : {"@icosphere:2", "vertices", "162", "faces", "320", "max distance", "unreachable",
                               "window propagations", "peak windows", "propagation"}) {
    EXPECT_NE(result.out.find(expected), std::string::npos) << expected << " missing from:\n" << result.out;
  }
}

TEST_F(Cli, OutputFormatsAgree) {
  for (const char* name : {"d.txt", "d.csv", "d.npy"}) {
    const RunResult result = run("distance @icosphere:2 --source 3 --out " + arg(name));
    ASSERT_EQ(result.exit_code, 0) << name << ": " << result.err;
    EXPECT_EQ(result.out, "") << "no summary when writing a file";
  }
  const std::vector<double> txt = parse_txt(path("d.txt"));
  const std::vector<double> csv = parse_csv(path("d.csv"));
  const std::vector<double> npy = parse_npy(path("d.npy"));
  ASSERT_EQ(txt.size(), 162u);
  expect_bitwise_equal(txt, csv);
  expect_bitwise_equal(txt, npy);

  // A closed surface: every distance is finite and at least the straight-line chord.
  const exactgeo::MeshSoup sphere = exactgeo::make_icosphere(2);
  EXPECT_EQ(txt[3], 0.0);
  for (std::size_t v = 0; v < txt.size(); ++v) {
    double chord_squared = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
      chord_squared += std::pow(sphere.positions[v * 3 + axis] - sphere.positions[3 * 3 + axis], 2);
    }
    EXPECT_TRUE(std::isfinite(txt[v])) << "vertex " << v;
    EXPECT_GE(txt[v] * (1 + 1e-12), std::sqrt(chord_squared)) << "vertex " << v;
  }
}

TEST_F(Cli, TxtRoundTripsEveryDouble) {
  // %.17g must give back the exact doubles the .npy holds, also on a mesh with irrational distances.
  ASSERT_EQ(run("distance @torus:12:8 --source 5 --out " + arg("d.txt")).exit_code, 0);
  ASSERT_EQ(run("distance @torus:12:8 --source 5 --out " + arg("d.npy")).exit_code, 0);
  expect_bitwise_equal(parse_txt(path("d.txt")), parse_npy(path("d.npy")));
}

TEST_F(Cli, FlatGridDistancesAreEuclidean) {
  // @grid:8:8 is documented as 8 x 8 unit squares, vertex j*9+i at (i, j, 0). Check that layout against
  // the generator, then that every distance is the straight-line distance (a flat convex domain).
  constexpr int kSide = 8, kColumns = kSide + 1;
  const exactgeo::MeshSoup grid = exactgeo::make_grid(kSide, kSide, kSide, kSide);
  ASSERT_EQ(grid.positions.size(), std::size_t(kColumns * kColumns * 3));
  for (int v = 0; v < kColumns * kColumns; ++v) {
    ASSERT_EQ(grid.positions[v * 3], v % kColumns);
    ASSERT_EQ(grid.positions[v * 3 + 1], v / kColumns);
  }

  struct Case {
    std::string sources;
    std::vector<int> source_vertices;
  };
  for (const Case& c : {Case{"--source 0", {0}}, Case{"--source 40", {40}}, Case{"--source 0 --source 80", {0, 80}},
                        Case{"--source 7 --source 65 --source 33", {7, 65, 33}}}) {
    const RunResult result = run("distance @grid:8:8 " + c.sources + " --out " + arg("d.txt"));
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const std::vector<double> distances = parse_txt(path("d.txt"));
    ASSERT_EQ(distances.size(), std::size_t(kColumns * kColumns));
    for (int v = 0; v < kColumns * kColumns; ++v) {
      double expected = kInf;
      for (int s : c.source_vertices) {
        expected = std::min(expected, std::hypot(v % kColumns - s % kColumns, v / kColumns - s / kColumns));
      }
      EXPECT_NEAR(distances[v], expected, 1e-12 * std::max(1.0, expected)) << c.sources << ", vertex " << v;
    }
  }
}

TEST_F(Cli, StatsJsonHasRequiredKeys) {
  const RunResult result =
      run("distance @icosphere:2 --source 0 --source 7 --stats " + arg("s.json") + " --out " + arg("d.txt"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json stats = nlohmann::json::parse(read_file(path("s.json")));
  for (const char* key : {"vertices", "faces", "source", "algorithm", "read_seconds", "build_seconds", "build_threads",
                          "build_timings", "propagation_seconds", "write_seconds", "window_propagations", "peak_windows",
                          "peak_window_bytes", "vertex_pops", "max_distance", "unreachable", "mesh_report"}) {
    EXPECT_TRUE(stats.contains(key)) << key;
  }
  EXPECT_EQ(stats["vertices"], 162);
  EXPECT_EQ(stats["faces"], 320);
  EXPECT_EQ(stats["source"], nlohmann::json::array({0, 7}));
  EXPECT_EQ(stats["algorithm"], "vtp");
  EXPECT_EQ(stats["unreachable"], 0);
  EXPECT_GE(stats["read_seconds"].get<double>(), 0.0);
  // The build's steps, each timed apart and after the read: together no more than the build.
  double steps = 0;
  exactgeo::for_each_build_stats_field([&](std::string_view name, auto, const char*) {
    if (!name.ends_with("_seconds")) return;
    ASSERT_TRUE(stats["build_timings"].contains(name)) << name;
    steps += stats["build_timings"][std::string(name)].get<double>();
  });
  EXPECT_GT(steps, 0.0);
  EXPECT_LE(steps, stats["build_seconds"].get<double>());
  EXPECT_GE(stats["build_threads"].get<unsigned>(), 1u);
  EXPECT_GE(stats["write_seconds"].get<double>(), 0.0);
  EXPECT_GE(stats["propagation_seconds"].get<double>(), 0.0);
  EXPECT_GT(stats["window_propagations"].get<std::uint64_t>(), 0u);
  EXPECT_GT(stats["peak_windows"].get<std::uint64_t>(), 0u);
  EXPECT_GT(stats["peak_window_bytes"].get<std::uint64_t>(), 0u);

  const std::vector<double> distances = parse_txt(path("d.txt"));
  EXPECT_EQ(stats["max_distance"].get<double>(), *std::max_element(distances.begin(), distances.end()));
  EXPECT_EQ(stats["mesh_report"]["vertices"], 162);
  EXPECT_EQ(stats["mesh_report"]["boundary_edges"], 0);
}

TEST_F(Cli, AlgorithmVariantsAndAblationsGiveTheSameDistancesAndSayWhatRan) {
  ASSERT_EQ(run("distance @torus --source 3 --out " + arg("default.txt")).exit_code, 0);
  const std::vector<double> expected = parse_txt(path("default.txt"));
  const RunResult result = run("distance @torus --source 3 --algorithm opftp --no-rule1 --no-rule23 --timers --stats " +
                               arg("s.json") + " --out " + arg("d.txt"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::vector<double> distances = parse_txt(path("d.txt"));
  ASSERT_EQ(distances.size(), expected.size());
  for (std::size_t v = 0; v < distances.size(); ++v) EXPECT_NEAR(distances[v], expected[v], 1e-12) << v;

  const nlohmann::json stats = nlohmann::json::parse(read_file(path("s.json")));
  EXPECT_EQ(stats["algorithm"], "opftp");
  EXPECT_EQ(stats["rule1"], false);
  EXPECT_EQ(stats["rule23"], false);
  EXPECT_EQ(stats["window_propagations"].get<std::uint64_t>(),
            stats["prime_propagations"].get<std::uint64_t>() + stats["secondary_propagations"].get<std::uint64_t>());
  EXPECT_GT(stats["face_pops"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(stats["vertex_pops"].get<std::uint64_t>(), 0u);
  for (const char* key : {"window_propagation_seconds", "queue_seconds"}) EXPECT_GT(stats[key].get<double>(), 0.0) << key;
  EXPECT_EQ(stats["pruning_seconds"].get<double>(), 0.0);  // Rules 2 and 3 are off

  // Without --timers the split is null, not a misleading zero; the summary names a non-default variant.
  const RunResult summary = run("distance @torus --source 3 --algorithm ftp --stats " + arg("t.json"));
  ASSERT_EQ(summary.exit_code, 0) << summary.err;
  EXPECT_NE(summary.out.find("ftp"), std::string::npos) << summary.out;
  EXPECT_TRUE(nlohmann::json::parse(read_file(path("t.json")))["pruning_seconds"].is_null());
}

// With several threads, --timers adds where the threads' time went and a timeline of the bands, as columns
// of one entry per band that add up to the run's counts.
TEST_F(Cli, TimersWithThreadsWriteTheBandTimeline) {
  ASSERT_EQ(run("distance @torus --source 3 --threads 3 --timers --quiet --stats " + arg("s.json")).exit_code, 0);
  const nlohmann::json stats = nlohmann::json::parse(read_file(path("s.json")));
  const nlohmann::json& bands = stats["band_timeline"];
  ASSERT_TRUE(bands.is_object()) << stats.dump();
  const std::size_t count = stats["parallel_bands"].get<std::size_t>();
  for (const char* column : {"vertices", "crossings", "depth", "seconds", "busy_seconds"})
    EXPECT_EQ(bands[column].size(), count) << column;
  std::uint64_t crossings = 0;
  for (const nlohmann::json& c : bands["crossings"]) crossings += c.get<std::uint64_t>();
  EXPECT_EQ(crossings, stats["list_crossings"].get<std::uint64_t>());
  EXPECT_GT(stats["parallel_busy_seconds"].get<double>(), 0.0);

  ASSERT_EQ(run("distance @torus --source 3 --threads 3 --quiet --stats " + arg("t.json")).exit_code, 0);
  const nlohmann::json untimed = nlohmann::json::parse(read_file(path("t.json")));
  EXPECT_FALSE(untimed.contains("band_timeline"));
  EXPECT_TRUE(untimed["parallel_busy_seconds"].is_null());
}

TEST_F(Cli, UnknownAlgorithmIsAUsageError) {
  expect_error(run("distance @torus --source 0 --algorithm mmp"), 1, "mmp");
}

// Two triangles that share an edge only through duplicated positions, plus a vertex used by no face.
constexpr const char* kSeamObj =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
    "v 1 0 0\nv 0 1 0\nv 1 1 0\n"
    "v 5 5 5\n"
    "f 1 2 3\nf 4 6 5\n";

TEST_F(Cli, UnreachableVerticesAreInfInEveryFormat) {
  write_file(path("seam.obj"), kSeamObj);
  for (const char* name : {"d.txt", "d.csv", "d.npy"}) {
    ASSERT_EQ(run("distance " + arg("seam.obj") + " --source 0 --out " + arg(name)).exit_code, 0) << name;
  }
  const std::vector<double> expected = {0, 1, 1, kInf, kInf, kInf, kInf};
  expect_bitwise_equal(parse_txt(path("d.txt")), expected);
  expect_bitwise_equal(parse_csv(path("d.csv")), expected);
  expect_bitwise_equal(parse_npy(path("d.npy")), expected);
  EXPECT_NE(read_file(path("d.txt")).find("\ninf\n"), std::string::npos);
  EXPECT_NE(read_file(path("d.csv")).find("\n3,inf\n"), std::string::npos);

  const RunResult summary = run("distance " + arg("seam.obj") + " --source 0 --stats " + arg("s.json"));
  ASSERT_EQ(summary.exit_code, 0) << summary.err;
  const nlohmann::json stats = nlohmann::json::parse(read_file(path("s.json")));
  EXPECT_EQ(stats["unreachable"], 4);
  EXPECT_EQ(stats["max_distance"], 1.0);
}

TEST_F(Cli, WeldJoinsTheSeam) {
  write_file(path("seam.obj"), kSeamObj);
  ASSERT_EQ(run("distance " + arg("seam.obj") + " --source 0 --weld --out " + arg("d.txt")).exit_code, 0);
  const std::vector<double> distances = parse_txt(path("d.txt"));
  const std::vector<double> expected = {0, 1, 1, 1, 1, std::sqrt(2.0), kInf};
  ASSERT_EQ(distances.size(), expected.size());
  for (std::size_t v = 0; v + 1 < expected.size(); ++v) EXPECT_NEAR(distances[v], expected[v], 1e-15) << v;
  EXPECT_EQ(distances.back(), kInf) << "the unused vertex stays unreachable";

  const RunResult plain = run("info " + arg("seam.obj") + " --json");
  const RunResult welded = run("info " + arg("seam.obj") + " --json --weld");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(welded.exit_code, 0) << welded.err;
  EXPECT_EQ(nlohmann::json::parse(plain.out)["welded_vertices"], 0);
  EXPECT_EQ(nlohmann::json::parse(plain.out)["components"], 2);
  EXPECT_GT(nlohmann::json::parse(welded.out)["welded_vertices"].get<int>(), 0);
  EXPECT_EQ(nlohmann::json::parse(welded.out)["components"], 1);
}

// info reports every field of the library's MeshReport, with the library's values.
TEST_F(Cli, InfoJsonHasEveryReportField) {
  const RunResult result = run("info @torus --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json info = nlohmann::json::parse(result.out);
  const exactgeo::MeshReport report = exactgeo::Mesh(exactgeo::make_bumpy_torus(64, 36)).report();
  exactgeo::for_each_report_field([&](const char* name, auto member, const char*) {
    ASSERT_TRUE(info.contains(name)) << name;
    EXPECT_EQ(info[name].get<std::size_t>(), report.*member) << name;
  });
  EXPECT_EQ(info["mesh"], "@torus");
  // The demo torus: 64 x 36 segments, closed, one piece, saddles between the bumps.
  EXPECT_EQ(info["vertices"], 64 * 36);
  EXPECT_EQ(info["faces"], 2 * 64 * 36);
  EXPECT_EQ(info["boundary_edges"], 0);
  EXPECT_EQ(info["components"], 1);
  EXPECT_GT(info["saddle_vertices"].get<int>(), 0);
}

TEST_F(Cli, InfoTextListsEveryReportField) {
  const RunResult result = run("info @grid:3:2");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  exactgeo::for_each_report_field([&](const char* name, auto, const char*) {
    EXPECT_NE(result.out.find(std::string("\n") + name + " "), std::string::npos) << name;
  });
}

TEST_F(Cli, VersionPrintsTheLibraryVersion) {
  const RunResult result = run("--version");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(result.out.find(exactgeo::kVersion), std::string::npos) << result.out;
}

TEST_F(Cli, HelpExitsZero) {
  const RunResult result = run("distance --help");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(result.out.find("@icosphere:K"), std::string::npos) << result.out;
}

// What --out's help says the PLY files hold is what the PLY tests below read: it once called the distance a float.
TEST_F(Cli, HelpSaysWhatThePlyFilesHold) {
  const RunResult result = run("distance --help");
  EXPECT_NE(result.out.find(".ply (the mesh, binary: float coordinates, a double distance property and colours;"),
            std::string::npos)
      << result.out;
  EXPECT_NE(result.out.find(".ascii.ply (the same as text, the coordinates as doubles too)"), std::string::npos)
      << result.out;
}

TEST_F(Cli, MissingFileIsInvalidInput) {
  expect_error(run("distance " + arg("no-such-mesh.obj") + " --source 0"), 2, "no-such-mesh.obj");
  expect_error(run("info " + arg("no-such-mesh.ply")), 2, "no-such-mesh.ply");
}

// A link to /dev/zero was read until memory ran out, and a FIFO waited for a writer forever.
TEST_F(Cli, NonRegularFilesAreInvalidInput) {
  fs::create_symlink("/dev/zero", path("zero.obj"));
  fs::create_directory(path("folder.ply"));
  ASSERT_EQ(::mkfifo(path("pipe.off").c_str(), 0600), 0);
  for (const char* name : {"zero.obj", "folder.ply", "pipe.off"}) {
    expect_error(run("distance " + arg(name) + " --source 0"), 2, path(name).string() + "': not a regular file");
    expect_error(run("info " + arg(name)), 2, path(name).string() + "': not a regular file");
  }
}

TEST_F(Cli, MalformedObjIsInvalidInput) {
  write_file(path("bad-index.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  expect_error(run("distance " + arg("bad-index.obj") + " --source 0"), 2, "bad-index.obj");
  write_file(path("bad-number.obj"), "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n");
  expect_error(run("info " + arg("bad-number.obj")), 2, "bad-number.obj");
}

TEST_F(Cli, SourceOutOfRangeIsInvalidInput) {
  expect_error(run("distance @icosphere:1 --source 42"), 2, "42");
  expect_error(run("distance @icosphere:1 --source 99999999999"), 2, "99999999999");
}

TEST_F(Cli, BuiltinParameterOutOfRangeIsInvalidInput) {
  expect_error(run("info @grid:0:4"), 2, "grid");
  // Level 14 was accepted and grew until memory ran out: its faces do not fit 32-bit indices.
  expect_error(run("info @icosphere:14"), 2, "icosphere subdivisions 14 out of range (0 to 13");
}

TEST_F(Cli, UsageErrors) {
  expect_error(run("distance @icosphere:1 --source 0 --frobnicate"), 1, "--frobnicate");
  expect_error(run("distance @icosphere:1"), 1, "--source");
  expect_error(run("distance @icosphere:1 --source-point 3:0.2,0.3"), 1, "3:0.2,0.3");
  expect_error(run("distance @icosphere:1 --source 0 --max-distance -2"), 1, "-2");
  expect_error(run("path @icosphere:1 --source 0"), 1, "--target");
  expect_error(run("path @icosphere:1 --source 0 --target 3 --out " + arg("p.txt")), 1, "p.txt");
  expect_error(run("distance @icosphere:1 --source -1"), 1, "-1");
  expect_error(run("distance @icosphere:1 --source abc"), 1, "abc");
  expect_error(run("distance @cube --source 0"), 1, "@cube");
  expect_error(run("frobnicate"), 1, "frobnicate");
  expect_error(run(""), 1, "subcommand");
}

TEST_F(Cli, BadOutputExtensionIsUsageError) {
  expect_error(run("distance @icosphere:1 --source 0 --out " + arg("d.xyz")), 1, "d.xyz");
  expect_error(run("distance @icosphere:1 --source 0 --out " + arg("no-extension")), 1, "no-extension");
  EXPECT_FALSE(fs::exists(path("d.xyz")));
}

TEST_F(Cli, UnwritableOutputIsInvalidInput) {
  expect_error(run("distance @icosphere:1 --source 0 --out " + arg("missing-dir/d.txt")), 2, "missing-dir/d.txt");
}

// --query-points reads the points --targets reads and answers each as a run with them as targets does.
TEST_F(Cli, QueryPointsAgreeWithTargets) {
  write_file(path("points.txt"), "7,12\n5:0.5,0.5,0 ; 24\n100:0.2,0.3,0.5\n311:0.6,0.1,0.3\n");
  const std::string from_source = "distance @torus:24:10 --source 3 ";
  ASSERT_EQ(run(from_source + "--targets " + arg("points.txt") + " --target-out " + arg("t.npy")).exit_code, 0);
  RunResult result = run(from_source + "--query-points " + arg("points.txt") + " --query-out " + arg("q.npy") +
                         " --stats " + arg("s.json"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::vector<double> targets = parse_npy(path("t.npy")), queried = parse_npy(path("q.npy"));
  ASSERT_EQ(queried.size(), 6u);
  ASSERT_EQ(targets.size(), queried.size());
  for (std::size_t i = 0; i < queried.size(); ++i) EXPECT_NEAR(queried[i], targets[i], 1e-13) << "point " << i;
  const nlohmann::json stats = nlohmann::json::parse(read_file(path("s.json")));
  EXPECT_EQ(stats["query_points"], 6);
  EXPECT_GT(stats["kept_windows"].get<double>(), 0);
  ASSERT_EQ(run(from_source + "--query-points " + arg("points.txt") + " --query-out " + arg("q.csv")).exit_code, 0);
  EXPECT_EQ(read_file(path("q.csv")).substr(0, 15), "point,distance\n");
  // Without --query-out the summary lists them.
  result = run(from_source + "--query-points " + arg("points.txt"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("point 5"), std::string::npos) << result.out;
  expect_error(run(from_source + "--query-points 9999 --query-out " + arg("q.npy")), 2, "9999");
  expect_error(run(from_source + "--query-points 5:0.5,x --query-out " + arg("q.npy")), 2,
               "point '5:0.5,x' is not a surface point");
}

TEST_F(Cli, PointSourcesTargetsAndLabelsOnAFlatGrid) {
  // @grid:4:4: vertex j*5+i at (i, j, 0); every distance is a straight line.
  write_file(path("targets.txt"), "7,12\n5:0.5,0.5,0 ; 24\n");
  const RunResult result = run("distance @grid:4:4 --source 0 --source-point 3:0.2,0.3,0.5 --targets " +
                               arg("targets.txt") + " --labels --out " + arg("d.csv") + " --target-out " + arg("t.csv"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const exactgeo::MeshSoup grid = exactgeo::make_grid(4, 4, 4, 4);
  std::array<double, 3> point{};
  for (int k = 0; k < 3; ++k)
    for (int axis = 0; axis < 3; ++axis)
      point[axis] += std::array<double, 3>{0.2, 0.3, 0.5}[k] * grid.positions[3 * grid.triangles[9 + k] + axis];
  const auto to_vertex = [&](const std::array<double, 3>& p, int v) {
    return std::hypot(p[0] - grid.positions[3 * v], p[1] - grid.positions[3 * v + 1]);
  };
  const std::array<double, 3> origin{0, 0, 0};
  // Targets: vertices 7 and 12, the midpoint of face 5's first edge, vertex 24.
  std::istringstream rows(read_file(path("t.csv")));
  std::string line;
  std::getline(rows, line);
  EXPECT_EQ(line, "target,distance,nearest_source");
  std::vector<std::array<double, 2>> expected;
  for (int v : {7, 12}) expected.push_back({std::min(to_vertex(origin, v), to_vertex(point, v)), 0});
  std::array<double, 3> midpoint{};
  for (int axis = 0; axis < 3; ++axis)
    midpoint[axis] = 0.5 * (grid.positions[3 * grid.triangles[15] + axis] + grid.positions[3 * grid.triangles[16] + axis]);
  const double to_mid_from_point = std::hypot(point[0] - midpoint[0], point[1] - midpoint[1]);
  expected.push_back({std::min(std::hypot(midpoint[0], midpoint[1]), to_mid_from_point), 0});
  expected.push_back({std::min(to_vertex(origin, 24), to_vertex(point, 24)), 0});
  for (std::size_t t = 0; std::getline(rows, line); ++t) {
    ASSERT_LT(t, expected.size()) << line;
    double distance = 0;
    long long label = -2;
    std::size_t index = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%zu,%lf,%lld", &index, &distance, &label), 3) << line;
    EXPECT_EQ(index, t);
    EXPECT_NEAR(distance, expected[t][0], 1e-12) << line;
    EXPECT_TRUE(label == 0 || label == 1) << line;
  }
  // Vertex rows carry labels: the nearer of the two sources (vertices first, then points).
  std::istringstream vertex_rows(read_file(path("d.csv")));
  std::getline(vertex_rows, line);
  EXPECT_EQ(line, "vertex,distance,nearest_source");
  for (int v = 0; std::getline(vertex_rows, line); ++v) {
    double distance = 0;
    long long label = -2;
    int index = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%d,%lf,%lld", &index, &distance, &label), 3) << line;
    if (std::isinf(distance)) {
      EXPECT_EQ(label, -1) << line;
      continue;
    }
    const double from_origin = to_vertex(origin, v), from_point = to_vertex(point, v);
    EXPECT_NEAR(distance, std::min(from_origin, from_point), 1e-12) << line;
    if (std::abs(from_origin - from_point) > 1e-9) EXPECT_EQ(label, from_origin < from_point ? 0 : 1) << line;
  }
}

TEST_F(Cli, MaxDistanceLeavesFartherVerticesAtInf) {
  ASSERT_EQ(run("distance @grid:8:8 --source 0 --max-distance 4.5 --out " + arg("d.txt")).exit_code, 0);
  const std::vector<double> d = parse_txt(path("d.txt"));
  ASSERT_EQ(d.size(), 81u);
  for (int v = 0; v < 81; ++v) {
    const double truth = std::hypot(v % 9, v / 9);
    if (truth <= 4.5 - 1e-9) EXPECT_NEAR(d[v], truth, 1e-12) << v;
    if (truth > 4.5 + 1e-9) EXPECT_TRUE(std::isinf(d[v])) << v;
  }
}

TEST_F(Cli, AsciiPlyOutputCarriesDistancesAndColours) {
  ASSERT_EQ(run("distance @grid:2:2 --source 0 --labels --out " + arg("d.ascii.ply")).exit_code, 0);
  std::istringstream lines(read_file(path("d.ascii.ply")));
  std::string line;
  std::vector<std::string> header;
  while (std::getline(lines, line) && line != "end_header") header.push_back(line);
  for (const char* expected : {"ply", "format ascii 1.0", "element vertex 9", "property double distance",
                               "property int nearest_source", "property uchar red", "element face 8",
                               "property list uchar int vertex_indices"})
    EXPECT_NE(std::find(header.begin(), header.end(), expected), header.end()) << expected;
  for (int v = 0; v < 9; ++v) {
    ASSERT_TRUE(std::getline(lines, line));
    double x, y, z, distance;
    int label, red, green, blue;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf %lf %lf %lf %d %d %d %d", &x, &y, &z, &distance, &label, &red, &green,
                          &blue), 8) << line;
    EXPECT_NEAR(distance, std::hypot(x, y), 1e-12);
    EXPECT_EQ(label, 0);
  }
  int faces = 0;
  while (std::getline(lines, line)) faces += line.rfind("3 ", 0) == 0;
  EXPECT_EQ(faces, 8);
}

// A binary little-endian PLY as .ply writes it: the header, then per vertex float x, y, z, double distance
// (int nearest_source with labels) and uchar red, green, blue, then per face a uchar 3 and three ints.
struct BinaryPly {
  std::vector<std::string> header;
  std::vector<std::array<float, 3>> vertices;  // x, y, z
  std::vector<double> distances;
  std::vector<std::int32_t> labels;
  std::vector<std::array<int, 3>> colours;
  std::vector<std::array<std::int32_t, 3>> faces;
};

BinaryPly read_binary_ply(const std::string& bytes, std::size_t vertex_count, std::size_t face_count, bool labels) {
  BinaryPly ply;
  std::size_t at = 0;
  while (true) {
    const std::size_t end = bytes.find('\n', at);
    if (end == std::string::npos) {
      ADD_FAILURE() << "no end_header";
      return ply;
    }
    ply.header.push_back(bytes.substr(at, end - at));
    at = end + 1;
    if (ply.header.back() == "end_header") break;
  }
  const auto u32 = [&] {
    std::uint32_t bits = 0;
    for (int byte = 0; byte < 4; ++byte) bits |= std::uint32_t(std::uint8_t(bytes[at++])) << (8 * byte);
    return bits;
  };
  const std::size_t vertex_bytes = 20 + (labels ? 4 : 0) + 3;
  EXPECT_EQ(bytes.size(), at + vertex_count * vertex_bytes + face_count * 13) << "the file's size";
  if (bytes.size() != at + vertex_count * vertex_bytes + face_count * 13) return ply;
  for (std::size_t v = 0; v < vertex_count; ++v) {
    std::array<float, 3> vertex{};
    for (float& value : vertex) value = std::bit_cast<float>(u32());
    ply.vertices.push_back(vertex);
    const std::uint64_t low = u32();
    ply.distances.push_back(std::bit_cast<double>(low | std::uint64_t{u32()} << 32));
    if (labels) ply.labels.push_back(std::bit_cast<std::int32_t>(u32()));
    ply.colours.push_back({std::uint8_t(bytes[at]), std::uint8_t(bytes[at + 1]), std::uint8_t(bytes[at + 2])});
    at += 3;
  }
  for (std::size_t f = 0; f < face_count; ++f) {
    EXPECT_EQ(bytes[at++], 3);
    std::array<std::int32_t, 3> face{};
    for (std::int32_t& corner : face) corner = std::bit_cast<std::int32_t>(u32());
    ply.faces.push_back(face);
  }
  return ply;
}

// .ply is binary: the same mesh, distances (the .npy's, bit for bit) and colours as .ascii.ply, unreachable vertices grey
// with distance inf; a quarter of the text's size or less.
TEST_F(Cli, PlyOutputIsBinaryWithTheAsciiPlysValues) {
  // Two grids side by side: the second is unreachable from vertex 0.
  write_file(path("two.obj"),
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0\nf 1 2 3\nf 2 4 3\nf 5 6 7\n");
  for (const bool labels : {false, true}) {
    const std::string flag = labels ? " --labels" : "";
    for (const char* mesh : {"@torus:24:10", "two.obj"}) {
      const std::string name = mesh[0] == '@' ? mesh : arg(mesh);
      ASSERT_EQ(run("distance " + name + " --source 0" + flag + " --out " + arg("d.ply")).exit_code, 0);
      ASSERT_EQ(run("distance " + name + " --source 0" + flag + " --out " + arg("d.ascii.ply")).exit_code, 0);
      ASSERT_EQ(run("distance " + name + " --source 0 --out " + arg("d.npy")).exit_code, 0);
      const std::vector<double> distances = parse_npy(path("d.npy"));
      const std::size_t n = distances.size();
      const std::size_t faces = mesh[0] == '@' ? 480 : 3;
      const BinaryPly ply = read_binary_ply(read_file(path("d.ply")), n, faces, labels);
      ASSERT_EQ(ply.vertices.size(), n);
      std::vector<std::string> expected_header = {
          "ply", "format binary_little_endian 1.0", "comment written by exactgeo: geodesic distance per vertex",
          "element vertex " + std::to_string(n), "property float x", "property float y", "property float z",
          "property double distance"};
      if (labels) expected_header.push_back("property int nearest_source");
      for (const char* line : {"property uchar red", "property uchar green", "property uchar blue"})
        expected_header.push_back(line);
      for (const std::string line : {"element face " + std::to_string(faces), std::string("property list uchar int vertex_indices"),
                                     std::string("end_header")})
        expected_header.push_back(line);
      EXPECT_EQ(ply.header, expected_header);
      // The text file: positions, distances and colours per vertex line, faces after.
      std::istringstream text(read_file(path("d.ascii.ply")));
      std::string line;
      while (std::getline(text, line) && line != "end_header") {}
      for (std::size_t v = 0; v < n; ++v) {
        ASSERT_TRUE(std::getline(text, line));
        std::istringstream fields(line);
        double x, y, z;
        std::string distance;
        int label = 0, red, green, blue;
        fields >> x >> y >> z >> distance;
        if (labels) fields >> label;
        fields >> red >> green >> blue;
        ASSERT_TRUE(fields) << line;
        EXPECT_EQ(ply.vertices[v][0], static_cast<float>(x));
        EXPECT_EQ(ply.vertices[v][1], static_cast<float>(y));
        EXPECT_EQ(ply.vertices[v][2], static_cast<float>(z));
        EXPECT_EQ(ply.distances[v], distances[v]) << v;
        EXPECT_EQ(std::isinf(distances[v]), distance == "inf");
        if (labels) EXPECT_EQ(ply.labels[v], label);
        EXPECT_EQ(ply.colours[v], (std::array<int, 3>{red, green, blue})) << v;
        if (std::isinf(distances[v])) EXPECT_EQ(ply.colours[v], (std::array<int, 3>{128, 128, 128}));
      }
      for (std::size_t f = 0; f < faces; ++f) {
        ASSERT_TRUE(std::getline(text, line));
        std::array<std::int32_t, 3> face{};
        int count = 0;
        std::istringstream(line) >> count >> face[0] >> face[1] >> face[2];
        EXPECT_EQ(count, 3);
        EXPECT_EQ(ply.faces[f], face) << f;
      }
      if (mesh[0] == '@') EXPECT_LT(read_file(path("d.ply")).size() * 2, read_file(path("d.ascii.ply")).size());
      // The library reads it back: the same mesh.
      ASSERT_EQ(run("info " + arg("d.ply") + " --json").exit_code, 0);
    }
  }
  EXPECT_EQ(run("distance @grid:2:2 --source 0 --out " + arg("D.PLY")).exit_code, 0);
  EXPECT_EQ(read_file(path("D.PLY")).find("format binary_little_endian 1.0"), 4u);
}

// A legacy binary VTK file as .vtk writes it: text lines, each block of big-endian numbers followed by a newline.
struct LegacyVtk {
  std::vector<std::string> lines;  // the text lines, in order
  std::vector<double> points;      // x, y, z per vertex
  std::vector<std::int32_t> polygons;
  std::vector<double> distances;
  std::vector<std::int32_t> labels;
};

LegacyVtk read_legacy_vtk(const std::string& bytes, std::size_t vertex_count, std::size_t face_count, bool labels) {
  LegacyVtk vtk;
  std::size_t at = 0;
  const auto line = [&] {
    const std::size_t end = bytes.find('\n', at);
    vtk.lines.push_back(bytes.substr(at, end - at));
    at = end == std::string::npos ? bytes.size() : end + 1;
  };
  const auto big_endian = [&](std::size_t size) {
    std::uint64_t bits = 0;
    for (std::size_t byte = 0; byte < size && at < bytes.size(); ++byte) bits = bits << 8 | std::uint8_t(bytes[at++]);
    return bits;
  };
  const auto doubles = [&](std::vector<double>& values, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) values.push_back(std::bit_cast<double>(big_endian(8)));
    EXPECT_EQ(bytes[at++], '\n') << "a newline after the binary block";
  };
  const auto ints = [&](std::vector<std::int32_t>& values, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i)
      values.push_back(std::bit_cast<std::int32_t>(static_cast<std::uint32_t>(big_endian(4))));
    EXPECT_EQ(bytes[at++], '\n') << "a newline after the binary block";
  };
  for (int i = 0; i < 5; ++i) line();
  doubles(vtk.points, 3 * vertex_count);
  line();
  ints(vtk.polygons, 4 * face_count);
  for (int i = 0; i < 3; ++i) line();
  doubles(vtk.distances, vertex_count);
  if (labels) {
    for (int i = 0; i < 2; ++i) line();
    ints(vtk.labels, vertex_count);
  }
  EXPECT_EQ(at, bytes.size()) << "bytes after the last block";
  return vtk;
}

// .vtk: the mesh with the distance as point data, which VTK-based tools read (their PLY reader keeps only
// colours): the positions and distances exactly, bit for bit the .npy's, inf included; labels as ints.
TEST_F(Cli, VtkOutputCarriesTheMeshAndTheDistancesExactly) {
  write_file(path("two.obj"),
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0.1\nf 1 2 3\nf 2 4 3\nf 5 6 7\n");
  ASSERT_EQ(run("distance " + arg("two.obj") + " --source 0 --out " + arg("d.npy")).exit_code, 0);
  ASSERT_EQ(run("distance " + arg("two.obj") + " --source 0 --labels --out " + arg("d.vtk")).exit_code, 0);
  const std::vector<double> distances = parse_npy(path("d.npy"));
  ASSERT_EQ(distances.size(), 7u);
  EXPECT_TRUE(std::isinf(distances[6]));
  const LegacyVtk vtk = read_legacy_vtk(read_file(path("d.vtk")), 7, 3, true);
  const std::vector<std::string> expected_lines = {"# vtk DataFile Version 3.0",
                                                   "written by exactgeo",
                                                   "BINARY",
                                                   "DATASET POLYDATA",
                                                   "POINTS 7 double",
                                                   "POLYGONS 3 12",
                                                   "POINT_DATA 7",
                                                   "SCALARS distance double 1",
                                                   "LOOKUP_TABLE default",
                                                   "SCALARS nearest_source int 1",
                                                   "LOOKUP_TABLE default"};
  EXPECT_EQ(vtk.lines, expected_lines);
  EXPECT_EQ(vtk.points, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 5, 0, 0, 6, 0, 0, 5, 1, 0.1}));
  EXPECT_EQ(vtk.polygons, (std::vector<std::int32_t>{3, 0, 1, 2, 3, 1, 3, 2, 3, 4, 5, 6}));
  expect_bitwise_equal(vtk.distances, distances);
  EXPECT_EQ(vtk.labels, (std::vector<std::int32_t>{0, 0, 0, 0, -1, -1, -1}));
  // Without labels the distance is the only point data.
  ASSERT_EQ(run("distance @torus:24:10 --source 3 --out " + arg("t.vtk")).exit_code, 0);
  ASSERT_EQ(run("distance @torus:24:10 --source 3 --out " + arg("t.npy")).exit_code, 0);
  const LegacyVtk torus = read_legacy_vtk(read_file(path("t.vtk")), 240, 480, false);
  expect_bitwise_equal(torus.distances, parse_npy(path("t.npy")));
  EXPECT_EQ(torus.lines.back(), "LOOKUP_TABLE default");
}

TEST_F(Cli, PathOnAFlatGridIsTheDiagonal) {
  for (const char* name : {"p.csv", "p.obj", "p.json"})
    ASSERT_EQ(run("path @grid:4:4 --source 0 --target 24 --out " + arg(name)).exit_code, 0) << name;
  const nlohmann::json path_json = nlohmann::json::parse(read_file(path("p.json")));
  EXPECT_NEAR(path_json["length"].get<double>(), 4 * std::sqrt(2.0), 1e-12);
  const auto& points = path_json["points"];
  ASSERT_GE(points.size(), 2u);
  for (const auto& p : points) EXPECT_NEAR(p[0].get<double>(), p[1].get<double>(), 1e-12);  // on the diagonal
  EXPECT_EQ(path_json["locations"].front()["vertex"], 0);
  EXPECT_EQ(path_json["locations"].back()["vertex"], 24);
  const std::string obj = read_file(path("p.obj"));
  EXPECT_EQ(static_cast<std::size_t>(std::count(obj.begin(), obj.end(), 'v')), points.size());
  EXPECT_NE(obj.find("\nl 1 2"), std::string::npos) << obj;
  const std::string csv = read_file(path("p.csv"));
  EXPECT_EQ(csv.rfind("x,y,z,kind,a,b,t\n", 0), 0u);
  EXPECT_EQ(static_cast<std::size_t>(std::count(csv.begin(), csv.end(), '\n')), points.size() + 1);
  const RunResult printed = run("path @grid:4:4 --source-point 0:0.2,0.3,0.5 --target 24");
  EXPECT_EQ(printed.exit_code, 0) << printed.err;
  EXPECT_NE(printed.out.find("path length"), std::string::npos) << printed.out;
}

// Issue 34, finding 1: vertices 2 and 3 coincide, an edge of the zero-area face (1 3 2) of zero length, and
// `path` exited 3 with "internal error: path tracing failed". The surface is the flat triangle 0 1 2, so the
// path is the straight segment, to either vertex.
TEST_F(Cli, PathThroughCoincidentVertices) {
  write_file(path("d.obj"), "v 0 0 0\nv 1 0 1\nv 0 1 2\nv 0 1 2\nf 1 2 3\nf 2 4 3\n");
  for (const int target : {2, 3}) {
    const RunResult result =
        run("path " + arg("d.obj") + " --source 0 --target " + std::to_string(target) + " --out " + arg("p.json"));
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const nlohmann::json path_json = nlohmann::json::parse(read_file(path("p.json")));
    EXPECT_NEAR(path_json["length"].get<double>(), std::sqrt(5.0), 1e-12 * std::sqrt(5.0)) << "target " << target;
    EXPECT_EQ(path_json["locations"].front()["vertex"], 0);
    EXPECT_EQ(path_json["locations"].back()["vertex"], target);
  }
}

// Issue 34, finding 2: a vertex named as a target where the mesh policy splits it (vertex 0 of a bowtie, two
// triangles meeting there only) stood on the first face using it, so `distance --targets` and `path --target`
// gave inf from the other wing, while `--out` gave the smallest over its copies. Each wing runs straight along
// an edge to vertex 0.
TEST_F(Cli, TargetAtASplitVertexIsThePerVertexDistance) {
  write_file(path("bowtie.obj"), "v 0 0 0\nv 3 0 0\nv 0 4 0\nv -2 0 0\nv 0 0 -1\nf 1 2 3\nf 1 4 5\n");
  for (const auto& [source, along_edge] : {std::pair{1, 3.0}, {2, 4.0}, {3, 2.0}, {4, 1.0}}) {
    SCOPED_TRACE(testing::Message() << "source " << source);
    const std::string mesh_and_source = arg("bowtie.obj") + " --source " + std::to_string(source);
    const RunResult result =
        run("distance " + mesh_and_source + " --targets 0 --target-out " + arg("t.txt") + " --out " + arg("d.txt"));
    ASSERT_EQ(result.exit_code, 0) << result.err;
    EXPECT_NEAR(parse_txt(path("t.txt")).at(0), along_edge, 1e-15 * along_edge);
    EXPECT_EQ(parse_txt(path("t.txt")).at(0), parse_txt(path("d.txt")).at(0));
    ASSERT_EQ(run("path " + mesh_and_source + " --target 0 --out " + arg("p.json")).exit_code, 0);
    const nlohmann::json path_json = nlohmann::json::parse(read_file(path("p.json")));
    EXPECT_NEAR(path_json["length"].get<double>(), along_edge, 1e-15 * along_edge);
    EXPECT_EQ(path_json["locations"].back()["vertex"], 0);
  }
}

// Reads a 2-D little-endian float64 .npy (rows x columns).
std::vector<double> parse_npy_matrix(const fs::path& path, std::size_t rows, std::size_t columns) {
  const std::string bytes = read_file(path);
  const std::size_t header_length = std::uint8_t(bytes[8]) | std::size_t(std::uint8_t(bytes[9])) << 8;
  const std::string header = bytes.substr(10, header_length);
  EXPECT_NE(header.find("'shape': (" + std::to_string(rows) + ", " + std::to_string(columns) + ")"), std::string::npos)
      << header;
  EXPECT_EQ(bytes.size(), 10 + header_length + rows * columns * 8);
  std::vector<double> values(rows * columns);
  for (std::size_t i = 0; i < values.size() && 10 + header_length + 8 * i + 8 <= bytes.size(); ++i) {
    std::uint64_t bits = 0;
    for (std::size_t byte = 0; byte < 8; ++byte)
      bits |= std::uint64_t(std::uint8_t(bytes[10 + header_length + 8 * i + byte])) << (8 * byte);
    values[i] = std::bit_cast<double>(bits);
  }
  return values;
}

TEST_F(Cli, MatrixRowsAreDistanceRunsInEveryFormat) {
  write_file(path("sources.txt"), "0\n17;200 5\n");
  ASSERT_EQ(run("matrix @torus:24:10 --sources " + arg("sources.txt") + " --threads 2 --out " + arg("m.npy")).exit_code, 0);
  const std::vector<std::uint32_t> sources = {0, 17, 200, 5};
  const std::size_t n = 240;
  const std::vector<double> matrix = parse_npy_matrix(path("m.npy"), sources.size(), n);
  for (std::size_t i = 0; i < sources.size(); ++i) {
    ASSERT_EQ(run("distance @torus:24:10 --source " + std::to_string(sources[i]) + " --out " + arg("d.npy")).exit_code, 0);
    const std::vector<double> row = parse_npy(path("d.npy"));
    expect_bitwise_equal(std::vector<double>(matrix.begin() + i * n, matrix.begin() + (i + 1) * n), row);
  }
  // With a cut-off: the CSV holds exactly the finite entries of the dense matrix.
  ASSERT_EQ(run("matrix @torus:24:10 --sources 0,17,200,5 --max-distance 1.5 --out " + arg("m.csv")).exit_code, 0);
  ASSERT_EQ(run("matrix @torus:24:10 --sources 0,17,200,5 --max-distance 1.5 --out " + arg("cut.npy")).exit_code, 0);
  const std::vector<double> cut = parse_npy_matrix(path("cut.npy"), sources.size(), n);
  std::istringstream rows(read_file(path("m.csv")));
  std::string line;
  std::getline(rows, line);
  EXPECT_EQ(line, "source,vertex,distance");
  std::size_t finite = 0;
  for (double d : cut) finite += std::isfinite(d);
  std::size_t listed = 0;
  while (std::getline(rows, line)) {
    std::size_t source = 0, vertex = 0;
    double d = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%zu,%zu,%lf", &source, &vertex, &d), 3) << line;
    EXPECT_EQ(d, cut[source * n + vertex]) << line;
    EXPECT_LE(d, 1.5);
    ++listed;
  }
  EXPECT_EQ(listed, finite);
  EXPECT_LT(finite, cut.size());
  // .npz: a zip archive with scipy's CSR members.
  ASSERT_EQ(run("matrix @torus:24:10 --sources 0,17 --max-distance 1.5 --out " + arg("m.npz")).exit_code, 0);
  const std::string npz = read_file(path("m.npz"));
  EXPECT_EQ(npz.rfind("PK", 0), 0u);
  for (const char* member : {"indices.npy", "indptr.npy", "format.npy", "shape.npy", "data.npy"})
    EXPECT_NE(npz.find(member), std::string::npos) << member;
}

TEST_F(Cli, SampleSpreadsOutFromTheFirstVertex) {
  const RunResult printed = run("sample @icosphere:2 -k 6 --first 3");
  ASSERT_EQ(printed.exit_code, 0) << printed.err;
  std::istringstream lines(printed.out);
  std::vector<int> samples;
  for (int v; lines >> v;) samples.push_back(v);
  ASSERT_EQ(samples.size(), 6u);
  EXPECT_EQ(samples[0], 3);
  ASSERT_EQ(run("sample @icosphere:2 -k 6 --first 3 --out " + arg("s.csv")).exit_code, 0);
  std::istringstream rows(read_file(path("s.csv")));
  std::string line;
  std::getline(rows, line);
  EXPECT_EQ(line, "sample,vertex,radius");
  double previous = kInf;
  for (std::size_t i = 0; std::getline(rows, line); ++i) {
    std::size_t index = 0;
    int vertex = 0;
    char radius[64] = {};
    ASSERT_EQ(std::sscanf(line.c_str(), "%zu,%d,%63s", &index, &vertex, radius), 3) << line;
    EXPECT_EQ(vertex, samples[i]);
    const double r = std::strtod(radius, nullptr);
    EXPECT_LE(r, previous) << "radii shrink";
    previous = r;
  }
  // The second sample on a sphere is the antipode: half the great circle, a bit less on the polyhedron.
  EXPECT_LT(previous, kInf);
  expect_error(run("sample @icosphere:2 -k 3 --first 9999"), 2, "9999");
  expect_error(run("sample @icosphere:2 -k 3 --first 1 x"), 1, "'x' is not a vertex index");
  // Several first samples, taken in their order, MESH before or after.
  const RunResult seeded = run("sample --first 7 3 @icosphere:2 -k 4");
  ASSERT_EQ(seeded.exit_code, 0) << seeded.err;
  EXPECT_EQ(seeded.out.rfind("7\n3\n", 0), 0u) << seeded.out;
  EXPECT_EQ(run("sample @icosphere:2 -k 4 --first 7 --first 3").out, seeded.out);
  expect_error(run("sample @icosphere:2 -k -1"), 1, "-1");  // not every vertex, as a wrapped count would give
  expect_error(run("sample @icosphere:2 -k 3 --out " + arg("s.ply")), 1, "s.ply");  // not text under a .ply name
  expect_error(run("matrix @icosphere:2 --sources 1 --threads -2 --out " + arg("m.npy")), 1, "-2");
  expect_error(run("matrix @icosphere:2 --sources 1,x --out " + arg("m.npy")), 2, "'x'");
  expect_error(run("matrix @icosphere:2 --sources 1 --out " + arg("m.txt")), 1, "m.txt");
}

// Everything is checked before an output is touched, and files are written beside their destination and
// renamed when complete: a failed run leaves an existing file as it was and no temporary file behind.
TEST_F(Cli, FailedRunsLeaveExistingOutputsUntouched) {
  const std::string kept = "an earlier result\n";
  for (const char* name : {"d.txt", "d.npy", "d.ply", "m.npy", "m.npz", "m.csv", "p.json", "s.csv"}) write_file(path(name), kept);
  expect_error(run("distance @icosphere:2 --source 9999 --out " + arg("d.txt")), 2, "9999");
  expect_error(run("distance @icosphere:2 --source 0 --targets 9999 --out " + arg("d.npy")), 2, "9999");
  expect_error(run("distance @icosphere:2 --source 0 --source-point 999:0.2,0.3,0.5 --out " + arg("d.ply")), 2, "999");
  for (const char* name : {"m.npy", "m.npz", "m.csv"})
    expect_error(run("matrix @icosphere:2 --sources 1,2,9999 --out " + arg(name)), 2, "9999");
  expect_error(run("path @icosphere:2 --source 0 --target 9999 --out " + arg("p.json")), 2, "9999");
  expect_error(run("sample @icosphere:2 -k 3 --first 9999 --out " + arg("s.csv")), 2, "9999");
  for (const char* name : {"d.txt", "d.npy", "d.ply", "m.npy", "m.npz", "m.csv", "p.json", "s.csv"})
    EXPECT_EQ(read_file(path(name)), kept) << name;
  for (const auto& entry : fs::directory_iterator(path("")))
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
}

// SIGINT, SIGTERM or SIGHUP in the middle of a run ends it at once, as the signal would, and removes the
// unfinished output: nothing is left that could be loaded as a result.
TEST_F(Cli, InterruptedRunsLeaveNoOutput) {
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    std::string sources;
    for (int s = 0; s < 2000; ++s) sources += (s ? "," : "") + std::to_string(s);
    const std::string out = path("m.npy").string();
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      std::freopen("/dev/null", "w", stderr);
      ::execl(EXACTGEO_CLI_PATH, "exactgeo", "matrix", "@icosphere:6", "--sources", sources.c_str(), "--threads", "1",
              "--out", out.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    // Interrupt once the output is being written (the temporary file exists), at most after 60 s.
    const auto partial_exists = [&] {
      for (const auto& entry : fs::directory_iterator(path("")))
        if (entry.path().filename().string().find(".partial") != std::string::npos) return true;
      return false;
    };
    for (int waited = 0; waited < 6000 && !partial_exists(); ++waited) ::usleep(10000);
    EXPECT_TRUE(partial_exists()) << "the run never started writing";
    ::kill(child, signal_number);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number) << "signal " << signal_number;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(partial_exists()) << "signal " << signal_number;
  }
}

// A sparse matrix's memory stays at a block of rows, not the whole result: 6,000 rows of 642 vertices with
// every entry finite are 46 MB of CSR data, written through temporary files; the peak stays far below.
TEST_F(Cli, NpzMatricesStreamThroughABlockOfRows) {
  std::string sources;
  for (int s = 0; s < 6000; ++s) sources += (s ? "," : "") + std::to_string(s % 642);
  const std::string out = path("m.npz").string();
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::execl(EXACTGEO_CLI_PATH, "exactgeo", "matrix", "@icosphere:3", "--sources", sources.c_str(), "--max-distance",
            "100", "--threads", "2", "--quiet", "--out", out.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  struct rusage usage {};
  ASSERT_EQ(::wait4(child, &status, 0, &usage), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  constexpr long kWholeResultKilobytes = 6000L * 642 * 12 / 1024;
  EXPECT_LT(usage.ru_maxrss, kWholeResultKilobytes / 3) << "peak resident kilobytes";
  const std::string npz = read_file(out);
  EXPECT_GT(npz.size(), 6000u * 642 * 12);  // every entry is there
}

// The samples file is a sources file: matrix --sources reads the vertex column of sample's CSV.
TEST_F(Cli, MatrixReadsTheSamplesThatSampleWrites) {
  ASSERT_EQ(run("sample @icosphere:2 -k 4 --out " + arg("s.csv")).exit_code, 0);
  ASSERT_EQ(run("sample @icosphere:2 -k 4 --out " + arg("s.txt")).exit_code, 0);
  ASSERT_EQ(run("matrix @icosphere:2 --sources " + arg("s.csv") + " --out " + arg("from-csv.npy")).exit_code, 0);
  ASSERT_EQ(run("matrix @icosphere:2 --sources " + arg("s.txt") + " --out " + arg("from-txt.npy")).exit_code, 0);
  EXPECT_EQ(read_file(path("from-csv.npy")), read_file(path("from-txt.npy")));
  write_file(path("bad.csv"), "sample,vertex,radius\n0,0,inf\n1,x,2\n");
  expect_error(run("matrix @icosphere:2 --sources " + arg("bad.csv") + " --out " + arg("m.npy")), 2, "line 3: 'x'");
}

// A .npy file of `values` stored as `descr` ("<i2", ">u8", "|u1", ...), laid out as numpy.save lays it: the
// preamble, the header padded to 64 bytes, then each value's low bytes in the descr's byte order.
std::string npy_file(const std::string& descr, const std::vector<std::int64_t>& values, std::string shape = "") {
  if (shape.empty()) shape = "(" + std::to_string(values.size()) + ",)";
  std::string header = "{'descr': '" + descr + "', 'fortran_order': False, 'shape': " + shape + ", }";
  header.append((64 - (10 + header.size() + 1) % 64) % 64, ' ');
  header += '\n';
  std::string bytes =
      std::string("\x93NUMPY\x01\x00", 8) + char(header.size() & 0xff) + char(header.size() >> 8) + header;
  const bool big_endian = descr[0] == '>';
  const std::size_t size = std::stoul(descr.substr(2));
  for (const std::int64_t value : values)
    for (std::size_t k = 0; k < size; ++k)
      bytes += char(static_cast<std::uint64_t>(value) >> (8 * (big_endian ? size - 1 - k : k)));
  return bytes;
}

// Whether a message holds only printable ASCII and newlines: nothing of a binary file reaches the terminal.
bool printable(const std::string& message) {
  return std::all_of(message.begin(), message.end(), [](char c) { return c == '\n' || (c >= 0x20 && c < 0x7f); });
}

// matrix --sources and --targets and distance --targets read .npy arrays of every integer dtype, in either
// byte order, as the text list of the same indices.
TEST_F(Cli, ListFilesAreNpyArraysOfAnyIntegerDtype) {
  const std::vector<std::int64_t> sources = {0, 17, 100, 5};
  const std::vector<std::int64_t> targets = {33, 2, 17};
  ASSERT_EQ(run("matrix @torus:24:10 --sources 0 17 100 5 --targets 33,2,17 --out " + arg("text.npy")).exit_code, 0);
  ASSERT_EQ(run("distance @torus:24:10 --source 3 --targets 33,2,17 --target-out " + arg("text.csv")).exit_code, 0);
  for (const char* type : {"i1", "i2", "i4", "i8", "u1", "u2", "u4", "u8"})
    for (const char order : {'<', '>'}) {
      const std::string descr = (type[1] == '1' ? '|' : order) + std::string(type);
      write_file(path("s.npy"), npy_file(descr, sources));
      write_file(path("t.npy"), npy_file(descr, targets));
      RunResult result = run("matrix @torus:24:10 --sources " + arg("s.npy") + " --targets " + arg("t.npy") +
                             " --quiet --out " + arg("m.npy"));
      ASSERT_EQ(result.exit_code, 0) << descr << ": " << result.err;
      EXPECT_EQ(read_file(path("m.npy")), read_file(path("text.npy"))) << descr;
      result = run("distance @torus:24:10 --source 3 --targets " + arg("t.npy") + " --target-out " + arg("t.csv"));
      ASSERT_EQ(result.exit_code, 0) << descr << ": " << result.err;
      EXPECT_EQ(read_file(path("t.csv")), read_file(path("text.csv"))) << descr;
    }
  // Version 2.0 files (a 4-byte header length), as numpy.save writes for huge headers.
  std::string version2 = npy_file("<i4", sources);
  version2 = std::string("\x93NUMPY\x02\x00", 8) + version2.substr(8, 2) + std::string(2, '\0') + version2.substr(10);
  write_file(path("v2.npy"), version2);
  ASSERT_EQ(run("matrix @torus:24:10 --sources " + arg("v2.npy") + " --targets 33 2 17 --quiet --out " + arg("m.npy"))
                .exit_code,
            0);
  EXPECT_EQ(read_file(path("m.npy")), read_file(path("text.npy")));
}

// What sample writes, matrix reads: its .npy, and its output on stdin through a pipe (CSV) or a redirect.
// distance --targets reads stdin too.
TEST_F(Cli, SamplesReachMatrixAsNpyAndThroughStandardInput) {
  ASSERT_EQ(run("sample @icosphere:2 -k 6 --out " + arg("s.npy")).exit_code, 0);
  ASSERT_EQ(run("sample @icosphere:2 -k 6 --out " + arg("s.txt")).exit_code, 0);
  ASSERT_EQ(run("matrix @icosphere:2 --sources " + arg("s.txt") + " --quiet --out " + arg("expected.npy")).exit_code,
            0);
  RunResult result = run("matrix @icosphere:2 --sources " + arg("s.npy") + " --quiet --out " + arg("m.npy"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(read_file(path("m.npy")), read_file(path("expected.npy")));
  for (const char* name : {"s.npy", "s.txt"}) {
    result = run("matrix @icosphere:2 --sources - --quiet --out " + arg("m.npy") + " < " + arg(name));
    ASSERT_EQ(result.exit_code, 0) << name << ": " << result.err;
    EXPECT_EQ(read_file(path("m.npy")), read_file(path("expected.npy"))) << name;
  }
  const std::string pipeline = "cd '" + path("").string() + "' && '" EXACTGEO_CLI_PATH
                               "' sample @icosphere:2 -k 6 --out - --quiet | '" EXACTGEO_CLI_PATH
                               "' matrix @icosphere:2 --sources - --quiet --out piped.npy 2>err";
  ASSERT_EQ(std::system(pipeline.c_str()), 0) << read_file(path("err"));
  EXPECT_EQ(read_file(path("piped.npy")), read_file(path("expected.npy")));
  // distance --targets takes sample's CSV too, piped in.
  ASSERT_EQ(run("distance @icosphere:2 --source 0 --targets " + arg("s.txt") + " --target-out " + arg("s.csv")).exit_code,
            0);
  const std::string sampled_targets = "cd '" + path("").string() + "' && '" EXACTGEO_CLI_PATH
                                      "' sample @icosphere:2 -k 6 --out - --quiet | '" EXACTGEO_CLI_PATH
                                      "' distance @icosphere:2 --source 0 --targets - --target-out piped.csv 2>err";
  ASSERT_EQ(std::system(sampled_targets.c_str()), 0) << read_file(path("err"));
  EXPECT_EQ(read_file(path("piped.csv")), read_file(path("s.csv")));
  write_file(path("targets.txt"), "5\n9;3:0.2,0.3,0.5\n");
  const std::string targets_to_csv = "distance @icosphere:2 --source 0 --targets " + arg("targets.txt");
  ASSERT_EQ(run(targets_to_csv + " --target-out " + arg("t.csv")).exit_code, 0);
  result = run("distance @icosphere:2 --source 0 --targets - --target-out - < " + arg("targets.txt"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.out, read_file(path("t.csv")));
}

// Lists that cannot be read are named, with the element at fault, and nothing of a binary file is printed.
TEST_F(Cli, BadListFilesAreNamedWithTheElementAndNoBinary) {
  const auto expect_list_error = [&](const std::string& file, const std::string& bytes, const std::string& expected) {
    write_file(path(file), bytes);
    for (const std::string command : {"matrix @icosphere:2 --sources " + arg(file) + " --out " + arg("m.npy"),
                                      "matrix @icosphere:2 --sources - --out " + arg("m.npy") + " < " + arg(file)}) {
      const RunResult result = run(command);
      expect_error(result, 2, expected);
      EXPECT_TRUE(printable(result.err)) << result.err;
      EXPECT_FALSE(fs::exists(path("m.npy")));
    }
    const RunResult result = run("distance @icosphere:2 --source 0 --targets " + arg(file));
    expect_error(result, 2, expected);
    EXPECT_NE(result.err.find(file), std::string::npos) << result.err;
  };
  expect_list_error("float.npy", npy_file("<f8", {0, 0x3ff0000000000000}),
                    "holds float64 values; indices must be integers");
  expect_list_error("bool.npy", npy_file("|b1", {1, 0}), "holds bool values");
  expect_list_error("two.npy", npy_file("<i4", {1, 2, 3, 4}, "(2, 2)"),
                    "array of shape (2, 2); indices must be a 1-D array");
  expect_list_error("negative.npy", npy_file("|i1", {3, -1}), "element [1] is -1, not an index");
  expect_list_error("negative64.npy", npy_file(">i8", {3, 4, -5}), "element [2] is -5, not an index");
  expect_list_error("huge.npy", npy_file("<u8", {std::int64_t{1} << 40}), "element [0] is 1099511627776, not an index");
  expect_list_error("beyond.npy", npy_file("<u2", {1, 2, 500}),
                    "element [2]: vertex 500 is out of range (mesh has 162 vertices)");
  const std::string three = npy_file("<i8", {1, 2, 3});
  expect_list_error("short.npy", three.substr(0, three.size() - 4),
                    "the header says 3 values of 8 bytes, but 20 bytes");
  expect_list_error("empty.npy", npy_file("<i8", {}), "no ");
  expect_list_error("records.npy", npy_file("<i8", {1}).replace(10, 17, "{'descr': [('a', '<i8')], "), "records");
  std::string garbage;
  for (int byte = 0; byte < 256; ++byte) garbage += char(byte);
  expect_list_error("garbage.bin", garbage, "binary data, not a list");
  expect_list_error("text.txt", "0 1 \xff\xfe\x9b", "'\\xFF\\xFE\\x9B'");
  // A text file named .npy is taken for a damaged .npy, not for a list.
  write_file(path("named.npy"), "0 1 2\n");
  expect_error(run("matrix @icosphere:2 --sources " + arg("named.npy") + " --out " + arg("m.npy")), 2,
               "not a .npy file");
  expect_error(run("matrix @icosphere:2 --sources missing.npy --out " + arg("m.npy")), 2,
               "cannot read 'missing.npy': no such file");
  // Standard input feeds one list.
  expect_error(run("matrix @icosphere:2 --sources - --targets - --out " + arg("m.npy") + " < /dev/null"), 1,
               "standard input (-) can feed one list");
  expect_error(run("matrix @icosphere:2 --sources - --out " + arg("m.npy") + " < /dev/null"), 2,
               "(standard input): no vertex given");
}

// --source, --source-point, --targets and matrix's --sources and --targets take several values, or repeat;
// MESH may come before them or after.
TEST_F(Cli, ListOptionsTakeSeveralValuesOrRepeat) {
  ASSERT_EQ(run("distance @torus:24:10 --source 0 --source 111 --labels --out " + arg("repeated.npy")).exit_code, 0);
  for (const std::string form : {"@torus:24:10 --source 0 111 --labels --out " + arg("x.npy"),
                                 "--source 0 111 @torus:24:10 --labels --out " + arg("x.npy"),
                                 "--labels --source 0 111 @torus:24:10 --out " + arg("x.npy")}) {
    const RunResult result = run("distance " + form);
    ASSERT_EQ(result.exit_code, 0) << form << ": " << result.err;
    EXPECT_EQ(read_file(path("x.npy")), read_file(path("repeated.npy"))) << form;
  }
  // Points and targets the same way.
  const std::string points = "--source-point 3:0.2,0.3,0.5 17:0.1,0.1,0.8";
  ASSERT_EQ(run("distance @torus:24:10 " + points + " --targets 5 6,7 --target-out " + arg("a.csv")).exit_code, 0);
  ASSERT_EQ(run("distance @torus:24:10 --source-point 3:0.2,0.3,0.5 --source-point 17:0.1,0.1,0.8 --targets '5 6,7' "
                "--target-out " + arg("b.csv")).exit_code, 0);
  ASSERT_EQ(run("distance " + points + " --targets 5 6 7 @torus:24:10 --target-out " + arg("c.csv")).exit_code, 0);
  EXPECT_EQ(read_file(path("a.csv")), read_file(path("b.csv")));
  EXPECT_EQ(read_file(path("a.csv")), read_file(path("c.csv")));
  // path and matrix.
  ASSERT_EQ(run("path @grid:4:4 --source 0 24 --target 12 --out " + arg("p1.json")).exit_code, 0);
  ASSERT_EQ(run("path --source 0 --source 24 @grid:4:4 --target 12 --out " + arg("p2.json")).exit_code, 0);
  EXPECT_EQ(read_file(path("p1.json")), read_file(path("p2.json")));
  ASSERT_EQ(run("matrix @icosphere:2 --sources 0 5 --sources 9 --out " + arg("m1.npy")).exit_code, 0);
  ASSERT_EQ(run("matrix --sources 0,5 9 @icosphere:2 --out " + arg("m2.npy")).exit_code, 0);
  EXPECT_EQ(read_file(path("m1.npy")), read_file(path("m2.npy")));
  // Still errors: no MESH, a value that is not a vertex.
  expect_error(run("distance --source 0 111"), 1, "MESH");
  expect_error(run("distance @grid:4:4 --source 0 x"), 1, "'x' is not a vertex index");
  expect_error(run("distance @grid:4:4 --source-point 0:1,0,0 9"), 1, "'9' is not a surface point");
  expect_error(run("distance @nothing --source 0"), 1, "unknown built-in mesh");
  expect_error(run("matrix @grid:4:4 --out " + arg("m.npy")), 1, "--sources");
}

// --out - writes CSV to stdout, with nothing else on it: the summary is left out, messages and progress go
// to stderr. Every command with a CSV format takes it.
TEST_F(Cli, OutDashWritesCsvToStdoutAlone) {
  ASSERT_EQ(run("distance @icosphere:2 --source 3 --labels --out " + arg("d.csv")).exit_code, 0);
  RunResult result = run("distance @icosphere:2 --source 3 --labels --out -");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.out, read_file(path("d.csv")));
  EXPECT_EQ(result.err, "");
  ASSERT_EQ(run("distance @icosphere:2 --source 3 --targets 5 9 --target-out " + arg("t.csv")).exit_code, 0);
  result = run("distance @icosphere:2 --source 3 --targets 5 9 --target-out -");
  EXPECT_EQ(result.out, read_file(path("t.csv")));
  for (const std::string command : {"matrix @icosphere:2 --sources 0 5 --targets 7 9 --out ", "sample @icosphere:2 -k 4 --out ",
                                     "path @grid:4:4 --source 0 --target 24 --out "}) {
    ASSERT_EQ(run(command + arg("x.csv")).exit_code, 0) << command;
    result = run(command + "-");
    ASSERT_EQ(result.exit_code, 0) << command << result.err;
    EXPECT_EQ(result.out, read_file(path("x.csv"))) << command;
    EXPECT_EQ(result.err, "") << command;
  }
  // Through a pipe, as a shell script uses it: the farthest vertex, and no stray output file named "-".
  const std::string pipeline = "cd '" + path("").string() + "' && '" EXACTGEO_CLI_PATH
                               "' distance @icosphere:2 --source 3 --out - 2>err | tail -n +2 | sort -t, -k2 -g | tail -1 >farthest";
  ASSERT_EQ(std::system(pipeline.c_str()), 0);
  EXPECT_EQ(read_file(path("err")), "");
  const std::string farthest = read_file(path("farthest"));
  ASSERT_EQ(run("distance @icosphere:2 --source 3 --out " + arg("plain.csv")).exit_code, 0);
  const std::vector<double> d = parse_csv(path("plain.csv"));
  EXPECT_EQ(std::strtod(farthest.c_str() + farthest.find(',') + 1, nullptr), *std::max_element(d.begin(), d.end()));
  EXPECT_FALSE(fs::exists(path("-")));
  // Binary formats need a file; two outputs cannot share stdout.
  expect_error(run("distance @icosphere:2 --source 3 --out - --target-out - --targets 5"), 1, "both");
  expect_error(run("matrix @icosphere:2 --sources 0 --out x.npz -"), 1, "");
}

// matrix --targets: the targets' columns of the full matrix, bit for bit; the .npz names the rows' and
// columns' vertices; targets come from lists, files, or sample's CSV.
TEST_F(Cli, MatrixTargetsAreColumnsOfTheFullMatrix) {
  const std::vector<std::uint32_t> sources = {0, 17, 200, 5};
  const std::vector<std::uint32_t> targets = {33, 2, 17, 100};
  ASSERT_EQ(run("matrix @torus:24:10 --sources 0 17 200 5 --out " + arg("full.npy")).exit_code, 0);
  ASSERT_EQ(run("matrix @torus:24:10 --sources 0 17 200 5 --targets 33,2 17 --targets 100 --threads 2 --out " +
                arg("block.npy")).exit_code, 0);
  const std::size_t n = 240;
  const std::vector<double> full = parse_npy_matrix(path("full.npy"), sources.size(), n);
  const std::vector<double> block = parse_npy_matrix(path("block.npy"), sources.size(), targets.size());
  for (std::size_t i = 0; i < sources.size(); ++i)
    for (std::size_t t = 0; t < targets.size(); ++t)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(block[i * targets.size() + t]),
                std::bit_cast<std::uint64_t>(full[i * n + targets[t]])) << i << " " << t;
  // CSV: row and column numbers.
  const RunResult csv = run("matrix @torus:24:10 --sources 0 17 200 5 --targets 33 2 17 100 --max-distance 2 --out -");
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  std::istringstream rows(csv.out);
  std::string line;
  std::getline(rows, line);
  EXPECT_EQ(line, "source,target,distance");
  while (std::getline(rows, line)) {
    std::size_t source = 0, target = 0;
    double d = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%zu,%zu,%lf", &source, &target, &d), 3) << line;
    EXPECT_EQ(d, full[source * n + targets[target]]) << line;
    EXPECT_LE(d, 2);
  }
  // .npz: the CSR members, sources, and targets only when given.
  ASSERT_EQ(run("matrix @torus:24:10 --sources 0 17 --targets 33 2 --out " + arg("t.npz")).exit_code, 0);
  ASSERT_EQ(run("matrix @torus:24:10 --sources 0 17 --out " + arg("s.npz")).exit_code, 0);
  EXPECT_NE(read_file(path("t.npz")).find("sources.npy"), std::string::npos);
  EXPECT_NE(read_file(path("t.npz")).find("targets.npy"), std::string::npos);
  EXPECT_NE(read_file(path("s.npz")).find("sources.npy"), std::string::npos);
  EXPECT_EQ(read_file(path("s.npz")).find("targets.npy"), std::string::npos);
  // sample's CSV as targets.
  ASSERT_EQ(run("sample @torus:24:10 -k 4 --out " + arg("s.csv")).exit_code, 0);
  ASSERT_EQ(run("sample @torus:24:10 -k 4 --out " + arg("s.txt")).exit_code, 0);
  ASSERT_EQ(run("matrix @torus:24:10 --sources 0 --targets " + arg("s.csv") + " --out " + arg("a.npy")).exit_code, 0);
  ASSERT_EQ(run("matrix @torus:24:10 --sources 0 --targets " + arg("s.txt") + " --out " + arg("b.npy")).exit_code, 0);
  EXPECT_EQ(read_file(path("a.npy")), read_file(path("b.npy")));
  expect_error(run("matrix @torus:24:10 --sources 0 --targets 3,99999 --out " + arg("m.npy")), 2, "99999");
  EXPECT_FALSE(fs::exists(path("m.npy")));
}

// --targets-beyond exact: targets beyond --max-distance get their exact distance (as gdist and pygeodesic
// answer), vertices beyond it still inf; the default gives them inf.
TEST_F(Cli, TargetsBeyondTheCutOff) {
  const std::string run_base = "distance @grid:8:8 --source 0 --targets 10 80 --max-distance 3";
  ASSERT_EQ(run(run_base + " --target-out " + arg("inf.csv")).exit_code, 0);
  ASSERT_EQ(run(run_base + " --targets-beyond exact --target-out " + arg("exact.csv") + " --out " + arg("d.npy")).exit_code, 0);
  EXPECT_EQ(read_file(path("inf.csv")), "target,distance\n0,1.4142135623730951\n1,inf\n");
  EXPECT_EQ(read_file(path("exact.csv")), "target,distance\n0,1.4142135623730951\n1,11.313708498984759\n");
  const std::vector<double> d = parse_npy(path("d.npy"));
  for (std::size_t v = 0; v < d.size(); ++v) {
    const double truth = std::hypot(double(v % 9), double(v / 9));
    if (truth <= 3) EXPECT_NEAR(d[v], truth, 1e-12) << v;
    else EXPECT_TRUE(std::isinf(d[v])) << v;
  }
  expect_error(run(run_base + " --targets-beyond sometimes"), 1, "sometimes");
}

// `locate` on a flat grid: the closest point of a point above it is straight below, of one beside it on
// the border; the .txt output is what --targets reads, the same targets as --target-xyz.
TEST_F(Cli, LocateFindsTheClosestSurfacePoints) {
  write_file(path("points.csv"), "x,y,z\n1.5,2.25,3\n-1 0.5 0\n");
  const RunResult csv = run("locate @grid:4:4 --points " + arg("points.csv") + " 4,4,-2 --out " + arg("l.csv"));
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  EXPECT_EQ(csv.out, "");
  const std::vector<std::array<double, 4>> expected = {{1.5, 2.25, 0, 3}, {0, 0.5, 0, 1}, {4, 4, 0, 2}};
  std::istringstream rows(read_file(path("l.csv")));
  std::string line;
  std::getline(rows, line);
  EXPECT_EQ(line, "point,face,b0,b1,b2,x,y,z,distance");
  const exactgeo::MeshSoup grid = exactgeo::make_grid(4, 4, 4, 4);
  std::size_t count = 0;
  for (; std::getline(rows, line); ++count) {
    ASSERT_LT(count, expected.size()) << line;
    std::size_t index = 0;
    unsigned face = 0;
    std::array<double, 3> b{}, x{};
    double distance = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%zu,%u,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &index, &face, &b[0], &b[1], &b[2], &x[0],
                          &x[1], &x[2], &distance),
              9)
        << line;
    EXPECT_EQ(index, count);
    for (int axis = 0; axis < 3; ++axis) {
      double from_face = 0;
      for (int k = 0; k < 3; ++k) from_face += b[k] * grid.positions[3 * grid.triangles[3 * face + k] + axis];
      EXPECT_NEAR(from_face, expected[count][axis], 1e-15) << line;
      EXPECT_NEAR(x[axis], expected[count][axis], 1e-15) << line;
    }
    EXPECT_NEAR(distance, expected[count][3], 1e-15) << line;
  }
  EXPECT_EQ(count, expected.size());
  // Without --out, the CSV on stdout.
  const RunResult printed = run("locate @grid:4:4 --points " + arg("points.csv") + " 4,4,-2");
  EXPECT_EQ(printed.exit_code, 0) << printed.err;
  EXPECT_EQ(printed.out, read_file(path("l.csv")));
  // As .txt, targets for `distance`: the same distances as the points in space as --target-xyz.
  ASSERT_EQ(run("locate @grid:4:4 --points " + arg("points.csv") + " --out " + arg("l.txt")).exit_code, 0);
  const std::string distance = "distance @grid:4:4 --source 0 ";
  ASSERT_EQ(run(distance + "--targets " + arg("l.txt") + " --target-out " + arg("t1.txt")).exit_code, 0);
  ASSERT_EQ(run(distance + "--target-xyz " + arg("points.csv") + " --target-out " + arg("t2.txt")).exit_code, 0);
  expect_bitwise_equal(parse_txt(path("t1.txt")), parse_txt(path("t2.txt")));
  EXPECT_NEAR(parse_txt(path("t1.txt"))[0], std::hypot(1.5, 2.25), 1e-12);
}

TEST_F(Cli, SourcesAndTargetsInSpace) {
  // Sources and targets at the closest points of points off a flat grid: distances are straight lines
  // between the points below them. Located targets come after --targets, located sources after the others.
  const RunResult run_result = run("distance @grid:4:4 --source-xyz 0,0,5 --targets 24 --target-xyz 4,4,-1 "
                                   "'2,0,1;0,3,0' --target-out " + arg("t.txt"));
  ASSERT_EQ(run_result.exit_code, 0) << run_result.err;
  const std::vector<double> t = parse_txt(path("t.txt"));
  ASSERT_EQ(t.size(), 4u);
  EXPECT_NEAR(t[0], 4 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(t[1], 4 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(t[2], 2, 1e-12);
  EXPECT_NEAR(t[3], 3, 1e-12);
  ASSERT_EQ(run("distance @grid:4:4 --source 24 --source-xyz -1,-1,0 --labels --out " + arg("d.csv")).exit_code, 0);
  EXPECT_NE(read_file(path("d.csv")).find("\n0,0,1\n"), std::string::npos);  // vertex 0 is source 1's own point
  // A path to a point in space ends at its closest point.
  ASSERT_EQ(run("path @grid:4:4 --source 0 --target-xyz 4,4,7 --out " + arg("p.json")).exit_code, 0);
  const nlohmann::json path_json = nlohmann::json::parse(read_file(path("p.json")));
  EXPECT_NEAR(path_json["length"].get<double>(), 4 * std::sqrt(2.0), 1e-12);
  EXPECT_EQ(path_json["locations"].back()["vertex"], 24);
}

TEST_F(Cli, BadPointsInSpace) {
  expect_error(run("locate @grid:4:4 --points 1,2"), 2, "--points: '1,2' is not a point X,Y,Z");
  expect_error(run("locate @grid:4:4 --points 1,2,3,4"), 2, "--points: '1,2,3,4' is not a point X,Y,Z");
  expect_error(run("locate @grid:4:4 --points 0,0,0 1,nan,0"), 2, "--points: point 1 has a non-finite coordinate");
  expect_error(run("distance @grid:4:4 --source 0 --target-xyz 'a,b,c'"), 2, "--target-xyz: no point given");
  expect_error(run("distance @grid:4:4 --source-xyz 0,0,x"), 2, "--source-xyz: '0,0,x' is not a point X,Y,Z");
  expect_error(run("path @grid:4:4 --source 0 --target-xyz '1,1,0;2,2,0'"), 2, "--target-xyz takes one point, not 2");
  expect_error(run("locate @grid:4:4"), 1, "--points is required");
  expect_error(run("locate @grid:4:4 --points 0,0,0 --out l.npy"), 1, "must be .txt or .csv");
  expect_error(run("path @grid:4:4 --source 0"), 1, "--target or --target-xyz");
  expect_error(run("path @grid:4:4 --source 0 --target 3 --target-xyz 0,0,0"), 1, "excludes");
}

TEST_F(Cli, BadPointsAndTargetsAreInvalidInput) {
  expect_error(run("distance @grid:4:4 --source-point 99:0.2,0.3,0.5"), 2, "face 99");
  expect_error(run("distance @grid:4:4 --source-point 3:0.2,0.3,0.9"), 2, "not barycentric");
  expect_error(run("distance @grid:4:4 --source 0 --targets 3,x"), 2, "'x'");
  expect_error(run("distance @grid:4:4 --source 0 --targets 500"), 2, "500");
  expect_error(run("path @grid:4:4 --source 0 --target '3;4'"), 2, "one vertex or point");
}

}  // namespace

namespace {

// Under an address-space limit (common on clusters) the system refuses most of 64 threads: the runs go on
// with those it starts and give one thread's answers, instead of waiting forever for threads that never came
// (issue 34). `timeout` turns a hang into a failure.
TEST_F(Cli, RunsGoOnWithTheThreadsTheSystemStarts) {
  ASSERT_EQ(run("distance @grid:30:30 --source 0 --threads 1 --out " + arg("one.txt")).exit_code, 0);
  ASSERT_EQ(run("matrix @grid:30:30 --sources 0 5 --threads 1 --out " + arg("one.csv")).exit_code, 0);
  const auto limited = [&](const std::string& arguments) {
    const std::string command = "(ulimit -v 307200; timeout 120 '" EXACTGEO_CLI_PATH "' " + arguments + ") >/dev/null 2>" +
                                arg("limited.err");
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(limited("distance @grid:30:30 --source 0 --threads 64 --out " + arg("many.txt")), 0)
      << read_file(path("limited.err"));
  const std::vector<double> many = parse_txt(path("many.txt")), one = parse_txt(path("one.txt"));
  ASSERT_EQ(many.size(), one.size());
  const double largest = *std::max_element(one.begin(), one.end());
  for (std::size_t v = 0; v < one.size(); ++v) EXPECT_NEAR(many[v], one[v], 1e-14 * largest) << "vertex " << v;
  EXPECT_EQ(limited("matrix @grid:30:30 --sources 0 5 --threads 64 --out " + arg("many.csv")), 0)
      << read_file(path("limited.err"));
  EXPECT_EQ(read_file(path("many.csv")), read_file(path("one.csv")));
}

// CLI11 stored a count too large for its variable clamped: 2^64 samples ran as 2^64 - 1 and exited 0.
TEST_F(Cli, CountsTooLargeForTheirVariableAreUsageErrors) {
  const RunResult samples = run("sample @icosphere:1 -k 18446744073709551616");
  expect_error(samples, 1, "--count");
  expect_error(samples, 1, "'18446744073709551616' is not a whole number from 0 to 18446744073709551615");
  expect_error(run("distance @icosphere:1 --source 0 --threads 4294967296"), 1, "--threads");
  expect_error(run("matrix @icosphere:1 --sources 0 --threads 4294967296 --out " + arg("m.npy")), 1, "--threads");
}

// info --json and --stats exited 3: nlohmann::json refuses to write a string that is not UTF-8, as a file name
// may be.
TEST_F(Cli, JsonOutputsTakeFileNamesThatAreNotUtf8) {
  write_file(path("seam-\xff.obj"), kSeamObj);
  const std::string replaced = path("seam-\xef\xbf\xbd.obj").string();  // U+FFFD in place of the byte
  const RunResult info = run("info --json " + arg("seam-\xff.obj"));
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_EQ(nlohmann::json::parse(info.out)["mesh"], replaced);
  EXPECT_NE(info.err.find("not UTF-8 has U+FFFD in place of its invalid bytes"), std::string::npos) << info.err;
  const RunResult distance =
      run("distance " + arg("seam-\xff.obj") + " --source 0 --weld --out " + arg("d.txt") + " --stats " + arg("s.json"));
  ASSERT_EQ(distance.exit_code, 0) << distance.err;
  EXPECT_EQ(nlohmann::json::parse(read_file(path("s.json")))["mesh"], replaced);
  EXPECT_NE(distance.err.find("U+FFFD"), std::string::npos) << distance.err;
}

// --out d.csv --target-out d.csv kept one of the two files, without a word.
TEST_F(Cli, OutputsNamingOneFileAreUsageErrors) {
  const std::string run_with = "distance @icosphere:1 --source 0 --targets 3 ";
  expect_error(run(run_with + "--out " + arg("d.csv") + " --target-out " + arg("d.csv")), 1,
               "--out and --target-out both write to");
  expect_error(run(run_with + "--out " + arg("d.csv") + " --stats " + arg("d.csv")), 1, "--out and --stats both write to");
  expect_error(run(run_with + "--target-out " + arg("d.csv") + " --stats '" + (path(".") / "d.csv").string() + "'"), 1,
               "--target-out and --stats both write to");
  fs::create_symlink("d.csv", path("link.csv"));  // to a file not written yet
  expect_error(run(run_with + "--out " + arg("link.csv") + " --stats " + arg("d.csv")), 1, "both write to");
  write_file(path("d.csv"), "kept\n");
  fs::create_hard_link(path("d.csv"), path("hard.csv"));
  expect_error(run(run_with + "--out " + arg("hard.csv") + " --target-out " + arg("d.csv")), 1, "both write to");
  EXPECT_EQ(read_file(path("d.csv")), "kept\n");
  EXPECT_EQ(run(run_with + "--out " + arg("d.csv") + " --target-out " + arg("t.csv")).exit_code, 0);
}

// A FIFO given as --out was replaced by a regular file, and so was a symbolic link, rather than written to.
TEST_F(Cli, OutputsGoIntoFifosAndThroughLinks) {
  ASSERT_EQ(run("distance @icosphere:1 --source 3 --out " + arg("expected.csv")).exit_code, 0);
  const std::string expected = read_file(path("expected.csv"));

  ASSERT_EQ(::mkfifo(path("pipe.csv").c_str(), 0600), 0);
  // The reader gives up after a while: a FIFO that nobody writes to would otherwise hold the test forever.
  const std::string command = "timeout 60 cat " + arg("pipe.csv") + " >" + arg("from-pipe.csv") + " & '" EXACTGEO_CLI_PATH
                              "' distance @icosphere:1 --source 3 --out " + arg("pipe.csv") +
                              " 2>" + arg("err.txt") + "; code=$?; wait; exit $code";
  const int status = std::system(command.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_file(path("err.txt"));
  EXPECT_TRUE(fs::is_fifo(path("pipe.csv")));
  EXPECT_EQ(read_file(path("from-pipe.csv")), expected);

  fs::create_directory(path("real"));
  fs::create_symlink("real/d.csv", path("link.csv"));  // to a file not written yet
  for (int pass = 0; pass < 2; ++pass) {  // then over the file written the first time
    ASSERT_EQ(run("distance @icosphere:1 --source 3 --out " + arg("link.csv")).exit_code, 0);
    EXPECT_TRUE(fs::is_symlink(path("link.csv"))) << "pass " << pass;
    EXPECT_EQ(read_file(path("real/d.csv")), expected) << "pass " << pass;
  }
}

// --algorithm ftp --threads 4 reported 4 threads, in the summary and --stats, while it ran on one.
TEST_F(Cli, SummaryAndStatsGiveTheThreadsTheRunShared) {
  const RunResult ftp =
      run("distance @icosphere:2 --source 0 --quiet --algorithm ftp --threads 4 --stats " + arg("f.json"));
  ASSERT_EQ(ftp.exit_code, 0) << ftp.err;
  EXPECT_EQ(nlohmann::json::parse(read_file(path("f.json")))["threads"], 1);
  // The summary's row: the name, spaces to align the values, the value.
  std::istringstream summary(ftp.out);
  std::string row;
  while (std::getline(summary, row) && !row.starts_with("threads ")) {
  }
  ASSERT_TRUE(row.starts_with("threads ")) << ftp.out;
  EXPECT_EQ(row.substr(row.find_first_not_of(' ', std::string_view("threads").size())), "1") << ftp.out;
  EXPECT_NE(ftp.err.find("note: the run used 1 of the 4 threads asked for: the face-sorted variants"), std::string::npos)
      << ftp.err;

  const RunResult vtp = run("distance @icosphere:2 --source 0 --quiet --threads 2 --stats " + arg("v.json"));
  ASSERT_EQ(vtp.exit_code, 0) << vtp.err;
  EXPECT_EQ(nlohmann::json::parse(read_file(path("v.json")))["threads"], 2);
  EXPECT_EQ(vtp.err, "");
}

}  // namespace
