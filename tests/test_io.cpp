// Mesh file readers across formats: line endings, dispatch by extension, the shared test meshes against the
// counts in their README, round trips, and random mutations of valid files. One file per format beside it.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/io.hpp"
#include "exactgeo/mesh.hpp"
#include "exactgeo/shapes.hpp"
#include "io_test_files.hpp"

namespace {

using namespace exactgeo_test;

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

  const std::string obj = "# round trip\n" + obj_text(mesh);

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
