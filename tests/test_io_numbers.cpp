// The readers' number parsing (parse_double, parse_integer) against std::from_chars itself: every token over a
// small alphabet up to a length, and seeded random decimals of every length and place of the point (the
// numbers files write), give the same verdict and, where read, the same value bit for bit.
#include <gtest/gtest.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <string_view>

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

}  // namespace
