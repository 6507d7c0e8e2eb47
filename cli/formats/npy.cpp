#include "npy.hpp"

#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <system_error>
#include <utility>

#include "exactgeo/error.hpp"

namespace exactgeo::cli {
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

namespace {

constexpr std::string_view kNpyMagic = "\x93NUMPY";

exactgeo::Error npy_error(const std::string& name, const std::string& why) {
  return exactgeo::Error(exactgeo::ErrorCode::invalid_argument, name + ": " + why);
}

// The text after `'key':` in the header's dict, spaces skipped; empty if the key is not there. NumPy writes
// the dict as Python's repr does (single quotes); double quotes are taken too.
std::string_view header_field(std::string_view header, std::string_view key) {
  for (const char quote : {'\'', '"'}) {
    const std::string quoted = quote + std::string(key) + quote;
    std::size_t at = header.find(quoted);
    if (at == std::string_view::npos) continue;
    at = header.find_first_not_of(' ', at + quoted.size());
    if (at == std::string_view::npos || header[at] != ':') continue;
    at = header.find_first_not_of(' ', at + 1);
    return at == std::string_view::npos ? std::string_view() : header.substr(at);
  }
  return {};
}

// A dtype string such as '<i8', '>u2' or '|u1': byte order, kind and size in bytes.
struct Dtype {
  char order = '|';
  char kind = 0;
  std::size_t bytes = 0;
};

std::optional<Dtype> parse_descr(std::string_view descr) {
  Dtype dtype;
  if (!descr.empty() && std::string_view("<>|=").find(descr.front()) != std::string_view::npos) {
    dtype.order = descr.front();
    descr.remove_prefix(1);
  }
  if (descr.size() < 2) return std::nullopt;
  dtype.kind = descr.front();
  const auto [end, error] = std::from_chars(descr.data() + 1, descr.data() + descr.size(), dtype.bytes);
  if (error != std::errc() || end != descr.data() + descr.size()) return std::nullopt;
  return dtype;
}

// NumPy's name for a dtype in messages: float64, int32, bool; the descr itself for the rarer kinds.
std::string dtype_name(const Dtype& dtype, std::string_view descr) {
  switch (dtype.kind) {
    case 'f': return "float" + std::to_string(8 * dtype.bytes);
    case 'i': return "int" + std::to_string(8 * dtype.bytes);
    case 'u': return "uint" + std::to_string(8 * dtype.bytes);
    case 'b': return "bool";
    default: return "'" + std::string(descr) + "'";
  }
}

// The sizes inside the shape's parentheses, "(10,)" or "(3, 2)"; nullopt if malformed.
std::optional<std::vector<std::size_t>> parse_shape(std::string_view field) {
  if (field.empty() || field.front() != '(') return std::nullopt;
  const std::size_t close = field.find(')');
  if (close == std::string_view::npos) return std::nullopt;
  std::vector<std::size_t> shape;
  std::string_view sizes = field.substr(1, close - 1);
  while (true) {
    const std::size_t start = sizes.find_first_not_of(' ');
    if (start == std::string_view::npos) break;
    sizes.remove_prefix(start);
    std::size_t size = 0;
    const auto [end, error] = std::from_chars(sizes.data(), sizes.data() + sizes.size(), size);
    if (error != std::errc()) return std::nullopt;
    shape.push_back(size);
    sizes.remove_prefix(static_cast<std::size_t>(end - sizes.data()));
    const std::size_t next = sizes.find_first_not_of(' ');
    if (next == std::string_view::npos) break;
    if (sizes[next] != ',') return std::nullopt;
    sizes.remove_prefix(next + 1);
  }
  return shape;
}

std::string shape_text(const std::vector<std::size_t>& shape) {
  std::string text = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) text += (i ? ", " : "") + std::to_string(shape[i]);
  return text + (shape.size() == 1 ? ",)" : ")");
}

}  // namespace

bool is_npy(std::string_view bytes) { return bytes.starts_with(kNpyMagic); }

