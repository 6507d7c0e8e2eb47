// The STL reader: ASCII and binary, exact merging of repeated corners, and its errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/io.hpp"
#include "io_test_files.hpp"

namespace {

using namespace exactgeo_test;

// ---------------------------------------------------------------------------------------------- STL

class IoStl : public IoFileTest {};

TEST_F(IoStl, AsciiMergesIdenticalPositions) {
  const MeshSoup soup = read_mesh_soup(write("part.stl",
                                             "solid part made by hand\n"
                                             "  facet normal 0 0 1\n"
                                             "    outer loop\n"
                                             "      vertex 0 0 0\n"
                                             "      vertex 1 0 0\n"
                                             "      vertex 0 1 0.5\n"
                                             "    endloop\n"
                                             "  endfacet\n"
                                             "  facet normal nan nan 1.#QNAN\r\n"  // ignored
                                             "    outer loop vertex 0 1 5e-1 vertex 1.0 0 0\n"
                                             "\tvertex 1 1 0 endloop\n"
                                             "  endfacet\n"
                                             "endsolid part made by hand\n"));
  EXPECT_EQ(soup.positions, kStlPositions);
  EXPECT_EQ(soup.triangles, kStlTriangles);
}

TEST_F(IoStl, BinaryMergesIdenticalPositions) {
  const MeshSoup soup = read_mesh_soup(write("part.stl", binary_stl("binary part", 2)));
  EXPECT_EQ(soup.positions, kStlPositions);
  EXPECT_EQ(soup.triangles, kStlTriangles);
}

TEST_F(IoStl, BinaryWhoseHeaderStartsWithSolid) {
  const MeshSoup soup = read_mesh_soup(write("solid.stl", binary_stl("solid exported as binary", 2)));
  EXPECT_EQ(soup.positions, kStlPositions);
  EXPECT_EQ(soup.triangles, kStlTriangles);
}

TEST_F(IoStl, AsciiWithByteOrderMarkIsAscii) {
  const MeshSoup soup = read_mesh_soup(write("bom.stl", std::string(kBom) +
                                                            "solid part\n"
                                                            "facet normal 0 0 1 outer loop\n"
                                                            "vertex 0 0 0 vertex 1 0 0 vertex 0 1 0.5\n"
                                                            "endloop endfacet\n"
                                                            "facet normal 0 0 1 outer loop\n"
                                                            "vertex 0 1 0.5 vertex 1 0 0 vertex 1 1 0\n"
                                                            "endloop endfacet\n"
                                                            "endsolid part\n"));
  EXPECT_EQ(soup.positions, kStlPositions);
  EXPECT_EQ(soup.triangles, kStlTriangles);
  // A binary file's header is 80 arbitrary bytes: one that starts like a byte-order mark is still binary.
  const MeshSoup binary = read_mesh_soup(write("bom_binary.stl", binary_stl(std::string(kBom) + "solid", 2)));
  EXPECT_EQ(binary.positions, kStlPositions);
  EXPECT_EQ(binary.triangles, kStlTriangles);
}

// Writers emit -0 and 0 for the same corner; merged by bits, the two became separate vertices and cracked
// the surface (every vertex beyond the crack at +inf).
TEST_F(IoStl, MinusZeroAndZeroAreOnePosition) {
  const MeshSoup ascii = read_mesh_soup(write("signed_zero.stl",
                                              "solid part\n"
                                              "facet normal 0 0 1 outer loop\n"
                                              "vertex 0 0 0 vertex 1 0 0 vertex 0 1 0.5\n"
                                              "endloop endfacet\n"
                                              "facet normal 0 0 1 outer loop\n"
                                              "vertex -0 1 0.5 vertex 1 -0 -0.0 vertex 1 1 -0\n"
                                              "endloop endfacet\n"
                                              "endsolid part\n"));
  EXPECT_EQ(ascii.positions, kStlPositions);
  EXPECT_EQ(ascii.triangles, kStlTriangles);

  std::string binary = binary_stl("binary", 2);
  const float minus_zero = -0.0f;
  for (std::size_t corner : {0, 1}) {  // the second triangle's first two corners: (0, 1, 0.5) and (1, 0, 0)
    const std::size_t at = 84 + 50 + 12 + 12 * corner + (corner == 0 ? 0 : 4);
    std::memcpy(binary.data() + at, &minus_zero, sizeof minus_zero);
  }
  const MeshSoup from_binary = read_mesh_soup(write("signed_zero_binary.stl", binary));
  EXPECT_EQ(from_binary.positions, kStlPositions);
  EXPECT_EQ(from_binary.triangles, kStlTriangles);
}

TEST_F(IoStl, Errors) {
  const std::string binary = binary_stl("binary", 3);
  expect_error("truncated.stl", binary, ErrorCode::invalid_mesh, {"file ends inside triangle 2", "3 triangles"});
  expect_error("trailing.stl", binary_stl("binary", 1), ErrorCode::invalid_mesh, {"50 bytes after the last"});
  expect_error("tiny.stl", "abc", ErrorCode::invalid_mesh, {"too short"});
  expect_error("zero.stl", binary_stl("binary", 0).substr(0, 84), ErrorCode::invalid_mesh, {"no vertices"});

  std::string nan = binary_stl("binary", 2);
  const float bad = std::numeric_limits<float>::infinity();
  std::memcpy(nan.data() + 84 + 50 + 12 + 4, &bad, 4);  // y of triangle 1's first corner
  expect_error("nan.stl", nan, ErrorCode::invalid_mesh, {"triangle 1", "non-finite"});

  const std::string facet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n";
  expect_error("keyword.stl", "solid x\n" + facet + "endloop\nendfacet\nvertx 1 2 3\n", ErrorCode::invalid_mesh,
               {"keyword.stl:9:", "'vertx'"});
  expect_error("outside.stl", "solid x\nvertex 0 0 0\n", ErrorCode::invalid_mesh,
               {"outside.stl:2:", "outside a facet"});
  expect_error("open.stl", "solid x\n" + facet, ErrorCode::invalid_mesh, {"inside a facet"});
  expect_error("number.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 q\n", ErrorCode::invalid_mesh,
               {"number.stl:4:", "'q'"});
  expect_error("two.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n",
               ErrorCode::invalid_mesh, {"two.stl:7:", "at least 3"});
  expect_error("ascnan.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 nan\n", ErrorCode::invalid_mesh,
               {"ascnan.stl:4:", "non-finite"});
}

}  // namespace
