// Reading in chunks on several threads gives what reading from start to end gives: the same soup, or the same
// first error with the same line number or element item. Checked on seeded random files of every format
// with every line ending, comments, extra values and elements, and defects, cut into chunks of a few bytes
// and blocks of single items (so that chunks begin and end everywhere), and on the shared meshes, also
// written as OFF and PLY.
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

// A PLY file as generated: its elements, each item's values per property (a list's start with its length),
// written as ASCII rows or as binary in either byte order.
struct PlyModel {
  struct Property {
    std::string count_type;  // empty for a scalar
    std::string type, name;
    // The type of the property's i-th value: a list's length comes first.
    const std::string& type_of(std::size_t i) const { return i == 0 && !count_type.empty() ? count_type : type; }
    std::string declaration() const {
      return (count_type.empty() ? "" : "list " + count_type + " ") + type + " " + name;
    }
  };
  struct Element {
    std::string name;
    std::uint64_t count = 0;  // as declared; the items may be fewer
    std::vector<Property> properties;
    std::vector<std::vector<std::vector<double>>> items;
  };
  std::vector<Element> elements;

  Element& element(const std::string& name) {
    return *std::find_if(elements.begin(), elements.end(), [&](const Element& e) { return e.name == name; });
  }
  static bool is_float(const std::string& type) {
    return type == "float" || type == "double" || type == "float32" || type == "float64";
  }
  static bool is_signed(const std::string& type) {
    return is_float(type) || type == "char" || type == "short" || type == "int" || type.starts_with("int");
  }

  std::vector<std::string> header_lines(const std::string& format) const {
    std::vector<std::string> lines = {"ply", "format " + format + " 1.0", "comment generated"};
    for (const Element& element : elements) {
      lines.push_back("element " + element.name + " " + std::to_string(element.count));
      for (const Property& property : element.properties) lines.push_back("property " + property.declaration());
    }
    lines.push_back("end_header");
    return lines;
  }

  // Each item's values as the tokens of its row.
  std::vector<std::vector<std::string>> ascii_rows() const {
    std::vector<std::vector<std::string>> rows;
    for (const Element& element : elements)
      for (const auto& item : element.items) {
        rows.emplace_back();
        for (std::size_t p = 0; p < element.properties.size(); ++p)
          for (std::size_t i = 0; i < item[p].size(); ++i) {
            char buffer[40];
            std::snprintf(buffer, sizeof buffer, is_float(element.properties[p].type_of(i)) ? "%.17g" : "%.0f",
                          item[p][i]);
            rows.back().push_back(buffer);
          }
      }
    return rows;
  }

  std::string binary_body(bool big_endian) const {
    std::string bytes;
    const auto put = [&](auto value) {
      char raw[sizeof value];
      std::memcpy(raw, &value, sizeof value);
      if (big_endian != (std::endian::native == std::endian::big)) std::reverse(raw, raw + sizeof value);
      bytes.append(raw, sizeof value);
    };
    const auto put_as = [&](const std::string& type, double value) {
      if (type == "char" || type == "int8") put(static_cast<std::int8_t>(value));
      if (type == "uchar" || type == "uint8") put(static_cast<std::uint8_t>(value));
      if (type == "short" || type == "int16") put(static_cast<std::int16_t>(value));
      if (type == "ushort" || type == "uint16") put(static_cast<std::uint16_t>(value));
      if (type == "int" || type == "int32") put(static_cast<std::int32_t>(value));
      if (type == "uint" || type == "uint32") put(static_cast<std::uint32_t>(value));
      if (type == "float" || type == "float32") put(static_cast<float>(value));
      if (type == "double" || type == "float64") put(value);
    };
    for (const Element& element : elements)
      for (const auto& item : element.items)
        for (std::size_t p = 0; p < element.properties.size(); ++p)
          for (std::size_t i = 0; i < item[p].size(); ++i) put_as(element.properties[p].type_of(i), item[p][i]);
    return bytes;
  }
};

