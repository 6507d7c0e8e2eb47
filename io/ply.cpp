// Stanford PLY 1.0 in ascii, binary_little_endian and binary_big_endian. Positions come from the x, y, z
// properties of the `vertex` element (any numeric type); polygons from the `vertex_indices` (or
// `vertex_index`) list of `face`, and triangle strips from the `vertex_indices` list of `tristrips`. Every
// other property and element is read past and dropped.
//
// The header is read from start to end. A large body is read on the team: an ASCII one in chunks of lines
// (one row per element item), a binary one in blocks of items whose byte offsets are found first. Either way
// the soup and the first error are those of a reading from start to end, which each item's parsing shares.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "assert.hpp"
#include "ply_header.hpp"
#include "readers.hpp"

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
    lists_unread_ = static_cast<std::size_t>(
        std::count_if(element.properties.begin(), element.properties.end(), is_list));
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

// Reads fixed-size values in the file's byte order; errors name the element item.
class BinaryBody {
 public:
  BinaryBody(const MeshFile& file, std::size_t offset, bool big_endian)
      : file_(file), offset_(offset), swap_(big_endian != (std::endian::native == std::endian::big)) {}

  void begin_item(const PlyElement& element, std::uint64_t index) {
    element_ = &element;
    index_ = index;
  }
  double read(PlyType type) {
    const std::size_t size = size_of(type);
    if (file_.bytes.size() - offset_ < size) fail_truncated();
    const char* at = file_.bytes.data() + offset_;
    offset_ += size;
    switch (type) {
      case PlyType::int8: return load<std::int8_t>(at);
      case PlyType::uint8: return load<std::uint8_t>(at);
      case PlyType::int16: return load<std::int16_t>(at);
      case PlyType::uint16: return load<std::uint16_t>(at);
      case PlyType::int32: return load<std::int32_t>(at);
      case PlyType::uint32: return load<std::uint32_t>(at);
      case PlyType::float32: return load<float>(at);
      case PlyType::float64: return load<double>(at);
    }
    return 0;
  }
  void skip(PlyType type, std::uint64_t count) {
    const std::size_t left = file_.bytes.size() - offset_;  // no overflow below: count <= left and a size <= 8
    if (count > left || count * size_of(type) > left) fail_truncated();
    offset_ += static_cast<std::size_t>(count) * size_of(type);
  }
  // Where the next value starts.
  std::size_t offset() const { return offset_; }
  // Binary items have no rows: their size follows from the header and the list lengths.
  void begin_list(std::int64_t) {}
  void end_item() {}
  [[noreturn]] void fail(const std::string& reason) const {
    throw_file_error(file_, item_name(*element_, index_) + ": " + reason);
  }
  static std::size_t min_bytes(PlyType type) { return size_of(type); }

 private:
  [[noreturn]] void fail_truncated() const { throw_file_error(file_, truncation_reason(*element_, index_)); }

  template <class T>
  double load(const char* at) const {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, at, sizeof(T));
    if (swap_) {
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    }
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return static_cast<double>(value);
  }

  const MeshFile& file_;
  std::size_t offset_;
  bool swap_;
  const PlyElement* element_ = nullptr;
  std::uint64_t index_ = 0;
};

// A list length or vertex index stored in a possibly floating-point property: it must be a whole number.
template <class Body>
std::int64_t whole_number(const Body& body, double value, std::string_view what) {
  constexpr double kLimit = 9.0e15;  // well inside the range where doubles hold every integer
  if (!(std::floor(value) == value && std::abs(value) < kLimit)) {
    body.fail(std::string(what) + " " + std::to_string(value) + " is not a whole number");
  }
  return static_cast<std::int64_t>(value);
}

template <class Body>
std::uint32_t vertex_index(const Body& body, double value, std::uint64_t vertex_count) {
  const std::int64_t index = whole_number(body, value, "vertex index");
  if (index < 0 || static_cast<std::uint64_t>(index) >= vertex_count) {
    body.fail(index_out_of_range(index, vertex_count));
  }
  return static_cast<std::uint32_t>(index);
}

// The values of one element item that the soup is made of; reused from item to item.
struct ItemValues {
  std::array<double, 3> xyz = {0, 0, 0};
  std::uint64_t corner_count = 0;      // the length of the vertex index list
  std::vector<double> corners;         // its values: always when parsed, skimmed only for a strip
  std::vector<std::uint32_t> polygon;  // the corners as checked indices
};

