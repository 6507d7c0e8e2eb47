// Mesh file readers: each format's features and errors on small files written here, the shared test
// meshes against the counts in their README, round trips, and random mutations of valid files.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/io.hpp"
#include "exactgeo/mesh.hpp"
#include "exactgeo/shapes.hpp"

namespace {

namespace fs = std::filesystem;
using exactgeo::Error;
using exactgeo::ErrorCode;
using exactgeo::MeshSoup;
using exactgeo::read_mesh_soup;

// Little- or big-endian binary content built value by value.
class Bytes {
 public:
  explicit Bytes(bool big_endian = false) : big_endian_(big_endian) {}

  template <class T>
  Bytes& put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (big_endian_ != (std::endian::native == std::endian::big)) std::reverse(raw, raw + sizeof(T));
    data.append(raw, sizeof(T));
    return *this;
  }
  Bytes& text(std::string_view s) {
    data += s;
    return *this;
  }

  std::string data;

 private:
  bool big_endian_;
};

std::string shortest(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

void expect_contains(const std::string& message, const std::string& fragment) {
  EXPECT_NE(message.find(fragment), std::string::npos) << "message: " << message << "\nexpected: " << fragment;
}

// Every test works in its own directory, removed afterwards.
class IoFileTest : public testing::Test {
 protected:
  void SetUp() override {
    const testing::TestInfo* info = testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("exactgeo_" + std::string(info->test_suite_name()) + "_" + info->name() +
                                        "_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& name, std::string_view bytes) const {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path;
  }

  // Reads `bytes` as file `name` and expects an error with `code` whose message has every fragment.
  void expect_error(const std::string& name, std::string_view bytes, ErrorCode code,
                    std::initializer_list<std::string> fragments) const {
    const fs::path path = write(name, bytes);
    try {
      read_mesh_soup(path);
      ADD_FAILURE() << name << " was read without error";
    } catch (const Error& error) {
      EXPECT_EQ(error.code(), code) << error.what();
      expect_contains(error.what(), name);
      for (const std::string& fragment : fragments) expect_contains(error.what(), fragment);
    }
  }

  fs::path dir_;
};

const std::vector<double> kTetraPositions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};

// ---------------------------------------------------------------------------------------------- OBJ

class IoObj : public IoFileTest {};

TEST_F(IoObj, ReadsPositionsAndTriangles) {
  const MeshSoup soup = read_mesh_soup(write("tetra.obj",
                                             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                             "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"));
  EXPECT_EQ(soup.positions, kTetraPositions);
  EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3}));
}

// A UTF-8 byte-order mark (Windows editors write one) is not part of the first statement: read as part of it,
// the first `v` line was dropped and every index shifted.
constexpr std::string_view kBom = "\xEF\xBB\xBF";

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

