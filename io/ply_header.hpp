// The header of a Stanford PLY file: its format, its elements and their properties, read from the first line to
// end_header, with the roles the soup reader gives them (x, y, z of the vertex; the corner list of faces and
// strips). The body is read in ply.cpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "readers.hpp"

namespace exactgeo::detail {

enum class PlyType : std::uint8_t { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

std::size_t size_of(PlyType type);

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::float32;        // the value type, or the item type of a list
  std::optional<PlyType> list_count_type;  // set for list properties
  int coordinate = -1;                     // 0, 1, 2 for the vertex's x, y, z; -1 otherwise
  bool holds_corners = false;              // the vertex index list of a face or triangle strip
};

enum class PlyElementKind : std::uint8_t { vertex, face, tristrips, other };

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  PlyElementKind kind = PlyElementKind::other;
};

enum class PlyFormat : std::uint8_t { ascii, binary_little_endian, binary_big_endian };

struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::uint64_t vertex_count = 0;
  std::string_view line_terminator;  // of the first line: the header's line ends, LF, CRLF or CR
};

// Reads the header, the cursor on the first line; fails (naming the line) on anything the reader cannot take.
PlyHeader read_header(TextCursor& cursor);

// "face 12": the element item an error is about.
std::string item_name(const PlyElement& element, std::uint64_t index);
// The message of a body that ends before the header's count of an element's items.
std::string truncation_reason(const PlyElement& element, std::uint64_t index);

}  // namespace exactgeo::detail
