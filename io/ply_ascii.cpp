// The ASCII body of a PLY file (see ply_body.hpp): each element item on a row of its own, read row after row,
// or, a large body, in chunks of lines on the team (one row per element item).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "assert.hpp"
#include "ply_body.hpp"

namespace exactgeo::detail {
namespace {

// Reads each element item from a row of its own, so that a row with too many or too few values is reported
// at that row: read across rows, an extra value on a vertex row was blamed on a later row.
class AsciiBody {
 public:
  explicit AsciiBody(TextCursor& cursor) : cursor_(cursor) {}

  void begin_item(const PlyElement& element, std::uint64_t index) {
    element_ = &element;
    index_ = index;
    values_read_ = 0;
    values_declared_ = element.properties.size();  // a list's length is one value, its items come on top
    const auto is_list = [](const PlyProperty& property) { return property.list_count_type.has_value(); };
    lists_unread_ =
        static_cast<std::size_t>(std::count_if(element.properties.begin(), element.properties.end(), is_list));
    has_lists_ = lists_unread_ > 0;
    if (!cursor_.next_data_line()) cursor_.fail(truncation_reason(element, index));
  }
  void begin_list(std::int64_t length) {
    values_declared_ += static_cast<std::uint64_t>(length);
    --lists_unread_;
  }
  double read(PlyType) {
    const std::string_view token = cursor_.next_token();
    if (token.empty()) fail_row_size(values_read_);
    ++values_read_;
    double value = 0;
    if (!parse_double(token, value)) fail("malformed number " + quoted(token));
    return value;
  }
  // Steps over `count` values without converting them.
  void skip(PlyType, std::uint64_t count) {
    for (std::uint64_t i = 0; i < count; ++i) {
      if (cursor_.next_token().empty()) fail_row_size(values_read_);
      ++values_read_;
    }
  }
  void end_item() {
    if (cursor_.peek_token().empty()) return;
    std::uint64_t values = values_read_;
    while (!cursor_.next_token().empty()) ++values;
    fail_row_size(values);
  }
  [[noreturn]] void fail(const std::string& reason) const {
    cursor_.fail(item_name(*element_, index_) + ": " + reason);
  }
  static std::size_t min_bytes(PlyType) { return 2; }  // a digit and a separator

 private:
  // "NAME:12: vertex 3 has 4 values, the header declares 3". Before a later list's length is read, only a
  // lower bound of the values the row needs is known.
  [[noreturn]] void fail_row_size(std::uint64_t values) const {
    cursor_.fail(item_name(*element_, index_) + " has " + std::to_string(values) + " values, the header" +
                 (has_lists_ ? " and its list lengths declare " : " declares ") +
                 (lists_unread_ > 0 ? "at least " : "") + std::to_string(values_declared_));
  }

  TextCursor& cursor_;
  const PlyElement* element_ = nullptr;
  std::uint64_t index_ = 0;
  std::uint64_t values_read_ = 0;
  std::uint64_t values_declared_ = 0;
  bool has_lists_ = false;
  std::size_t lists_unread_ = 0;  // list properties whose length is not read yet
};

// The rows of an ASCII body, one per item: the elements with properties take `count` rows each, in file order
// (an item without properties has no row).
class AsciiRows {
 public:
  explicit AsciiRows(const PlyHeader& header) {
    first_row_.push_back(0);
    for (const PlyElement& element : header.elements) {
      if (element.properties.empty()) continue;
      elements_.push_back(&element);
      // Saturated: a header may declare more rows than 64 bits count; no file holds that many.
      const std::uint64_t end = first_row_.back() + element.count;
      first_row_.push_back(end < first_row_.back() ? std::numeric_limits<std::uint64_t>::max() : end);
    }
  }

  std::uint64_t declared() const { return first_row_.back(); }
  // The rows [first, end) of the elements `wanted` holds.
  template <class Wanted>
  std::pair<std::uint64_t, std::uint64_t> rows_of(Wanted&& wanted) const {
    std::uint64_t first = declared(), end = 0;
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      if (!wanted(*elements_[e])) continue;
      first = std::min(first, first_row_[e]);
      end = std::max(end, first_row_[e + 1]);
    }
    return {first, std::max(first, end)};
  }
  // Calls visit(element, item) for the rows [first, end), below declared().
  template <class Visit>
  void for_each_row(std::uint64_t first, std::uint64_t end, Visit&& visit) const {
    std::size_t e = element_of(first);
    for (std::uint64_t row = first; row < end; ++row) {
      while (row >= first_row_[e + 1]) ++e;
      visit(*elements_[e], row - first_row_[e]);
    }
  }
  // The element and item of a row below declared().
  std::pair<const PlyElement*, std::uint64_t> item_of(std::uint64_t row) const {
    const std::size_t e = element_of(row);
    return {elements_[e], row - first_row_[e]};
  }

