// Shared pieces of the mesh file readers: the file in memory, error messages that name the file and line,
// locale-independent number parsing, fan triangulation, the sinks that items are parsed into, a line/token
// cursor for the text formats, and the chunks a body is cut into for the team.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/mesh.hpp"
#include "parallel.hpp"

namespace exactgeo::detail {

// A whole mesh file loaded into memory, and the name that prefixes every message about it.
struct MeshFile {
  std::string name;        // the path as the caller gave it
  std::string_view bytes;  // the file's content
};

// Throw Error(invalid_mesh) with the message "<name>: <reason>" (binary formats, whole-file problems).
[[noreturn]] void throw_file_error(const MeshFile& file, std::string_view reason);
// Throw Error(invalid_mesh) with the message "<name>:<line>: <reason>" (text formats; lines count from 1).
[[noreturn]] void throw_line_error(const MeshFile& file, std::size_t line, std::string_view reason);

// A token as it appears in messages: quoted, and cut short if it is long or not printable.
std::string quoted(std::string_view token);

// Whole-token parsing, independent of the C locale. An optional leading '+' is accepted. Both return false
// unless the entire token is a number; parse_double accepts "nan" and "inf", so callers check finiteness.
bool parse_double(std::string_view token, double& value);
bool parse_integer(std::string_view token, std::int64_t& value);

// The scanning rules every text reader shares: blanks separate tokens (a table: tokenising is most of
// reading a large text file), and numbers are runs of decimal digits.
inline constexpr auto kBlanks = [] {
  std::array<bool, 256> blank{};
  for (unsigned char c : {' ', '\t', '\r', '\v', '\f'}) blank[c] = true;
  return blank;
}();
inline bool is_blank(char c) { return kBlanks[static_cast<unsigned char>(c)]; }

// The first character at or after `at` that is not a blank, or `end`.
inline const char* skip_blanks(const char* at, const char* const end) {
  while (at != end && is_blank(*at)) ++at;
  return at;
}

// Where the token starting at `at` ends: the first blank after it, or `end`.
inline const char* token_end(const char* at, const char* const end) {
  while (at != end && !is_blank(*at)) ++at;
  return at;
}

// Reads the run of decimal digits at the start of [at, end) onto `value` (value = value * 10 + digit for
// each, wrapping modulo 2^64: callers refuse runs too long to fit) and returns where the run ends.
inline const char* read_digit_run(const char* at, const char* const end, std::uint64_t& value) {
  for (unsigned digit; at != end && (digit = static_cast<unsigned>(*at - '0')) < 10; ++at) value = value * 10 + digit;
  return at;
}

// How many items to reserve for `count` items declared in a header when each takes at least
// `min_bytes_per_item` of the `bytes_left` in the file: a lying header must not allocate gigabytes.
std::size_t plausible_count(std::uint64_t count, std::size_t bytes_left, std::size_t min_bytes_per_item);

// Reasons worded alike in every format.
std::string too_few_corners(std::size_t corners);  // a polygon with fewer than 3 corners
std::string index_out_of_range(std::int64_t index, std::uint64_t vertex_count);
std::string too_many_vertices(std::uint64_t vertex_count);  // more than 32-bit indices address

// Where a reader puts what its items make. Read from start to end, they are appended to the soup...
struct SoupAppender {
  MeshSoup& soup;
  void position(const std::array<double, 3>& p) { soup.positions.insert(soup.positions.end(), p.begin(), p.end()); }
  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    soup.triangles.insert(soup.triangles.end(), {a, b, c});
  }
};
// ...read in chunks, each chunk writes them in place, from slots counted by an earlier pass...
struct SoupWriter {
  double* next_position = nullptr;
  std::uint32_t* next_triangle = nullptr;
  void position(const std::array<double, 3>& p) { next_position = std::copy(p.begin(), p.end(), next_position); }
  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    next_triangle[0] = a;
    next_triangle[1] = b;
    next_triangle[2] = c;
    next_triangle += 3;
  }
};
// ...and that counting pass only counts the triangles.
struct TriangleCounter {
  std::uint64_t triangles = 0;
  void position(const std::array<double, 3>&) {}
  void triangle(std::uint32_t, std::uint32_t, std::uint32_t) { ++triangles; }
};

