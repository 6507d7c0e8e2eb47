// The `matrix` command: rows equal to single runs in every format, streamed .npz, target columns, and the
// samples `sample` writes as its sources.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.hpp"

namespace {

using namespace exactgeo_test;

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

// A column may name a vertex no face uses: +inf, as that vertex's column of the full matrix (the library's
// promise); a row may not, nor may a column name a vertex out of range.
TEST_F(Cli, MatrixColumnOfAVertexNoFaceUsesIsInfinite) {
  write_file(path("seam.obj"), kSeamObj);
  ASSERT_EQ(run("matrix " + arg("seam.obj") + " --sources 0 --out " + arg("full.npy")).exit_code, 0);
  const RunResult block_run = run("matrix " + arg("seam.obj") + " --sources 0 --targets 6,1 --out " + arg("b.npy"));
  ASSERT_EQ(block_run.exit_code, 0) << block_run.err;
  const std::vector<double> full = parse_npy_matrix(path("full.npy"), 1, 7);
  const std::vector<double> block = parse_npy_matrix(path("b.npy"), 1, 2);
  EXPECT_TRUE(std::isinf(full[6]));
  EXPECT_TRUE(std::isinf(block[0]));
  EXPECT_EQ(block[1], full[1]);
  EXPECT_EQ(block[1], 1.0);
  expect_error(run("matrix " + arg("seam.obj") + " --sources 6 --out " + arg("m.npy")), 2,
               "--sources: vertex 6 is used by no face");
  write_file(path("far.npy"), npy_file("<i4", {1, 7}));
  expect_error(run("matrix " + arg("seam.obj") + " --sources 0 --targets " + arg("far.npy") + " --out " + arg("m.npy")),
               2, "element [1]: vertex 7 is out of range");
  EXPECT_FALSE(fs::exists(path("m.npy")));
}

TEST_F(Cli, MatrixReadsTheSamplesThatSampleWrites) {
  ASSERT_EQ(run("sample @icosphere:2 -k 4 --out " + arg("s.csv")).exit_code, 0);
  ASSERT_EQ(run("sample @icosphere:2 -k 4 --out " + arg("s.txt")).exit_code, 0);
  ASSERT_EQ(run("matrix @icosphere:2 --sources " + arg("s.csv") + " --out " + arg("from-csv.npy")).exit_code, 0);
  ASSERT_EQ(run("matrix @icosphere:2 --sources " + arg("s.txt") + " --out " + arg("from-txt.npy")).exit_code, 0);
  EXPECT_EQ(read_file(path("from-csv.npy")), read_file(path("from-txt.npy")));
  write_file(path("bad.csv"), "sample,vertex,radius\n0,0,inf\n1,x,2\n");
  expect_error(run("matrix @icosphere:2 --sources " + arg("bad.csv") + " --out " + arg("m.npy")), 2, "line 3: 'x'");
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

}  // namespace
