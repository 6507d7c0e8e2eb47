// Public entry points for reading mesh files, and the helpers the per-format readers share.
#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <system_error>

#include <sys/stat.h>
#include <unistd.h>


#include "exactgeo/error.hpp"
#include "exactgeo/io.hpp"
#include "readers.hpp"

namespace exactgeo {
namespace detail {
namespace {

// std::from_chars rejects a leading '+'; files do write it.
std::string_view without_plus(std::string_view token) {
  if (token.size() > 1 && token.front() == '+' && token[1] != '-' && token[1] != '+') {
    token.remove_prefix(1);
  }
  return token;
}

}  // namespace

void throw_file_error(const MeshFile& file, std::string_view reason) {
  std::string message = file.name;
  message += ": ";
  message += reason;
  throw Error(ErrorCode::invalid_mesh, message);
}

void throw_line_error(const MeshFile& file, std::size_t line, std::string_view reason) {
  std::string message = file.name;
  message += ':';
  message += std::to_string(line);
  message += ": ";
  message += reason;
  throw Error(ErrorCode::invalid_mesh, message);
}

std::string quoted(std::string_view token) {
  constexpr std::size_t kMaxShown = 40;
  std::string text = "'";
  for (char c : token.substr(0, kMaxShown)) {
    text += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  }
  text += token.size() > kMaxShown ? "...'" : "'";
  return text;
}

namespace {

// 10^k for k <= 22: exactly representable as doubles (5^22 < 2^53).
constexpr std::array<double, 23> kExactPowersOfTen = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

// Numbers as mesh files mostly write them, a sign, digits and a decimal point ("-0.123456", "17", "2."):
// when the digits, read as an integer m, are at most 2^53 and at most 22 follow the point, m and 10^k are
// both exact doubles, and one IEEE division gives m / 10^k correctly rounded: the value from_chars gives,
// at a fraction of its cost (numbers are a quarter of reading a large OBJ). Reads such a number at the
// start of [at, end) and returns where it ends; nullptr for anything else, which from_chars then reads (or
// refuses), whatever follows it.
const char* read_plain_decimal(const char* at, const char* const end, double& value) {
  const bool negative = at != end && *at == '-';
  if (at != end && (*at == '-' || *at == '+')) ++at;
  // Digits before the point, then after it; more than 19 may wrap around 64 bits, and are refused below.
  std::uint64_t digits = 0;
  const auto read_digits = [&] {
    const char* const first = at;
    at = read_digit_run(at, end, digits);
    return at - first;
  };
  std::ptrdiff_t digit_count = read_digits(), after_point = 0;
  if (at != end && *at == '.') {
    ++at;
    after_point = read_digits();
    digit_count += after_point;
  }
  if (digit_count == 0 || digit_count > 19 || digits > (std::uint64_t{1} << 53) || after_point > 22) return nullptr;
  const double magnitude = static_cast<double>(digits) / kExactPowersOfTen[static_cast<std::size_t>(after_point)];
  value = negative ? -magnitude : magnitude;
  return at;
}

bool parse_plain_decimal(std::string_view token, double& value) {
  return read_plain_decimal(token.data(), token.data() + token.size(), value) == token.data() + token.size();
}

// Integers of up to 18 digits with a sign, by hand (no overflow possible); false for anything else.
bool parse_plain_integer(std::string_view token, std::int64_t& value) {
  const char* at = token.data();
  const char* const end = at + token.size();
  const bool negative = at != end && *at == '-';
  if (at != end && (*at == '-' || *at == '+')) ++at;
  if (at == end || end - at > 18) return false;
  std::int64_t magnitude = 0;
  for (; at != end; ++at) {
    const auto digit = static_cast<unsigned>(*at - '0');
    if (digit >= 10) return false;
    magnitude = magnitude * 10 + digit;
  }
  value = negative ? -magnitude : magnitude;
  return true;
}

// Any other number (an exponent, more digits than one exact division allows, "inf"), by from_chars.
bool parse_other_double(std::string_view token, double& value) {
  token = without_plus(token);
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  if (result.ptr != end) return false;
  // Beyond the range of double, from_chars leaves the value alone: the number still reads as what it rounds
  // to, +-inf or +-0 (a coordinate of inf is then named by the mesh's own check, not called malformed).
  if (result.ec == std::errc::result_out_of_range) value = std::strtod(std::string(token).c_str(), nullptr);
  return result.ec == std::errc() || result.ec == std::errc::result_out_of_range;
}

}  // namespace

bool parse_double(std::string_view token, double& value) {
  return parse_plain_decimal(token, value) || parse_other_double(token, value);
}

bool parse_integer(std::string_view token, std::int64_t& value) {
  if (parse_plain_integer(token, value)) return true;
  token = without_plus(token);
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  return result.ec == std::errc() && result.ptr == end;
}

std::size_t plausible_count(std::uint64_t count, std::size_t bytes_left, std::size_t min_bytes_per_item) {
  const std::uint64_t room = bytes_left / std::max<std::size_t>(min_bytes_per_item, 1);
  return static_cast<std::size_t>(std::min(count, room));
}

std::string too_few_corners(std::size_t corners) {
  return "face with " + std::to_string(corners) + " vertices (a face needs at least 3)";
}

std::string index_out_of_range(std::int64_t index, std::uint64_t vertex_count) {
  return "vertex index " + std::to_string(index) + " out of range (file has " + std::to_string(vertex_count) +
         " vertices)";
}

std::string too_many_vertices(std::uint64_t vertex_count) {
  return std::to_string(vertex_count) + " vertices exceed the range of 32-bit indices";
}

std::vector<std::size_t> line_chunks(std::string_view bytes, std::size_t begin, const ParallelTeam& team,
                                     std::size_t min_chunk_bytes) {
  const std::size_t size = bytes.size() - std::min(begin, bytes.size());
  const std::size_t wanted = std::clamp<std::size_t>(size / std::max<std::size_t>(min_chunk_bytes, 1), 1,
                                                     std::max<std::size_t>(1, team.range_count(size, min_chunk_bytes)));
  std::vector<std::size_t> bounds = {begin};
  // A line starts after an LF, or after a CR that no LF follows (a CRLF is never cut in two).
  const auto starts_line = [&](std::size_t at) {
    return bytes[at - 1] == '\n' || (bytes[at - 1] == '\r' && bytes[at] != '\n');
  };
  for (std::size_t k = 1; k < wanted; ++k) {
    std::size_t at = std::max(begin + size * k / wanted, bounds.back() + 1);
    while (at < bytes.size() && !starts_line(at)) ++at;
    if (at >= bytes.size()) break;
    bounds.push_back(at);
  }
  bounds.push_back(bytes.size());
  return bounds;
}

TextChunks count_chunk_rows(const MeshFile& file, char comment, std::vector<std::size_t> bounds,
                            std::size_t header_lines, const ParallelTeam& team) {
  TextChunks chunks{std::move(bounds), {}, {}};
  const std::size_t count = chunks.count();
  chunks.lines_before.assign(count + 1, 0);
  chunks.rows_before.assign(count + 1, 0);
  team.for_each(count, 1, [&](std::size_t k) {
    TextCursor cursor(file, comment, chunks.bounds[k], chunks.bounds[k + 1], 0);
    std::uint64_t rows = 0;
    while (cursor.next_data_line()) ++rows;
    chunks.lines_before[k + 1] = cursor.line_number();
    chunks.rows_before[k + 1] = rows;
  });
  chunks.lines_before[0] = header_lines;
  for (std::size_t k = 0; k < count; ++k) {
    chunks.lines_before[k + 1] += chunks.lines_before[k];
    chunks.rows_before[k + 1] += chunks.rows_before[k];
  }
  return chunks;
}

bool TextCursor::next_line() {
  const std::string_view text = file_.bytes.substr(0, end_);
  if (next_line_start_ >= text.size()) {
    line_ = {};
    return false;
  }
  // A line ends at LF, CRLF or a lone CR (classic Mac OS): read as one line, a CR-only file had no faces.
  // memchr finds the LF, then a CR before it, a handful of bytes at a time.
  const char* start = text.data() + next_line_start_;
  const std::size_t rest = text.size() - next_line_start_;
  const void* lf = std::memchr(start, '\n', rest);
  const std::size_t to_lf = lf ? static_cast<std::size_t>(static_cast<const char*>(lf) - start) : rest;
  const void* cr = may_hold_cr_ ? std::memchr(start, '\r', to_lf) : nullptr;
  const std::size_t end = next_line_start_ + (cr ? static_cast<std::size_t>(static_cast<const char*>(cr) - start) : to_lf);
  line_ = text.substr(next_line_start_, end - next_line_start_);
  const bool crlf = end + 1 < text.size() && text[end] == '\r' && text[end + 1] == '\n';
  terminator_ = text.substr(end, crlf ? 2 : 1);
  next_line_start_ = end + terminator_.size();
  ++line_number_;
  return true;
}

bool TextCursor::next_data_line() {
  while (next_line()) {
    const char* const line_end = line_.data() + line_.size();
    const char* const first = skip_blanks(line_.data(), line_end);
    if (first != line_end && (comment_ == '\0' || *first != comment_)) return true;
  }
  return false;
}

std::string_view TextCursor::next_token() {
  const char* const line_end = line_.data() + line_.size();
  const char* const begin = skip_blanks(line_.data(), line_end);
  if (begin == line_end || (comment_ != '\0' && *begin == comment_)) {
    line_ = {};
    return {};
  }
  const char* const end = token_end(begin, line_end);
  const std::string_view token(begin, static_cast<std::size_t>(end - begin));
  line_.remove_prefix(static_cast<std::size_t>(end - line_.data()));
  return token;
}

std::string_view TextCursor::peek_token() const {
  TextCursor copy = *this;
  return copy.next_token();
}

std::string_view TextCursor::next_token_any_line() {
  for (;;) {
    const std::string_view token = next_token();
    if (!token.empty() || !next_line()) return token;
  }
}

std::size_t TextCursor::count_tokens() {
  // next_token's rules in one pass: a token starts after a blank (or at the start), and one starting with
  // the comment character ends the line.
  std::size_t tokens = 0;
  bool in_token = false;
  for (const char c : line_) {
    if (is_blank(c)) {
      in_token = false;
    } else if (!in_token) {
      if (comment_ != '\0' && c == comment_) break;
      in_token = true;
      ++tokens;
    }
  }
  line_ = {};
  return tokens;
}

std::string_view TextCursor::read_token(std::string_view what) {
  const std::string_view token = next_token();
  if (token.empty()) fail(std::string("missing ") + std::string(what));
  return token;
}

double TextCursor::read_double(std::string_view what) {
  const std::string_view token = read_token(what);
  double value = 0;
  if (!parse_double(token, value)) fail("malformed number " + quoted(token) + " for " + std::string(what));
  return value;
}

std::int64_t TextCursor::read_integer(std::string_view what) {
  const std::string_view token = read_token(what);
  std::int64_t value = 0;
  if (!parse_integer(token, value)) fail("malformed integer " + quoted(token) + " for " + std::string(what));
  return value;
}

std::array<double, 3> TextCursor::read_position() {
  // Three finite numbers, each ending at a blank or the line's end, read in one pass over the line without
  // cutting it into tokens first: plain decimals by one exact division, any other number (printed with 17
  // digits, whose mantissa passes 2^53, or with an exponent) by from_chars on its extent. Any other line, and
  // every error, through the tokens below.
  std::array<double, 3> direct;
  const char* at = line_.data();
  const char* const end = at + line_.size();
  bool all_read = true;
  for (double& coordinate : direct) {
    at = skip_blanks(at, end);
    const char* number_end = read_plain_decimal(at, end, coordinate);
    if (number_end == nullptr || (number_end != end && !is_blank(*number_end))) {
      number_end = token_end(at, end);
      const std::string_view token(at, static_cast<std::size_t>(number_end - at));
      all_read = !token.empty() && parse_other_double(token, coordinate) && std::isfinite(coordinate);
      if (!all_read) break;
    }
    at = number_end;
  }
  if (all_read) {
    line_.remove_prefix(static_cast<std::size_t>(at - line_.data()));
    return direct;
  }
  const std::array<double, 3> position = {read_double("vertex x"), read_double("vertex y"), read_double("vertex z")};
  for (double coordinate : position) {
    if (!std::isfinite(coordinate)) fail("non-finite vertex coordinate");
  }
  return position;
}

void TextCursor::fail(std::string_view reason) const { throw_line_error(file_, line_number_, reason); }

}  // namespace detail

namespace {

std::string_view file_kind(const std::filesystem::file_status& status) {
  namespace fs = std::filesystem;
  if (fs::is_directory(status)) return "a directory";
  if (fs::is_fifo(status)) return "a FIFO";
  if (fs::is_character_file(status) || fs::is_block_file(status)) return "a device";
  if (fs::is_socket(status)) return "a socket";
  return "an unknown kind of file";
}

// A file's bytes, read into memory.
struct FileBytes {
  std::unique_ptr<char[]> data;
  std::size_t size = 0;
  std::string_view view() const { return {data.get(), size}; }
};

// Regular files of a known size are read in blocks by the team's threads straight into one buffer (the
// kernel's copy from its cache is the cost, and it parallelises); files whose size is not known up front
// (size 0 in /proc and the like) are read to their end in order.
FileBytes read_whole_file(const std::filesystem::path& path, const detail::ParallelTeam& team) {
  const auto fail_because = [&](const char* action, const std::string& reason) {
    throw Error(ErrorCode::io_error, std::string("cannot ") + action + " '" + path.string() + "': " + reason);
  };
  const auto fail = [&](const char* action) { fail_because(action, std::strerror(errno)); };
  // Checked before opening: reading /dev/zero (or a link to it) never ends, opening a FIFO waits for a
  // writer, and a directory reads as nothing. A path that does not exist is left to fopen's message.
  std::error_code status_error;
  const std::filesystem::file_status status = std::filesystem::status(path, status_error);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    fail_because("read", "not a regular file (" + std::string(file_kind(status)) + ")");
  }
  errno = 0;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> stream(std::fopen(path.string().c_str(), "rb"), &std::fclose);
  if (!stream) fail("open");
  const int descriptor = fileno(stream.get());
  struct stat info = {};
  if (fstat(descriptor, &info) != 0) fail("read");
  FileBytes bytes;
  if (info.st_size > 0) {
    bytes.size = static_cast<std::size_t>(info.st_size);
    bytes.data = std::make_unique_for_overwrite<char[]>(bytes.size);
    detail::advise_huge_pages(bytes.data.get(), bytes.size);
    constexpr std::size_t kBlock = std::size_t{1} << 22;
    const std::size_t blocks = (bytes.size + kBlock - 1) / kBlock;
    std::atomic<int> error{0};  // errno of a failed read, or -1 if the file ended early
    team.for_each(blocks, 1, [&](std::size_t block) {
      std::size_t at = block * kBlock;
      const std::size_t end = std::min(bytes.size, at + kBlock);
      while (at < end) {
        const ssize_t got = pread(descriptor, bytes.data.get() + at, end - at, static_cast<off_t>(at));
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) {
          error = got < 0 ? errno : -1;
          return;
        }
        at += static_cast<std::size_t>(got);
      }
    });
    if (error == -1) fail_because("read", "the file became shorter while it was read");
    if (error != 0) fail_because("read", std::strerror(error));
    return bytes;
  }
  std::string text;
  char buffer[1 << 16];
  for (;;) {
    const std::size_t got = std::fread(buffer, 1, sizeof buffer, stream.get());
    text.append(buffer, got);
    if (got < sizeof buffer) break;
  }
  if (std::ferror(stream.get())) fail("read");
  bytes.size = text.size();
  bytes.data = std::make_unique_for_overwrite<char[]>(bytes.size);
  std::copy(text.begin(), text.end(), bytes.data.get());
  return bytes;
}

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

}  // namespace

