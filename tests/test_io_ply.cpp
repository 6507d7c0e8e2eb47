// The PLY reader: ASCII and binary in both byte orders, every numeric type, strips, and errors naming the element.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/io.hpp"
#include "io_test_files.hpp"

namespace {

using namespace exactgeo_test;

// ---------------------------------------------------------------------------------------------- PLY

class IoPly : public IoFileTest {};

TEST_F(IoPly, AsciiWithCommentsExtraPropertiesAndPolygons) {
  const MeshSoup soup = read_mesh_soup(write("ascii.ply",
                                             "ply\n"
                                             "format ascii 1.0\n"
                                             "comment written by hand\n"
                                             "obj_info nothing\n"
                                             "element vertex 4\n"
                                             "property uchar red\n"
                                             "property float x\n"
                                             "property list uchar float weights\n"
                                             "property float y\n"
                                             "property double z\n"
                                             "element edge 1\n"
                                             "property int vertex1\n"
                                             "property int vertex2\n"
                                             "element face 2\n"
                                             "property uchar flags\n"
                                             "property list uint uint vertex_index\n"
                                             "end_header\n"
                                             "255 0 2 0.5 0.5 0 0\n"
                                             "0 1 0 0 0.25\n"
                                             "7 2 1 9 1.5 -3\n"
                                             "7 0 3 1 2 3 0 0.125\n"
                                             "0 1\n"
                                             "1 4 0 1 2 3\n"
                                             "1 3 3 2 1\n"));
  EXPECT_EQ(soup.positions, (std::vector<double>{0, 0, 0, 1, 0, 0.25, 2, 1.5, -3, 0, 0, 0.125}));
  EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 3, 2, 1}));
}

TEST_F(IoPly, BinaryBothByteOrdersWithMixedTypes) {
  for (bool big_endian : {false, true}) {
    SCOPED_TRACE(big_endian ? "big endian" : "little endian");
    const MeshSoup soup = read_mesh_soup(write("binary.ply", binary_ply(big_endian)));
    EXPECT_EQ(soup.positions, (std::vector<double>{0.5, 0.1, 3, -1.25, 2.5, -4, 3, -7.75, 100000, 0, 1e-300, 0}));
    EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 3, 2, 1}));
  }
}

TEST_F(IoPly, ByteOrderMarkIsSkippedInAsciiAndBinary) {
  const MeshSoup ascii = read_mesh_soup(write("bom.ply", std::string(kBom) +
                                                             "ply\nformat ascii 1.0\nelement vertex 4\n"
                                                             "property float x\nproperty float y\nproperty float z\n"
                                                             "element face 4\nproperty list uchar int vertex_indices\n"
                                                             "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                                             "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n"));
  EXPECT_EQ(ascii.positions, kTetraPositions);
  EXPECT_EQ(ascii.triangles, (std::vector<std::uint32_t>{0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3}));
  for (bool big_endian : {false, true}) {  // the binary body starts after the header, wherever that ends
    const MeshSoup binary = read_mesh_soup(write("bom_binary.ply", std::string(kBom) + binary_ply(big_endian)));
    EXPECT_EQ(binary.positions, read_mesh_soup(write("binary.ply", binary_ply(big_endian))).positions);
    EXPECT_EQ(binary.triangles, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 3, 2, 1}));
  }
}

TEST_F(IoPly, TriangleStripsAlternateWindingAndKeepDegenerateTriangles) {
  const MeshSoup soup = read_mesh_soup(write("strips.ply",
                                             "ply\nformat ascii 1.0\n"
                                             "element vertex 6\n"
                                             "property float x\nproperty float y\nproperty float z\n"
                                             "element tristrips 1\n"
                                             "property list int int vertex_indices\n"
                                             "end_header\n"
                                             "0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 1 0\n2 2 0\n"
                                             "10 0 1 2 3 -1 3 4 5 5 4\n"));
  EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 3, 3, 4, 5, 5, 4, 5, 5, 5, 4}));
}