// A polygon whose indices are already checked, as the triangles (c0 c1 c2), (c0 c2 c3), ...
template <class Sink>
void emit_fan(std::span<const std::uint32_t> polygon, Sink& sink) {
  for (std::size_t i = 2; i < polygon.size(); ++i) sink.triangle(polygon[0], polygon[i - 1], polygon[i]);
}
// How many triangles emit_fan makes of a polygon with `corners` corners (none of one with too few, an error).
inline std::uint64_t fan_triangle_count(std::uint64_t corners) { return corners >= 3 ? corners - 2 : 0; }

// How an item is read: parsed, every value converted and checked (a malformed one is named), or skimmed, only
// what fixes the item's extent and the triangles it makes converted (a list's length). A skimming pass finds
// where each chunk's triangles start before the chunks are parsed; any error a skim meets, the parse meets
// too, at that item or before.
enum class Reading : std::uint8_t { parse, skim };

// Editors on Windows start UTF-8 text with a byte-order mark; it is not part of the first line.
inline constexpr std::string_view kUtf8ByteOrderMark = "\xEF\xBB\xBF";
inline std::size_t byte_order_mark_size(std::string_view bytes) {
  return bytes.starts_with(kUtf8ByteOrderMark) ? kUtf8ByteOrderMark.size() : 0;
}

// Walks a text file line by line and, within a line, token by token (tokens are separated by spaces and
// tabs). Lines end at LF, CRLF or a lone CR. A token starting with the comment character ends its line. A
// byte-order mark at the start of the file is skipped.
class TextCursor {
 public:
  explicit TextCursor(const MeshFile& file, char comment = '\0')
      : file_(file), end_(file.bytes.size()), comment_(comment), next_line_start_(byte_order_mark_size(file.bytes)) {}
  // The lines of bytes [begin, end) alone, begin the start of a line (end the end of one, or of the file),
  // numbered in messages as if `lines_before` lines came before them.
  TextCursor(const MeshFile& file, char comment, std::size_t begin, std::size_t end, std::size_t lines_before)
      : file_(file),
        end_(end),
        comment_(comment),
        next_line_start_(begin == 0 ? byte_order_mark_size(file.bytes) : begin),
        line_number_(lines_before),
        may_hold_cr_(begin < end && std::memchr(file.bytes.data() + begin, '\r', end - begin) != nullptr) {}

  // Move to the next line; false at the end of the file.
  bool next_line();
  // Move to the next line that has a token, skipping blank and comment lines; false at the end of the file.
  bool next_data_line();
  // The next token on the current line, or an empty view when the line has no more.
  std::string_view next_token();
  // The token next_token would return, without consuming it.
  std::string_view peek_token() const;
  // What is left of the current line, unread; and dropping it.
  std::string_view rest_of_line() const { return line_; }
  void skip_rest_of_line() { line_ = {}; }
  // The next token, moving to later lines as needed; an empty view at the end of the file.
  std::string_view next_token_any_line();

  // How many tokens the rest of the current line holds, consuming them (next_token's rules, one pass).
  std::size_t count_tokens();
  // The next token on the current line; throws naming `what` if it is missing.
  std::string_view read_token(std::string_view what);
  // The next token on the current line as a number; throws naming `what` if it is missing or malformed.
  double read_double(std::string_view what);
  std::int64_t read_integer(std::string_view what);
  // The next three tokens as a vertex position; throws if one is missing, malformed or not finite.
  std::array<double, 3> read_position();

  // Byte offset just past the current line: where a binary body starts after a text header.
  std::size_t offset_after_line() const { return next_line_start_; }
  // What ended the current line: "\n", "\r\n", "\r", or empty at the end of the file.
  std::string_view line_terminator() const { return terminator_; }

