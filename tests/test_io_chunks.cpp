// Reading in chunks on several threads gives what reading from start to end gives: the same soup, or the same
// first error with the same line number. Checked on seeded random files with every line ending, comments,
// relative indices and defects, cut into chunks of a few bytes (so that chunks begin and end everywhere),
// and on the shared meshes.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <limits>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include "exactgeo/error.hpp"
#include "exactgeo/io.hpp"
#include "readers.hpp"
#include "test_meshes.hpp"

namespace {

using exactgeo::MeshSoup;
using exactgeo::detail::MeshFile;
using exactgeo::detail::ParallelTeam;
using exactgeo::detail::WorkerPool;

using Reader = MeshSoup (*)(const MeshFile&, const ParallelTeam&, std::size_t);

// The soup, or the error's message.
struct Outcome {
  MeshSoup soup;
  std::string error;
};

// On more than one thread, every pass over items is cut into ranges of single items too.
Outcome read_with(Reader reader, const MeshFile& file, WorkerPool& pool, std::size_t chunk_bytes) {
  Outcome outcome;
  try {
    outcome.soup = reader(file, ParallelTeam{pool, {}, pool.threads() > 1 ? 1u : 0u}, chunk_bytes);
  } catch (const exactgeo::Error& e) {
    outcome.error = e.what();
  }
  return outcome;
}

void expect_same_as_serial(Reader reader, const std::string& text, const std::string& what) {
  WorkerPool one(1), two(2), three(3);
  const MeshFile file{"chunks.txt", text};
  const Outcome serial = read_with(reader, file, one, exactgeo::detail::kMinChunkBytes);
  for (WorkerPool* pool : {&two, &three})
    for (std::size_t chunk_bytes : {1, 2, 3, 5, 8, 13, 64}) {
      const Outcome chunked = read_with(reader, file, *pool, chunk_bytes);
      ASSERT_EQ(chunked.error, serial.error) << what << ", " << pool->threads() << " threads, chunks of " << chunk_bytes;
      ASSERT_EQ(chunked.soup.positions, serial.soup.positions) << what << ", chunks of " << chunk_bytes;
      ASSERT_EQ(chunked.soup.triangles, serial.soup.triangles) << what << ", chunks of " << chunk_bytes;
    }
}

// A random OBJ text: vertices and polygons (3 to 5 corners, absolute or relative indices, slash forms), other
// statements, comments and blank lines, any mix of LF, CRLF and lone CR, and with `defects` > 0 a chance of
// a malformed line (a bad number, index 0, an index out of range, too few corners).
std::string random_obj(std::mt19937_64& random, int lines, bool defects) {
  std::string text = random() % 4 == 0 ? "\xEF\xBB\xBF" : "";
  const char* endings[] = {"\n", "\r\n", "\r"};
  std::uniform_real_distribution<double> coordinate(-10, 10);
  int vertices = 0;
  for (int line = 0; line < lines; ++line) {
    const int kind = static_cast<int>(random() % 10);
    if (kind < 4 || vertices < 3) {
      char buffer[96];
      std::snprintf(buffer, sizeof buffer, "v %.17g %.9g %g", coordinate(random), coordinate(random), coordinate(random));
      text += buffer;
      ++vertices;
    } else if (kind < 8) {
      const int corners = 3 + static_cast<int>(random() % 3);
      text += "f";
      for (int c = 0; c < corners; ++c) {
        const int index = 1 + static_cast<int>(random() % vertices);
        text += random() % 3 == 0 ? " " + std::to_string(index - vertices - 1) : " " + std::to_string(index);
        if (random() % 4 == 0) text += "/1/2";
      }
    } else if (kind == 8) {
      text += random() % 2 ? "# a comment" : "vn 0 0 1";
    }
    if (defects && random() % 200 == 0) {
      const char* bad[] = {"v 1 2 x", "f 1 0 2", "f 1 2 99999", "f 1 2", "v 1e999 0 0", "f 1 -99999 2"};
      text += endings[random() % 3];
      text += bad[random() % 6];
    }
    text += endings[random() % 3];
  }
  return text;
}

TEST(IoChunks, RandomObjFilesReadTheSameInChunks) {
  std::mt19937_64 random(20261127);
  for (int file = 0; file < 60; ++file) {
    const std::string text = random_obj(random, 20 + file * 3, file % 2 == 1);
    expect_same_as_serial(&exactgeo::detail::read_obj, text, "random OBJ " + std::to_string(file));
  }
}

// A binary STL whose corners are drawn from a few positions, -0 and +0 among them, so that many are shared;
// with `defect`, one corner somewhere is not finite.
std::string random_binary_stl(std::mt19937_64& random, int triangles, bool defect) {
  std::string bytes(80, ' ');
  const auto put = [&](auto value) { bytes.append(reinterpret_cast<const char*>(&value), sizeof value); };
  put(static_cast<std::uint32_t>(triangles));
  const float pool[] = {0.0f, -0.0f, 1.0f, 2.5f, -3.0f};
  const int bad = defect ? static_cast<int>(random() % (9 * triangles)) : -1;
  for (int t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) put(0.0f);  // the normal
    for (int c = 0; c < 9; ++c) put(9 * t + c == bad ? std::numeric_limits<float>::infinity() : pool[random() % 5]);
    put(std::uint16_t{0});
  }
  return bytes;
}

TEST(IoChunks, BinaryStlSharesCornersAsInOrder) {
  std::mt19937_64 random(3804);
  for (int file = 0; file < 20; ++file) {
    const std::string bytes = random_binary_stl(random, 5 + file * 7, file % 3 == 2);
    expect_same_as_serial(&exactgeo::detail::read_stl, bytes, "random STL " + std::to_string(file));
  }
}

TEST(IoChunks, ErrorsNameTheirLineInAnyChunk) {
  // The first of several errors is reported, whichever chunk holds it.
  const std::string text = "v 0 0 0\r\nv 1 0 0\rv 0 1 0\n\nf 1 2 3\r\nf 1 2 x\nf 1 2 0\nv 1 1 nan\n";
  expect_same_as_serial(&exactgeo::detail::read_obj, text, "three errors");
  WorkerPool two(2);
  const Outcome chunked = read_with(&exactgeo::detail::read_obj, {"chunks.txt", text}, two, 1);
  EXPECT_NE(chunked.error.find("chunks.txt:6:"), std::string::npos) << chunked.error;
}

TEST(IoChunks, SharedMeshesReadTheSameInChunks) {
  EXACTGEO_SKIP_IF_NO_SHARED_MESHES();
  const std::filesystem::path dir = EXACTGEO_SHARED_MESH_DIR;
  for (const char* name : {"woody.obj", "beetle.obj", "teapot.obj", "suzanne.obj"}) {
    const MeshSoup whole = exactgeo::read_mesh_soup(dir / name, {.threads = 1});
    WorkerPool three(3);
    std::ifstream in(dir / name, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const Outcome chunked = read_with(&exactgeo::detail::read_obj, {name, text}, three, 4096);
    EXPECT_EQ(chunked.error, "") << name;
    EXPECT_EQ(chunked.soup.positions, whole.positions) << name;
    EXPECT_EQ(chunked.soup.triangles, whole.triangles) << name;
  }
}

}  // namespace