// Random elements: sometimes one before the vertices and one after the faces (with lists), vertices with
// x, y, z of any type among other values (sometimes a list), an element without properties, faces of 3 to 5
// corners (or all triangles) with values beside the index list, sometimes triangle strips.
PlyModel random_ply_model(std::mt19937_64& random) {
  const auto pick = [&](std::initializer_list<const char*> names) {
    return std::string(names.begin()[random() % names.size()]);
  };
  const auto any_scalar = [&] {
    return pick({"char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint16", "float32",
                 "float64"});
  };
  // A value in the range of every type (char's included).
  const auto value_of = [&](const std::string& type) {
    return PlyModel::is_float(type) ? std::uniform_real_distribution<double>(-10, 10)(random)
                                    : static_cast<double>(random() % 100) - (PlyModel::is_signed(type) ? 50 : 0);
  };
  const auto scalar = [&](const std::string& type) { return std::vector<double>{value_of(type)}; };
  const auto list = [&](const std::string& type, std::size_t length) {
    std::vector<double> values = {static_cast<double>(length)};
    for (std::size_t i = 0; i < length; ++i) values.push_back(value_of(type));
    return values;
  };

  PlyModel model;
  const std::uint64_t vertex_count = 3 + random() % 20;
  if (random() % 4 == 0) {
    model.elements.push_back({"camera", 1 + random() % 2, {{"", "float", "a"}, {"uchar", "int", "ids"}}, {}});
  }
  PlyModel::Element vertex{"vertex", vertex_count, {}, {}};
  for (const char* axis : {"x", "y", "z"}) {
    vertex.properties.push_back({"", random() % 4 == 0 ? any_scalar() : pick({"float", "double"}), axis});
  }
  for (std::uint64_t extra = random() % 3; extra > 0; --extra) {
    vertex.properties.insert(vertex.properties.begin() + static_cast<std::ptrdiff_t>(random() % 4),
                             {"", any_scalar(), "extra" + std::to_string(extra)});
  }
  if (random() % 5 == 0) vertex.properties.push_back({pick({"uchar", "int"}), "float", "weights"});
  model.elements.push_back(vertex);
  if (random() % 6 == 0) model.elements.push_back({"nothing", 5000000000, {}, {}});
  PlyModel::Element face{"face", 1 + random() % 25, {}, {}};
  if (random() % 3 == 0) face.properties.push_back({"", "uchar", "flags"});
  face.properties.push_back({pick({"uchar", "int", "char", "ushort", "uint8", "int32"}),
                             vertex_count < 100 && random() % 4 == 0 ? pick({"uchar", "short", "float"})
                                                                     : pick({"int", "uint", "int32", "uint32"}),
                             random() % 5 == 0 ? "vertex_index" : "vertex_indices"});
  if (random() % 3 == 0) face.properties.push_back({"", "float", "quality"});
  model.elements.push_back(face);
  if (random() % 6 == 0) {
    model.elements.push_back({"tristrips", 1 + random() % 2, {{"int", "int", "vertex_indices"}}, {}});
  }
  if (random() % 4 == 0) model.elements.push_back({"material", 1 + random() % 3, {{"int", "double", "values"}}, {}});

  const bool all_triangles = random() % 2 == 0;
  for (PlyModel::Element& element : model.elements) {
    element.items.resize(element.properties.empty() ? 0 : element.count);
    for (auto& item : element.items) {
      for (const PlyModel::Property& property : element.properties) {
        if (property.count_type.empty()) {
          item.push_back(scalar(property.type));
        } else if (property.name.starts_with("vertex_ind")) {
          const bool strip = element.name == "tristrips";
          const std::size_t corners = strip ? 3 + random() % 6 : all_triangles ? 3 : 3 + random() % 3;
          std::vector<double> indices = {static_cast<double>(corners)};
          for (std::size_t c = 0; c < corners; ++c) {
            indices.push_back(strip && random() % 5 == 0 ? -1.0 : static_cast<double>(random() % vertex_count));
          }
          item.push_back(indices);
        } else {
          item.push_back(list(property.type, random() % 4));
        }
      }
    }
  }
  return model;
}