  // Throw Error(invalid_mesh) naming the file and the current line.
  [[noreturn]] void fail(std::string_view reason) const;
  std::size_t line_number() const { return line_number_; }

 private:
  const MeshFile& file_;
  std::size_t end_;  // where the cursor's lines end: the file's end, or a chunk's
  char comment_;
  std::string_view line_;  // unread rest of the current line
  std::string_view terminator_;
  std::size_t next_line_start_;
  std::size_t line_number_ = 0;
  // Whether a CR may end a line: the chunks of most files hold none, found by one memchr over the chunk, and
  // their lines then need no search for one (a memchr call per line).
  bool may_hold_cr_ = true;
};

// Where the team's chunks of a text body start: bounds[k] to bounds[k + 1] is chunk k, for k below
// bounds.size() - 1, covering [begin, bytes.size()). Each starts at the start of a line and holds at least
// min_chunk_bytes (the last one whatever is left): a few chunks per thread on a large file, one on a small.
std::vector<std::size_t> line_chunks(std::string_view bytes, std::size_t begin, const ParallelTeam& team,
                                     std::size_t min_chunk_bytes);
// Chunks below this are not worth a thread; the tests use smaller ones, so that small files run through the
// chunked code too.
inline constexpr std::size_t kMinChunkBytes = std::size_t{1} << 20;

// A text body's chunks (bounds from line_chunks) and where each starts among the file's lines and among the
// body's rows, the lines with a token (blank lines and comment lines are not rows). Entry k of lines_before
// and rows_before is chunk k's; the last entry holds the file's lines and the body's rows.
struct TextChunks {
  std::vector<std::size_t> bounds;
  std::vector<std::size_t> lines_before;
  std::vector<std::uint64_t> rows_before;

  std::size_t count() const { return bounds.size() - 1; }
  // Chunk k's lines alone, numbered as in the whole file.
  TextCursor cursor(const MeshFile& file, char comment, std::size_t k) const {
    return TextCursor(file, comment, bounds[k], bounds[k + 1], lines_before[k]);
  }
  // A cursor past the last line, where a reading from start to end that wants another row finds none.
  TextCursor end_cursor(const MeshFile& file, char comment) const {
    return TextCursor(file, comment, bounds.back(), bounds.back(), lines_before.back());
  }
};
// Counts each chunk's lines and rows on the team; `header_lines` come before the first chunk.
TextChunks count_chunk_rows(const MeshFile& file, char comment, std::vector<std::size_t> bounds,
                            std::size_t header_lines, const ParallelTeam& team);

// Calls body(k) for each chunk k in [0, count) on the team. A chunk stops at its first Error, which is kept;
// once all are done, the earliest chunk's is rethrown: with chunks in file order, the error that a reading
// from start to end meets first.
template <class Body>
void for_each_chunk(const ParallelTeam& team, std::size_t count, Body&& body) {
  std::vector<std::exception_ptr> failure(count);
  team.for_each(count, 1, [&](std::size_t k) {
    try {
      body(k);
    } catch (const Error&) {
      failure[k] = std::current_exception();
    }
  });
  for (const std::exception_ptr& f : failure)
    if (f) std::rethrow_exception(f);
}

// One function per format; each returns the soup with every index checked against its vertex count and
// every coordinate finite. Emptiness is checked by the caller. Each gives the same soup and the same first
// error on any team and chunk size.
MeshSoup read_obj(const MeshFile& file, const ParallelTeam& team, std::size_t min_chunk_bytes = kMinChunkBytes);
MeshSoup read_ply(const MeshFile& file, const ParallelTeam& team, std::size_t min_chunk_bytes = kMinChunkBytes);
MeshSoup read_off(const MeshFile& file, const ParallelTeam& team, std::size_t min_chunk_bytes = kMinChunkBytes);
MeshSoup read_stl(const MeshFile& file, const ParallelTeam& team, std::size_t min_chunk_bytes = kMinChunkBytes);

}  // namespace exactgeo::detail
