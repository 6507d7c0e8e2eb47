// Reading meshes from files: OBJ, PLY (ASCII, binary little and big endian), OFF and STL (ASCII, binary).
// The format is chosen by the file's extension (case-insensitive). Polygons are fan-triangulated.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stop_token>
#include <vector>

#include "exactgeo/export.hpp"
#include "exactgeo/mesh.hpp"

namespace exactgeo {

struct ReadOptions {
  // Threads reading and parsing the file: 0 takes one per core. Never more than the cores, nor than one per
  // megabyte of file. The soup, and the first error in a malformed file, are the same on any thread count.
  unsigned threads = 0;
  std::stop_token stop = {};  // a stop request ends the read with Error(cancelled)
};

// Throws exactgeo::Error: io_error if the file cannot be read or is not a regular file (after following
// links: a directory, FIFO or device is refused before it is opened), invalid_mesh naming the file, the line
// (text formats; lines end at LF, CRLF or a lone CR) or element (binary formats) and the reason for
// malformed content.
EXACTGEO_API MeshSoup read_mesh_soup(const std::filesystem::path& path, const ReadOptions& options = {});

// read_mesh_soup followed by validation into a Mesh, both on options.threads threads.
EXACTGEO_API Mesh load_mesh(const std::filesystem::path& path, const MeshOptions& options = {});

}  // namespace exactgeo
