// Reading in chunks on several threads gives what reading from start to end gives: the same soup, or the same
// first error with the same line number. Checked on seeded random files with every line ending, comments,
// relative indices and defects, cut into chunks of a few bytes (so that chunks begin and end everywhere),
// and on the shared meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

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

const char* random_line_end(std::mt19937_64& random) {
  const char* endings[] = {"\n", "\r\n", "\r"};
  return endings[random() % 3];
}

// How many of the files a generator makes read without error: a generator whose files all fail (or none
// does) tests less than it seems to.
struct Tally {
  int valid = 0, failed = 0;
  void add(Reader reader, const std::string& text) {
    WorkerPool one(1);
    (read_with(reader, {"chunks.txt", text}, one, exactgeo::detail::kMinChunkBytes).error.empty() ? valid : failed)++;
  }
};

// A random OFF text: the keyword or none (COFF's vertex rows carry a colour), the counts on the keyword's line
// or a later one, comments and blank lines anywhere, polygons of 3 to 5 corners with optional colours, rows
// after the last face (never read), any mix of LF, CRLF and lone CR; with `defects`, a chance of a bad
// number, an index out of range, too few corners, a missing index or coordinate, or missing rows.
std::string random_off(std::mt19937_64& random, int vertex_count, int face_count, bool defects) {
  std::uniform_real_distribution<double> coordinate(-10, 10);
  const int keyword = static_cast<int>(random() % 4);  // OFF, COFF, none, OFF with the counts
  std::vector<std::string> header = {keyword == 0 ? "OFF" : keyword == 1 ? "COFF" : ""};
  const std::string counts = std::to_string(vertex_count) + " " + std::to_string(face_count) + " 0";
  if (keyword == 3) {
    header[0] = "OFF " + counts;
  } else {
    header.push_back("# the counts");
    header.push_back(counts);
  }
  std::vector<std::string> rows;
  for (int v = 0; v < vertex_count; ++v) {
    char buffer[96];
    std::snprintf(buffer, sizeof buffer, "%.17g %.9g %g", coordinate(random), coordinate(random), coordinate(random));
    rows.push_back(buffer);
    if (keyword == 1) rows.back() += " 0.5 0.5 1 1";
    if (random() % 8 == 0) rows.back() += " # a vertex";
  }
  for (int f = 0; f < face_count; ++f) {
    const int corners = 3 + static_cast<int>(random() % 3);
    rows.push_back(std::to_string(corners));
    for (int c = 0; c < corners; ++c) rows.back() += " " + std::to_string(random() % vertex_count);
    if (random() % 4 == 0) rows.back() += " 255 0 0";
  }
  if (random() % 3 == 0) rows.push_back(random() % 2 ? "3 0 1 2" : "not read");
  if (defects && random() % 3 != 0) {
    std::string& vertex = rows[random() % vertex_count];
    std::string& face = rows[vertex_count + random() % face_count];
    switch (random() % 7) {
      case 0: vertex.replace(0, vertex.find(' '), "1.5.3"); break;
      case 1: vertex = "0 0"; break;
      case 2: face = "3 0 1 " + std::to_string(random() % 2 ? vertex_count + 1 : -1); break;
      case 3: face = "2 0 1"; break;
      case 4: face = "4 0 1 2"; break;
      case 5: vertex = "1 nan 0"; break;
      case 6: rows.resize(rows.size() - 1 - random() % rows.size()); break;
    }
  }
  std::string text = random() % 4 == 0 ? "\xEF\xBB\xBF" : "";
  const auto add_line = [&](const std::string& line) {
    const int extra = static_cast<int>(random() % 10);
    if (extra == 0) text += std::string(random_line_end(random)) + (random() % 2 ? "  " : "");  // a blank line
    if (extra == 1) text += std::string("# between") + random_line_end(random);
    text += line + random_line_end(random);
  };
  for (const std::string& line : header)
    if (!line.empty()) add_line(line);
  for (const std::string& row : rows) add_line(row);
  return text;
}

TEST(IoChunks, RandomOffFilesReadTheSameInChunks) {
  std::mt19937_64 random(5150);
  Tally tally;
  for (int file = 0; file < 80; ++file) {
    const std::string text = random_off(random, 3 + file % 17, 1 + file % 23, file % 2 == 1);
    expect_same_as_serial(&exactgeo::detail::read_off, text, "random OFF " + std::to_string(file));
    tally.add(&exactgeo::detail::read_off, text);
  }
  EXPECT_GE(tally.valid, 40);
  EXPECT_GE(tally.failed, 15);
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
