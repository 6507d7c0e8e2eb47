// The OFF reader: comments, colours, polygons, keyword variants, and its errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/io.hpp"
#include "io_test_files.hpp"

namespace {

using namespace exactgeo_test;

// ---------------------------------------------------------------------------------------------- OFF

class IoOff : public IoFileTest {};

TEST_F(IoOff, CommentsColoursAndPolygons) {
  const MeshSoup soup = read_mesh_soup(write("shape.off",
                                             "OFF\r\n"
                                             "# a comment before the counts\r\n"
                                             "\r\n"
                                             "5 2 0\r\n"
                                             "0 0 0\r\n"
                                             "1 0 0  # trailing comment\r\n"
                                             "\t2 1 0\r\n"
                                             "1 2 0\r\n"
                                             "0 1 -0.5\r\n"
                                             "# faces follow\r\n"
                                             "5 0 1 2 3 4 255 0 0\r\n"
                                             "3 4 3 2 0.5 0.5 0.5 1.0\r\n"));
  EXPECT_EQ(soup.positions, (std::vector<double>{0, 0, 0, 1, 0, 0, 2, 1, 0, 1, 2, 0, 0, 1, -0.5}));
  EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4, 4, 3, 2}));
}

TEST_F(IoOff, ByteOrderMarkIsSkipped) {
  for (const std::string header : {"OFF\n", ""}) {  // the keyword is optional
    const MeshSoup soup = read_mesh_soup(write("bom.off", std::string(kBom) + header +
                                                              "4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                                              "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n"));
    EXPECT_EQ(soup.positions, kTetraPositions);
    EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3}));
  }
}

TEST_F(IoOff, PrefixedKeywordsAndCountsOnTheKeywordLine) {
  for (const char* keyword : {"COFF", "NOFF", "CNOFF", "STOFF", "STCNOFF"}) {
    SCOPED_TRACE(keyword);
    const MeshSoup soup = read_mesh_soup(write("prefixed.off", std::string(keyword) +
                                                                   " 3 1 3\n"
                                                                   "0 0 0 1 0 0 1\n"
                                                                   "1 0 0 0 1 0 1\n"
                                                                   "0 1 0 0 0 1 1\n"
                                                                   "3 0 1 2\n"));
    EXPECT_EQ(soup.positions, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
    EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 1, 2}));
  }
}

TEST_F(IoOff, Errors) {
  const std::string triangle = "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n";
  expect_error("nocounts.off", "OFF\n# only a comment\n", ErrorCode::invalid_mesh, {"missing vertex and face counts"});
  expect_error("nofacecount.off", "OFF\n3\n", ErrorCode::invalid_mesh, {"nofacecount.off:2:", "face count"});
  expect_error("negative.off", "OFF\n-3 1\n", ErrorCode::invalid_mesh, {"negative.off:2:", "negative"});
  expect_error("variant.off", "4OFF\n3 1\n", ErrorCode::invalid_mesh, {"variant.off:1:", "'4OFF'"});
  expect_error("binary.off", "OFF BINARY\n", ErrorCode::invalid_mesh, {"binary.off:1:", "binary"});
  expect_error("fewvertices.off", "OFF\n3 1\n0 0 0\n1 0 0\n", ErrorCode::invalid_mesh,
               {"file ends after 2 of 3 vertices"});
  expect_error("fewfaces.off", triangle, ErrorCode::invalid_mesh, {"file ends after 0 of 1 faces"});
  expect_error("range.off", triangle + "3 0 1 3\n", ErrorCode::invalid_mesh,
               {"range.off:6:", "3 out of range", "3 vertices"});
  expect_error("negindex.off", triangle + "3 0 1 -1\n", ErrorCode::invalid_mesh, {"negindex.off:6:", "-1 out of range"});
  expect_error("short.off", triangle + "2 0 1\n", ErrorCode::invalid_mesh, {"short.off:6:", "at least 3"});
  expect_error("missing.off", triangle + "4 0 1 2\n", ErrorCode::invalid_mesh, {"missing.off:6:", "missing"});
  expect_error("number.off", "OFF\n3 1\n0 0 0\n1 0 O\n", ErrorCode::invalid_mesh, {"number.off:4:", "'O'"});
  expect_error("nan.off", "OFF\n3 1\n0 0 0\n1 0 nan\n", ErrorCode::invalid_mesh, {"nan.off:4:", "non-finite"});
  expect_error("empty.off", "OFF\n0 0\n", ErrorCode::invalid_mesh, {"no vertices"});
}

}  // namespace
