// NumPy's file formats: .npy (one array: a short text header, then the raw data) and .npz (a zip of .npy
// files, written here: stored, as numpy.savez does), which numpy.load and scipy.sparse.load_npz read; and
// .npy arrays of indices read back, as numpy.save writes them.
#pragma once

#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "little_endian.hpp"

namespace exactgeo::cli {

// The .npy preamble and header for a C-ordered array: `descr` is NumPy's dtype string ('<f8', '<i4', '|S3').
// A zero-dimensional array has an empty shape. Padded with spaces to `length` bytes if that is longer (a
// multiple of 64), so that a header written before the shape was known can be rewritten in place.
std::string npy_header(std::string_view descr, std::span<const std::size_t> shape, std::size_t length = 0);

// A whole .npy file: the header, then `data` (little-endian bytes of the shape's values).
void write_npy(std::FILE* file, std::string_view descr, std::span<const std::size_t> shape,
               std::span<const unsigned char> data);

// Whether `bytes` begins as a .npy file does.
bool is_npy(std::string_view bytes);

// The values of a 1-D .npy array of integers (int8 to int64 or uint8 to uint64, either byte order; format
// versions 1.0 to 3.0) as 32-bit indices, the library's type; with `columns` above 1, of a C-ordered array of
// shape (n, columns), row after row. `bytes` is the whole file; `name` begins every message. Throws
// exactgeo::Error(invalid_argument) for anything else, naming the element at fault where one is: not a .npy
// file, another dtype (floats, booleans, records), another shape or order, data shorter or longer than the
// header says, a negative value or one of 2^32 or more.
std::vector<std::uint32_t> read_npy_indices(std::string_view bytes, const std::string& name, std::size_t columns = 1);

// Little-endian bytes of values, as .npy data (the store component's, which its Zarr chunks use too).
using exactgeo::store::little_endian_bytes;

// A 1-D .npy array of unknown length, written as it grows to an anonymous temporary file, so that memory
// stays at what one append holds. Throws exactgeo::Error(io_error) if the file cannot be written.
class GrowingNpy {
 public:
  explicit GrowingNpy(std::string descr);
  ~GrowingNpy();
  GrowingNpy(const GrowingNpy&) = delete;
  GrowingNpy& operator=(const GrowingNpy&) = delete;

  void append(std::span<const unsigned char> little_endian_values, std::size_t count);
  // Writes the header with the final length and hands over the file, rewound; the caller closes it.
  std::FILE* finish();

 private:
  std::string descr_;
  std::FILE* file_;
  std::size_t count_ = 0;
};

// One member of an .npz archive: NAME.npy holding the array, from memory or from a finished GrowingNpy.
struct NpzMember {
  std::string name;
  std::string descr;
  std::vector<std::size_t> shape;
  std::vector<unsigned char> data;
  std::FILE* npy_file = nullptr;  // if set, the whole .npy (descr, shape and data unused); write_npz closes it
};

// A zip archive of the members, uncompressed, as numpy.savez writes them. Throws exactgeo::Error(io_error)
// naming the file if it cannot be written.
void write_npz(const std::string& path, std::span<const NpzMember> members);

}  // namespace exactgeo::cli
