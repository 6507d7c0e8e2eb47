// STL, ASCII and binary. STL stores each triangle with its own three positions, so vertices are shared by
// merging equal positions (by value: -0 and 0 are one position), numbered in order of first appearance. A
// binary file may also start with "solid", so the size decides: a binary file is exactly 84 + 50 * triangle
// count bytes.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <unordered_map>

#include "readers.hpp"
#include "same_position.hpp"

namespace exactgeo::detail {
namespace {

constexpr std::size_t kBinaryHeaderBytes = 84;  // 80-byte comment, then a uint32 triangle count
constexpr std::size_t kBinaryTriangleBytes = 50;  // normal, three corners (12 floats), uint16 attribute

// Numbers positions in order of first appearance, giving equal ones the same index. Coordinates are finite
// (checked before), so the bits identify a value once -0 is mapped to 0: writers emit both for one corner,
// and keeping them apart would cut the surface there.
class VertexMerger {
 public:
  VertexMerger(MeshSoup& soup, std::size_t expected_vertices) : soup_(soup) {
    indices_.reserve(expected_vertices);
  }

  std::uint32_t index_of(double x, double y, double z) {
    const auto bits = [](double c) { return std::bit_cast<std::uint64_t>(c + 0.0); };  // -0 + 0 = +0
    const Key key = {bits(x), bits(y), bits(z)};
    const auto [it, inserted] = indices_.try_emplace(key, static_cast<std::uint32_t>(indices_.size()));
    if (inserted) soup_.positions.insert(soup_.positions.end(), {x, y, z});
    return it->second;
  }

 private:
  using Key = std::array<std::uint64_t, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& key) const noexcept {
      std::uint64_t h = key[0] * 0x9E3779B97F4A7C15ull;
      h = (h ^ (h >> 29) ^ key[1]) * 0xBF58476D1CE4E5B9ull;
      h = (h ^ (h >> 31) ^ key[2]) * 0x94D049BB133111EBull;
      return static_cast<std::size_t>(h ^ (h >> 32));
    }
  };

  MeshSoup& soup_;
  std::unordered_map<Key, std::uint32_t, KeyHash> indices_;
};

std::uint32_t load_uint32_le(const char* at) {
  unsigned char b[4];
  std::memcpy(b, at, 4);
  return std::uint32_t{b[0]} | std::uint32_t{b[1]} << 8 | std::uint32_t{b[2]} << 16 | std::uint32_t{b[3]} << 24;
}

float load_float_le(const char* at) { return std::bit_cast<float>(load_uint32_le(at)); }

// Corners are numbered by their first appearance, as VertexMerger numbers them, but found on the team: each
// corner's first corner at the same position, then the first ones numbered in order.
MeshSoup read_binary_stl(const MeshFile& file, std::uint32_t triangle_count, const ParallelTeam& team) {
  const std::size_t corner_count = 3 * std::size_t{triangle_count};
  const char* records = file.bytes.data() + kBinaryHeaderBytes;
  const auto corner_position = [&](std::size_t corner) {
    const char* at = records + corner / 3 * kBinaryTriangleBytes + 12 + 12 * (corner % 3);  // after the normal
    return std::array<double, 3>{load_float_le(at), load_float_le(at + 4), load_float_le(at + 8)};
  };
  const std::size_t bad = team.reduce_ranges(
      corner_count, 1 << 14, corner_count,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t c = begin; c < end; ++c) {
          const auto [x, y, z] = corner_position(c);
          if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return c;
        }
        return corner_count;
      },
      [](std::size_t a, std::size_t b) { return std::min(a, b); });
  if (bad < corner_count) throw_file_error(file, "triangle " + std::to_string(bad / 3) + ": non-finite coordinate");
  const MeshArray<std::uint32_t> first = first_at_same_position(team, corner_count, corner_position);
  MeshArray<std::uint32_t> vertex(corner_count);
  team.for_each(corner_count, 1 << 14, [&](std::size_t c) { vertex[c] = first[c] == c; });
  const std::uint64_t vertex_count = exclusive_prefix_sum(team, vertex);
  MeshSoup soup;
  resize_on_team(team, soup.positions, 3 * vertex_count);
  resize_on_team(team, soup.triangles, corner_count);
  team.for_each(corner_count, 1 << 14, [&](std::size_t c) {
    soup.triangles[c] = vertex[first[c]];
    if (first[c] != c) return;
    const std::array<double, 3> p = corner_position(c);
    std::copy(p.begin(), p.end(), soup.positions.begin() + 3 * std::ptrdiff_t(vertex[c]));
  });
  return soup;
}