 private:
  // Elements without items share their first row with the next element: the last element starting at or
  // before the row holds it.
  std::size_t element_of(std::uint64_t row) const {
    const auto after = std::upper_bound(first_row_.begin(), first_row_.end(), row);
    return static_cast<std::size_t>(after - first_row_.begin()) - 1;
  }

  std::vector<const PlyElement*> elements_;
  std::vector<std::uint64_t> first_row_;  // of each element, then the rows all declare
};

// An ASCII body of several chunks of lines, on the team. Pass 1 (count_chunk_rows) counts each chunk's lines
// and rows, so that each chunk knows the element item of each of its rows; pass 2 skims the rows of faces
// and strips for the triangles they make; pass 3 parses every chunk into its place. Rows after the last
// declared item are never read, as from start to end.
MeshSoup read_ascii_body_in_chunks(const MeshFile& file, const PlyHeader& header, const TextChunks& chunks,
                                   const ParallelTeam& team) {
  const AsciiRows rows(header);
  const std::size_t chunk_count = chunks.count();
  const auto rows_of_chunk = [&](std::size_t k) {
    return std::pair{std::min(chunks.rows_before[k], rows.declared()),
                     std::min(chunks.rows_before[k + 1], rows.declared())};
  };
  const std::pair<std::uint64_t, std::uint64_t> triangle_rows = rows.rows_of(makes_triangles);
  const std::uint64_t first_triangle_row = triangle_rows.first, end_triangle_row = triangle_rows.second;
  std::vector<std::uint64_t> triangles_before(chunk_count + 1, 0);
  team.for_each(chunk_count, 1, [&](std::size_t k) {
    const auto [first, end] = rows_of_chunk(k);
    if (end <= first_triangle_row || first >= end_triangle_row) return;
    TextCursor cursor = chunks.cursor(file, '\0', k);
    AsciiBody body(cursor);
    ItemValues values;
    std::uint64_t triangles = 0;
    try {
      rows.for_each_row(first, std::min(end, end_triangle_row), [&](const PlyElement& element, std::uint64_t item) {
        if (makes_triangles(element)) {
          triangles += skim_item(body, element, item, header.vertex_count, values);
        } else {
          cursor.next_data_line();
        }
      });
    } catch (const Error&) {
      // Counted up to this row; pass 3 stops at its error, or an earlier one, before writing past them.
    }
    triangles_before[k + 1] = triangles;
  });
  for (std::size_t k = 0; k < chunk_count; ++k) triangles_before[k + 1] += triangles_before[k];

  const std::uint64_t rows_read = std::min(chunks.rows_before[chunk_count], rows.declared());
  const std::pair<std::uint64_t, std::uint64_t> vertex_rows =
      rows.rows_of([](const PlyElement& element) { return element.kind == PlyElementKind::vertex; });
  const std::uint64_t first_vertex_row = vertex_rows.first, end_vertex_row = vertex_rows.second;
  const auto vertex_of_row = [&](std::uint64_t row) {
    return std::clamp(row, first_vertex_row, end_vertex_row) - first_vertex_row;
  };
  MeshSoup soup;
  resize_on_team(team, soup.positions, 3 * vertex_of_row(rows_read));
  resize_on_team(team, soup.triangles, 3 * triangles_before[chunk_count]);
  for_each_chunk(team, chunk_count, [&](std::size_t k) {
    const auto [first, end] = rows_of_chunk(k);
    TextCursor cursor = chunks.cursor(file, '\0', k);
    AsciiBody body(cursor);
    SoupWriter sink{soup.positions.data() + 3 * vertex_of_row(first), soup.triangles.data() + 3 * triangles_before[k]};
    ItemValues values;
    rows.for_each_row(first, end, [&](const PlyElement& element, std::uint64_t item) {
      read_item(body, element, item, header.vertex_count, values, sink);
    });
    EXACTGEO_ASSERT(sink.next_triangle == soup.triangles.data() + 3 * triangles_before[k + 1]);
  });
  if (rows_read < rows.declared()) {  // the error a reading from start to end meets at the end of the file
    TextCursor end = chunks.end_cursor(file, '\0');
    AsciiBody body(end);
    const auto [element, item] = rows.item_of(rows_read);
    body.begin_item(*element, item);
  }
  return soup;
}

}  // namespace

MeshSoup read_ascii_body(const MeshFile& file, const PlyHeader& header, TextCursor& cursor, const ParallelTeam& team,
                         std::size_t min_chunk_bytes) {
  const std::size_t body_offset = cursor.offset_after_line();
  std::vector<std::size_t> bounds = line_chunks(file.bytes, body_offset, team, min_chunk_bytes);
  if (bounds.size() > 2) {
    return read_ascii_body_in_chunks(file, header,
                                     count_chunk_rows(file, '\0', std::move(bounds), cursor.line_number(), team), team);
  }
  // One chunk (a small body, or one thread): read on from the header, row after row.
  MeshSoup soup;
  AsciiBody body(cursor);
  read_body(body, file.bytes.size() - body_offset, header, soup);
  return soup;
}

}  // namespace exactgeo::detail
