// Helpers of the mesh reader tests (test_io*.cpp): binary content built value by value, a fixture that
// writes each test's files into a folder of its own, and sample files that several of them read.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/io.hpp"

namespace exactgeo_test {

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

inline std::string shortest(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

// The soup as OBJ text: every coordinate in its shortest form that reads back as the same double.
inline std::string obj_text(const MeshSoup& soup) {
  std::string text;
  for (std::size_t i = 0; i < soup.positions.size(); i += 3)
    text += "v " + shortest(soup.positions[i]) + " " + shortest(soup.positions[i + 1]) + " " +
            shortest(soup.positions[i + 2]) + "\n";
  for (std::size_t i = 0; i < soup.triangles.size(); i += 3)
    text += "f " + std::to_string(soup.triangles[i] + 1) + " " + std::to_string(soup.triangles[i + 1] + 1) + " " +
            std::to_string(soup.triangles[i + 2] + 1) + "\n";
  return text;
}

inline void expect_contains(const std::string& message, const std::string& fragment) {
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

inline const std::vector<double> kTetraPositions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};

// A UTF-8 byte-order mark (Windows editors write one) is not part of the first statement: read as part of it,
// the first `v` line was dropped and every index shifted.
inline constexpr std::string_view kBom = "\xEF\xBB\xBF";

// A binary PLY with every numeric type: x, y, z in different types between properties to skip, a list
// property on vertices, an element before the faces and one after them with a list.
inline std::string binary_ply(bool big_endian, std::size_t* face1_offset = nullptr) {
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

// Two triangles sharing the edge B-C: A B C and C B D. A repeated position is written once more, as a
// distinct float that happens to be close, to check merging is exact.
inline const std::array<std::array<float, 3>, 6> kStlCorners = {{
    {0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f},   // A B C
    {0, 1, 0.5f}, {1, 0, 0}, {1, 1, 0},  // C B D
}};
inline const std::vector<double> kStlPositions = {0, 0, 0, 1, 0, 0, 0, 1, 0.5, 1, 1, 0};
inline const std::vector<std::uint32_t> kStlTriangles = {0, 1, 2, 2, 1, 3};

inline std::string binary_stl(std::string_view header_text, std::uint32_t declared_triangles) {
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

}  // namespace exactgeo_test