// Strips list their vertices so that each new one makes a triangle with the two before it; the winding
// alternates, and -1 ends a strip. Every index is checked before the first triangle is made.
template <class Body, class Sink>
void emit_strips(const Body& body, std::uint64_t vertex_count, ItemValues& values, Sink& sink) {
  constexpr std::uint32_t kStripEnd = std::numeric_limits<std::uint32_t>::max();  // never a vertex index
  values.polygon.clear();
  for (double value : values.corners) {
    values.polygon.push_back(value == -1.0 ? kStripEnd : vertex_index(body, value, vertex_count));
  }
  std::uint32_t previous[2] = {0, 0};
  std::size_t strip_length = 0;
  for (std::uint32_t index : values.polygon) {
    if (index == kStripEnd) {
      strip_length = 0;
      continue;
    }
    if (strip_length >= 2) {
      const bool odd = strip_length % 2 == 1;
      sink.triangle(previous[odd ? 1 : 0], previous[odd ? 0 : 1], index);
    }
    previous[0] = previous[1];
    previous[1] = index;
    ++strip_length;
  }
}

// Reads one item's values, from its begin_item to its end_item. Parsed, every value is converted; skimmed,
// only the list lengths are, and a strip's corners, whose triangles depend on where its -1s are.
template <Reading reading, class Body>
void read_values(Body& body, const PlyElement& element, std::uint64_t item, ItemValues& values) {
  body.begin_item(element, item);
  values.corner_count = 0;
  values.corners.clear();
  const bool keep_corners = reading == Reading::parse || element.kind == PlyElementKind::tristrips;
  for (const PlyProperty& property : element.properties) {
    if (!property.list_count_type) {
      if constexpr (reading == Reading::parse) {
        const double value = body.read(property.type);
        if (property.coordinate >= 0) values.xyz[static_cast<std::size_t>(property.coordinate)] = value;
      } else {
        body.skip(property.type, 1);
      }
      continue;
    }
    const std::int64_t length = whole_number(body, body.read(*property.list_count_type), "list length");
    if (length < 0) body.fail("negative list length");
    body.begin_list(length);
    const auto count = static_cast<std::uint64_t>(length);
    if (property.holds_corners) values.corner_count = count;
    if (property.holds_corners && keep_corners) {
      for (std::uint64_t i = 0; i < count; ++i) values.corners.push_back(body.read(property.type));
    } else if (reading == Reading::parse) {
      for (std::uint64_t i = 0; i < count; ++i) body.read(property.type);  // converted to be checked
    } else {
      body.skip(property.type, count);
    }
  }
  body.end_item();
}

// Parses one item and hands the sink what it makes: a vertex's position, a face's fan, a strip's triangles.
// Everything is checked before the sink gets anything, so an item that fails writes nothing: a chunk's
// writes stay inside the slots its skim counted.
template <class Body, class Sink>
void read_item(Body& body, const PlyElement& element, std::uint64_t item, std::uint64_t vertex_count,
               ItemValues& values, Sink& sink) {
  read_values<Reading::parse>(body, element, item, values);
  switch (element.kind) {
    case PlyElementKind::vertex:
      if (!std::isfinite(values.xyz[0]) || !std::isfinite(values.xyz[1]) || !std::isfinite(values.xyz[2])) {
        body.fail("non-finite coordinate");
      }
      sink.position(values.xyz);
      break;
    case PlyElementKind::face:
      if (values.corners.size() < 3) body.fail(too_few_corners(values.corners.size()));
      values.polygon.clear();
      for (double value : values.corners) values.polygon.push_back(vertex_index(body, value, vertex_count));
      emit_fan(values.polygon, sink);
      break;
    case PlyElementKind::tristrips:
      emit_strips(body, vertex_count, values, sink);
      break;
    case PlyElementKind::other:
      break;
  }
}

// Skims one item: the triangles it makes if it parses.
template <class Body>
std::uint64_t skim_item(Body& body, const PlyElement& element, std::uint64_t item, std::uint64_t vertex_count,
                        ItemValues& values) {
  read_values<Reading::skim>(body, element, item, values);
  TriangleCounter counter;
  if (element.kind == PlyElementKind::face) counter.triangles = fan_triangle_count(values.corner_count);
  if (element.kind == PlyElementKind::tristrips) emit_strips(body, vertex_count, values, counter);
  return counter.triangles;
}

bool makes_triangles(const PlyElement& element) {
  return element.kind == PlyElementKind::face || element.kind == PlyElementKind::tristrips;
}

