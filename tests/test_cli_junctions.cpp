// The commands on the junction fuzzing's meshes (bowties, books of pages, sheets with a fin, vertices doubled in
// place: exactgeo_test::random_junction_case) and on height fields with T-junctions closed by slivers and
// near-slivers (random_sliver_case), read from an OBJ file with a vertex no face uses added. What `distance` (targets,
// labels, query points, sources and targets given in space), `pairs`, `matrix` and `path` write is the library's answer
// on the same soup: bit for bit where the library's answer is the same on any thread count (pairs, matrix rows) or the
// command runs one thread, to 1e-14 of the largest distance on two. The fuzzing holds the library to the surface; this
// holds the commands' own reading of vertices, points and lists at split and doubled vertices to the library.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_run.hpp"
#include "exactgeo/exactgeo.hpp"
#include "io_test_files.hpp"
#include "test_meshes.hpp"

namespace {

using namespace exactgeo_test;
using exactgeo::SurfacePoint;

constexpr std::uint64_t kCases = 30;   // seeds 1 to 30: about a second of commands
constexpr double kExact = 1e-14;       // relative to the largest distance, on two threads
constexpr double kPathLength = 1e-12;  // path length against distance, relative (the README's junction promise)

std::string point_text(const SurfacePoint& point) {
  return std::to_string(point.face) + ":" + shortest(point.barycentric[0]) + "," + shortest(point.barycentric[1]) +
         "," + shortest(point.barycentric[2]);
}

// What the command wrote against the library's answer: the same bits on one thread; on two, both +inf or
// within kExact of the largest.
void expect_same_distances(const std::vector<double>& written, const std::vector<double>& expected, unsigned threads,
                           const std::string& what) {
  ASSERT_EQ(written.size(), expected.size()) << what;
  if (threads == 1) {
    EXPECT_NO_FATAL_FAILURE(expect_bitwise_equal(written, expected)) << what;
    return;
  }
  const double largest = max_finite(expected);
  for (std::size_t i = 0; i < written.size(); ++i)
    EXPECT_TRUE((std::isinf(written[i]) && std::isinf(expected[i])) ||
                std::abs(written[i] - expected[i]) <= kExact * largest)
        << what << " " << i << ": " << written[i] << " against " << expected[i];
}

// A CSV of `first`,distance,nearest_source rows in order (distance --labels).
struct LabelledRows {
  std::vector<double> distances;
  std::vector<long> labels;
};
LabelledRows parse_labelled_csv(const fs::path& file, const std::string& first) {
  LabelledRows rows;
  std::istringstream lines(read_file(file));
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, first + ",distance,nearest_source");
  while (std::getline(lines, line)) {
    const std::size_t comma = line.find(','), second = line.find(',', comma + 1);
    EXPECT_EQ(line.substr(0, comma), std::to_string(rows.distances.size())) << line;
    rows.distances.push_back(std::strtod(line.c_str() + comma + 1, nullptr));
    rows.labels.push_back(std::strtol(line.c_str() + second + 1, nullptr, 10));
  }
  return rows;
}

// The library's labels as the command writes them: -1 for none.
std::vector<long> labels_of(const std::vector<std::uint32_t>& nearest) {
  std::vector<long> labels;
  for (const std::uint32_t n : nearest) labels.push_back(n == exactgeo::kNoSource ? -1 : static_cast<long>(n));
  return labels;
}

