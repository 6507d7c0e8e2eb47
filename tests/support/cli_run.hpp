// The exactgeo command run as users run it, for the command's tests (test_cli*.cpp): a scratch folder per test,
// the command through the shell with its exit code, stdout and stderr, and readers of the files it writes.
#pragma once
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace exactgeo_test {

namespace fs = std::filesystem;

inline constexpr double kInf = std::numeric_limits<double>::infinity();

struct RunResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

inline std::string read_file(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

inline void write_file(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

inline std::vector<double> parse_txt(const fs::path& path) {
  std::vector<double> values;
  std::istringstream lines(read_file(path));
  for (std::string line; std::getline(lines, line);) values.push_back(std::strtod(line.c_str(), nullptr));
  return values;
}

// Checks the "vertex,distance" header and that rows come in vertex order.
inline std::vector<double> parse_csv(const fs::path& path) {
  std::vector<double> values;
  std::istringstream lines(read_file(path));
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "vertex,distance");
  while (std::getline(lines, line)) {
    const std::size_t comma = line.find(',');
    EXPECT_NE(comma, std::string::npos) << line;
    EXPECT_EQ(line.substr(0, comma), std::to_string(values.size()));
    values.push_back(std::strtod(line.c_str() + comma + 1, nullptr));
  }
  return values;
}

// Validates the NumPy v1.0 header of a 1-D little-endian float64 array and returns its values.
inline std::vector<double> parse_npy(const fs::path& path) {
  const std::string bytes = read_file(path);
  if (bytes.size() < 10) {
    ADD_FAILURE() << "npy file too short";
    return {};
  }
  EXPECT_EQ(bytes.substr(0, 6), "\x93NUMPY");
  EXPECT_EQ(bytes[6], 1);  // format version 1.0
  EXPECT_EQ(bytes[7], 0);
  const std::size_t header_length = std::uint8_t(bytes[8]) | std::size_t(std::uint8_t(bytes[9])) << 8;
  const std::size_t data_offset = 10 + header_length;
  EXPECT_EQ(data_offset % 16, 0u) << "the format requires the data to be aligned";
  const std::string header = bytes.substr(10, header_length);
  EXPECT_EQ(header.back(), '\n');
  EXPECT_NE(header.find("'descr': '<f8'"), std::string::npos) << header;
  EXPECT_NE(header.find("'fortran_order': False"), std::string::npos) << header;
  const std::size_t shape = header.find("'shape': (");
  EXPECT_NE(shape, std::string::npos) << header;
  const std::size_t count = std::strtoull(header.c_str() + shape + 10, nullptr, 10);
  EXPECT_NE(header.find("'shape': (" + std::to_string(count) + ",)"), std::string::npos) << header;
  EXPECT_EQ(bytes.size(), data_offset + count * 8);

  std::vector<double> values(count);
  for (std::size_t i = 0; i < count && data_offset + i * 8 + 8 <= bytes.size(); ++i) {
    std::uint64_t bits = 0;
    for (std::size_t byte = 0; byte < 8; ++byte) {
      bits |= std::uint64_t(std::uint8_t(bytes[data_offset + i * 8 + byte])) << (8 * byte);
    }
    values[i] = std::bit_cast<double>(bits);
  }
  return values;
}

// Reads a 2-D little-endian float64 .npy (rows x columns).
inline std::vector<double> parse_npy_matrix(const fs::path& path, std::size_t rows, std::size_t columns) {
  const std::string bytes = read_file(path);
  const std::size_t header_length = std::uint8_t(bytes[8]) | std::size_t(std::uint8_t(bytes[9])) << 8;
  const std::string header = bytes.substr(10, header_length);
  EXPECT_NE(header.find("'shape': (" + std::to_string(rows) + ", " + std::to_string(columns) + ")"), std::string::npos)
      << header;
  EXPECT_EQ(bytes.size(), 10 + header_length + rows * columns * 8);
  std::vector<double> values(rows * columns);
  for (std::size_t i = 0; i < values.size() && 10 + header_length + 8 * i + 8 <= bytes.size(); ++i) {
    std::uint64_t bits = 0;
    for (std::size_t byte = 0; byte < 8; ++byte)
      bits |= std::uint64_t(std::uint8_t(bytes[10 + header_length + 8 * i + byte])) << (8 * byte);
    values[i] = std::bit_cast<double>(bits);
  }
  return values;
}

inline void expect_bitwise_equal(const std::vector<double>& a, const std::vector<double>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a[i]), std::bit_cast<std::uint64_t>(b[i])) << "vertex " << i;
  }
}

// Each test gets its own scratch directory, removed afterwards.
class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("exactgeo_cli_" + std::string(test->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path path(const std::string& name) const { return dir_ / name; }

  // Runs `exactgeo ARGUMENTS` through the shell; ARGUMENTS must already be quoted where needed.
  RunResult run(const std::string& arguments) const {
    const fs::path out = path("stdout"), err = path("stderr");
    const std::string command =
        "'" EXACTGEO_CLI_PATH "' " + arguments + " >'" + out.string() + "' 2>'" + err.string() + "'";
    const int status = std::system(command.c_str());
    RunResult result;
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    result.out = read_file(out);
    result.err = read_file(err);
    return result;
  }

  // Quoted path of a scratch file, for use in arguments.
  std::string arg(const std::string& name) const { return "'" + path(name).string() + "'"; }

  // An error: the given exit code, nothing on stdout, one "exactgeo: " message on stderr naming `expected`.
  static void expect_error(const RunResult& result, int exit_code, const std::string& expected) {
    EXPECT_EQ(result.exit_code, exit_code) << result.err;
    EXPECT_EQ(result.out, "");
    EXPECT_EQ(result.err.rfind("exactgeo: ", 0), 0u) << result.err;
    EXPECT_NE(result.err.find(expected), std::string::npos) << result.err;
    EXPECT_LE(std::count(result.err.begin(), result.err.end(), '\n'), 2) << result.err;
  }

 private:
  fs::path dir_;
};

// Two triangles that share an edge only through duplicated positions, plus a vertex used by no face.
inline constexpr const char* kSeamObj =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
    "v 1 0 0\nv 0 1 0\nv 1 1 0\n"
    "v 5 5 5\n"
    "f 1 2 3\nf 4 6 5\n";

// A .npy file of `values` stored as `descr` ("<i2", ">u8", "|u1", ...), laid out as numpy.save lays it: the
// preamble, the header padded to 64 bytes, then each value's low bytes in the descr's byte order.
inline std::string npy_file(const std::string& descr, const std::vector<std::int64_t>& values, std::string shape = "") {
  if (shape.empty()) shape = "(" + std::to_string(values.size()) + ",)";
  std::string header = "{'descr': '" + descr + "', 'fortran_order': False, 'shape': " + shape + ", }";
  header.append((64 - (10 + header.size() + 1) % 64) % 64, ' ');
  header += '\n';
  std::string bytes =
      std::string("\x93NUMPY\x01\x00", 8) + char(header.size() & 0xff) + char(header.size() >> 8) + header;
  const bool big_endian = descr[0] == '>';
  const std::size_t size = std::stoul(descr.substr(2));
  for (const std::int64_t value : values)
    for (std::size_t k = 0; k < size; ++k)
      bytes += char(static_cast<std::uint64_t>(value) >> (8 * (big_endian ? size - 1 - k : k)));
  return bytes;
}

}  // namespace exactgeo_test
