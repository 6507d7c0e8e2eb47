// The readers' number parsing (parse_double, parse_integer) against std::from_chars itself: every token over a
// small alphabet up to a length, and seeded random decimals of every length and place of the point (the
// numbers files write), give the same verdict and, where read, the same value bit for bit.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "exactgeo/error.hpp"
#include "readers.hpp"

namespace {

using exactgeo::detail::parse_double;
using exactgeo::detail::parse_integer;

// The readers' rule, from the standard library alone: one leading '+' is allowed before a digit or a point,
// and the whole token must be the number.
std::string_view without_leading_plus(std::string_view token) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '+' && token[1] != '-') token.remove_prefix(1);
  return token;
}

// from_chars's double, nullopt if it refuses the token; `out_of_range` set where it is beyond double (the
// readers then round it to inf or 0, which this test leaves to test_io_obj).
std::optional<double> reference_double(std::string_view token, bool& out_of_range) {
  token = without_leading_plus(token);
  double value = 0;
  const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
  out_of_range = result.ec == std::errc::result_out_of_range;
  if (result.ptr != token.data() + token.size() || result.ec != std::errc()) return std::nullopt;
  return value;
}

std::optional<std::int64_t> reference_integer(std::string_view token) {
  token = without_leading_plus(token);
  std::int64_t value = 0;
  const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
  if (result.ptr != token.data() + token.size() || result.ec != std::errc()) return std::nullopt;
  return value;
}

// Fails the test unless both parsers agree with from_chars on `token`; returns whether it was a number.
bool expect_same_as_from_chars(const std::string& token) {
  bool out_of_range = false;
  const std::optional<double> expected = reference_double(token, out_of_range);
  double value = 0;
  const bool parsed = parse_double(token, value);
  if (!out_of_range) {
    EXPECT_EQ(parsed, expected.has_value()) << "'" << token << "'";
    if (parsed && expected) {
      EXPECT_EQ(std::bit_cast<std::uint64_t>(value), std::bit_cast<std::uint64_t>(*expected)) << "'" << token << "'";
    }
  }
  const std::optional<std::int64_t> expected_integer = reference_integer(token);
  std::int64_t integer = 0;
  const bool parsed_integer = parse_integer(token, integer);
  EXPECT_EQ(parsed_integer, expected_integer.has_value()) << "'" << token << "'";
  if (parsed_integer && expected_integer) {
    EXPECT_EQ(integer, *expected_integer) << "'" << token << "'";
  }
  return parsed;
}

TEST(IoNumbers, EveryShortTokenReadsAsFromCharsReadsIt) {
  // Signs, points, digits, an exponent and a stray letter, every string of them up to 6 characters
  // (299,593 tokens).
  constexpr std::string_view kAlphabet = "+-.059ex";
  std::size_t numbers = 0;
  std::string token;
  for (std::size_t length = 0; length <= 6; ++length) {
    std::size_t total = 1;
    for (std::size_t i = 0; i < length; ++i) total *= kAlphabet.size();
    token.assign(length, ' ');
    for (std::size_t code = 0; code < total; ++code) {
      std::size_t rest = code;
      for (std::size_t i = 0; i < length; ++i, rest /= kAlphabet.size()) token[i] = kAlphabet[rest % kAlphabet.size()];
      numbers += expect_same_as_from_chars(token);
      if (testing::Test::HasFailure()) return;
    }
  }
  EXPECT_GT(numbers, 9000u);  // the walk met numbers, not only refusals
}

TEST(IoNumbers, RandomDecimalsReadBitForBitAsFromCharsReadsThem) {
  std::mt19937_64 random(38);
  std::string token;
  for (int trial = 0; trial < 400000; ++trial) {
    token.clear();
    const int sign = static_cast<int>(random() % 3);
    if (sign == 1) token += '-';
    if (sign == 2) token += '+';
    // Up to 25 digits, with the point anywhere (or nowhere), leading zeros now and then; a third of the
    // mantissas near 2^53, where the exact division stops being possible.
    std::string digits;
    if (trial % 3 == 0) {
      digits = std::to_string((std::uint64_t{1} << 53) - 8 + random() % 16);
    } else {
      const std::size_t count = 1 + random() % 25;
      for (std::size_t i = 0; i < count; ++i) digits += static_cast<char>('0' + random() % 10);
    }
    if (random() % 8 == 0) digits.insert(0, random() % 4, '0');
    const std::size_t point = random() % (digits.size() + 2);
    if (point <= digits.size()) digits.insert(point, 1, '.');
    token += digits;
    expect_same_as_from_chars(token);
    if (testing::Test::HasFailure()) return;
  }
}

TEST(IoNumbers, FixedPrecisionCoordinatesReadBitForBit) {
  // What writers produce, printf's %.Nf and %.17g of random doubles of every scale.
  std::mt19937_64 random(3801);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  char text[400];
  for (int trial = 0; trial < 200000; ++trial) {
    const double x = std::ldexp(unit(random), static_cast<int>(random() % 120) - 60);
    const int written = trial % 2 == 0 ? std::snprintf(text, sizeof text, "%.*f", static_cast<int>(random() % 24), x)
                                       : std::snprintf(text, sizeof text, "%.17g", x);
    ASSERT_GT(written, 0);
    expect_same_as_from_chars(text);
    if (testing::Test::HasFailure()) return;
  }
}

