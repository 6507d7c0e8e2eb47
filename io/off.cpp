// Object File Format (Geomview OFF), ASCII: an optional `OFF` keyword (or a prefixed variant such as COFF,
// NOFF, STOFF whose extra per-vertex values are ignored), a line with the vertex, face and (ignored) edge
// counts, one vertex per line, then one polygon per line as `n i0 ... i(n-1)` with optional trailing colour
// values. `#` starts a comment.
#include <array>
#include <cstdint>
#include <limits>
#include <string>

#include "readers.hpp"

namespace exactgeo::detail {
namespace {

// The keyword is [ST][C][N]OFF; the letters announce extra values on vertex lines, which are skipped anyway.
// 4OFF (homogeneous coordinates) and nOFF (a dimension line) change the layout and are rejected.
bool is_off_keyword(std::string_view token) {
  if (!token.ends_with("OFF")) return false;
  std::string_view prefix = token.substr(0, token.size() - 3);
  for (std::string_view letters : {"ST", "C", "N"}) {
    if (prefix.starts_with(letters)) prefix.remove_prefix(letters.size());
  }
  return prefix.empty();
}

std::uint64_t read_count(TextCursor& cursor, std::string_view what) {
  const std::int64_t count = cursor.read_integer(what);
  if (count < 0) cursor.fail("negative " + std::string(what));
  return static_cast<std::uint64_t>(count);
}

}  // namespace

MeshSoup read_off(const MeshFile& file, const ParallelTeam&, std::size_t) {
  TextCursor cursor(file, '#');
  if (!cursor.next_data_line()) throw_file_error(file, "empty file (no OFF header)");

  // The keyword may be followed by the counts on the same line, or be left out altogether.
  const std::string_view first = cursor.peek_token();
  if (is_off_keyword(first)) {
    cursor.next_token();
    if (cursor.peek_token() == "BINARY") cursor.fail("binary OFF is not supported");
    if (cursor.peek_token().empty() && !cursor.next_data_line()) cursor.fail("missing vertex and face counts");
  } else if (first.ends_with("OFF")) {
    cursor.fail("unsupported OFF variant " + quoted(first));
  }
  const std::uint64_t vertex_count = read_count(cursor, "vertex count");
  const std::uint64_t face_count = read_count(cursor, "face count");
  if (vertex_count > std::numeric_limits<std::uint32_t>::max()) {
    cursor.fail(too_many_vertices(vertex_count));
  }

  MeshSoup soup;
  // Each vertex or face line holds at least "0 0 0\n" or "3 0 0 0\n".
  const std::size_t bytes_left = file.bytes.size() - cursor.offset_after_line();
  soup.positions.reserve(3 * plausible_count(vertex_count, bytes_left, 6));
  for (std::uint64_t v = 0; v < vertex_count; ++v) {
    if (!cursor.next_data_line()) {
      cursor.fail("file ends after " + std::to_string(v) + " of " + std::to_string(vertex_count) + " vertices");
    }
    const std::array<double, 3> position = cursor.read_position();
    soup.positions.insert(soup.positions.end(), position.begin(), position.end());
  }

  soup.triangles.reserve(3 * plausible_count(face_count, bytes_left, 8));
  std::vector<std::uint32_t> polygon;
  for (std::uint64_t f = 0; f < face_count; ++f) {
    if (!cursor.next_data_line()) {
      cursor.fail("file ends after " + std::to_string(f) + " of " + std::to_string(face_count) + " faces");
    }
    const std::uint64_t corners = read_count(cursor, "face vertex count");
    if (corners < 3) cursor.fail(too_few_corners(corners));
    polygon.clear();
    for (std::uint64_t c = 0; c < corners; ++c) {
      const std::int64_t index = cursor.read_integer("face vertex index");
      if (index < 0 || static_cast<std::uint64_t>(index) >= vertex_count) {
        cursor.fail(index_out_of_range(index, vertex_count));
      }
      polygon.push_back(static_cast<std::uint32_t>(index));
    }
    append_fan(polygon, soup.triangles);
  }
  return soup;
}

}  // namespace exactgeo::detail
