// The per-vertex files other tools read: ASCII and binary PLY with distances and colours, legacy VTK.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.hpp"

namespace {

using namespace exactgeo_test;

// What --out's help says the PLY files hold is what the PLY tests below read: it once called the distance a float.
TEST_F(Cli, HelpSaysWhatThePlyFilesHold) {
  const RunResult result = run("distance --help");
  EXPECT_NE(result.out.find(".ply (the mesh, binary: float coordinates, a double distance property and colours;"),
            std::string::npos)
      << result.out;
  EXPECT_NE(result.out.find(".ascii.ply (the same as text, the coordinates as doubles too)"), std::string::npos)
      << result.out;
}

TEST_F(Cli, AsciiPlyOutputCarriesDistancesAndColours) {
  ASSERT_EQ(run("distance @grid:2:2 --source 0 --labels --out " + arg("d.ascii.ply")).exit_code, 0);
  std::istringstream lines(read_file(path("d.ascii.ply")));
  std::string line;
  std::vector<std::string> header;
  while (std::getline(lines, line) && line != "end_header") header.push_back(line);
  for (const char* expected : {"ply", "format ascii 1.0", "element vertex 9", "property double distance",
                               "property int nearest_source", "property uchar red", "element face 8",
                               "property list uchar int vertex_indices"})
    EXPECT_NE(std::find(header.begin(), header.end(), expected), header.end()) << expected;
  for (int v = 0; v < 9; ++v) {
    ASSERT_TRUE(std::getline(lines, line));
    double x, y, z, distance;
    int label, red, green, blue;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf %lf %lf %lf %d %d %d %d", &x, &y, &z, &distance, &label, &red, &green,
                          &blue), 8) << line;
    EXPECT_NEAR(distance, std::hypot(x, y), 1e-12);
    EXPECT_EQ(label, 0);
  }
  int faces = 0;
  while (std::getline(lines, line)) faces += line.rfind("3 ", 0) == 0;
  EXPECT_EQ(faces, 8);
}

// A binary little-endian PLY as .ply writes it: the header, then per vertex float x, y, z, double distance
// (int nearest_source with labels) and uchar red, green, blue, then per face a uchar 3 and three ints.
struct BinaryPly {
  std::vector<std::string> header;
  std::vector<std::array<float, 3>> vertices;  // x, y, z
  std::vector<double> distances;
  std::vector<std::int32_t> labels;
  std::vector<std::array<int, 3>> colours;
  std::vector<std::array<std::int32_t, 3>> faces;
};

BinaryPly read_binary_ply(const std::string& bytes, std::size_t vertex_count, std::size_t face_count, bool labels) {
  BinaryPly ply;
  std::size_t at = 0;
  while (true) {
    const std::size_t end = bytes.find('\n', at);
    if (end == std::string::npos) {
      ADD_FAILURE() << "no end_header";
      return ply;
    }
    ply.header.push_back(bytes.substr(at, end - at));
    at = end + 1;
    if (ply.header.back() == "end_header") break;
  }
  const auto u32 = [&] {
    std::uint32_t bits = 0;
    for (int byte = 0; byte < 4; ++byte) bits |= std::uint32_t(std::uint8_t(bytes[at++])) << (8 * byte);
    return bits;
  };
  const std::size_t vertex_bytes = 20 + (labels ? 4 : 0) + 3;
  EXPECT_EQ(bytes.size(), at + vertex_count * vertex_bytes + face_count * 13) << "the file's size";
  if (bytes.size() != at + vertex_count * vertex_bytes + face_count * 13) return ply;
  for (std::size_t v = 0; v < vertex_count; ++v) {
    std::array<float, 3> vertex{};
    for (float& value : vertex) value = std::bit_cast<float>(u32());
    ply.vertices.push_back(vertex);
    const std::uint64_t low = u32();
    ply.distances.push_back(std::bit_cast<double>(low | std::uint64_t{u32()} << 32));
    if (labels) ply.labels.push_back(std::bit_cast<std::int32_t>(u32()));
    ply.colours.push_back({std::uint8_t(bytes[at]), std::uint8_t(bytes[at + 1]), std::uint8_t(bytes[at + 2])});
    at += 3;
  }
  for (std::size_t f = 0; f < face_count; ++f) {
    EXPECT_EQ(bytes[at++], 3);
    std::array<std::int32_t, 3> face{};
    for (std::int32_t& corner : face) corner = std::bit_cast<std::int32_t>(u32());
    ply.faces.push_back(face);
  }
  return ply;
}