class CliJunctions : public Cli {
 protected:
  // One case: the mesh written, the library's answers beside each command's.
  void check_case(std::uint64_t seed) {
    Random random(seed);
    std::string family;
    exactgeo::MeshSoup soup;
    if (seed % 3 != 0) {
      JunctionCase c = random_junction_case(random);
      family = std::move(c.family);
      soup = std::move(c.soup);
    } else {  // a height field with T-junctions closed by slivers, or by near-slivers (lifted by up to 1e-9)
      SliverCase c = random_sliver_case(random, seed % 2 == 1);
      family = std::move(c.family);
      soup = std::move(c.soup);
    }
    SCOPED_TRACE(testing::Message() << "seed " << seed << ": " << family);
    const std::uint32_t unused = add_vertex(soup, {7, 7, 7});
    write_file(path("m.obj"), obj_text(soup));
    const exactgeo::Mesh mesh(soup);
    const unsigned threads = 1 + seed % 2;
    const std::string on_threads = " --threads " + std::to_string(threads);
    const std::string common = on_threads + " --quiet";  // pairs and path print no progress
    std::vector<std::uint32_t> used(soup.triangles.begin(), soup.triangles.end());
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    const auto any_vertex = [&] { return used[random.below(used.size())]; };
    // Points inside a face, on a side and at a corner: a corner is that input vertex, split or not.
    const auto any_point = [&] { return random_face_point(soup, random, static_cast<int>(random.below(3))); };

    const std::uint32_t source = any_vertex();
    const std::vector<std::uint32_t> source_list = {source};
    exactgeo::GeodesicOptions one_thread;
    one_thread.threads = 1;

    // distance --targets from a vertex and a point, with labels: target vertices (doubled ones among them, as
    // random picks) and points.
    const std::vector<SurfacePoint> sources = {exactgeo::vertex_point(mesh, source), any_point()};
    std::vector<SurfacePoint> targets;
    std::string target_list;
    for (int k = 0; k < 4; ++k) {
      const std::uint32_t v = any_vertex();
      targets.push_back(exactgeo::vertex_point(mesh, v));
      target_list += (k ? "," : "") + std::to_string(v);
    }
    for (int k = 0; k < 3; ++k) {
      targets.push_back(any_point());
      target_list += " " + point_text(targets.back());
    }
    write_file(path("targets.txt"), target_list + "\n");
    const RunResult with_targets =
        run("distance " + arg("m.obj") + " --source " + std::to_string(source) + " --source-point " +
            point_text(sources[1]) + " --targets " + arg("targets.txt") + " --labels --out " + arg("d.csv") +
            " --target-out " + arg("t.csv") + common);
    ASSERT_EQ(with_targets.exit_code, 0) << with_targets.err;
    exactgeo::GeodesicSolver solver(mesh);
    const exactgeo::GeodesicResult& targeted = solver.solve(sources, targets, one_thread);
    const LabelledRows vertex_rows = parse_labelled_csv(path("d.csv"), "vertex");
    const LabelledRows target_rows = parse_labelled_csv(path("t.csv"), "target");
    expect_same_distances(vertex_rows.distances, targeted.distances, threads, "vertices, with targets");
    expect_same_distances(target_rows.distances, targeted.target_distances, threads, "targets");
    if (threads == 1) {  // on more, a near tie of the two sources may go either way
      EXPECT_EQ(vertex_rows.labels, labels_of(targeted.nearest_source));
      EXPECT_EQ(target_rows.labels, labels_of(targeted.target_nearest_source));
    }

    // distance --source-xyz and --target-xyz: points in space in the mesh's box, each at its closest surface point.
    std::vector<double> xyz;
    std::string xyz_text[3];
    for (int k = 0; k < 3; ++k) {
      for (int axis = 0; axis < 3; ++axis) {
        double lo = HUGE_VAL, hi = -HUGE_VAL;
        for (std::size_t i = axis; i < soup.positions.size() - 3; i += 3) {  // the vertex no face uses is last
          lo = std::min(lo, soup.positions[i]);
          hi = std::max(hi, soup.positions[i]);
        }
        xyz.push_back(random.uniform(lo - 0.1, hi + 0.1));
        xyz_text[k] += (axis ? "," : "") + shortest(xyz.back());
      }
    }
    const RunResult in_space =
        run("distance " + arg("m.obj") + " --source-xyz " + xyz_text[0] + " --target-xyz '" + xyz_text[1] + ";" +
            xyz_text[2] + "' --out " + arg("dx.npy") + " --target-out " + arg("tx.npy") + common);
    ASSERT_EQ(in_space.exit_code, 0) << in_space.err;
    const std::vector<SurfacePoint> located = exactgeo::locate(mesh, xyz).points;
    const exactgeo::GeodesicResult& from_space =
        solver.solve(std::span(located).first(1), std::span(located).subspan(1), one_thread);
    expect_same_distances(parse_npy(path("dx.npy")), from_space.distances, threads, "vertices, from a point in space");
    expect_same_distances(parse_npy(path("tx.npy")), from_space.target_distances, threads, "targets in space");

    // distance --query-points: every vertex and the points, after a whole run.
    std::vector<SurfacePoint> queries;
    std::string query_list;
    for (int k = 0; k < 4; ++k) {
      queries.push_back(any_point());
      query_list += point_text(queries.back()) + "\n";
    }
    write_file(path("queries.txt"), query_list);
    const RunResult with_queries =
        run("distance " + arg("m.obj") + " --source " + std::to_string(source) + " --query-points " +
            arg("queries.txt") + " --out " + arg("full.npy") + " --query-out " + arg("q.npy") + common);
    ASSERT_EQ(with_queries.exit_code, 0) << with_queries.err;
    exactgeo::GeodesicOptions keeping = one_thread;
    keeping.keep_windows = true;
    const std::vector<double> full = solver.solve(source_list, {}, keeping).distances;
    const std::vector<double> at_queries = solver.distance_at(queries);
    expect_same_distances(parse_npy(path("full.npy")), full, threads, "vertices");
    expect_same_distances(parse_npy(path("q.npy")), at_queries, threads, "query points");
    EXPECT_TRUE(std::isinf(full[unused]));

    // pairs: vertices and points on either side, one pair per line.
    std::vector<SurfacePoint> a, b;
    std::string pair_lines;
    for (int k = 0; k < 6; ++k) {
      const bool a_vertex = k % 2 == 0, b_vertex = k < 3;
      const std::uint32_t va = any_vertex(), vb = any_vertex();
      a.push_back(a_vertex ? exactgeo::vertex_point(mesh, va) : any_point());
      b.push_back(b_vertex ? exactgeo::vertex_point(mesh, vb) : any_point());
      pair_lines += (a_vertex ? std::to_string(va) : point_text(a.back())) + " " +
                    (b_vertex ? std::to_string(vb) : point_text(b.back())) + "\n";
    }
    write_file(path("pairs.txt"), pair_lines);
    const RunResult pairs =
        run("pairs " + arg("m.obj") + " --pairs " + arg("pairs.txt") + " --out " + arg("p.npy") + on_threads);
    ASSERT_EQ(pairs.exit_code, 0) << pairs.err;
    EXPECT_NO_FATAL_FAILURE(
        expect_bitwise_equal(parse_npy(path("p.npy")), exactgeo::pair_distances(mesh, a, b).distances));

    // matrix --targets: rows from three vertices, columns of any vertex, the one no face uses among them (+inf).
    const std::vector<std::uint32_t> rows = {any_vertex(), any_vertex(), any_vertex()};
    exactgeo::MatrixOptions columns;
    columns.target_vertices = std::vector<std::uint32_t>{any_vertex(), unused, any_vertex(), any_vertex()};
    std::string row_list, column_list;
    for (const std::uint32_t v : rows) row_list += (row_list.empty() ? "" : ",") + std::to_string(v);
    for (const std::uint32_t v : *columns.target_vertices)
      column_list += (column_list.empty() ? "" : ";") + std::to_string(v);
    const RunResult matrix = run("matrix " + arg("m.obj") + " --sources " + row_list + " --targets '" + column_list +
                                 "' --out " + arg("m.npy") + common);
    ASSERT_EQ(matrix.exit_code, 0) << matrix.err;
    const std::vector<double> block = exactgeo::distance_matrix(mesh, rows, columns);
    EXPECT_NO_FATAL_FAILURE(expect_bitwise_equal(parse_npy_matrix(path("m.npy"), 3, 4), block));
    for (std::size_t row = 0; row < rows.size(); ++row) EXPECT_TRUE(std::isinf(block[row * 4 + 1]));

    // path: to a vertex and to a point the source reaches, as long as their distances and ending where named.
    std::vector<std::uint32_t> reached;
    for (const std::uint32_t v : used)
      if (std::isfinite(full[v])) reached.push_back(v);
    const std::uint32_t to_vertex = reached[random.below(reached.size())];
    const auto check_path = [&](const std::string& target, double distance, bool at_vertex) {
      const RunResult result = run("path " + arg("m.obj") + " --source " + std::to_string(source) + " --target " +
                                   target + " --out " + arg("path.json") + on_threads);
      ASSERT_EQ(result.exit_code, 0) << result.err;
      const nlohmann::json path_json = nlohmann::json::parse(read_file(path("path.json")));
      const auto& points = path_json["points"];
      double length = 0;
      for (std::size_t i = 1; i < points.size(); ++i)
        length += exactgeo_test::distance(points[i - 1].get<Vec3>(), points[i].get<Vec3>());
      const double rounding = 1e-15 * max_finite(full);
      EXPECT_LE(std::abs(path_json["length"].get<double>() - distance), kPathLength * distance + rounding)
          << "path to " << target;
      EXPECT_LE(std::abs(length - distance), kPathLength * distance + rounding) << "path to " << target;
      EXPECT_EQ(path_json["locations"].front()["vertex"], source) << "path to " << target;
      if (at_vertex) EXPECT_EQ(path_json["locations"].back()["vertex"], to_vertex) << "path to " << target;
    };
    check_path(std::to_string(to_vertex), full[to_vertex], true);
    const auto reached_query =
        std::find_if(at_queries.begin(), at_queries.end(), [](double d) { return std::isfinite(d); });
    if (reached_query != at_queries.end())
      check_path(point_text(queries[reached_query - at_queries.begin()]), *reached_query, false);
  }
};

TEST_F(CliJunctions, CommandsGiveTheLibrarysAnswers) {
  for (std::uint64_t seed = 1; seed <= kCases; ++seed) {
    check_case(seed);
    if (HasFatalFailure()) return;
  }
}

}  // namespace