// solid name / facet normal nx ny nz / outer loop / vertex x y z (three times) / endloop / endfacet / ... /
// endsolid name. Read token by token, so the line layout does not matter; several solids are concatenated.
MeshSoup read_ascii_stl(const MeshFile& file) {
  MeshSoup soup;
  VertexMerger merger(soup, file.bytes.size() / 512);  // ~250 bytes a facet, half as many vertices as facets
  TextCursor cursor(file);
  std::vector<std::uint32_t> polygon;
  bool in_facet = false;
  for (std::string_view token = cursor.next_token_any_line(); !token.empty();
       token = cursor.next_token_any_line()) {
    if (token == "solid" || token == "endsolid") {
      if (in_facet) cursor.fail("'" + std::string(token) + "' inside a facet");
      cursor.skip_rest_of_line();  // the solid's name
    } else if (token == "facet") {
      if (in_facet) cursor.fail("'facet' before the previous facet's 'endfacet'");
      if (cursor.next_token() != "normal") cursor.fail("expected 'normal' after 'facet'");
      // The normal is recomputable and ignored; some writers put "nan" or "1.#QNAN" there for slivers.
      for (int i = 0; i < 3; ++i) {
        if (cursor.next_token().empty()) cursor.fail("missing normal component");
      }
      in_facet = true;
      polygon.clear();
    } else if (token == "vertex") {
      if (!in_facet) cursor.fail("'vertex' outside a facet");
      const auto [x, y, z] = cursor.read_position();
      polygon.push_back(merger.index_of(x, y, z));
    } else if (token == "endfacet") {
      if (!in_facet) cursor.fail("'endfacet' without 'facet'");
      if (polygon.size() < 3) cursor.fail(too_few_corners(polygon.size()));
      SoupAppender sink{soup};
      emit_fan(polygon, sink);
      in_facet = false;
    } else if (token == "outer") {
      if (cursor.next_token() != "loop") cursor.fail("expected 'loop' after 'outer'");
    } else if (token != "endloop") {
      cursor.fail("unexpected " + quoted(token));
    }
  }
  if (in_facet) cursor.fail("file ends inside a facet");
  return soup;
}

bool starts_with_solid(std::string_view bytes) {
  bytes.remove_prefix(byte_order_mark_size(bytes));
  const std::size_t first = bytes.find_first_not_of(" \t\r\n");
  return first != std::string_view::npos && bytes.substr(first).starts_with("solid");
}

}  // namespace

MeshSoup read_stl(const MeshFile& file, const ParallelTeam& team, std::size_t) {
  const std::string_view bytes = file.bytes;
  const std::uint32_t triangle_count = bytes.size() >= kBinaryHeaderBytes ? load_uint32_le(bytes.data() + 80) : 0;
  const std::uint64_t binary_size = kBinaryHeaderBytes + std::uint64_t{kBinaryTriangleBytes} * triangle_count;
  if (bytes.size() >= kBinaryHeaderBytes && bytes.size() == binary_size) return read_binary_stl(file, triangle_count, team);
  if (starts_with_solid(bytes)) return read_ascii_stl(file);
  if (bytes.size() < kBinaryHeaderBytes) {
    throw_file_error(file, "too short for a binary STL (" + std::to_string(bytes.size()) + " bytes, need 84)");
  }
  const std::string declared = "the header declares " + std::to_string(triangle_count) + " triangles";
  if (bytes.size() < binary_size) {
    const std::size_t complete = (bytes.size() - kBinaryHeaderBytes) / kBinaryTriangleBytes;
    throw_file_error(file, "file ends inside triangle " + std::to_string(complete) + " (" + declared + ")");
  }
  throw_file_error(file, std::to_string(bytes.size() - binary_size) + " bytes after the last triangle (" +
                             declared + ")");
}

}  // namespace exactgeo::detail