// A binary PLY with every numeric type: x, y, z in different types between properties to skip, a list
// property on vertices, an element before the faces and one after them with a list.
std::string binary_ply(bool big_endian, std::size_t* face1_offset = nullptr) {
  Bytes bytes(big_endian);
  bytes.text("ply\n");
  bytes.text(big_endian ? "format binary_big_endian 1.0\n" : "format binary_little_endian 1.0\n");
  bytes.text(
      "comment every type\n"
      "element vertex 4\n"
      "property uchar red\n"
      "property float32 x\n"
      "property list uint8 int16 weights\n"
      "property double y\n"
      "property short temperature\n"
      "property int z\n"
      "property ushort flags\n"
      "property char tag\n"
      "property uint32 id\n"
      "element edge 1\n"
      "property int32 vertex1\n"
      "property int32 vertex2\n"
      "element face 2\n"
      "property list uchar int vertex_indices\n"
      "property float quality\n"
      "element material 1\n"
      "property list int float64 values\n"
      "end_header\n");
  const float xs[] = {0.5f, -1.25f, 3.0f, 0.0f};
  const double ys[] = {0.1, 2.5, -7.75, 1e-300};
  const std::int32_t zs[] = {3, -4, 100000, 0};
  for (int v = 0; v < 4; ++v) {
    bytes.put<std::uint8_t>(200).put(xs[v]);
    bytes.put<std::uint8_t>(static_cast<std::uint8_t>(v));  // weights: v values
    for (int w = 0; w < v; ++w) bytes.put<std::int16_t>(-1);
    bytes.put(ys[v]).put<std::int16_t>(-300).put(zs[v]).put<std::uint16_t>(65535);
    bytes.put<std::int8_t>(-5).put<std::uint32_t>(4000000000u);
  }
  bytes.put<std::int32_t>(0).put<std::int32_t>(1);
  bytes.put<std::uint8_t>(4).put<std::int32_t>(0).put<std::int32_t>(1).put<std::int32_t>(2).put<std::int32_t>(3);
  bytes.put(0.5f);
  if (face1_offset) *face1_offset = bytes.data.size();
  bytes.put<std::uint8_t>(3).put<std::int32_t>(3).put<std::int32_t>(2).put<std::int32_t>(1);
  bytes.put(0.25f);
  bytes.put<std::int32_t>(2).put(1.0).put(2.0);
  return bytes.data;
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

// ---------------------------------------------------------------------------------------------- STL

class IoStl : public IoFileTest {};

// Two triangles sharing the edge B-C: A B C and C B D. A repeated position is written once more, as a
// distinct float that happens to be close, to check merging is exact.
const std::array<std::array<float, 3>, 6> kStlCorners = {{
    {0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f},   // A B C
    {0, 1, 0.5f}, {1, 0, 0}, {1, 1, 0},  // C B D
}};
const std::vector<double> kStlPositions = {0, 0, 0, 1, 0, 0, 0, 1, 0.5, 1, 1, 0};
const std::vector<std::uint32_t> kStlTriangles = {0, 1, 2, 2, 1, 3};

std::string binary_stl(std::string_view header_text, std::uint32_t declared_triangles) {
  Bytes bytes;
  std::string header(header_text);
  header.resize(80, ' ');
  bytes.text(header).put(declared_triangles);
  for (int t = 0; t < 2; ++t) {
    bytes.put(0.f).put(0.f).put(1.f);
    for (int c = 0; c < 3; ++c) {
      for (float v : kStlCorners[3 * t + c]) bytes.put(v);
    }
    bytes.put<std::uint16_t>(0);
  }
  return bytes.data;
}

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

// ------------------------------------------------------------------------------------- line endings

class IoLineEndings : public IoFileTest {};

// `text` with each LF replaced by `line_end`.
std::string with_line_ends(std::string_view text, std::string_view line_end) {
  std::string converted;
  for (char c : text) {
    if (c == '\n') {
      converted += line_end;
    } else {
      converted += c;
    }
  }
  return converted;
}

// Files whose lines end in a lone CR (classic Mac OS) were read as a single line: an OBJ had "no faces".
// Every text format reads CR-only and CRLF files as it reads the LF file.
TEST_F(IoLineEndings, CrOnlyAndCrlfReadLikeLf) {
  const std::pair<std::string, std::string> kFiles[] = {
      {"tetra.obj", "# tetrahedron\nv 0 0 0\nv 1 0 0\n\nv 0 1 0\nv 0 0 1 # last\n"
                    "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4"},
      {"tetra.off", "OFF\n# counts\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n"},
      {"tetra.ply", "ply\nformat ascii 1.0\ncomment lines\nelement vertex 4\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
                    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n"},
      {"part.stl", "solid part\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0.5\n"
                   "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 1 0.5\nvertex 1 0 0\n"
                   "vertex 1 1 0\nendloop\nendfacet\nendsolid part\n"},
  };
  for (const auto& [name, text] : kFiles) {
    const MeshSoup expected = read_mesh_soup(write(name, text));
    for (const std::string_view line_end : {"\r", "\r\n"}) {
      SCOPED_TRACE(name + (line_end == "\r" ? " CR" : " CRLF"));
      const MeshSoup soup = read_mesh_soup(write(name, with_line_ends(text, line_end)));
      EXPECT_EQ(soup.positions, expected.positions);
      EXPECT_EQ(soup.triangles, expected.triangles);
    }
  }
}

TEST_F(IoLineEndings, ErrorsCountCrOnlyLines) {
  for (const std::string_view line_end : {"\r", "\r\n"}) {
    SCOPED_TRACE(line_end == "\r" ? "CR" : "CRLF");
    const auto lines = [&](std::string_view text) { return with_line_ends(text, line_end); };
    expect_error("range.obj", lines("v 0 0 0\nv 1 0 0\n\nv 0 1 0\nf 1 2 4\n"), ErrorCode::invalid_mesh,
                 {"range.obj:5:", "4 out of range"});
    expect_error("range.off", lines("OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), ErrorCode::invalid_mesh,
                 {"range.off:6:", "3 out of range"});
    expect_error("type.ply", lines("ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n"),
                 ErrorCode::invalid_mesh, {"type.ply:4:", "float128"});
    expect_error("number.ply",
                 lines("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                       "property float z\nend_header\n0 0 0\n1 zero 0\n"),
                 ErrorCode::invalid_mesh, {"number.ply:9:", "'zero'"});
    expect_error("keyword.stl", lines("solid x\nfacet normal 0 0 1\nouter loop\nvertx 1 2 3\n"),
                 ErrorCode::invalid_mesh, {"keyword.stl:4:", "'vertx'"});
  }
}

// A binary PLY's header may end its lines in a lone CR; its body then starts right after end_header's CR,
// even when the first byte of the body is an LF (here: a uchar property of value 10).
TEST_F(IoLineEndings, BinaryPlyAfterCrOnlyHeader) {
  const auto binary = [](std::string_view line_end) {
    Bytes bytes;
    bytes.text(with_line_ends("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty uchar flags\n"
                              "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                              "property list uchar int vertex_indices\nend_header\n",
                              line_end));
    for (const std::array<float, 3> p : {std::array{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}}) {
      bytes.put<std::uint8_t>('\n').put(p[0]).put(p[1]).put(p[2]);
    }
    bytes.put<std::uint8_t>(3).put<std::int32_t>(0).put<std::int32_t>(1).put<std::int32_t>(2);
    return bytes.data;
  };
  const MeshSoup expected = read_mesh_soup(write("lf.ply", binary("\n")));
  EXPECT_EQ(expected.positions, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  for (const std::string_view line_end : {"\r", "\r\n"}) {
    const MeshSoup soup = read_mesh_soup(write("other.ply", binary(line_end)));
    EXPECT_EQ(soup.positions, expected.positions);
    EXPECT_EQ(soup.triangles, expected.triangles);
  }
}

// --------------------------------------------------------------------------------- files and dispatch

class IoFiles : public IoFileTest {};

TEST_F(IoFiles, ExtensionIsCaseInsensitive) {
  const MeshSoup soup = read_mesh_soup(write("TRIANGLE.Obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_EQ(soup.triangles, (std::vector<std::uint32_t>{0, 1, 2}));
}

TEST_F(IoFiles, UnknownExtensionIsNamed) {
  expect_error("mesh.xyz", "v 0 0 0\n", ErrorCode::invalid_mesh, {"'.xyz'"});
  expect_error("mesh", "v 0 0 0\n", ErrorCode::invalid_mesh, {"no extension"});
}

TEST_F(IoFiles, UnreadableFileIsAnIoErrorWithTheReason) {
  const fs::path missing = dir_ / "missing.obj";
  try {
    read_mesh_soup(missing);
    ADD_FAILURE() << "a missing file was read";
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::io_error);
    expect_contains(error.what(), missing.string());
    expect_contains(error.what(), std::strerror(ENOENT));
  }
  const fs::path directory = dir_ / "folder.ply";
  fs::create_directory(directory);
  try {
    read_mesh_soup(directory);
    ADD_FAILURE() << "a directory was read";
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::io_error);
    expect_contains(error.what(), directory.string());
  }
}

// Anything but a regular file is refused before it is opened: a link to /dev/zero was read until memory ran
// out, and opening a FIFO waited for a writer forever.
TEST_F(IoFiles, NonRegularFilesAreRefusedBeforeReading) {
  const fs::path zero = dir_ / "zero.obj";
  fs::create_symlink("/dev/zero", zero);
  const fs::path directory = dir_ / "folder.ply";
  fs::create_directory(directory);
  const fs::path fifo = dir_ / "pipe.off";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  for (const auto& [path, kind] : {std::pair{zero, "a device"}, {directory, "a directory"}, {fifo, "a FIFO"}}) {
    SCOPED_TRACE(path.string());
    for (const bool load : {false, true}) {
      try {
        if (load) {
          exactgeo::load_mesh(path);
        } else {
          read_mesh_soup(path);
        }
        ADD_FAILURE() << "read without error";
      } catch (const Error& error) {
        EXPECT_EQ(error.code(), ErrorCode::io_error);
        expect_contains(error.what(), "cannot read '" + path.string() + "': not a regular file");
        expect_contains(error.what(), kind);
      }
    }
  }
}

TEST_F(IoFiles, LoadMeshValidatesTheSoup) {
  const fs::path path = write("tetra.off", "OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                           "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n");
  const exactgeo::Mesh mesh = exactgeo::load_mesh(path);
  EXPECT_EQ(mesh.vertex_count(), 4u);
  EXPECT_EQ(mesh.face_count(), 4u);
  EXPECT_EQ(std::vector<double>(mesh.positions().begin(), mesh.positions().end()), kTetraPositions);
}

// ------------------------------------------------------------------------------------- shared meshes

TEST(IoSharedMeshes, CountsMatchTheReadme) {
  const fs::path dir = EXACTGEO_SHARED_MESH_DIR;
  if (!fs::is_directory(dir)) GTEST_SKIP() << "shared meshes not found at " << dir;
  struct Expected {
    const char* file;
    std::size_t vertices;
    std::size_t faces;
  };
  // From the table in the directory's README.md (faces after fan triangulation).
  const Expected kExpected[] = {
      {"woody.obj", 694, 1267},        {"suzanne.obj", 507, 968},
      {"beetle.obj", 1148, 2053},      {"cow.obj", 2903, 5804},
      {"spot.obj", 2930, 5856},        {"teapot.obj", 3644, 6320},
      {"homer.obj", 6002, 12000},      {"fandisk.obj", 6475, 12946},
      {"rocker-arm.obj", 10044, 20088}, {"stanford-bunny.obj", 35947, 69451},
      {"nefertiti.obj", 49971, 99938},
  };
  for (const Expected& expected : kExpected) {
    SCOPED_TRACE(expected.file);
    const MeshSoup soup = read_mesh_soup(dir / expected.file);
    EXPECT_EQ(soup.positions.size(), 3 * expected.vertices);
    EXPECT_EQ(soup.triangles.size(), 3 * expected.faces);
  }
}

// ---------------------------------------------------------------------------------------- round trip

class IoRoundTrip : public IoFileTest {};

TEST_F(IoRoundTrip, WrittenFilesReadBackEqual) {
  const MeshSoup mesh = exactgeo::make_bumpy_torus(12, 7);
  const std::size_t vertex_count = mesh.positions.size() / 3;
  const std::size_t face_count = mesh.triangles.size() / 3;
  ASSERT_GT(face_count, 0u);

  std::string obj = "# round trip\n";
  for (std::size_t v = 0; v < vertex_count; ++v) {
    obj += "v " + shortest(mesh.positions[3 * v]) + " " + shortest(mesh.positions[3 * v + 1]) + " " +
           shortest(mesh.positions[3 * v + 2]) + "\n";
  }
  for (std::size_t f = 0; f < face_count; ++f) {
    obj += "f " + std::to_string(mesh.triangles[3 * f] + 1) + " " + std::to_string(mesh.triangles[3 * f + 1] + 1) +
           " " + std::to_string(mesh.triangles[3 * f + 2] + 1) + "\n";
  }

  std::string off = "OFF\n" + std::to_string(vertex_count) + " " + std::to_string(face_count) + " 0\n";
  for (std::size_t v = 0; v < vertex_count; ++v) {
    off += shortest(mesh.positions[3 * v]) + " " + shortest(mesh.positions[3 * v + 1]) + " " +
           shortest(mesh.positions[3 * v + 2]) + "\n";
  }
  for (std::size_t f = 0; f < face_count; ++f) {
    off += "3 " + std::to_string(mesh.triangles[3 * f]) + " " + std::to_string(mesh.triangles[3 * f + 1]) + " " +
           std::to_string(mesh.triangles[3 * f + 2]) + "\n";
  }

  Bytes ply(true);
  ply.text("ply\nformat binary_big_endian 1.0\nelement vertex " + std::to_string(vertex_count) + "\n");
  ply.text("property double x\nproperty double y\nproperty double z\n");
  ply.text("element face " + std::to_string(face_count) + "\nproperty list uchar uint vertex_indices\nend_header\n");
  for (double coordinate : mesh.positions) ply.put(coordinate);
  for (std::size_t f = 0; f < face_count; ++f) {
    ply.put<std::uint8_t>(3).put(mesh.triangles[3 * f]).put(mesh.triangles[3 * f + 1]).put(mesh.triangles[3 * f + 2]);
  }

  for (const auto& [name, bytes] : {std::pair{"torus.obj", obj}, {"torus.off", off}, {"torus.ply", ply.data}}) {
    SCOPED_TRACE(name);
    const MeshSoup soup = read_mesh_soup(write(name, bytes));
    EXPECT_EQ(soup.positions, mesh.positions);
    EXPECT_EQ(soup.triangles, mesh.triangles);
  }

  // STL keeps float corners per triangle: expect the same corners in float precision, and one vertex per
  // distinct float position.
  Bytes stl;
  stl.text(std::string(80, '\0')).put(static_cast<std::uint32_t>(face_count));
  std::set<std::array<float, 3>> distinct;
  for (std::size_t f = 0; f < face_count; ++f) {
    stl.put(0.f).put(0.f).put(0.f);
    for (int c = 0; c < 3; ++c) {
      const std::size_t v = mesh.triangles[3 * f + c];
      const std::array<float, 3> corner = {static_cast<float>(mesh.positions[3 * v]),
                                           static_cast<float>(mesh.positions[3 * v + 1]),
                                           static_cast<float>(mesh.positions[3 * v + 2])};
      for (float coordinate : corner) stl.put(coordinate);
      distinct.insert(corner);
    }
    stl.put<std::uint16_t>(0);
  }
  const MeshSoup soup = read_mesh_soup(write("torus.stl", stl.data));
  EXPECT_EQ(soup.positions.size(), 3 * distinct.size());
  ASSERT_EQ(soup.triangles.size(), mesh.triangles.size());
  for (std::size_t corner = 0; corner < mesh.triangles.size(); ++corner) {
    for (int axis = 0; axis < 3; ++axis) {
      ASSERT_EQ(soup.positions[3 * soup.triangles[corner] + axis],
                static_cast<float>(mesh.positions[3 * mesh.triangles[corner] + axis]))
          << "corner " << corner;
    }
  }
}

// ---------------------------------------------------------------------------------------- mutations

class IoMutations : public IoFileTest {};

// Random damage to valid files of every format must end in a result or an exactgeo::Error, never in a
// crash, a hang or another exception. Fixed seed, so a failure reproduces.
TEST_F(IoMutations, DamagedFilesFailCleanly) {
  const std::pair<std::string, std::string> kSeeds[] = {
      {"seed.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1/1 2//2 3/3/3 -1\nf 4 3 2\n"},
      {"seed.off", "COFF\n4 2 0\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n0 1 0 1 1 1 1\n1 1 0 1 1 1 1\n4 0 1 3 2\n3 0 1 2 9\n"},
      {"seed.ply", binary_ply(false)},
      {"seed.ply", binary_ply(true)},
      {"seed.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
      {"seed.stl", binary_stl("solid binary", 2)},
      {"seed.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                   "endloop\nendfacet\nendsolid s\n"},
  };
  const std::string kInteresting[] = {"-1", "0", "4294967295", "999999999999", "nan", "1e999", "\n", " ", "/",
                                      "#", "-", "list", "end_header", "\r\n"};
  std::mt19937 random(12345);
  auto below = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(random); };
  for (int round = 0; round < 300; ++round) {
    const auto& [name, seed] = kSeeds[round % std::size(kSeeds)];
    std::string bytes = seed;
    const int edits = 1 + static_cast<int>(below(4));
    for (int e = 0; e < edits && !bytes.empty(); ++e) {
      const std::size_t at = below(bytes.size());
      switch (below(5)) {
        case 0: bytes[at] = static_cast<char>(below(256)); break;
        case 1: bytes.erase(at, 1 + below(8)); break;
        case 2: bytes.insert(at, kInteresting[below(std::size(kInteresting))]); break;
        case 3: bytes.resize(at); break;
        case 4: bytes.insert(at, bytes.substr(below(bytes.size()), 1 + below(16))); break;
      }
    }
    try {
      // A new name each round: rewriting one file would make the file system flush it every time.
      read_mesh_soup(write(std::to_string(round) + name, bytes));
    } catch (const Error&) {
    } catch (const std::exception& other) {
      ADD_FAILURE() << "round " << round << " (" << name << "): unexpected " << other.what();
    }
  }
}

}  // namespace
