// The `pairs` command: pairs from text, .npy and standard input, each the library's pair distance bit for bit,
// and bad pairs named by line or element.
#include <gtest/gtest.h>

#include <cstdlib>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "exactgeo/shapes.hpp"

#include "cli_run.hpp"

namespace {

using namespace exactgeo_test;

// `pairs`: the pairs of a text file (a header, vertex pairs, a point pair) and of an (n, 2) .npy array, from a
// file or standard input; each distance the library's pair_distances, bit for bit, and a targets-mode run's.
TEST_F(Cli, PairsFromTextNpyAndStandardInput) {
  write_file(path("pairs.csv"), "a,b\n3 17\n5,200\n12:0.2,0.3,0.5 40\n9 9\n");
  const RunResult csv = run("pairs @torus:24:10 --pairs " + arg("pairs.csv") + " --threads 2 --out " + arg("d.csv"));
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  EXPECT_EQ(csv.out, "");
  const exactgeo::Mesh torus(exactgeo::make_bumpy_torus(24, 10));
  const std::vector<exactgeo::SurfacePoint> a = {exactgeo::vertex_point(torus, 3), exactgeo::vertex_point(torus, 5),
                                                 {12, {0.2, 0.3, 0.5}}, exactgeo::vertex_point(torus, 9)};
  const std::vector<exactgeo::SurfacePoint> b = {exactgeo::vertex_point(torus, 17), exactgeo::vertex_point(torus, 200),
                                                 exactgeo::vertex_point(torus, 40), exactgeo::vertex_point(torus, 9)};
  const std::vector<double> expected = exactgeo::pair_distances(torus, a, b).distances;
  std::istringstream rows(read_file(path("d.csv")));
  std::string line;
  std::getline(rows, line);
  EXPECT_EQ(line, "pair,distance");
  std::vector<double> written;
  for (std::size_t i = 0; std::getline(rows, line); ++i) {
    EXPECT_EQ(line.substr(0, line.find(',')), std::to_string(i));
    written.push_back(std::strtod(line.c_str() + line.find(',') + 1, nullptr));
  }
  expect_bitwise_equal(written, expected);
  EXPECT_EQ(expected[3], 0.0);
  for (std::size_t i = 0; i < a.size(); ++i) {
    exactgeo::GeodesicSolver solver(torus);
    EXPECT_NEAR(expected[i], solver.solve(std::span(&a[i], 1), std::span(&b[i], 1)).target_distances[0], 1e-14 * expected[1]);
  }
  // The vertex pairs as an (n, 2) .npy array, from standard input, to a .npy file.
  write_file(path("pairs.npy"), npy_file("<i4", {3, 17, 5, 200, 9, 9}, "(3, 2)"));
  const RunResult npy = run("pairs @torus:24:10 --pairs - --out " + arg("d.npy") + " < " + arg("pairs.npy"));
  ASSERT_EQ(npy.exit_code, 0) << npy.err;
  expect_bitwise_equal(parse_npy(path("d.npy")), {expected[0], expected[1], expected[3]});
  // Without --out, the CSV on stdout; pairs inline.
  const RunResult inline_pairs = run("pairs @torus:24:10 --pairs '3,17;5 200' '12:0.2,0.3,0.5 40' '9 9'");
  ASSERT_EQ(inline_pairs.exit_code, 0) << inline_pairs.err;
  EXPECT_EQ(inline_pairs.out, read_file(path("d.csv")));
}

TEST_F(Cli, BadPairsAreNamed) {
  expect_error(run("pairs @grid:4:4 --pairs '3 4 5'"), 2, "--pairs: line 1: '3 4 5' is not a pair");
  expect_error(run("pairs @grid:4:4 --pairs '3 4;5 999'"), 2, "--pairs: line 2: vertex 999 is out of range");
  expect_error(run("pairs @grid:4:4 --pairs '3 x'"), 2, "'x' is neither a vertex index nor a point");
  write_file(path("flat.npy"), npy_file("<i8", {1, 2, 3}));
  expect_error(run("pairs @grid:4:4 --pairs " + arg("flat.npy")), 2, "indices must be an (n, 2) array");
  write_file(path("far.npy"), npy_file("<u2", {1, 2, 999, 3}, "(2, 2)"));
  expect_error(run("pairs @grid:4:4 --pairs " + arg("far.npy")), 2, "element [1, 0]: vertex 999 is out of range");
  expect_error(run("pairs @grid:4:4"), 1, "--pairs is required");
  expect_error(run("pairs @grid:4:4 --pairs '1 2' --out d.ply"), 1, "must be .txt, .csv or .npy");
  expect_error(run("pairs @grid:4:4 --pairs '1 2' --max-distance -1"), 1, "--max-distance");
}

}  // namespace