MeshSoup read_mesh_soup(const std::filesystem::path& path, const ReadOptions& options) {
  using Reader = MeshSoup (*)(const detail::MeshFile&, const detail::ParallelTeam&, std::size_t);
  const std::string extension = lowercase(path.extension().string());
  Reader reader = nullptr;
  if (extension == ".obj") reader = &detail::read_obj;
  if (extension == ".ply") reader = &detail::read_ply;
  if (extension == ".off") reader = &detail::read_off;
  if (extension == ".stl") reader = &detail::read_stl;
  if (!reader) {
    const std::string found = extension.empty() ? "no extension" : "unsupported extension '" + extension + "'";
    throw Error(ErrorCode::invalid_mesh, path.string() + ": " + found + " (expected .obj, .ply, .off or .stl)");
  }
  // One thread per chunk of file at most: a file under two chunks is read and parsed on the calling thread.
  std::error_code size_error;
  const std::uintmax_t size = std::filesystem::file_size(path, size_error);
  const std::uintmax_t worth = size_error ? 1 : std::max<std::uintmax_t>(1, size / detail::kMinChunkBytes);
  detail::WorkerPool pool(static_cast<unsigned>(
      std::min<std::uintmax_t>({detail::threads_or_cores(options.threads), detail::threads_or_cores(0), worth})));
  const detail::ParallelTeam team{pool, options.stop};
  const FileBytes bytes = read_whole_file(path, team);
  const detail::MeshFile file{path.string(), bytes.view()};
  MeshSoup soup = reader(file, team, detail::kMinChunkBytes);
  if (soup.positions.empty()) detail::throw_file_error(file, "no vertices");
  if (soup.triangles.empty()) detail::throw_file_error(file, "no faces");
  return soup;
}

Mesh load_mesh(const std::filesystem::path& path, const MeshOptions& options) {
  return Mesh(read_mesh_soup(path, {.threads = options.threads, .stop = options.stop}), options);
}

}  // namespace exactgeo