// .ply is binary: the same mesh, distances (the .npy's, bit for bit) and colours as .ascii.ply, unreachable vertices grey
// with distance inf; a quarter of the text's size or less.
TEST_F(Cli, PlyOutputIsBinaryWithTheAsciiPlysValues) {
  // Two grids side by side: the second is unreachable from vertex 0.
  write_file(path("two.obj"),
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0\nf 1 2 3\nf 2 4 3\nf 5 6 7\n");
  for (const bool labels : {false, true}) {
    const std::string flag = labels ? " --labels" : "";
    for (const char* mesh : {"@torus:24:10", "two.obj"}) {
      const std::string name = mesh[0] == '@' ? mesh : arg(mesh);
      ASSERT_EQ(run("distance " + name + " --source 0" + flag + " --out " + arg("d.ply")).exit_code, 0);
      ASSERT_EQ(run("distance " + name + " --source 0" + flag + " --out " + arg("d.ascii.ply")).exit_code, 0);
      ASSERT_EQ(run("distance " + name + " --source 0 --out " + arg("d.npy")).exit_code, 0);
      const std::vector<double> distances = parse_npy(path("d.npy"));
      const std::size_t n = distances.size();
      const std::size_t faces = mesh[0] == '@' ? 480 : 3;
      const BinaryPly ply = read_binary_ply(read_file(path("d.ply")), n, faces, labels);
      ASSERT_EQ(ply.vertices.size(), n);
      std::vector<std::string> expected_header = {"ply",
                                                  "format binary_little_endian 1.0",
                                                  "comment written by exactgeo",
                                                  "element vertex " + std::to_string(n),
                                                  "property float x",
                                                  "property float y",
                                                  "property float z",
                                                  "property double distance"};
      if (labels) expected_header.push_back("property int nearest_source");
      for (const char* line : {"property uchar red", "property uchar green", "property uchar blue"})
        expected_header.push_back(line);
      for (const std::string line : {"element face " + std::to_string(faces), std::string("property list uchar int vertex_indices"),
                                     std::string("end_header")})
        expected_header.push_back(line);
      EXPECT_EQ(ply.header, expected_header);
      // The text file: positions, distances and colours per vertex line, faces after.
      std::istringstream text(read_file(path("d.ascii.ply")));
      std::string line;
      while (std::getline(text, line) && line != "end_header") {}
      for (std::size_t v = 0; v < n; ++v) {
        ASSERT_TRUE(std::getline(text, line));
        std::istringstream fields(line);
        double x, y, z;
        std::string distance;
        int label = 0, red, green, blue;
        fields >> x >> y >> z >> distance;
        if (labels) fields >> label;
        fields >> red >> green >> blue;
        ASSERT_TRUE(fields) << line;
        EXPECT_EQ(ply.vertices[v][0], static_cast<float>(x));
        EXPECT_EQ(ply.vertices[v][1], static_cast<float>(y));
        EXPECT_EQ(ply.vertices[v][2], static_cast<float>(z));
        EXPECT_EQ(ply.distances[v], distances[v]) << v;
        EXPECT_EQ(std::isinf(distances[v]), distance == "inf");
        if (labels) EXPECT_EQ(ply.labels[v], label);
        EXPECT_EQ(ply.colours[v], (std::array<int, 3>{red, green, blue})) << v;
        if (std::isinf(distances[v])) EXPECT_EQ(ply.colours[v], (std::array<int, 3>{128, 128, 128}));
      }
      for (std::size_t f = 0; f < faces; ++f) {
        ASSERT_TRUE(std::getline(text, line));
        std::array<std::int32_t, 3> face{};
        int count = 0;
        std::istringstream(line) >> count >> face[0] >> face[1] >> face[2];
        EXPECT_EQ(count, 3);
        EXPECT_EQ(ply.faces[f], face) << f;
      }
      if (mesh[0] == '@') EXPECT_LT(read_file(path("d.ply")).size() * 2, read_file(path("d.ascii.ply")).size());
      // The library reads it back: the same mesh.
      ASSERT_EQ(run("info " + arg("d.ply") + " --json").exit_code, 0);
    }
  }
  EXPECT_EQ(run("distance @grid:2:2 --source 0 --out " + arg("D.PLY")).exit_code, 0);
  EXPECT_EQ(read_file(path("D.PLY")).find("format binary_little_endian 1.0"), 4u);
}

// A legacy binary VTK file as .vtk writes it: text lines, each block of big-endian numbers followed by a newline.
struct LegacyVtk {
  std::vector<std::string> lines;  // the text lines, in order
  std::vector<double> points;      // x, y, z per vertex
  std::vector<std::int32_t> polygons;
  std::vector<double> distances;
  std::vector<std::int32_t> labels;
};

LegacyVtk read_legacy_vtk(const std::string& bytes, std::size_t vertex_count, std::size_t face_count, bool labels) {
  LegacyVtk vtk;
  std::size_t at = 0;
  const auto line = [&] {
    const std::size_t end = bytes.find('\n', at);
    vtk.lines.push_back(bytes.substr(at, end - at));
    at = end == std::string::npos ? bytes.size() : end + 1;
  };
  const auto big_endian = [&](std::size_t size) {
    std::uint64_t bits = 0;
    for (std::size_t byte = 0; byte < size && at < bytes.size(); ++byte) bits = bits << 8 | std::uint8_t(bytes[at++]);
    return bits;
  };
  const auto doubles = [&](std::vector<double>& values, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) values.push_back(std::bit_cast<double>(big_endian(8)));
    EXPECT_EQ(bytes[at++], '\n') << "a newline after the binary block";
  };
  const auto ints = [&](std::vector<std::int32_t>& values, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i)
      values.push_back(std::bit_cast<std::int32_t>(static_cast<std::uint32_t>(big_endian(4))));
    EXPECT_EQ(bytes[at++], '\n') << "a newline after the binary block";
  };
  for (int i = 0; i < 5; ++i) line();
  doubles(vtk.points, 3 * vertex_count);
  line();
  ints(vtk.polygons, 4 * face_count);
  for (int i = 0; i < 3; ++i) line();
  doubles(vtk.distances, vertex_count);
  if (labels) {
    for (int i = 0; i < 2; ++i) line();
    ints(vtk.labels, vertex_count);
  }
  EXPECT_EQ(at, bytes.size()) << "bytes after the last block";
  return vtk;
}

