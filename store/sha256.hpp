// SHA-256 (FIPS 180-4) for the Zarr stores' mesh hash and block digests, which must equal Python's
// hashlib.sha256 over the same bytes. A compact implementation of our own rather than OpenSSL: the command
// links nothing else that has one, and OpenSSL would be a shared library the wheel must carry for a few
// hashes of megabytes.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace exactgeo::store {

class Sha256 {
 public:
  Sha256();
  void update(std::span<const unsigned char> bytes);
  void update(std::string_view text);
  // The digest as 64 lower-case hex digits, as hashlib's hexdigest(); the object is spent afterwards.
  std::string hex_digest();

 private:
  void compress(const unsigned char* block);

  std::array<std::uint32_t, 8> state_;
  std::array<unsigned char, 64> pending_{};  // the bytes of an unfinished block
  std::size_t pending_size_ = 0;
  std::uint64_t total_bytes_ = 0;
};

}  // namespace exactgeo::store