// Reads the body from start to end.
template <class Body>
void read_body(Body& body, std::size_t bytes_left, const PlyHeader& header, MeshSoup& soup) {
  ItemValues values;
  SoupAppender sink{soup};
  for (const PlyElement& element : header.elements) {
    // Items without properties take no room, so a huge count of them must not be looped over.
    if (element.properties.empty()) continue;
    std::size_t min_item_bytes = 0;
    for (const PlyProperty& property : element.properties) {
      min_item_bytes += Body::min_bytes(property.list_count_type.value_or(property.type));
    }
    const std::size_t plausible = plausible_count(element.count, bytes_left, min_item_bytes);
    if (element.kind == PlyElementKind::vertex) soup.positions.reserve(3 * plausible);
    if (element.kind == PlyElementKind::face) soup.triangles.reserve(soup.triangles.size() + 3 * plausible);
    for (std::uint64_t item = 0; item < element.count; ++item) {
      read_item(body, element, item, header.vertex_count, values, sink);
    }
  }
}

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
  soup.positions.resize(3 * vertex_of_row(rows_read));
  soup.triangles.resize(3 * triangles_before[chunk_count]);
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

// A run of one element's items, parsed on its own from its byte offset, and where its triangles start.
struct BinaryBlock {
  const PlyElement* element = nullptr;
  std::uint64_t first_item = 0, end_item = 0;
  std::size_t offset = 0;
  std::uint64_t triangles_before = 0;
};

struct BinaryLayout {
  std::vector<BinaryBlock> blocks;  // in file order
  std::uint64_t vertices = 0;       // the positions the blocks hold
  std::uint64_t triangles = 0;      // the triangles they make
  std::exception_ptr stopped_at;    // the error of the item the blocks end with, where one did not skim
};

// Items per block at least, below which a thread is not worth starting.
constexpr std::size_t kItemGrain = std::size_t{1} << 14;

// Locates the items of a binary body's elements, so that blocks of them can be parsed on the team.
class BinaryLocator {
 public:
  BinaryLocator(const MeshFile& file, const PlyHeader& header, bool big_endian, const ParallelTeam& team)
      : file_(file), header_(header), big_endian_(big_endian), team_(team) {}

  BinaryLayout locate(std::size_t body_offset) const {
    BinaryLayout layout;
    std::size_t offset = body_offset;
    for (const PlyElement& element : header_.elements) {
      // Items without properties take no room, so a huge count of them must not be looped over.
      if (element.properties.empty()) continue;
      if (!locate_items(element, offset, layout)) break;
    }
    return layout;
  }

 private:
  // Cuts an element's items into blocks and finds where each block starts, in bytes and in triangles; moves
  // `offset` past the element. Returns false if an item does not skim: the blocks then end with it, and
  // parsing it raises the file's first error, if no earlier item does.
  bool locate_items(const PlyElement& element, std::size_t& offset, BinaryLayout& layout) const {
    // Every item takes a byte at least: past that many, the file has surely ended.
    const std::uint64_t count = std::min<std::uint64_t>(element.count, file_.bytes.size() - offset + 1);
    if (count == 0) return true;
    const std::size_t blocks = team_.range_count(count, kItemGrain);
    const auto first_of = [&](std::size_t b) { return count * b / blocks; };
    const auto add_block = [&](std::size_t b, std::uint64_t end, std::size_t block_offset, std::uint64_t triangles) {
      layout.blocks.push_back({&element, first_of(b), std::min(first_of(b + 1), end), block_offset, triangles});
    };
    if (const std::optional<UniformItems> uniform = uniform_items(element, offset)) {
      for (std::size_t b = 0; b < blocks; ++b) {
        add_block(b, count, offset + first_of(b) * uniform->bytes, layout.triangles + first_of(b) * uniform->triangles);
      }
      offset += count * uniform->bytes;
      finish(element, count, count * uniform->triangles, layout);
      return true;
    }
    // Items of varying size: one light walk through them finds each block's start.
    BinaryBody body(file_, offset, big_endian_);
    ItemValues values;
    std::uint64_t triangles = 0, end = count;
    for (std::size_t b = 0; b < blocks && !layout.stopped_at; ++b) {
      throw_if_stopped(team_.stop);  // the walk is serial: a stop should not wait for all of it
      add_block(b, end, body.offset(), layout.triangles + triangles);
      for (std::uint64_t item = first_of(b); item < first_of(b + 1); ++item) {
        try {
          triangles += skim_item(body, element, item, header_.vertex_count, values);
        } catch (const Error&) {
          layout.stopped_at = std::current_exception();
          end = item + 1;
          layout.blocks.back().end_item = end;
          break;
        }
      }
    }
    offset = body.offset();
    finish(element, end, triangles, layout);
    return !layout.stopped_at;
  }

  void finish(const PlyElement& element, std::uint64_t items, std::uint64_t triangles, BinaryLayout& layout) const {
    if (element.kind == PlyElementKind::vertex) layout.vertices = items;
    layout.triangles += triangles;
  }

  struct UniformItems {
    std::size_t bytes;
    std::uint64_t triangles;
  };

