// The `locate` command: closest surface points of points in space.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "exactgeo/shapes.hpp"

#include "cli_run.hpp"

namespace {

using namespace exactgeo_test;

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

}  // namespace
