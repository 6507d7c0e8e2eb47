// The distance matrix store component (store/): SHA-256 against FIPS 180-4's examples and hashlib, the block rule,
// the metadata and settings it writes, and how it names what differs. The writer's files, end to end through the
// command, are tests/test_cli_store.cpp's; the layout against docs/distributed.md and the stores written before
// this component, python/tests/test_store_layout.py's.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "matrix_store.hpp"
#include "sha256.hpp"
#include "store_files.hpp"

namespace {

using exactgeo::store::Sha256;

std::string sha256_hex(std::string_view text) {
  Sha256 digest;
  digest.update(text);
  return digest.hex_digest();
}

std::string sha256_hex(std::span<const unsigned char> bytes) {
  Sha256 digest;
  digest.update(bytes);
  return digest.hex_digest();
}

// FIPS 180-4's examples (NIST's "SHA256.pdf" and "SHA2_Additional.pdf").
TEST(Sha256, GivesTheStandardsExampleDigests) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex("abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmnoijklmnopjklmnopqklmnopqrlmnopq"
                       "rsmnopqrstnopqrstu"),
            "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// Pseudo-random bytes from a 64-bit LCG (the top byte of each state), which Python reproduces:
//   x = 0x2545F4914F6CDD1D; each byte: x = (x * 6364136223846793005 + 1442695040888963407) % 2**64; byte x >> 56
// The expected digests are hashlib's:
//   sha256("".join(sha256(b[:n]).hexdigest() for n in range(301)).encode()) and sha256(b) for all of b.
std::vector<unsigned char> lcg_bytes(std::size_t count) {
  std::vector<unsigned char> bytes(count);
  std::uint64_t x = 0x2545F4914F6CDD1DULL;
  for (unsigned char& byte : bytes) {
    x = x * 6364136223846793005ULL + 1442695040888963407ULL;
    byte = static_cast<unsigned char>(x >> 56);
  }
  return bytes;
}

TEST(Sha256, AgreesWithHashlibOnEveryLengthUpTo300AndOnAMegabyte) {
  const std::vector<unsigned char> bytes = lcg_bytes((std::size_t{1} << 20) + 300);
  std::string digests;
  for (std::size_t n = 0; n <= 300; ++n) digests += sha256_hex(std::span(bytes).first(n));
  EXPECT_EQ(sha256_hex(digests), "2ab4783b13891610b193ebbea94dd9b05c0d7a3cc485d31a3b377dd01b7ca7d6");
  EXPECT_EQ(sha256_hex(bytes), "71cfce4a51359a692bf41783807ddb31946d10bb8ac2c3d898254be12a5825ee");
  // Fed in pieces of every size across block boundaries, the digest is the same.
  for (std::size_t piece : {1, 3, 63, 64, 65, 1000}) {
    Sha256 digest;
    for (std::size_t at = 0; at < bytes.size(); at += piece)
      digest.update(std::span(bytes).subspan(at, std::min(piece, bytes.size() - at)));
    EXPECT_EQ(digest.hex_digest(), "71cfce4a51359a692bf41783807ddb31946d10bb8ac2c3d898254be12a5825ee") << piece;
  }
}

// The block rule for a new store: 32 MiB a chunk, 4096 rows, some 32 blocks.
TEST(MatrixStore, DefaultBlockRowsFollowTheBlockRule) {
  EXPECT_EQ(exactgeo::store::default_block_rows(128, 512, 4), 4u);
  EXPECT_EQ(exactgeo::store::default_block_rows(5, 10, 8), 1u);
  EXPECT_EQ(exactgeo::store::default_block_rows(1000000, 50000, 4), 167u);
  EXPECT_EQ(exactgeo::store::default_block_rows(1000000, 10, 8), 4096u);
}

// What zarr-python 3 writes for create_array(shape=(10, 7), chunks=(4, 7), dtype="float32",
// fill_value=nan, dimension_names=["source", "target"], compressors=None).
TEST(MatrixStore, ArrayMetadataIsWhatZarrPythonWritesForUncompressedChunks) {
  const auto expected = nlohmann::ordered_json::parse(R"({
    "shape": [10, 7], "data_type": "float32",
    "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [4, 7]}},
    "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
    "fill_value": "NaN", "codecs": [{"name": "bytes", "configuration": {"endian": "little"}}],
    "attributes": {}, "dimension_names": ["source", "target"], "zarr_format": 3, "node_type": "array",
    "storage_transformers": []})");
  EXPECT_EQ(exactgeo::store::array_metadata(std::vector<std::size_t>{10, 7}, std::vector<std::size_t>{4, 7}, "float32",
                                            "NaN", {"source", "target"}),
            expected);
}

exactgeo::store::StoreSettings small_settings() {
  return {.mesh_sha256 = std::string(64, 'a'),
          .vertex_count = 25,
          .face_count = 32,
          .weld = false,
          .sources = {0, 3, 7},
          .targets = std::nullopt,
          .columns = 25,
          .dtype = "float32",
          .max_distance = std::nullopt,
          .block_rows = 2};
}

TEST(MatrixStore, SettingsHaveTheDocumentedKeysInOrder) {
  const nlohmann::ordered_json json = exactgeo::store::settings_json(small_settings());
  std::vector<std::string> keys;
  for (const auto& item : json.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"format", "version", "mesh_sha256", "vertex_count", "face_count",
                                            "weld_duplicate_positions", "sources", "targets", "shape", "dtype",
                                            "max_distance", "layout", "block_rows", "blocks", "zarr_format"}));
  EXPECT_EQ(json["blocks"], 2);
  EXPECT_EQ(json["layout"], "dense");
  EXPECT_TRUE(json["targets"].is_null() && json["max_distance"].is_null());
}

TEST(MatrixStore, DifferencesNameWhatDiffers) {
  exactgeo::store::StoreSettings other = small_settings();
  other.sources = {0, 3, 7, 8, 9, 10};
  other.dtype = "float64";
  other.block_rows = 3;
  const auto stored = exactgeo::store::settings_json(small_settings());
  const auto wanted = exactgeo::store::settings_json(other);
  EXPECT_TRUE(exactgeo::store::store_differences(stored, stored, true).empty());
  const std::vector<std::string> found = exactgeo::store::store_differences(stored, wanted, false);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0], "other sources (the store's: 3 sources [0, 3, 7]; these: 6 sources [0, 3, 7, 8, 9, ...])");
  EXPECT_EQ(found[1], R"(another dtype (the store's: "float32"; this run's: "float64"))");
  EXPECT_EQ(exactgeo::store::store_differences(stored, wanted, true).back(),
            "another block_rows (the store's: 2; this run's: 3)");
}

}  // namespace