  // The size and triangles every item of the element has, if all have the first one's (so that where each
  // starts follows from it) and all are in the file: always true of an element without lists, checked on
  // the team otherwise (a mesh of triangles, say).
  std::optional<UniformItems> uniform_items(const PlyElement& element, std::size_t offset) const {
    const auto skim = [&](std::uint64_t item, std::size_t at, ItemValues& values) -> std::optional<UniformItems> {
      BinaryBody body(file_, at, big_endian_);
      try {
        const std::uint64_t triangles = skim_item(body, element, item, header_.vertex_count, values);
        return UniformItems{body.offset() - at, triangles};
      } catch (const Error&) {
        return std::nullopt;
      }
    };
    ItemValues values;
    const std::optional<UniformItems> first = skim(0, offset, values);
    if (!first || element.count > (file_.bytes.size() - offset) / first->bytes) return std::nullopt;
    const auto is_list = [](const PlyProperty& property) { return property.list_count_type.has_value(); };
    if (std::none_of(element.properties.begin(), element.properties.end(), is_list)) return first;
    // An int per range, not a bool: the ranges write their results side by side.
    const int uniform = team_.reduce_ranges(
        element.count - 1, kItemGrain, 1,
        [&](std::size_t begin, std::size_t end) {
          ItemValues range_values;
          for (std::size_t item = begin + 1; item < end + 1; ++item) {
            const std::optional<UniformItems> other = skim(item, offset + item * first->bytes, range_values);
            if (!other || other->bytes != first->bytes || other->triangles != first->triangles) return 0;
          }
          return 1;
        },
        [](int a, int b) { return std::min(a, b); });
    return uniform ? first : std::nullopt;
  }

  const MeshFile& file_;
  const PlyHeader& header_;
  bool big_endian_;
  const ParallelTeam& team_;
};

// A binary body on the team: its items located (BinaryLocator), then each block parsed into its place.
MeshSoup read_binary_body_on_team(const MeshFile& file, const PlyHeader& header, std::size_t body_offset,
                                  bool big_endian, const ParallelTeam& team) {
  const BinaryLayout layout = BinaryLocator(file, header, big_endian, team).locate(body_offset);
  MeshSoup soup;
  soup.positions.resize(3 * layout.vertices);
  soup.triangles.resize(3 * layout.triangles);
  for_each_chunk(team, layout.blocks.size(), [&](std::size_t k) {
    const BinaryBlock& block = layout.blocks[k];
    BinaryBody body(file, block.offset, big_endian);
    const bool vertices = block.element->kind == PlyElementKind::vertex;
    SoupWriter sink{vertices ? soup.positions.data() + 3 * block.first_item : nullptr,
                    soup.triangles.data() + 3 * block.triangles_before};
    ItemValues values;
    for (std::uint64_t item = block.first_item; item < block.end_item; ++item) {
      read_item(body, *block.element, item, header.vertex_count, values, sink);
    }
    EXACTGEO_ASSERT(sink.next_triangle == soup.triangles.data() + 3 * (k + 1 < layout.blocks.size()
                                                                           ? layout.blocks[k + 1].triangles_before
                                                                           : layout.triangles));
  });
  // Parsing the item that did not skim fails too, at that item or before: this is only in case it does not.
  if (layout.stopped_at) std::rethrow_exception(layout.stopped_at);
  return soup;
}

}  // namespace

MeshSoup read_ply(const MeshFile& file, const ParallelTeam& team, std::size_t min_chunk_bytes) {
  TextCursor cursor(file);
  const PlyHeader header = read_header(cursor);
  std::size_t body_offset = cursor.offset_after_line();
  // In a header whose lines end in a lone CR, an LF after end_header's CR is the binary body's first byte.
  if (header.format != PlyFormat::ascii && header.line_terminator == "\r" && cursor.line_terminator() == "\r\n") {
    --body_offset;
  }
  const std::size_t bytes_left = file.bytes.size() - body_offset;
  MeshSoup soup;
  if (header.format == PlyFormat::ascii) {
    std::vector<std::size_t> bounds = line_chunks(file.bytes, body_offset, team, min_chunk_bytes);
    if (bounds.size() > 2) {
      return read_ascii_body_in_chunks(
          file, header, count_chunk_rows(file, '\0', std::move(bounds), cursor.line_number(), team), team);
    }
    // One chunk (a small body, or one thread): read on from the header, row after row.
    AsciiBody body(cursor);
    read_body(body, bytes_left, header, soup);
  } else {
    const bool big_endian = header.format == PlyFormat::binary_big_endian;
    if (team.threads() > 1 && bytes_left >= min_chunk_bytes) {
      return read_binary_body_on_team(file, header, body_offset, big_endian, team);
    }
    // A body below a chunk's worth, or one thread: read item after item.
    BinaryBody body(file, body_offset, big_endian);
    read_body(body, bytes_left, header, soup);
  }
  return soup;
}

}  // namespace exactgeo::detail
