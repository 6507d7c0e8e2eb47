// The PLY header, line by line (see ply_header.hpp).
#include "ply_header.hpp"

#include <limits>
#include <utility>

namespace exactgeo::detail {
namespace {

std::optional<PlyType> ply_type_named(std::string_view name) {
  struct Named {
    std::string_view name;
    PlyType type;
  };
  // The original names and the sized aliases that many writers use instead.
  static constexpr Named kNames[] = {
      {"char", PlyType::int8},     {"int8", PlyType::int8},       {"uchar", PlyType::uint8},
      {"uint8", PlyType::uint8},   {"short", PlyType::int16},     {"int16", PlyType::int16},
      {"ushort", PlyType::uint16}, {"uint16", PlyType::uint16},   {"int", PlyType::int32},
      {"int32", PlyType::int32},   {"uint", PlyType::uint32},     {"uint32", PlyType::uint32},
      {"float", PlyType::float32}, {"float32", PlyType::float32}, {"double", PlyType::float64},
      {"float64", PlyType::float64},
  };
  for (const Named& named : kNames) {
    if (named.name == name) return named.type;
  }
  return std::nullopt;
}

PlyElementKind element_kind(std::string_view name) {
  if (name == "vertex") return PlyElementKind::vertex;
  if (name == "face") return PlyElementKind::face;
  if (name == "tristrips") return PlyElementKind::tristrips;
  return PlyElementKind::other;
}

PlyType read_type(TextCursor& cursor) {
  const std::string_view token = cursor.next_token();
  if (token.empty()) cursor.fail("missing property type");
  const std::optional<PlyType> type = ply_type_named(token);
  if (!type) cursor.fail("unknown property type " + quoted(token));
  return *type;
}

PlyProperty read_property(TextCursor& cursor) {
  PlyProperty property;
  if (cursor.peek_token() == "list") {
    cursor.next_token();
    property.list_count_type = read_type(cursor);
    if (*property.list_count_type >= PlyType::float32) cursor.fail("list count type must be an integer type");
  }
  property.type = read_type(cursor);
  property.name = std::string(cursor.next_token());
  if (property.name.empty()) cursor.fail("missing property name");
  return property;
}

// Mark the properties the soup is made of, and check that the elements we read have them.
void assign_roles(TextCursor& cursor, PlyElement& element) {
  auto find = [&](std::string_view name) -> PlyProperty* {
    for (PlyProperty& property : element.properties) {
      if (property.name == name) return &property;
    }
    return nullptr;
  };
  if (element.kind == PlyElementKind::vertex) {
    constexpr const char* kNames[] = {"x", "y", "z"};
    for (int coordinate = 0; coordinate < 3; ++coordinate) {
      const std::string name = kNames[coordinate];
      PlyProperty* property = find(name);
      if (!property) cursor.fail("vertex element has no '" + name + "' property");
      if (property->list_count_type) cursor.fail("vertex property '" + name + "' is a list");
      property->coordinate = coordinate;
    }
  } else if (element.kind != PlyElementKind::other) {
    PlyProperty* property = find("vertex_indices");
    if (!property && element.kind == PlyElementKind::face) property = find("vertex_index");
    if (!property) cursor.fail(element.name + " element has no 'vertex_indices' property");
    if (!property->list_count_type) cursor.fail(element.name + " property '" + property->name + "' is not a list");
    property->holds_corners = true;
  }
}

}  // namespace

std::size_t size_of(PlyType type) {
  constexpr std::size_t kSizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSizes[static_cast<std::size_t>(type)];
}

PlyHeader read_header(TextCursor& cursor) {
  if (!cursor.next_line() || cursor.next_token() != "ply" || !cursor.next_token().empty()) {
    cursor.fail("not a PLY file (the first line must be 'ply')");
  }
  PlyHeader header;
  header.line_terminator = cursor.line_terminator();
  bool has_format = false;
  for (;;) {
    if (!cursor.next_line()) cursor.fail("the header has no 'end_header' line");
    const std::string_view keyword = cursor.next_token();
    if (keyword.empty() || keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") break;
    if (keyword == "format") {
      const std::string_view format = cursor.next_token();
      if (format == "ascii") {
        header.format = PlyFormat::ascii;
      } else if (format == "binary_little_endian") {
        header.format = PlyFormat::binary_little_endian;
      } else if (format == "binary_big_endian") {
        header.format = PlyFormat::binary_big_endian;
      } else {
        cursor.fail("unsupported PLY format " + quoted(format));
      }
      const std::string_view version = cursor.next_token();
      if (version != "1.0") cursor.fail("unsupported PLY version " + quoted(version) + " (expected '1.0')");
      has_format = true;
    } else if (keyword == "element") {
      PlyElement element;
      element.name = std::string(cursor.next_token());
      if (element.name.empty()) cursor.fail("missing element name");
      const std::int64_t count = cursor.read_integer("element count");
      if (count < 0) cursor.fail("negative element count");
      element.count = static_cast<std::uint64_t>(count);
      element.kind = element_kind(element.name);
      if (element.kind == PlyElementKind::vertex && element.count > std::numeric_limits<std::uint32_t>::max()) {
        cursor.fail(too_many_vertices(element.count));
      }
      if (element.kind != PlyElementKind::other) {
        for (const PlyElement& earlier : header.elements) {
          if (earlier.kind == element.kind) cursor.fail("second '" + element.name + "' element");
        }
      }
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) cursor.fail("property before any element");
      header.elements.back().properties.push_back(read_property(cursor));
    } else {
      cursor.fail("unexpected " + quoted(keyword) + " in the PLY header");
    }
  }
  if (!has_format) cursor.fail("the header has no 'format' line");

  bool has_vertices = false;
  for (PlyElement& element : header.elements) {
    assign_roles(cursor, element);
    if (element.kind == PlyElementKind::vertex) {
      header.vertex_count = element.count;
      has_vertices = true;
    }
  }
  if (!has_vertices) cursor.fail("no 'vertex' element in the header");
  return header;
}

std::string item_name(const PlyElement& element, std::uint64_t index) {
  return element.name + " " + std::to_string(index);
}

std::string truncation_reason(const PlyElement& element, std::uint64_t index) {
  return "file ends inside " + item_name(element, index) + " (the header declares " +
         std::to_string(element.count) + ")";
}

}  // namespace exactgeo::detail
