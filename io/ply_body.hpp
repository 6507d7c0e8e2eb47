// The body of a Stanford PLY file (the header is read by ply_header.*, the whole file by ply.cpp::read_ply): how
// one element item is read, shared by the ASCII body (ply_ascii.cpp) and the binary body (ply_binary.cpp), each
// read from start to end or on the team. Either way the soup and the first error are those of a reading from
// start to end, which each item's parsing shares.
//
// A Body reads an item's values in its encoding: begin_item(element, index), begin_list(length), read(type),
// skip(type, count), end_item(), fail(reason) naming the item, and min_bytes(type), the fewest bytes a value
// takes.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "exactgeo/mesh.hpp"
#include "parallel.hpp"
#include "ply_header.hpp"
#include "readers.hpp"

namespace exactgeo::detail {

// Reads an ASCII body, the cursor on end_header's line: in chunks of lines on the team if the body is at least
// two chunks of `min_chunk_bytes`, else row after row.
MeshSoup read_ascii_body(const MeshFile& file, const PlyHeader& header, TextCursor& cursor, const ParallelTeam& team,
                         std::size_t min_chunk_bytes);
// Reads a binary body starting at byte `body_offset`: in blocks of items on the team if it holds `min_chunk_bytes`
// or more and the team has threads, else item after item.
MeshSoup read_binary_body(const MeshFile& file, const PlyHeader& header, std::size_t body_offset,
                          const ParallelTeam& team, std::size_t min_chunk_bytes);

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

inline bool makes_triangles(const PlyElement& element) {
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

}  // namespace exactgeo::detail
