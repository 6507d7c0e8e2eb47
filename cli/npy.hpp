// NumPy's file formats: .npy (one array: a short text header, then the raw data) and .npz (a zip of .npy
// files, written with libzip), which numpy.load and scipy.sparse.load_npz read.
#pragma once

#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace exactgeo::cli {

// The .npy preamble and header for a C-ordered array: `descr` is NumPy's dtype string ('<f8', '<i4', '|S3').
// A zero-dimensional array has an empty shape.
std::string npy_header(std::string_view descr, std::span<const std::size_t> shape);

// Little-endian bytes of values, as .npy data.
std::vector<unsigned char> little_endian_bytes(std::span<const double> values);
std::vector<unsigned char> little_endian_bytes(std::span<const std::int32_t> values);
std::vector<unsigned char> little_endian_bytes(std::span<const std::int64_t> values);

// One member of an .npz archive: NAME.npy holding the array.
struct NpzMember {
  std::string name;
  std::string descr;
  std::vector<std::size_t> shape;
  std::vector<unsigned char> data;
};

// A zip archive of the members, uncompressed, as numpy.savez writes them. Throws exactgeo::Error(io_error)
// naming the file if it cannot be written.
void write_npz(const std::string& path, std::span<const NpzMember> members);

}  // namespace exactgeo::cli
