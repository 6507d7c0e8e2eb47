// The `sample` command: farthest points in order with shrinking radii, and counts it cannot give.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.hpp"

namespace {

using namespace exactgeo_test;

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

// The samples file is a sources file: matrix --sources reads the vertex column of sample's CSV.
// More samples than vertices is an error before any work; more than one piece holds gives what it holds, and a
// warning says how many (the Python function does both the same way).
TEST_F(Cli, SampleSaysWhenItCannotGiveTheCountAskedFor) {
  // Two triangles apart: from vertex 0 only the first three vertices are within reach.
  write_file(path("two.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0\nf 1 2 3\nf 4 5 6\n");
  expect_error(run("sample " + arg("two.obj") + " -k 7"), 2, "--count 7 exceeds the mesh's 6 vertices");
  const RunResult fewer = run("sample " + arg("two.obj") + " -k 5 --quiet");
  ASSERT_EQ(fewer.exit_code, 0) << fewer.err;
  EXPECT_EQ(fewer.out, "0\n1\n2\n");
  EXPECT_NE(fewer.err.find("warning: 3 of the 5 samples asked for"), std::string::npos) << fewer.err;
  const RunResult all = run("sample " + arg("two.obj") + " -k 3 --quiet");
  ASSERT_EQ(all.exit_code, 0) << all.err;
  EXPECT_EQ(all.err, "");
}

}  // namespace