// One defect in the values, where the model allows it: a non-finite coordinate, an index out of range or not
// whole, too few corners, a negative list length.
void add_value_defect(std::mt19937_64& random, PlyModel& model) {
  PlyModel::Element& vertex = model.element("vertex");
  PlyModel::Element& face = model.element("face");
  const std::size_t corner_list = face.properties.front().count_type.empty() ? 1 : 0;
  const PlyModel::Property& corners = face.properties[corner_list];
  std::vector<double>& polygon = face.items[random() % face.items.size()][corner_list];
  switch (random() % 5) {
    case 0: {
      const std::size_t axis = random() % vertex.properties.size();
      if (vertex.properties[axis].count_type.empty() && PlyModel::is_float(vertex.properties[axis].type)) {
        vertex.items[random() % vertex.items.size()][axis][0] = random() % 2 ? std::nan("") : -HUGE_VAL;
      }
      break;
    }
    case 1: polygon[1 + random() % (polygon.size() - 1)] = static_cast<double>(vertex.count + random() % 5); break;
    case 2:
      if (PlyModel::is_float(corners.type)) polygon[1] = 1.5;
      else if (PlyModel::is_signed(corners.type)) polygon[1] = -1;
      break;
    case 3: polygon = {2, 0, 1}; break;
    case 4:
      if (PlyModel::is_signed(corners.count_type)) polygon = {-1};
      break;
  }
}

// A random ASCII PLY: rows of a random model, each ending in LF, CRLF or a lone CR, with blank lines between
// and rows after the last item (never read); with `defects`, a chance of a defect in the values, a malformed
// number, a value too many or too few on a row, or missing rows.
std::string random_ascii_ply(std::mt19937_64& random, bool defects) {
  PlyModel model = random_ply_model(random);
  if (defects && random() % 3 == 0) add_value_defect(random, model);
  std::vector<std::vector<std::string>> rows = model.ascii_rows();
  if (random() % 4 == 0) rows.push_back({"1", "2", "3"});
  if (defects && random() % 2 == 0) {
    std::vector<std::string>& row = rows[random() % rows.size()];
    switch (random() % 4) {
      case 0: row[random() % row.size()] = random() % 2 ? "x" : "1e"; break;
      case 1: row.push_back("7"); break;
      case 2: row.pop_back(); break;
      case 3: rows.resize(rows.size() - 1 - random() % rows.size()); break;
    }
  }
  std::string text;
  for (const std::string& line : model.header_lines("ascii")) text += line + random_line_end(random);
  for (const std::vector<std::string>& row : rows) {
    if (random() % 8 == 0) text += std::string(random() % 2 ? " \t" : "") + random_line_end(random);
    for (std::size_t t = 0; t < row.size(); ++t) text += (t == 0 ? "" : random() % 5 == 0 ? "  " : " ") + row[t];
    text += random_line_end(random);
  }
  return text;
}

TEST(IoChunks, RandomAsciiPlyFilesReadTheSameInChunks) {
  std::mt19937_64 random(1994);
  Tally tally;
  for (int file = 0; file < 120; ++file) {
    const std::string text = random_ascii_ply(random, file % 2 == 1);
    expect_same_as_serial(&exactgeo::detail::read_ply, text, "random ASCII PLY " + std::to_string(file));
    tally.add(&exactgeo::detail::read_ply, text);
  }
  EXPECT_GE(tally.valid, 60);
  EXPECT_GE(tally.failed, 20);
}

// A random binary PLY in either byte order, its header's lines ending alike in LF, CRLF or a lone CR; with
// `defects`, a chance of a defect in the values or of the file cut short anywhere in its body.
std::string random_binary_ply(std::mt19937_64& random, bool defects) {
  PlyModel model = random_ply_model(random);
  if (defects && random() % 2 == 0) add_value_defect(random, model);
  const bool big_endian = random() % 2 == 0;
  const char* line_end = random() % 4 == 0 ? random_line_end(random) : "\n";
  std::string bytes;
  for (const std::string& line : model.header_lines(big_endian ? "binary_big_endian" : "binary_little_endian")) {
    bytes += line + line_end;
  }
  const std::size_t header_size = bytes.size();
  bytes += model.binary_body(big_endian);
  if (defects && random() % 3 == 0) bytes.resize(header_size + random() % (bytes.size() - header_size));
  return bytes;
}