// .vtk: the mesh with the distance as point data, which VTK-based tools read (their PLY reader keeps only
// colours): the positions and distances exactly, bit for bit the .npy's, inf included; labels as ints.
TEST_F(Cli, VtkOutputCarriesTheMeshAndTheDistancesExactly) {
  write_file(path("two.obj"),
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0.1\nf 1 2 3\nf 2 4 3\nf 5 6 7\n");
  ASSERT_EQ(run("distance " + arg("two.obj") + " --source 0 --out " + arg("d.npy")).exit_code, 0);
  ASSERT_EQ(run("distance " + arg("two.obj") + " --source 0 --labels --out " + arg("d.vtk")).exit_code, 0);
  const std::vector<double> distances = parse_npy(path("d.npy"));
  ASSERT_EQ(distances.size(), 7u);
  EXPECT_TRUE(std::isinf(distances[6]));
  const LegacyVtk vtk = read_legacy_vtk(read_file(path("d.vtk")), 7, 3, true);
  const std::vector<std::string> expected_lines = {"# vtk DataFile Version 3.0",
                                                   "written by exactgeo",
                                                   "BINARY",
                                                   "DATASET POLYDATA",
                                                   "POINTS 7 double",
                                                   "POLYGONS 3 12",
                                                   "POINT_DATA 7",
                                                   "SCALARS distance double 1",
                                                   "LOOKUP_TABLE default",
                                                   "SCALARS nearest_source int 1",
                                                   "LOOKUP_TABLE default"};
  EXPECT_EQ(vtk.lines, expected_lines);
  EXPECT_EQ(vtk.points, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 5, 0, 0, 6, 0, 0, 5, 1, 0.1}));
  EXPECT_EQ(vtk.polygons, (std::vector<std::int32_t>{3, 0, 1, 2, 3, 1, 3, 2, 3, 4, 5, 6}));
  expect_bitwise_equal(vtk.distances, distances);
  EXPECT_EQ(vtk.labels, (std::vector<std::int32_t>{0, 0, 0, 0, -1, -1, -1}));
  // Without labels the distance is the only point data.
  ASSERT_EQ(run("distance @torus:24:10 --source 3 --out " + arg("t.vtk")).exit_code, 0);
  ASSERT_EQ(run("distance @torus:24:10 --source 3 --out " + arg("t.npy")).exit_code, 0);
  const LegacyVtk torus = read_legacy_vtk(read_file(path("t.vtk")), 240, 480, false);
  expect_bitwise_equal(torus.distances, parse_npy(path("t.npy")));
  EXPECT_EQ(torus.lines.back(), "LOOKUP_TABLE default");
}

}  // namespace
