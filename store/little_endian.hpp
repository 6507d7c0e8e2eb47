// Values as little-endian bytes, whatever the host's byte order: the bytes of Zarr chunks, .npy data and the
// hashes taken over them.
#pragma once

#include <bit>
#include <cstdint>
#include <span>
#include <vector>

namespace exactgeo::store {

namespace detail {
template <typename T, typename Bits>
std::vector<unsigned char> bytes_of(std::span<const T> values) {
  std::vector<unsigned char> bytes;
  bytes.reserve(values.size() * sizeof(T));
  for (const T value : values) {
    const auto bits = std::bit_cast<Bits>(value);
    for (std::size_t byte = 0; byte < sizeof(T); ++byte)
      bytes.push_back(static_cast<unsigned char>(bits >> (8 * byte)));
  }
  return bytes;
}
}  // namespace detail

inline std::vector<unsigned char> little_endian_bytes(std::span<const double> values) {
  return detail::bytes_of<double, std::uint64_t>(values);
}
inline std::vector<unsigned char> little_endian_bytes(std::span<const float> values) {
  return detail::bytes_of<float, std::uint32_t>(values);
}
inline std::vector<unsigned char> little_endian_bytes(std::span<const std::uint32_t> values) {
  return detail::bytes_of<std::uint32_t, std::uint32_t>(values);
}
inline std::vector<unsigned char> little_endian_bytes(std::span<const std::int32_t> values) {
  return detail::bytes_of<std::int32_t, std::uint32_t>(values);
}
inline std::vector<unsigned char> little_endian_bytes(std::span<const std::int64_t> values) {
  return detail::bytes_of<std::int64_t, std::uint64_t>(values);
}

}  // namespace exactgeo::store