std::vector<std::uint32_t> read_npy_indices(std::string_view bytes, const std::string& name, std::size_t columns) {
  if (!is_npy(bytes)) throw npy_error(name, "not a .npy file (it does not begin with \\x93NUMPY)");
  // Version 1.0 gives the header's length in 2 bytes; 2.0 and 3.0 (a UTF-8 header) in 4.
  constexpr std::size_t kVersionAt = 6;
  if (bytes.size() < kVersionAt + 2) throw npy_error(name, "the .npy header is cut short");
  const int major = static_cast<unsigned char>(bytes[kVersionAt]);
  if (major < 1 || major > 3)
    throw npy_error(name, ".npy format version " + std::to_string(major) + " is not one this reader knows (1 to 3)");
  const std::size_t length_bytes = major == 1 ? 2 : 4;
  const std::size_t header_at = kVersionAt + 2 + length_bytes;
  if (bytes.size() < header_at) throw npy_error(name, "the .npy header is cut short");
  std::size_t header_length = 0;
  for (std::size_t k = 0; k < length_bytes; ++k)
    header_length |= std::size_t{static_cast<unsigned char>(bytes[kVersionAt + 2 + k])} << (8 * k);
  if (bytes.size() - header_at < header_length) throw npy_error(name, "the .npy header is cut short");
  const std::string_view header = bytes.substr(header_at, header_length);
  const std::string_view data = bytes.substr(header_at + header_length);

  const std::string_view descr_field = header_field(header, "descr");
  if (descr_field.starts_with('['))
    throw npy_error(name, "holds records (a structured dtype), not integers: save a plain integer array");
  const char quote = descr_field.empty() ? 0 : descr_field.front();
  const std::size_t descr_end = quote ? descr_field.find(quote, 1) : std::string_view::npos;
  if ((quote != '\'' && quote != '"') || descr_end == std::string_view::npos)
    throw npy_error(name, "the .npy header has no dtype ('descr')");
  const std::string_view descr = descr_field.substr(1, descr_end - 1);
  const std::optional<Dtype> dtype = parse_descr(descr);
  if (!dtype) throw npy_error(name, "the .npy header's dtype '" + std::string(descr) + "' is malformed");
  const bool integer = (dtype->kind == 'i' || dtype->kind == 'u') &&
                       (dtype->bytes == 1 || dtype->bytes == 2 || dtype->bytes == 4 || dtype->bytes == 8);
  if (!integer)
    throw npy_error(name, "holds " + dtype_name(*dtype, descr) +
                              " values; indices must be integers (save it as an int or uint array, e.g. "
                              "a.astype(numpy.int64))");
  const std::optional<std::vector<std::size_t>> shape = parse_shape(header_field(header, "shape"));
  if (!shape) throw npy_error(name, "the .npy header has no shape, or a malformed one");
  const bool table = columns > 1;
  if (table ? shape->size() != 2 || (*shape)[1] != columns : shape->size() != 1)
    throw npy_error(name, "holds an array of shape " + shape_text(*shape) + "; indices must be " +
                              (table ? "an (n, " + std::to_string(columns) + ") array" : "a 1-D array"));
  if (table && header_field(header, "fortran_order").starts_with("True"))
    throw npy_error(name, "holds a Fortran-ordered array; save a C-ordered one (numpy.ascontiguousarray)");
  const std::size_t rows = shape->front();
  if (rows > data.size() / dtype->bytes / columns || rows * columns * dtype->bytes != data.size())
    throw npy_error(name, "the header says " + std::to_string(rows) +
                              (table ? " rows of " + std::to_string(columns) + " values" : " values") + " of " +
                              std::to_string(dtype->bytes) + " bytes, but " + std::to_string(data.size()) +
                              " bytes of data follow it");
  const std::size_t count = rows * columns;

  const bool big_endian = dtype->order == '>' || (dtype->order == '=' && std::endian::native == std::endian::big);
  const bool is_signed = dtype->kind == 'i';
  const unsigned bits = static_cast<unsigned>(8 * dtype->bytes);
  std::vector<std::uint32_t> indices(count);
  for (std::size_t i = 0; i < count; ++i) {
    std::uint64_t value = 0;
    for (std::size_t k = 0; k < dtype->bytes; ++k) {
      const std::size_t byte = big_endian ? dtype->bytes - 1 - k : k;
      value |= std::uint64_t{static_cast<unsigned char>(data[i * dtype->bytes + byte])} << (8 * k);
    }
    const bool negative = is_signed && (value >> (bits - 1)) != 0;
    if (negative || value > std::numeric_limits<std::uint32_t>::max()) {
      // Sign-extended to 64 bits to be printed as the negative number it is.
      const std::string text = negative ? std::to_string(static_cast<std::int64_t>(
                                              bits == 64 ? value : value | (~std::uint64_t{0} << bits)))
                                        : std::to_string(value);
      const std::string element =
          table ? std::to_string(i / columns) + ", " + std::to_string(i % columns) : std::to_string(i);
      throw npy_error(name, "element [" + element + "] is " + text + ", not an index (0 to " +
                                std::to_string(std::numeric_limits<std::uint32_t>::max()) + ")");
    }
    indices[i] = static_cast<std::uint32_t>(value);
  }
  return indices;
}

