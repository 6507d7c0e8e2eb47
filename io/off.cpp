// Object File Format (Geomview OFF), ASCII: an optional `OFF` keyword (or a prefixed variant such as COFF,
// NOFF, STOFF whose extra per-vertex values are ignored), a line with the vertex, face and (ignored) edge
// counts, one vertex per line, then one polygon per line as `n i0 ... i(n-1)` with optional trailing colour
// values. `#` starts a comment.
//
// The header is read from start to end; a body of several chunks of lines is read on the team, giving the
// soup and the first error of a reading from start to end.
#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "assert.hpp"
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

// The counts of the header: the body's rows are the vertices' rows, then the faces'.
struct OffCounts {
  std::uint64_t vertices = 0, faces = 0;
  std::uint64_t rows() const { return vertices + faces; }  // no overflow: vertices fit in 32 bits
};

// Moves to the next row, that of item `row`; fails naming what is missing if the file has no more.
void begin_row(TextCursor& cursor, const OffCounts& counts, std::uint64_t row) {
  if (cursor.next_data_line()) return;
  if (row < counts.vertices) {
    cursor.fail("file ends after " + std::to_string(row) + " of " + std::to_string(counts.vertices) + " vertices");
  }
  cursor.fail("file ends after " + std::to_string(row - counts.vertices) + " of " + std::to_string(counts.faces) +
              " faces");
}

// The row of item `row`: a vertex's position (values after it, such as a colour, are ignored), or a face's
// corner count and that many vertex indices (colour values after them are ignored). Skimmed, only a face's
// corner count is converted and its indices checked to be there, and the sink counts its triangles.
template <Reading reading, class Sink>
void read_row(TextCursor& cursor, const OffCounts& counts, std::uint64_t row, std::vector<std::uint32_t>& polygon,
              Sink& sink) {
  begin_row(cursor, counts, row);
  if (row < counts.vertices) {
    if constexpr (reading == Reading::parse) sink.position(cursor.read_position());
    return;
  }
  const std::uint64_t corners = read_count(cursor, "face vertex count");
  if (corners < 3) cursor.fail(too_few_corners(corners));
  polygon.clear();
  for (std::uint64_t c = 0; c < corners; ++c) {
    if constexpr (reading == Reading::skim) {
      cursor.read_token("face vertex index");
    } else {
      const std::int64_t index = cursor.read_integer("face vertex index");
      if (index < 0 || static_cast<std::uint64_t>(index) >= counts.vertices) {
        cursor.fail(index_out_of_range(index, counts.vertices));
      }
      polygon.push_back(static_cast<std::uint32_t>(index));
    }
  }
  if constexpr (reading == Reading::skim) {
    sink.triangles += fan_triangle_count(corners);
  } else {
    emit_fan(polygon, sink);
  }
}

// The body in chunks of lines on the team. Pass 1 counts each chunk's lines and rows, so that each chunk
// knows which rows it holds; pass 2 skims its face rows for the triangles they make; pass 3 parses every
// chunk into its place. Rows after the last face are never read, as from start to end.
MeshSoup read_body_in_chunks(const MeshFile& file, const OffCounts& counts, const TextChunks& chunks,
                             const ParallelTeam& team) {
  const std::size_t chunk_count = chunks.count();
  const auto rows_of = [&](std::size_t k) {
    return std::pair{std::min(chunks.rows_before[k], counts.rows()),
                     std::min(chunks.rows_before[k + 1], counts.rows())};
  };
  std::vector<std::uint64_t> triangles_before(chunk_count + 1, 0);
  team.for_each(chunk_count, 1, [&](std::size_t k) {
    const auto [first, end] = rows_of(k);
    if (end <= counts.vertices) return;
    TextCursor cursor = chunks.cursor(file, '#', k);
    std::vector<std::uint32_t> polygon;
    TriangleCounter counter;
    try {
      for (std::uint64_t row = first; row < end; ++row) read_row<Reading::skim>(cursor, counts, row, polygon, counter);
    } catch (const Error&) {
      // Counted up to this row; pass 3 stops at its error, or an earlier one, before writing past them.
    }
    triangles_before[k + 1] = counter.triangles;
  });
  for (std::size_t k = 0; k < chunk_count; ++k) triangles_before[k + 1] += triangles_before[k];

  const std::uint64_t rows_read = std::min(chunks.rows_before[chunk_count], counts.rows());
  MeshSoup soup;
  resize_on_team(team, soup.positions, 3 * std::min(rows_read, counts.vertices));
  resize_on_team(team, soup.triangles, 3 * triangles_before[chunk_count]);
  for_each_chunk(team, chunk_count, [&](std::size_t k) {
    const auto [first, end] = rows_of(k);
    TextCursor cursor = chunks.cursor(file, '#', k);
    SoupWriter sink{soup.positions.data() + 3 * std::min(first, counts.vertices),
                    soup.triangles.data() + 3 * triangles_before[k]};
    std::vector<std::uint32_t> polygon;
    for (std::uint64_t row = first; row < end; ++row) read_row<Reading::parse>(cursor, counts, row, polygon, sink);
    EXACTGEO_ASSERT(sink.next_triangle == soup.triangles.data() + 3 * triangles_before[k + 1]);
  });
  if (rows_read < counts.rows()) {  // the error a reading from start to end meets at the end of the file
    TextCursor end = chunks.end_cursor(file, '#');
    begin_row(end, counts, rows_read);
  }
  return soup;
}

}  // namespace

MeshSoup read_off(const MeshFile& file, const ParallelTeam& team, std::size_t min_chunk_bytes) {
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
  OffCounts counts;
  counts.vertices = read_count(cursor, "vertex count");
  counts.faces = read_count(cursor, "face count");
  if (counts.vertices > std::numeric_limits<std::uint32_t>::max()) {
    cursor.fail(too_many_vertices(counts.vertices));
  }

  const std::size_t body_offset = cursor.offset_after_line();
  std::vector<std::size_t> bounds = line_chunks(file.bytes, body_offset, team, min_chunk_bytes);
  if (bounds.size() > 2) {
    return read_body_in_chunks(file, counts, count_chunk_rows(file, '#', std::move(bounds), cursor.line_number(), team),
                               team);
  }
  // One chunk (a small body, or one thread): read on from the header, row after row.
  MeshSoup soup;
  // Each vertex or face line holds at least "0 0 0\n" or "3 0 0 0\n".
  const std::size_t bytes_left = file.bytes.size() - body_offset;
  soup.positions.reserve(3 * plausible_count(counts.vertices, bytes_left, 6));
  soup.triangles.reserve(3 * plausible_count(counts.faces, bytes_left, 8));
  SoupAppender sink{soup};
  std::vector<std::uint32_t> polygon;
  for (std::uint64_t row = 0; row < counts.rows(); ++row) read_row<Reading::parse>(cursor, counts, row, polygon, sink);
  return soup;
}

}  // namespace exactgeo::detail
