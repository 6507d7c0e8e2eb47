// Stanford PLY 1.0 in ascii, binary_little_endian and binary_big_endian. Positions come from the x, y, z
// properties of the `vertex` element (any numeric type); polygons from the `vertex_indices` (or
// `vertex_index`) list of `face`, and triangle strips from the `vertex_indices` list of `tristrips`. Every
// other property and element is read past and dropped.
//
// The header is read from start to end (ply_header.cpp), then the body in its format: ply_ascii.cpp and
// ply_binary.cpp, which share the reading of an item (ply_body.hpp).
#include "ply_body.hpp"

namespace exactgeo::detail {

MeshSoup read_ply(const MeshFile& file, const ParallelTeam& team, std::size_t min_chunk_bytes) {
  TextCursor cursor(file);
  const PlyHeader header = read_header(cursor);
  if (header.format == PlyFormat::ascii) return read_ascii_body(file, header, cursor, team, min_chunk_bytes);
  std::size_t body_offset = cursor.offset_after_line();
  // In a header whose lines end in a lone CR, an LF after end_header's CR is the binary body's first byte.
  if (header.line_terminator == "\r" && cursor.line_terminator() == "\r\n") --body_offset;
  return read_binary_body(file, header, body_offset, team, min_chunk_bytes);
}

}  // namespace exactgeo::detail
