// The `distance` command end to end: sources and targets of every form, output formats that agree, the
// statistics and timers, variants, seams, cut-offs, and distances on meshes whose answer is known in closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "exactgeo/exactgeo.hpp"
#include "exactgeo/shapes.hpp"

#include "cli_run.hpp"

namespace {

using namespace exactgeo_test;

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
