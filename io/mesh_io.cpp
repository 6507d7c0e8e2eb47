// Public entry points for reading mesh files, and the helpers the per-format readers share.
#include <algorithm>
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

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

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

bool parse_double(std::string_view token, double& value) {
  token = without_plus(token);
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  if (result.ptr != end) return false;
  // Beyond the range of double, from_chars leaves the value alone: the number still reads as what it rounds
  // to, +-inf or +-0 (a coordinate of inf is then named by the mesh's own check, not called malformed).
  if (result.ec == std::errc::result_out_of_range) value = std::strtod(std::string(token).c_str(), nullptr);
  return result.ec == std::errc() || result.ec == std::errc::result_out_of_range;
}

bool parse_integer(std::string_view token, std::int64_t& value) {
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

void append_fan(std::span<const std::uint32_t> polygon, std::vector<std::uint32_t>& triangles) {
  for (std::size_t i = 2; i < polygon.size(); ++i) {
    triangles.insert(triangles.end(), {polygon[0], polygon[i - 1], polygon[i]});
  }
}

bool TextCursor::next_line() {
  const std::string_view text = file_.bytes;
  if (next_line_start_ >= text.size()) {
    line_ = {};
    return false;
  }
  // A line ends at LF, CRLF or a lone CR (classic Mac OS): read as one line, a CR-only file had no faces.
  const std::size_t end = std::min(text.find_first_of("\r\n", next_line_start_), text.size());
  line_ = text.substr(next_line_start_, end - next_line_start_);
  terminator_ = text.substr(end, text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
  next_line_start_ = end + terminator_.size();
  ++line_number_;
  return true;
}

bool TextCursor::next_data_line() {
  while (next_line()) {
    const auto first = std::find_if_not(line_.begin(), line_.end(), is_blank);
    if (first != line_.end() && (comment_ == '\0' || *first != comment_)) return true;
  }
  return false;
}

std::string_view TextCursor::next_token() {
  std::size_t begin = 0;
  while (begin < line_.size() && is_blank(line_[begin])) ++begin;
  if (begin == line_.size() || (comment_ != '\0' && line_[begin] == comment_)) {
    line_ = {};
    return {};
  }
  std::size_t end = begin;
  while (end < line_.size() && !is_blank(line_[end])) ++end;
  const std::string_view token = line_.substr(begin, end - begin);
  line_.remove_prefix(end);
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

double TextCursor::read_double(std::string_view what) {
  const std::string_view token = next_token();
  if (token.empty()) fail(std::string("missing ") + std::string(what));
  double value = 0;
  if (!parse_double(token, value)) fail("malformed number " + quoted(token) + " for " + std::string(what));
  return value;
}

std::int64_t TextCursor::read_integer(std::string_view what) {
  const std::string_view token = next_token();
  if (token.empty()) fail(std::string("missing ") + std::string(what));
  std::int64_t value = 0;
  if (!parse_integer(token, value)) fail("malformed integer " + quoted(token) + " for " + std::string(what));
  return value;
}

std::array<double, 3> TextCursor::read_position() {
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

std::string read_whole_file(const std::filesystem::path& path) {
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
  std::string bytes;
  char buffer[1 << 16];
  for (;;) {
    const std::size_t got = std::fread(buffer, 1, sizeof buffer, stream.get());
    bytes.append(buffer, got);
    if (got < sizeof buffer) break;
  }
  if (std::ferror(stream.get())) fail("read");
  return bytes;
}

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

}  // namespace

MeshSoup read_mesh_soup(const std::filesystem::path& path) {
  using Reader = MeshSoup (*)(const detail::MeshFile&);
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
  const std::string bytes = read_whole_file(path);
  const detail::MeshFile file{path.string(), bytes};
  MeshSoup soup = reader(file);
  if (soup.positions.empty()) detail::throw_file_error(file, "no vertices");
  if (soup.triangles.empty()) detail::throw_file_error(file, "no faces");
  return soup;
}

Mesh load_mesh(const std::filesystem::path& path, const MeshOptions& options) {
  return Mesh(read_mesh_soup(path), options);
}

}  // namespace exactgeo