namespace {

// The zip format's CRC-32 (reflected polynomial 0xEDB88320), one byte at a time through a table.
class Crc32 {
 public:
  void update(std::span<const unsigned char> bytes) {
    static const auto table = [] {
      std::array<std::uint32_t, 256> t{};
      for (std::uint32_t i = 0; i < 256; ++i) {
        std::uint32_t c = i;
        for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        t[i] = c;
      }
      return t;
    }();
    for (const unsigned char b : bytes) value_ = table[(value_ ^ b) & 0xff] ^ (value_ >> 8);
  }
  std::uint32_t value() const { return value_ ^ 0xFFFFFFFFu; }

 private:
  std::uint32_t value_ = 0xFFFFFFFFu;
};

// Little-endian fields of the zip records.
class Record {
 public:
  Record& u16(std::uint64_t v) { return put(v, 2); }
  Record& u32(std::uint64_t v) { return put(v, 4); }
  Record& u64(std::uint64_t v) { return put(v, 8); }
  Record& text(std::string_view s) {
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    return *this;
  }
  Record& append(const Record& other) {
    bytes_.insert(bytes_.end(), other.bytes_.begin(), other.bytes_.end());
    return *this;
  }
  const std::vector<unsigned char>& bytes() const { return bytes_; }

 private:
  Record& put(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) bytes_.push_back(static_cast<unsigned char>(v >> (8 * i)));
    return *this;
  }
  std::vector<unsigned char> bytes_;
};

constexpr std::uint64_t kZip32Limit = 0xFFFFFFFFu;  // sizes and offsets from here on need ZIP64 fields
constexpr std::uint16_t kUtf8Names = 0x0800;
constexpr std::uint16_t kDosDate = 0x21;  // 1980-01-01, the earliest a zip can say: archives are reproducible

// Each member's file is closed once written, or if the archive is abandoned.
struct MemberFiles {
  std::vector<std::FILE*> files;
  ~MemberFiles() {
    for (std::FILE* f : files)
      if (f) std::fclose(f);
  }
};

}  // namespace