TEST(IoChunks, RandomBinaryPlyFilesReadTheSameOnTheTeam) {
  std::mt19937_64 random(777);
  Tally tally;
  for (int file = 0; file < 160; ++file) {
    const std::string bytes = random_binary_ply(random, file % 2 == 1);
    expect_same_as_serial(&exactgeo::detail::read_ply, bytes, "random binary PLY " + std::to_string(file));
    tally.add(&exactgeo::detail::read_ply, bytes);
  }
  EXPECT_GE(tally.valid, 80);
  EXPECT_GE(tally.failed, 25);
}

TEST(IoChunks, ErrorsNameTheirLineInAnyChunk) {
  // The first of several errors is reported, whichever chunk holds it.
  const std::string text = "v 0 0 0\r\nv 1 0 0\rv 0 1 0\n\nf 1 2 3\r\nf 1 2 x\nf 1 2 0\nv 1 1 nan\n";
  expect_same_as_serial(&exactgeo::detail::read_obj, text, "three errors");
  WorkerPool two(2);
  const Outcome chunked = read_with(&exactgeo::detail::read_obj, {"chunks.txt", text}, two, 1);
  EXPECT_NE(chunked.error.find("chunks.txt:6:"), std::string::npos) << chunked.error;
}

// A soup as a PLY model: double x, y, z and a list uchar int vertex_indices.
PlyModel ply_model_of(const MeshSoup& soup) {
  PlyModel model;
  model.elements.push_back(
      {"vertex", soup.positions.size() / 3, {{"", "double", "x"}, {"", "double", "y"}, {"", "double", "z"}}, {}});
  for (std::size_t v = 0; v < soup.positions.size(); v += 3) {
    model.elements.back().items.push_back({{soup.positions[v]}, {soup.positions[v + 1]}, {soup.positions[v + 2]}});
  }
  model.elements.push_back({"face", soup.triangles.size() / 3, {{"uchar", "int", "vertex_indices"}}, {}});
  for (std::size_t t = 0; t < soup.triangles.size(); t += 3) {
    const auto corner = [&](std::size_t c) { return static_cast<double>(soup.triangles[t + c]); };
    model.elements.back().items.push_back({{3, corner(0), corner(1), corner(2)}});
  }
  return model;
}

std::string join_lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

// The soup as each format would hold it: OFF, ASCII PLY, binary PLY in both byte orders.
std::vector<std::pair<std::string, std::string>> other_formats_of(const MeshSoup& soup) {
  const PlyModel model = ply_model_of(soup);
  std::vector<std::string> ascii_lines;
  for (const std::vector<std::string>& row : model.ascii_rows()) {
    std::string line;
    for (const std::string& token : row) line += (line.empty() ? "" : " ") + token;
    ascii_lines.push_back(line);
  }
  const std::string ascii_body = join_lines(ascii_lines);
  std::vector<std::pair<std::string, std::string>> files;
  files.emplace_back("OFF", "OFF\n" + std::to_string(soup.positions.size() / 3) + " " +
                                std::to_string(soup.triangles.size() / 3) + " 0\n" + ascii_body);
  files.emplace_back("ASCII PLY", join_lines(model.header_lines("ascii")) + ascii_body);
  for (bool big_endian : {false, true}) {
    files.emplace_back(big_endian ? "big-endian PLY" : "little-endian PLY",
                       join_lines(model.header_lines(big_endian ? "binary_big_endian" : "binary_little_endian")) +
                           model.binary_body(big_endian));
  }
  return files;
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
    // Written as OFF and PLY, the mesh reads back as the same soup, whole or in chunks of 4 KiB.
    WorkerPool one(1);
    for (const auto& [format, bytes] : other_formats_of(whole)) {
      const Reader reader = format == "OFF" ? &exactgeo::detail::read_off : &exactgeo::detail::read_ply;
      for (const Outcome& outcome : {read_with(reader, {name, bytes}, one, exactgeo::detail::kMinChunkBytes),
                                     read_with(reader, {name, bytes}, three, 4096)}) {
        EXPECT_EQ(outcome.error, "") << name << " as " << format;
        EXPECT_EQ(outcome.soup.positions, whole.positions) << name << " as " << format;
        EXPECT_EQ(outcome.soup.triangles, whole.triangles) << name << " as " << format;
      }
    }
  }
}

}  // namespace
