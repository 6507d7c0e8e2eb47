// Reading meshes from files: OBJ, PLY (ASCII, binary little and big endian), OFF and STL (ASCII, binary).
// The format is chosen by the file's extension (case-insensitive). Polygons are fan-triangulated.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "exactgeo/export.hpp"
#include "exactgeo/mesh.hpp"

namespace exactgeo {

// Throws exactgeo::Error: io_error if the file cannot be read or is not a regular file (after following
// links: a directory, FIFO or device is refused before it is opened), invalid_mesh naming the file, the line
// (text formats; lines end at LF, CRLF or a lone CR) or element (binary formats) and the reason for
// malformed content.
EXACTGEO_API MeshSoup read_mesh_soup(const std::filesystem::path& path);

// read_mesh_soup followed by validation into a Mesh.
EXACTGEO_API Mesh load_mesh(const std::filesystem::path& path, const MeshOptions& options = {});

}  // namespace exactgeo
