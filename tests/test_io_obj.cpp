// The OBJ reader: statements, index forms, polygons, numbers at the edges of double, and its errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/io.hpp"
#include "io_test_files.hpp"

namespace {

using namespace exactgeo_test;

// ---------------------------------------------------------------------------------------------- OBJ

class IoObj : public IoFileTest {};

TEST_F(IoObj, ReadsPositionsAndTriangles) {
  const MeshSoup soup = read_mesh_soup(write("tetra.obj",
                                             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                             "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"));
  EXPECT_EQ(soup.positions, kTetraPositions);
  EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3}));
}

// Numbers beyond double's range read as what they round to: an underflow is 0 (and subnormals stay exact), an
// overflow is inf, which the mesh check then names (below, overflow.obj).
TEST_F(IoObj, NumbersAtTheEdgesOfDoubleRoundAsStrtodWould) {
  const MeshSoup soup = read_mesh_soup(write("tiny.obj", "v 1e-400 -1e-400 4.9406564584124654e-324\nv +1 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_EQ(soup.positions[0], 0.0);
  EXPECT_TRUE(std::signbit(soup.positions[1]));
  EXPECT_EQ(soup.positions[2], std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(soup.positions[3], 1.0);
}

TEST_F(IoObj, ByteOrderMarkIsSkipped) {
  const MeshSoup soup = read_mesh_soup(write("bom.obj", std::string(kBom) +
                                                           "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                                           "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"));
  EXPECT_EQ(soup.positions, kTetraPositions);
  EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3}));
}

TEST_F(IoObj, SlashFormsAndNegativeIndices) {
  const MeshSoup soup = read_mesh_soup(write("slashes.obj",
                                             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                             "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
                                             "f 1/1 2/2 3/3\n"
                                             "f 1//1 2//1 4//1\n"
                                             "f 2/2/1 3/3/1 4/1/1\n"
                                             "f -2 -4 -1\n"
                                             "f -1/1/1 -2//1 -3/2\n"));
  EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 1, 2, 0, 1, 3, 1, 2, 3, 2, 0, 3, 3, 2, 1}));
}

// Plain face corners ("12", "12/3", "12//5") are read straight from the line, any other form token by token:
// seeded random files of polygons, their corners written plain, with a '+' and counted back from the latest
// vertex (both read as tokens), read to the same triangles.
TEST_F(IoObj, PlainCornersReadAsTheTokensRead) {
  std::mt19937 random(38);
  for (int trial = 0; trial < 20; ++trial) {
    std::string forms[3];
    std::size_t vertices = 0;
    const auto blanks = [&] { return std::string(1 + random() % 2, random() % 3 == 0 ? '\t' : ' '); };
    for (int line = 0; line < 300; ++line) {
      if (vertices < 3 || random() % 3 == 0) {
        for (std::string& form : forms) form += "v 0 " + std::to_string(line) + " 1\n";
        ++vertices;
        continue;
      }
      const std::size_t corners = 3 + random() % 4;
      for (std::string& form : forms) form += "f";
      for (std::size_t k = 0; k < corners; ++k) {
        const std::size_t index = 1 + random() % vertices;
        const std::string tail = std::array<std::string, 4>{"", "/7", "//2", "/3/4"}[random() % 4];
        const std::string space = blanks();
        forms[0] += space + std::to_string(index) + tail;
        forms[1] += space + "+" + std::to_string(index) + tail;
        forms[2] += space + "-" + std::to_string(vertices + 1 - index) + tail;
      }
      for (std::string& form : forms) form += random() % 2 ? "\n" : " \n";
    }
    const MeshSoup plain = read_mesh_soup(write("plain.obj", forms[0]));
    EXPECT_EQ(read_mesh_soup(write("signed.obj", forms[1])).triangles, plain.triangles) << "trial " << trial;
    EXPECT_EQ(read_mesh_soup(write("relative.obj", forms[2])).triangles, plain.triangles) << "trial " << trial;
  }
}

TEST_F(IoObj, NegativeIndicesCountBackFromTheLatestVertex) {
  const MeshSoup soup = read_mesh_soup(write("relative.obj",
                                             "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"
                                             "v 1 1 0\nf -3 -2 -1\n"));
  EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 1, 2, 1, 2, 3}));
}

TEST_F(IoObj, PolygonsAreFanTriangulated) {
  const MeshSoup soup = read_mesh_soup(write("polygons.obj",
                                             "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\n"
                                             "f 1 2 3 4\nf 5 4 3 2 1\n"));
  EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 4, 3, 2, 4, 2, 1, 4, 1, 0}));
}

TEST_F(IoObj, CrlfTabsCommentsAndOtherStatements) {
  const MeshSoup soup = read_mesh_soup(write("messy.obj",
                                             "# exported by hand\r\n"
                                             "mtllib messy.mtl\r\n"
                                             "o thing\r\n"
                                             "\r\n"
                                             "v\t0 0 0 1.0\r\n"           // w component
                                             "v 1.5e0 -0 +0 0.2 0.3 0.4\r\n"  // colours after xyz
                                             "  v  0\t2.25  -1e-3  # trailing comment\r\n"
                                             "vn 0 0 1\r\nvt 0.5 0.5\r\nvp 0.1\r\n"
                                             "g group\r\ns off\r\nusemtl red\r\n"
                                             "l 1 2\r\n"
                                             "f 1 2 3 # a comment after a face\r\n"
                                             "f\t3\t2\t1"));  // no newline at the end
  EXPECT_EQ(soup.positions, (std::vector<double>{0, 0, 0, 1.5, -0.0, 0, 0, 2.25, -1e-3}));
  EXPECT_TRUE(std::signbit(soup.positions[4]));
  EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 0}));
}

TEST_F(IoObj, Errors) {
  const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expect_error("range.obj", triangle + "f 1 2 4\n", ErrorCode::invalid_mesh,
               {"range.obj:4:", "4 out of range", "3 vertices"});
  expect_error("negative.obj", triangle + "f 1 2 -4\n", ErrorCode::invalid_mesh,
               {"negative.obj:4:", "-4 out of range", "3 vertices"});
  expect_error("zero.obj", triangle + "f 0 1 2\n", ErrorCode::invalid_mesh, {"zero.obj:4:", "index 0"});
  expect_error("short.obj", triangle + "f 1 2\n", ErrorCode::invalid_mesh, {"short.obj:4:", "at least 3"});
  expect_error("corner.obj", triangle + "f 1/1 x/2 3\n", ErrorCode::invalid_mesh, {"corner.obj:4:", "'x/2'"});
  expect_error("number.obj", "v 0 0 0\nv 1 zero 0\n", ErrorCode::invalid_mesh, {"number.obj:2:", "'zero'"});
  expect_error("missing.obj", "v 0 0\n", ErrorCode::invalid_mesh, {"missing.obj:1:", "missing vertex z"});
  expect_error("nan.obj", "v 0 0 0\n\nv nan 0 0\n", ErrorCode::invalid_mesh, {"nan.obj:3:", "non-finite"});
  expect_error("inf.obj", "v 0 -inf 0\n", ErrorCode::invalid_mesh, {"inf.obj:1:", "non-finite"});
  expect_error("overflow.obj", "v 0 0 1e999\n", ErrorCode::invalid_mesh, {"overflow.obj:1:", "non-finite"});
  expect_error("nofaces.obj", triangle, ErrorCode::invalid_mesh, {"no faces"});
  expect_error("empty.obj", "# nothing\n", ErrorCode::invalid_mesh, {"no vertices"});
}

}  // namespace