TEST_F(IoPly, Errors) {
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  const std::string face_header = "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string ascii = "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz;
  const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n";
  expect_error("magic.ply", "plx\nformat ascii 1.0\n", ErrorCode::invalid_mesh, {"magic.ply:1:", "not a PLY"});
  expect_error("format.ply", "ply\nformat binary_middle_endian 1.0\n", ErrorCode::invalid_mesh,
               {"format.ply:2:", "unsupported PLY format", "binary_middle_endian"});
  expect_error("version.ply", "ply\nformat ascii 2.0\n", ErrorCode::invalid_mesh, {"version.ply:2:", "'2.0'"});
  expect_error("noformat.ply", "ply\nelement vertex 0\nend_header\n", ErrorCode::invalid_mesh, {"'format'"});
  expect_error("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n",
               ErrorCode::invalid_mesh, {"type.ply:4:", "unknown property type", "float128"});
  expect_error("noz.ply",
               "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
               ErrorCode::invalid_mesh, {"noz.ply:", "'z'"});
  expect_error("count.ply", "ply\nformat ascii 1.0\nelement vertex many\n", ErrorCode::invalid_mesh,
               {"count.ply:3:", "'many'"});
  expect_error("noend.ply", ascii, ErrorCode::invalid_mesh, {"end_header"});
  expect_error("novertex.ply", "ply\nformat ascii 1.0\n" + face_header, ErrorCode::invalid_mesh,
               {"no 'vertex' element"});
  expect_error("nolist.ply", ascii + "element face 1\nproperty int flags\nend_header\n", ErrorCode::invalid_mesh,
               {"vertex_indices"});
  expect_error("number.ply", ascii + face_header + "0 0 0\n1 zero 0\n", ErrorCode::invalid_mesh,
               {"number.ply:11:", "vertex 1", "'zero'"});
  expect_error("range.ply", ascii + face_header + vertices + "3 0 1 3\n", ErrorCode::invalid_mesh,
               {"range.ply:13:", "face 0", "3 out of range", "3 vertices"});
  expect_error("short.ply", ascii + face_header + vertices + "2 0 1\n", ErrorCode::invalid_mesh,
               {"short.ply:13:", "face 0", "at least 3"});
  expect_error("fraction.ply", ascii + face_header + vertices + "3 0 1.5 2\n", ErrorCode::invalid_mesh,
               {"fraction.ply:13:", "whole number"});
  expect_error("nan.ply", ascii + face_header + "0 0 0\n1 nan 0\n0 1 0\n", ErrorCode::invalid_mesh,
               {"nan.ply:11:", "vertex 1", "non-finite"});
  expect_error("asciishort.ply", ascii + face_header + vertices + "3 0 1\n", ErrorCode::invalid_mesh,
               {"asciishort.ply:13:", "face 0 has 3 values, the header and its list lengths declare 4"});
  expect_error("asciitruncated.ply", ascii + face_header + vertices, ErrorCode::invalid_mesh,
               {"file ends inside face 0"});
  expect_error("nofaces.ply", ascii + "end_header\n" + vertices, ErrorCode::invalid_mesh, {"no faces"});
  expect_error("toomany.ply", "ply\nformat ascii 1.0\nelement vertex 5000000000\n" + xyz + face_header,
               ErrorCode::invalid_mesh, {"toomany.ply:3:", "5000000000", "32-bit"});
}

// Each item of an ASCII body is a row of its own. Read as one stream of values, a vertex row with an extra
// value shifted every later value, and the error (if any) named a later row.
TEST_F(IoPly, AsciiRowsWithTooManyOrTooFewValuesAreNamed) {
  const std::string header =  // 9 lines; the vertex rows are lines 10 to 12, the face row line 13
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  expect_error("extra.ply", header + "0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n", ErrorCode::invalid_mesh,
               {"extra.ply:11: vertex 1 has 4 values, the header declares 3"});
  expect_error("few.ply", header + "0 0 0\n1 0 0\n0 1\n3 0 1 2\n", ErrorCode::invalid_mesh,
               {"few.ply:12: vertex 2 has 2 values, the header declares 3"});
  expect_error("longface.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2 0\n", ErrorCode::invalid_mesh,
               {"longface.ply:13: face 0 has 5 values, the header and its list lengths declare 4"});
  expect_error("shortface.ply", header + "0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", ErrorCode::invalid_mesh,
               {"shortface.ply:13: face 0 has 4 values, the header and its list lengths declare 5"});
  // A value missing before a later list's length: only a lower bound is known.
  expect_error("listlater.ply",
               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
               "property list uchar float weights\nend_header\n0 0 0 0\n1 0\n",
               ErrorCode::invalid_mesh,
               {"listlater.ply:10: vertex 1 has 2 values, the header and its list lengths declare at least 4"});
  // Blank rows between items are allowed, and do not shift the line numbers.
  expect_error("blank.ply", header + "0 0 0\n\n1 0 0 7\n0 1 0\n3 0 1 2\n", ErrorCode::invalid_mesh,
               {"blank.ply:12: vertex 1 has 4 values"});
}

TEST_F(IoPly, BinaryErrorsNameTheElement) {
  std::size_t face1_offset = 0;
  const std::string file = binary_ply(false, &face1_offset);
  expect_error("truncated.ply", file.substr(0, face1_offset + 6), ErrorCode::invalid_mesh,
               {"file ends inside face 1", "declares 2"});
  expect_error("cut.ply", file.substr(0, file.size() - 1), ErrorCode::invalid_mesh, {"inside material 0"});

  Bytes nan;
  nan.text("ply\nformat binary_little_endian 1.0\nelement vertex 2\n");
  nan.text("property float x\nproperty float y\nproperty float z\nend_header\n");
  nan.put(0.0f).put(0.0f).put(0.0f).put(1.0f).put(std::numeric_limits<float>::quiet_NaN()).put(0.0f);
  expect_error("nan.ply", nan.data, ErrorCode::invalid_mesh, {"vertex 1", "non-finite"});

  // Counts far beyond what the file holds are reported as truncation, without allocating for them.
  Bytes huge;
  huge.text("ply\nformat binary_little_endian 1.0\nelement vertex 3\n");
  huge.text("property float x\nproperty float y\nproperty float z\n");
  huge.text("element face 1000000000000\nproperty list uchar int vertex_indices\nend_header\n");
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) huge.put(v);
  huge.put<std::uint8_t>(3).put<std::int32_t>(0).put<std::int32_t>(1).put<std::int32_t>(2);
  expect_error("huge.ply", huge.data, ErrorCode::invalid_mesh, {"inside face 1", "1000000000000"});

  Bytes long_list;
  long_list.text("ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n");
  long_list.text("property float z\nproperty list uint int junk\nend_header\n");
  long_list.put(0.f).put(0.f).put(0.f).put<std::uint32_t>(4000000000u).put<std::int32_t>(7);
  expect_error("longlist.ply", long_list.data, ErrorCode::invalid_mesh, {"inside vertex 0"});
}

}  // namespace
