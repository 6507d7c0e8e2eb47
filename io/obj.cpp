// Wavefront OBJ: `v` positions and `f` polygons; every other statement (vt, vn, o, g, s, usemtl, l, ...)
// is ignored. Face corners may be written v, v/vt, v//vn or v/vt/vn; indices are 1-based, or negative
// to count back from the latest vertex.
//
// Read in chunks of lines on the team: a first pass counts each chunk's lines, vertices and triangles, so
// that a second pass parses every chunk straight into its place in the soup, knowing how many vertices come
// before each line (relative indices, range checks) and each line's number (messages). The soup and the
// first error are those of a reading from start to end.
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

// Whether a line's first token is the one-letter statement `letter` (compared as characters: comparing
// string views calls memcmp, a tenth of a large file's reading).
bool is_statement(std::string_view token, char letter) { return token.size() == 1 && token[0] == letter; }

// The corners of the face line most files write, plain 1-based indices each perhaps followed by /vt or //vn,
// separated by blanks ("f 12 7 9", "f 12/3/12 7/4/7 9/5/9"), read straight from the rest of the line
// (`corners`) into `polygon` as zero-based indices, without cutting the line into tokens first. False for
// anything else (a sign, a comment, index 0 or out of range, a stray character), which the tokens then
// read, or name as the error.
bool read_plain_corners(std::string_view corners, std::size_t vertex_count, std::vector<std::uint32_t>& polygon) {
  polygon.clear();
  const char* at = corners.data();
  const char* const end = at + corners.size();
  for (;;) {
    at = skip_blanks(at, end);
    if (at == end) return true;
    std::uint64_t index = 0;  // wraps past 19 digits, but more than 10 are refused
    const char* const first_digit = at;
    at = read_digit_run(at, end, index);
    if (at == first_digit || at - first_digit > 10 || index == 0 || index > vertex_count) return false;
    if (at != end && *at == '/') at = token_end(at, end);  // texture and normal indices: not read, as in corner_index
    if (at != end && !is_blank(*at)) return false;
    polygon.push_back(static_cast<std::uint32_t>(index - 1));
  }
}

// What a chunk holds, and so where its lines, vertices and triangles start once the chunks before it are
// summed.
struct ChunkCounts {
  std::size_t lines = 0, vertices = 0, triangles = 0;
};

ChunkCounts count_chunk(const MeshFile& file, std::size_t begin, std::size_t end) {
  ChunkCounts counts;
  TextCursor cursor(file, '#', begin, end, 0);
  while (cursor.next_line()) {
    const std::string_view statement = cursor.next_token();
    if (is_statement(statement, 'v')) {
      ++counts.vertices;
    } else if (is_statement(statement, 'f')) {
      counts.triangles += fan_triangle_count(cursor.count_tokens());  // fewer than 3: an error the parsing pass raises
    }
  }
  counts.lines = cursor.line_number();
  return counts;
}

void parse_chunk(const MeshFile& file, std::size_t begin, std::size_t end, const ChunkCounts& before,
                 MeshSoup& soup) {
  TextCursor cursor(file, '#', begin, end, before.lines);
  SoupWriter sink{soup.positions.data() + 3 * before.vertices, soup.triangles.data() + 3 * before.triangles};
  std::size_t vertex_count = before.vertices;
  std::vector<std::uint32_t> polygon;
  while (cursor.next_line()) {
    const std::string_view statement = cursor.next_token();
    if (is_statement(statement, 'v')) {
      const std::array<double, 3> p = cursor.read_position();
      if (vertex_count + 1 > std::numeric_limits<std::uint32_t>::max()) cursor.fail(too_many_vertices(vertex_count + 1));
      sink.position(p);
      ++vertex_count;
    } else if (is_statement(statement, 'f')) {
      if (read_plain_corners(cursor.rest_of_line(), vertex_count, polygon)) {
        cursor.skip_rest_of_line();
      } else {
        polygon.clear();
        for (std::string_view token = cursor.next_token(); !token.empty(); token = cursor.next_token()) {
          polygon.push_back(corner_index(cursor, token, vertex_count));
        }
      }
      if (polygon.size() < 3) cursor.fail(too_few_corners(polygon.size()));
      emit_fan(polygon, sink);
    }
  }
}

}  // namespace

MeshSoup read_obj(const MeshFile& file, const ParallelTeam& team, std::size_t min_chunk_bytes) {
  const std::vector<std::size_t> bounds = line_chunks(file.bytes, 0, team, min_chunk_bytes);
  const std::size_t chunks = bounds.size() - 1;
  // Pass 1: counts; then where each chunk starts.
  std::vector<ChunkCounts> before(chunks + 1);
  team.for_each(chunks, 1, [&](std::size_t k) { before[k + 1] = count_chunk(file, bounds[k], bounds[k + 1]); });
  for (std::size_t k = 0; k < chunks; ++k) {
    before[k + 1].lines += before[k].lines;
    before[k + 1].vertices += before[k].vertices;
    before[k + 1].triangles += before[k].triangles;
  }
  MeshSoup soup;
  resize_on_team(team, soup.positions, 3 * before[chunks].vertices);
  resize_on_team(team, soup.triangles, 3 * before[chunks].triangles);
  // Pass 2: every chunk parsed into its place; the earliest chunk's error is the file's first.
  for_each_chunk(team, chunks, [&](std::size_t k) { parse_chunk(file, bounds[k], bounds[k + 1], before[k], soup); });
  return soup;
}

}  // namespace exactgeo::detail
