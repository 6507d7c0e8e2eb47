#include "npy.hpp"

#include <zip.h>

#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <utility>

#include "exactgeo/error.hpp"

namespace exactgeo::cli {
namespace {

template <typename T, typename Bits>
std::vector<unsigned char> bytes_of(std::span<const T> values) {
  std::vector<unsigned char> bytes;
  bytes.reserve(values.size() * sizeof(T));
  for (const T value : values) {
    const auto bits = std::bit_cast<Bits>(value);
    for (std::size_t byte = 0; byte < sizeof(T); ++byte) bytes.push_back(static_cast<unsigned char>(bits >> (8 * byte)));
  }
  return bytes;
}

}  // namespace

std::string npy_header(std::string_view descr, std::span<const std::size_t> shape, std::size_t length) {
  std::string dims;
  for (std::size_t d : shape) dims += std::to_string(d) + ", ";
  if (shape.size() > 1) dims.resize(dims.size() - 2);  // (n,) keeps its comma, (n, m) does not end in one
  if (shape.size() == 1) dims.pop_back();
  std::string header = "{'descr': '" + std::string(descr) + "', 'fortran_order': False, 'shape': (" + dims + "), }";
  constexpr std::size_t kPreambleBytes = 10;  // magic (6) + version (2) + header length (2)
  constexpr std::size_t kAlignment = 64;      // the data starts aligned
  const std::size_t unpadded = kPreambleBytes + header.size() + 1;  // + the closing newline
  header.append((kAlignment - unpadded % kAlignment) % kAlignment, ' ');
  if (kPreambleBytes + header.size() + 1 < length) header.append(length - kPreambleBytes - header.size() - 1, ' ');
  header += '\n';
  const auto header_length = static_cast<std::uint16_t>(header.size());
  const char preamble[kPreambleBytes] = {'\x93', 'N', 'U', 'M', 'P', 'Y', 1, 0,
                                         static_cast<char>(header_length & 0xff), static_cast<char>(header_length >> 8)};
  return std::string(preamble, kPreambleBytes) + header;
}

void write_npy(std::FILE* file, std::string_view descr, std::span<const std::size_t> shape,
               std::span<const unsigned char> data) {
  const std::string header = npy_header(descr, shape);
  std::fwrite(header.data(), 1, header.size(), file);
  std::fwrite(data.data(), 1, data.size(), file);
}

std::vector<unsigned char> little_endian_bytes(std::span<const double> values) {
  return bytes_of<double, std::uint64_t>(values);
}
std::vector<unsigned char> little_endian_bytes(std::span<const std::int32_t> values) {
  return bytes_of<std::int32_t, std::uint32_t>(values);
}
std::vector<unsigned char> little_endian_bytes(std::span<const std::int64_t> values) {
  return bytes_of<std::int64_t, std::uint64_t>(values);
}

namespace {

// Room for the header of any 1-D array: the longest shape there is.
std::size_t growing_header_length(std::string_view descr) {
  const std::size_t longest = SIZE_MAX;
  return npy_header(descr, std::span(&longest, 1)).size();
}

exactgeo::Error temporary_file_error() {
  return exactgeo::Error(exactgeo::ErrorCode::io_error,
                         std::string("cannot write a temporary file for the .npz archive: ") + std::strerror(errno));
}

}  // namespace

GrowingNpy::GrowingNpy(std::string descr) : descr_(std::move(descr)), file_(std::tmpfile()) {
  if (!file_) throw temporary_file_error();
  const std::string placeholder(growing_header_length(descr_), ' ');
  std::fwrite(placeholder.data(), 1, placeholder.size(), file_);
}

GrowingNpy::~GrowingNpy() {
  if (file_) std::fclose(file_);
}

void GrowingNpy::append(std::span<const unsigned char> little_endian_values, std::size_t count) {
  std::fwrite(little_endian_values.data(), 1, little_endian_values.size(), file_);
  count_ += count;
}

std::FILE* GrowingNpy::finish() {
  const std::string header = npy_header(descr_, std::span(&count_, 1), growing_header_length(descr_));
  std::rewind(file_);
  std::fwrite(header.data(), 1, header.size(), file_);
  if (std::fflush(file_) != 0 || std::ferror(file_)) throw temporary_file_error();
  std::rewind(file_);
  return std::exchange(file_, nullptr);
}

void write_npz(const std::string& path, std::span<const NpzMember> members) {
  int error = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  const auto fail = [&](const std::string& why) {
    throw exactgeo::Error(exactgeo::ErrorCode::io_error, "cannot write '" + path + "': " + why);
  };
  if (!archive) {
    zip_error_t reason;
    zip_error_init_with_code(&reason, error);
    const std::string text = zip_error_strerror(&reason);
    zip_error_fini(&reason);
    fail(text);
  }
  // libzip reads the sources when the archive is closed: keep every member's bytes alive until then.
  std::vector<std::vector<unsigned char>> contents;
  contents.reserve(members.size());
  for (const NpzMember& member : members) {
    zip_source_t* source = nullptr;
    if (member.npy_file) {
      source = zip_source_filep(archive, member.npy_file, 0, -1);  // closes the file when done with it
    } else {
      const std::string header = npy_header(member.descr, member.shape);
      std::vector<unsigned char>& content = contents.emplace_back(header.begin(), header.end());
      content.insert(content.end(), member.data.begin(), member.data.end());
      source = zip_source_buffer(archive, content.data(), content.size(), 0);
    }
    const zip_int64_t index =
        source ? zip_file_add(archive, (member.name + ".npy").c_str(), source, ZIP_FL_ENC_UTF_8) : -1;
    if (index < 0) {
      if (source) zip_source_free(source);
      const std::string text = zip_strerror(archive);
      zip_discard(archive);
      fail(text);
    }
    zip_set_file_compression(archive, static_cast<zip_uint64_t>(index), ZIP_CM_STORE, 0);
  }
  if (zip_close(archive) != 0) {
    const std::string text = zip_strerror(archive);
    zip_discard(archive);
    fail(text);
  }
}

}  // namespace exactgeo::cli
