// Wavefront OBJ: `v` positions and `f` polygons; every other statement (vt, vn, o, g, s, usemtl, l, ...)
// is ignored. Face corners may be written v, v/vt, v//vn or v/vt/vn; indices are 1-based, or negative
// to count back from the latest vertex.
#include <array>
#include <cstdint>
#include <limits>
#include <string>

#include "readers.hpp"

namespace exactgeo::detail {
namespace {

// The vertex part of a face corner token ("7", "7/2", "7//3", "-1/2/3") as a zero-based index.
std::uint32_t corner_index(TextCursor& cursor, std::string_view token, std::size_t vertex_count) {
  const std::string_view vertex_part = token.substr(0, token.find('/'));
  std::int64_t index = 0;
  if (!parse_integer(vertex_part, index)) cursor.fail("malformed face corner " + quoted(token));
  if (index == 0) cursor.fail("face index 0 is invalid (OBJ indices start at 1)");
  const auto count = static_cast<std::int64_t>(vertex_count);
  const std::int64_t resolved = index > 0 ? index - 1 : count + index;
  if (resolved < 0 || resolved >= count) {
    cursor.fail("face index " + std::to_string(index) + " out of range (file has " + std::to_string(vertex_count) +
                " vertices before this line)");
  }
  return static_cast<std::uint32_t>(resolved);
}

}  // namespace

MeshSoup read_obj(const MeshFile& file) {
  MeshSoup soup;
  std::vector<std::uint32_t> polygon;
  TextCursor cursor(file, '#');
  while (cursor.next_line()) {
    const std::string_view statement = cursor.next_token();
    if (statement == "v") {
      const std::array<double, 3> position = cursor.read_position();
      const std::uint64_t vertex_count = soup.positions.size() / 3 + 1;
      if (vertex_count > std::numeric_limits<std::uint32_t>::max()) cursor.fail(too_many_vertices(vertex_count));
      soup.positions.insert(soup.positions.end(), position.begin(), position.end());
    } else if (statement == "f") {
      polygon.clear();
      const std::size_t vertex_count = soup.positions.size() / 3;
      for (std::string_view token = cursor.next_token(); !token.empty(); token = cursor.next_token()) {
        polygon.push_back(corner_index(cursor, token, vertex_count));
      }
      if (polygon.size() < 3) cursor.fail(too_few_corners(polygon.size()));
      append_fan(polygon, soup.triangles);
    }
  }
  return soup;
}

}  // namespace exactgeo::detail