TEST(IoNumbers, DigitRunsStopAtEveryByteAsFromCharsStops) {
  // Runs of up to 17 digits broken by every byte value, at every place before and after it.
  std::mt19937_64 random(3802);
  std::size_t numbers = 0;
  for (int stop = 0; stop < 256; ++stop) {
    for (std::size_t before = 0; before <= 17; ++before)
      for (std::size_t after = 0; after <= 10; ++after) {
        std::string token = random() % 2 ? "-" : "";
        for (std::size_t i = 0; i < before; ++i) token += static_cast<char>('0' + random() % 10);
        token += static_cast<char>(stop);
        for (std::size_t i = 0; i < after; ++i) token += static_cast<char>('0' + random() % 10);
        numbers += expect_same_as_from_chars(token);
        if (testing::Test::HasFailure()) return;
      }
  }
  EXPECT_GT(numbers, 2000u);  // the runs with a point and those of digits only were read as numbers
}

TEST(IoNumbers, ObjVertexLinesReadTheirNumbersAsFromChars) {
  // Vertex lines are read without tokens where they can be: numbers of every form (plain, printed with 17
  // digits, exponents, a '+', not finite, malformed, missing) between any blanks give the coordinates
  // from_chars gives, or an error naming the line when one is not a finite number.
  std::mt19937_64 random(3804);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const char* blanks[] = {" ", "\t", "  ", "\v", " \f "};
  const char* others[] = {"nan", "inf", "-inf", "1e", "1.5e+", "0x1p3", "1,5", "#1", "--1", "+-1", "1.2.3", "4a"};
  exactgeo::detail::WorkerPool pool(1);
  for (int trial = 0; trial < 30000; ++trial) {
    std::string text = "v";
    std::array<double, 3> expected{};
    bool all_finite = true;
    const int numbers = trial % 50 == 0 ? 2 : 3;
    for (int k = 0; k < numbers; ++k) {
      char number[64];
      const double x = std::ldexp(unit(random), static_cast<int>(random() % 80) - 40);
      switch (random() % 6) {
        case 0:
          std::snprintf(number, sizeof number, "%.*f", static_cast<int>(random() % 10), x);
          break;
        case 1:
          std::snprintf(number, sizeof number, "%.17g", x);
          break;
        case 2:
          std::snprintf(number, sizeof number, "%.*e", static_cast<int>(random() % 17), x);
          break;
        case 3:
          std::snprintf(number, sizeof number, "+%.9g", std::abs(x));
          break;
        case 4:  // hexadecimal: refused by both
          std::snprintf(number, sizeof number, "%a", x);
          break;
        default:
          std::snprintf(number, sizeof number, "%s", random() % 4 == 0 ? others[random() % 12] : "0.5");
          break;
      }
      bool out_of_range = false;
      const std::optional<double> value = reference_double(number, out_of_range);
      ASSERT_FALSE(out_of_range) << number;
      all_finite = all_finite && value && std::isfinite(*value);
      if (value) expected[static_cast<std::size_t>(k)] = *value;
      text += blanks[random() % 5];
      text += number;
    }
    all_finite = all_finite && numbers == 3;
    text += random() % 3 == 0 ? " # a comment\n" : random() % 2 ? " \n" : "\n";
    try {
      const exactgeo::MeshSoup soup = exactgeo::detail::read_obj(exactgeo::detail::MeshFile{"vertex.obj", text},
                                                                 exactgeo::detail::ParallelTeam{pool});
      ASSERT_TRUE(all_finite) << "read: " << text;
      ASSERT_EQ(soup.positions.size(), 3u);
      for (std::size_t k = 0; k < 3; ++k)
        ASSERT_EQ(std::bit_cast<std::uint64_t>(soup.positions[k]), std::bit_cast<std::uint64_t>(expected[k])) << text;
    } catch (const exactgeo::Error& e) {
      ASSERT_FALSE(all_finite) << e.what() << ": " << text;
      ASSERT_NE(std::string(e.what()).find("vertex.obj:1: "), std::string::npos) << e.what();
    }
  }
}

TEST(IoNumbers, ObjCornersWithLongDigitRunsReadAsWritten) {
  // Face corners padded with leading zeros (runs of 1 to 13 digits; more than 10 go to the tokens), any
  // blanks between them and /vt/vn after them, against the triangles written.
  std::mt19937_64 random(3803);
  for (int file = 0; file < 40; ++file) {
    std::string text;
    const int vertices = 3 + static_cast<int>(random() % 200);
    for (int v = 0; v < vertices; ++v) text += "v " + std::to_string(v) + " " + std::to_string(v % 7) + " 0\n";
    std::vector<std::uint32_t> expected;
    const char* blanks[] = {" ", "\t", "  ", "\v", "\f", " \t"};
    const char* suffixes[] = {"", "", "/1", "//2", "/1/2"};
    for (int face = 0; face < 50; ++face) {
      const int corners = 3 + static_cast<int>(random() % 3);
      std::vector<std::uint32_t> polygon;
      text += "f";
      for (int c = 0; c < corners; ++c) {
        polygon.push_back(static_cast<std::uint32_t>(random() % vertices));
        text += blanks[random() % 6];
        text += std::string(random() % 12, '0') + std::to_string(polygon.back() + 1) + suffixes[random() % 5];
      }
      text += random() % 2 ? "\n" : " \n";
      for (int c = 2; c < corners; ++c) expected.insert(expected.end(), {polygon[0], polygon[c - 1], polygon[c]});
    }
    exactgeo::detail::WorkerPool pool(1);
    const exactgeo::MeshSoup soup =
        exactgeo::detail::read_obj(exactgeo::detail::MeshFile{"corners.obj", text},
                                   exactgeo::detail::ParallelTeam{pool}, exactgeo::detail::kMinChunkBytes);
    ASSERT_EQ(soup.triangles, expected) << "file " << file << ":\n" << text;
  }
}

}  // namespace