// A stored (uncompressed) zip, as numpy.savez writes: each member's local header (with its size and CRC,
// computed first, so no data descriptors), its bytes, then the central directory; ZIP64 fields where a size,
// an offset or the count does not fit in the classic ones (numpy's reader, Python's zipfile, reads them).
void write_npz(const std::string& path, std::span<const NpzMember> members) {
  MemberFiles member_files;
  for (const NpzMember& member : members) member_files.files.push_back(member.npy_file);
  const auto fail = [&](const std::string& why) {
    throw exactgeo::Error(exactgeo::ErrorCode::io_error, "cannot write '" + path + "': " + why);
  };
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> out(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!out) fail(std::strerror(errno));
  std::uint64_t offset = 0;
  const auto write = [&](std::span<const unsigned char> bytes) {
    if (std::fwrite(bytes.data(), 1, bytes.size(), out.get()) != bytes.size()) fail(std::strerror(errno));
    offset += bytes.size();
  };
  Record directory;
  std::vector<unsigned char> chunk(1 << 20);
  for (std::size_t m = 0; m < members.size(); ++m) {
    const NpzMember& member = members[m];
    const std::string name = member.name + ".npy";
    std::vector<unsigned char> content;
    std::FILE* in = member.npy_file;
    Crc32 crc;
    std::uint64_t size = 0;
    if (in) {  // first pass: size and CRC
      std::rewind(in);
      for (std::size_t n; (n = std::fread(chunk.data(), 1, chunk.size(), in)) > 0; size += n)
        crc.update(std::span(chunk.data(), n));
      if (std::ferror(in)) fail(std::strerror(errno));
      std::rewind(in);
    } else {
      const std::string header = npy_header(member.descr, member.shape);
      content.assign(header.begin(), header.end());
      content.insert(content.end(), member.data.begin(), member.data.end());
      crc.update(content);
      size = content.size();
    }
    const std::uint64_t local_offset = offset;
    const bool zip64_size = size >= kZip32Limit;
    const bool zip64_offset = local_offset >= kZip32Limit;
    const std::uint16_t version = (zip64_size || zip64_offset) ? 45 : 20;
    Record local;
    local.u32(0x04034b50).u16(version).u16(kUtf8Names).u16(0).u16(0).u16(kDosDate).u32(crc.value());
    local.u32(zip64_size ? kZip32Limit : size).u32(zip64_size ? kZip32Limit : size);
    local.u16(name.size()).u16(zip64_size ? 20 : 0).text(name);
    if (zip64_size) local.u16(0x0001).u16(16).u64(size).u64(size);
    write(local.bytes());
    if (in) {
      for (std::size_t n; (n = std::fread(chunk.data(), 1, chunk.size(), in)) > 0;) write(std::span(chunk.data(), n));
      if (std::ferror(in)) fail(std::strerror(errno));
      std::fclose(in);
      member_files.files[m] = nullptr;
    } else {
      write(content);
    }
    Record extra;
    if (zip64_size) extra.u64(size).u64(size);
    if (zip64_offset) extra.u64(local_offset);
    Record entry;
    entry.u32(0x02014b50).u16(version).u16(version).u16(kUtf8Names).u16(0).u16(0).u16(kDosDate).u32(crc.value());
    entry.u32(zip64_size ? kZip32Limit : size).u32(zip64_size ? kZip32Limit : size);
    const std::size_t extra_size = extra.bytes().size();
    entry.u16(name.size()).u16(extra_size ? extra_size + 4 : 0).u16(0).u16(0).u16(0).u32(0);
    entry.u32(zip64_offset ? kZip32Limit : local_offset).text(name);
    if (extra_size) entry.u16(0x0001).u16(extra_size).append(extra);
    directory.append(entry);
  }
  const std::uint64_t directory_offset = offset;
  const std::uint64_t directory_size = directory.bytes().size();
  write(directory.bytes());
  const std::uint64_t count = members.size();
  const bool zip64_end = directory_offset >= kZip32Limit || directory_size >= kZip32Limit || count >= 0xFFFF;
  Record end;
  if (zip64_end) {
    const std::uint64_t zip64_end_offset = offset;
    end.u32(0x06064b50).u64(44).u16(45).u16(45).u32(0).u32(0).u64(count).u64(count);
    end.u64(directory_size).u64(directory_offset);
    end.u32(0x07064b50).u32(0).u64(zip64_end_offset).u32(1);
  }
  end.u32(0x06054b50).u16(0).u16(0).u16(zip64_end ? 0xFFFF : count).u16(zip64_end ? 0xFFFF : count);
  end.u32(zip64_end ? kZip32Limit : directory_size).u32(zip64_end ? kZip32Limit : directory_offset).u16(0);
  write(end.bytes());
  if (std::fflush(out.get()) != 0 || std::ferror(out.get())) fail(std::strerror(errno));
}

}  // namespace exactgeo::cli
