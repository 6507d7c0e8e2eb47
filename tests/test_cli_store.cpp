// The pieces behind `exactgeo matrix --out M.zarr --shard I/N`: SHA-256 against FIPS 180-4's examples and
// hashlib, shard and block-range syntax, the store writer's files (python/tests/test_cli_zarr.py checks that
// zarr-python and exactgeo.distributed read them), and what --verify and --resume make of every file of a
// store damaged in turn.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "exactgeo/shapes.hpp"
#include "sha256.hpp"
#include "zarr_store.hpp"

namespace {

namespace fs = std::filesystem;
using exactgeo::cli::Sha256;

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

TEST(Shard, ParsesIOverNAndRejectsAnythingElseSayingWhy) {
  const exactgeo::cli::Shard first = exactgeo::cli::parse_shard("0/1");
  EXPECT_EQ(first.index, 0u);
  EXPECT_EQ(first.count, 1u);
  const exactgeo::cli::Shard last = exactgeo::cli::parse_shard("11/12");
  EXPECT_EQ(last.index, 11u);
  EXPECT_EQ(last.count, 12u);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"4/4", "must be below 4"}, {"9/3", "must be below 3"}, {"0/0", "is 0"},     {"1", "not a shard I/N"},
      {"a/2", "not a shard"},     {"1/", "not a shard"},      {"/2", "not a shard"}, {"-1/2", "not a shard"},
      {"1/2/3", "not a shard"},   {" 1/2", "not a shard"},    {"", "not a shard"}};
  for (const auto& [text, reason] : bad) {
    try {
      exactgeo::cli::parse_shard(text);
      ADD_FAILURE() << "'" << text << "' was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  }
}

TEST(Shard, TheShardsOfABlockCountPartitionIt) {
  EXPECT_EQ(exactgeo::cli::shard_blocks({1, 3}, 10), (std::vector<std::size_t>{1, 4, 7}));
  EXPECT_EQ(exactgeo::cli::shard_blocks({5, 6}, 4), std::vector<std::size_t>{});
  for (std::size_t count : {1, 2, 3, 7, 40}) {
    std::multiset<std::size_t> all;
    for (std::size_t index = 0; index < count; ++index)
      for (std::size_t block : exactgeo::cli::shard_blocks({index, count}, 23)) {
        EXPECT_EQ(block % count, index);
        all.insert(block);
      }
    EXPECT_EQ(all.size(), 23u);
    EXPECT_EQ(std::set<std::size_t>(all.begin(), all.end()).size(), 23u);
  }
}

TEST(Shard, BlockNumbersPrintAsCompactRanges) {
  using exactgeo::cli::block_ranges;
  EXPECT_EQ(block_ranges(std::vector<std::size_t>{}), "none");
  EXPECT_EQ(block_ranges(std::vector<std::size_t>{4}), "4");
  EXPECT_EQ(block_ranges(std::vector<std::size_t>{0, 1, 2, 5, 7, 8, 9}), "0-2, 5, 7-9");
  EXPECT_EQ(block_ranges(std::vector<std::size_t>{3, 4, 10}), "3-4, 10");
}

// distributed.py's _default_block_rows: 32 MiB a chunk, 4096 rows, some 32 blocks.
TEST(ZarrStore, DefaultBlockRowsFollowThePythonRule) {
  EXPECT_EQ(exactgeo::cli::default_block_rows(128, 512, 4), 4u);
  EXPECT_EQ(exactgeo::cli::default_block_rows(5, 10, 8), 1u);
  EXPECT_EQ(exactgeo::cli::default_block_rows(1000000, 50000, 4), 167u);
  EXPECT_EQ(exactgeo::cli::default_block_rows(1000000, 10, 8), 4096u);
}

// What zarr-python 3 writes for create_array(shape=(10, 7), chunks=(4, 7), dtype="float32",
// fill_value=nan, dimension_names=["source", "target"], compressors=None).
TEST(ZarrStore, ArrayMetadataIsWhatZarrPythonWritesForUncompressedChunks) {
  const auto expected = nlohmann::ordered_json::parse(R"({
    "shape": [10, 7], "data_type": "float32",
    "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [4, 7]}},
    "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
    "fill_value": "NaN", "codecs": [{"name": "bytes", "configuration": {"endian": "little"}}],
    "attributes": {}, "dimension_names": ["source", "target"], "zarr_format": 3, "node_type": "array",
    "storage_transformers": []})");
  EXPECT_EQ(exactgeo::cli::array_metadata(std::vector<std::size_t>{10, 7}, std::vector<std::size_t>{4, 7}, "float32",
                                          "NaN", {"source", "target"}),
            expected);
}

exactgeo::cli::StoreSettings small_settings() {
  return {.mesh_sha256 = std::string(64, 'a'), .vertex_count = 25, .face_count = 32, .weld = false,
          .sources = {0, 3, 7}, .targets = std::nullopt, .columns = 25, .dtype = "float32",
          .max_distance = std::nullopt, .block_rows = 2};
}

TEST(ZarrStore, SettingsHaveThePythonKeysInOrder) {
  const nlohmann::ordered_json json = exactgeo::cli::settings_json(small_settings());
  std::vector<std::string> keys;
  for (const auto& item : json.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"format", "version", "mesh_sha256", "vertex_count", "face_count",
                                            "weld_duplicate_positions", "sources", "targets", "shape", "dtype",
                                            "max_distance", "layout", "block_rows", "blocks", "zarr_format"}));
  EXPECT_EQ(json["blocks"], 2);
  EXPECT_EQ(json["layout"], "dense");
  EXPECT_TRUE(json["targets"].is_null() && json["max_distance"].is_null());
}

TEST(ZarrStore, DifferencesNameWhatDiffers) {
  exactgeo::cli::StoreSettings other = small_settings();
  other.sources = {0, 3, 7, 8, 9, 10};
  other.dtype = "float64";
  other.block_rows = 3;
  const auto stored = exactgeo::cli::settings_json(small_settings());
  const auto wanted = exactgeo::cli::settings_json(other);
  EXPECT_TRUE(exactgeo::cli::store_differences(stored, stored, true).empty());
  const std::vector<std::string> found = exactgeo::cli::store_differences(stored, wanted, false);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0], "other sources (the store's: 3 sources [0, 3, 7]; these: 6 sources [0, 3, 7, 8, 9, ...])");
  EXPECT_EQ(found[1], R"(another dtype (the store's: "float32"; this run's: "float64"))");
  EXPECT_EQ(exactgeo::cli::store_differences(stored, wanted, true).back(),
            "another block_rows (the store's: 2; this run's: 3)");
}

std::string read_bytes(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

struct TemporaryFolder {
  fs::path path;
  explicit TemporaryFolder(const fs::path& parent = fs::temp_directory_path())
      : path(parent / ("exactgeo-store-test-" + std::to_string(::getpid()))) {
    fs::remove_all(path);
  }
  ~TemporaryFolder() { fs::remove_all(path); }
};

// A block's chunk and marker appear once its last row has arrived; the last chunk is padded to full size.
TEST(ZarrStore, WritesEachBlockWholeThenItsMarker) {
  const TemporaryFolder folder;
  const exactgeo::MeshSoup soup = exactgeo::make_grid(4, 4, 4, 4);
  const exactgeo::Mesh mesh(soup);
  const std::vector<std::uint32_t> sources = {0, 3, 7};
  const fs::path store = folder.path / "m.zarr";
  exactgeo::cli::StoreRequest request;
  request.mesh = &mesh;
  request.block_rows = 2;
  request.quiet = true;
  const auto writer = exactgeo::cli::open_matrix_store(store.string(), {sources, {}, mesh.vertex_count()}, request);
  const std::vector<exactgeo::cli::RowRange> ranges = writer->row_ranges(sources.size());
  ASSERT_EQ(ranges.size(), 2u);
  EXPECT_EQ(ranges[1].first, 2u);
  EXPECT_EQ(ranges[1].end, 3u);
  const std::size_t columns = mesh.vertex_count();
  std::vector<double> row(columns, 1.5);
  row[4] = std::numeric_limits<double>::infinity();
  writer->write_rows(0, row);
  EXPECT_FALSE(fs::exists(store / "distances" / "c" / "0" / "0"));  // half a block: nothing yet
  EXPECT_FALSE(fs::exists(store / "done" / "block_000000"));
  writer->write_rows(1, row);
  writer->write_rows(2, row);
  writer->finish();
  const std::string last = read_bytes(store / "distances" / "c" / "1" / "0");
  ASSERT_EQ(last.size(), 2 * columns * sizeof(float));
  float value = 0, padding = 0, unreachable = 0;
  std::memcpy(&value, last.data(), sizeof value);
  std::memcpy(&unreachable, last.data() + 4 * sizeof(float), sizeof unreachable);
  std::memcpy(&padding, last.data() + columns * sizeof(float), sizeof padding);
  EXPECT_EQ(value, 1.5f);
  EXPECT_TRUE(std::isinf(unreachable));
  EXPECT_TRUE(std::isnan(padding));
  const auto marker = nlohmann::json::parse(read_bytes(store / "done" / "block_000001" / "zarr.json"));
  EXPECT_EQ(marker["attributes"]["rows"], nlohmann::json({2, 3}));
  // The digest covers the rows written, not the padding.
  EXPECT_EQ(marker["attributes"]["sha256"],
            sha256_hex(std::span(reinterpret_cast<const unsigned char*>(last.data()), columns * sizeof(float))));
  const exactgeo::cli::StoreStatus status = exactgeo::cli::read_store_status(store);
  EXPECT_EQ(status.done, (std::vector<std::size_t>{0, 1}));
  EXPECT_TRUE(status.missing.empty());
  // No temporary file is left beside the chunks or markers.
  for (const auto& entry : fs::recursive_directory_iterator(store))
    EXPECT_NE(entry.path().filename().string()[0], '.') << entry.path();
}

TEST(ZarrStore, RefusesAFolderThatIsNotAStoreAndChangesNothing) {
  const TemporaryFolder folder;
  fs::create_directories(folder.path / "mine.zarr");
  std::ofstream(folder.path / "mine.zarr" / "notes.txt") << "keep me";
  const exactgeo::Mesh mesh(exactgeo::make_grid(2, 2, 2, 2));
  const std::vector<std::uint32_t> sources = {0};
  exactgeo::cli::StoreRequest request;
  request.mesh = &mesh;
  request.quiet = true;
  EXPECT_THROW(exactgeo::cli::open_matrix_store((folder.path / "mine.zarr").string(),
                                                {sources, {}, mesh.vertex_count()}, request),
               exactgeo::Error);
  EXPECT_EQ(read_bytes(folder.path / "mine.zarr" / "notes.txt"), "keep me");
  EXPECT_EQ(std::distance(fs::directory_iterator(folder.path / "mine.zarr"), fs::directory_iterator()), 1);
}

// A store of 5 rows in blocks of 2 on a 5 x 5 grid, and what the command's writer puts in it.
struct SmallMatrix {
  exactgeo::Mesh mesh{exactgeo::make_grid(4, 4, 4, 4)};
  std::vector<std::uint32_t> sources = {0, 3, 7, 12, 20};
  std::optional<double> max_distance;  // set: the sparse layout
  std::vector<double> rows;            // the whole matrix, inf beyond the cut-off
  static constexpr std::size_t kBlocks = 3;

  explicit SmallMatrix(std::optional<double> cut) : max_distance(cut) {
    exactgeo::MatrixOptions options;
    if (cut) options.geodesic.max_distance = *cut;
    rows = exactgeo::distance_matrix(mesh, sources, options);
  }

  // What `exactgeo matrix MESH --sources ... --block-rows 2 --out STORE [--resume [--verify]]` does.
  void write(const fs::path& store, bool resume = false, bool verify = false) const {
    exactgeo::cli::StoreRequest request;
    request.mesh = &mesh;
    request.max_distance = max_distance;
    request.block_rows = 2;
    request.resume = resume;
    request.verify = verify;
    request.quiet = true;
    const std::size_t columns = mesh.vertex_count();
    const auto writer = exactgeo::cli::open_matrix_store(store.string(), {sources, {}, columns}, request);
    for (const exactgeo::cli::RowRange& range : writer->row_ranges(sources.size()))
      writer->write_rows(range.first,
                         std::span(rows).subspan(range.first * columns, (range.end - range.first) * columns));
    writer->finish();
  }

  // The files a block's values are read from: its chunk or pieces, and the metadata saying how to read them.
  std::vector<std::string> block_files(std::size_t block) const {
    if (!max_distance) return {"distances/zarr.json", "distances/c/" + std::to_string(block) + "/0"};
    std::vector<std::string> files;
    for (const char* piece : {"data", "indices", "indptr"})
      for (const char* file : {"zarr.json", "c/0"})
        files.push_back("csr/block_00000" + std::to_string(block) + "/" + piece + "/" + file);
    return files;
  }

  // What a reader reads from a store, part by part (each block, the settings, the source and target arrays, the
  // mesh), as the files each part is read from.
  std::vector<std::pair<std::string, std::vector<std::string>>> parts() const {
    std::vector<std::pair<std::string, std::vector<std::string>>> all;
    for (std::size_t block = 0; block < kBlocks; ++block)
      all.push_back({"block " + std::to_string(block), block_files(block)});
    all.push_back({"settings", {"zarr.json"}});
    for (const char* axis : {"source", "target"})
      all.push_back({axis, {std::string(axis) + "/zarr.json", std::string(axis) + "/c/0"}});
    all.push_back({"mesh", {"mesh/zarr.json", "mesh/vertices/zarr.json", "mesh/vertices/c/0/0", "mesh/faces/zarr.json",
                            "mesh/faces/c/0/0"}});
    return all;
  }

  // What a reader gets from `file` of `store`: of a chunk its values (the last dense chunk's padding rows are
  // not values), of metadata what says how to read the chunks (of the root, the settings that say what the matrix
  // is); nothing if it cannot be read.
  std::optional<nlohmann::json> reading(const fs::path& store, const std::string& file) const {
    std::error_code missing;
    if (!fs::exists(store / file, missing)) return nlohmann::json("absent");
    std::string bytes = read_bytes(store / file);
    if (!file.ends_with("zarr.json")) {
      if (!max_distance && file == block_files(kBlocks - 1)[1])
        bytes.resize(std::min(bytes.size(), mesh.vertex_count() * sizeof(float)));
      return nlohmann::json::binary(std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
    }
    const nlohmann::json metadata = nlohmann::json::parse(bytes, nullptr, false);
    if (!metadata.is_object()) return std::nullopt;
    nlohmann::json read;
    for (const char* key :
         {"zarr_format", "node_type", "shape", "data_type", "chunk_grid", "chunk_key_encoding", "fill_value", "codecs"})
      if (metadata.contains(key)) read[key] = metadata[key];
    if (file == "zarr.json") {
      const nlohmann::json attributes = metadata.value("attributes", nlohmann::json::object());
      const nlohmann::json settings = attributes.is_object() ? attributes.value("exactgeo", nlohmann::json()) : nullptr;
      for (const char* key : {"format", "mesh_sha256", "vertex_count", "face_count", "weld_duplicate_positions",
                              "sources", "targets", "shape", "dtype", "max_distance", "layout", "block_rows", "blocks"})
        read["settings"][key] = settings.is_object() ? settings.value(key, nlohmann::json()) : nlohmann::json();
    }
    return read;
  }

  // The parts of `store` a reader reads as it reads them from `pristine`.
  std::set<std::string> right_parts(const fs::path& store, const fs::path& pristine) const {
    std::set<std::string> right;
    for (const auto& [part, files] : parts())
      if (std::all_of(files.begin(), files.end(), [&](const std::string& file) {
            const std::optional<nlohmann::json> read = reading(store, file);
            return read && read == reading(pristine, file);
          }))
        right.insert(part);
    return right;
  }
};

// Sparse pieces left by an attempt that never wrote its marker are not what the next attempt vouches for:
// they are replaced (as a dense block's chunk is), and the marker hashes what is on disk.
TEST(ZarrStore, PiecesLeftWithoutAMarkerAreReplacedNotKept) {
  const TemporaryFolder folder;
  const SmallMatrix matrix(1.5);
  const fs::path store = folder.path / "s.zarr";
  matrix.write(store);
  const fs::path chunk = store / "csr" / "block_000001" / "data" / "c" / "0";
  const std::string data = read_bytes(chunk);
  std::ofstream(chunk, std::ios::binary) << std::string(data.size(), '\7');
  fs::remove_all(store / "done" / "block_000001");
  EXPECT_EQ(exactgeo::cli::read_store_status(store).missing, std::vector<std::size_t>{1});
  matrix.write(store, /*resume=*/true);
  EXPECT_EQ(read_bytes(chunk), data);
  const exactgeo::cli::StoreStatus status = exactgeo::cli::read_store_status(store, /*verify=*/true);
  EXPECT_TRUE(status.complete() && status.corrupt.empty());
}

// A damage done to one file of a store: "flipped" (8 bytes in the middle), "truncated" (to half), "deleted",
// "edited" (valid JSON with the value at `leaf`, a JSON pointer, changed), or "crashed" (block `block`'s values
// flipped and its marker gone, as a crash between the two leaves it).
struct Damage {
  std::string file, how, leaf;
  std::size_t block = 0;
};

// A JSON value changed to another of its type: a number plus one, a flag flipped, the last character of a text
// to the next one (a hex digit to the next hex digit), null to 0.
nlohmann::json edited(const nlohmann::json& value) {
  if (value.is_boolean()) return !value.get<bool>();
  if (value.is_number_unsigned()) return value.get<std::uint64_t>() + 1;
  if (value.is_number_integer()) return value.get<std::int64_t>() + 1;
  if (value.is_number_float()) return value.get<double>() + 1;
  if (!value.is_string()) return 0;
  std::string text = value.get<std::string>();
  if (text.empty()) return "x";
  const std::string hex = "0123456789abcdef0";
  const std::size_t digit = hex.find(text.back());
  text.back() = digit != std::string::npos ? hex[digit + 1] : static_cast<char>(text.back() + 1);
  return text;
}

void damage(const fs::path& store, const Damage& damage) {
  const fs::path target = store / damage.file;
  if (damage.how == "deleted") {
    fs::remove(target);
    return;
  }
  std::string bytes = read_bytes(target);
  if (damage.how == "edited") {
    nlohmann::json document = nlohmann::json::parse(bytes);
    const nlohmann::json::json_pointer leaf(damage.leaf);
    document[leaf] = edited(document[leaf]);
    bytes = document.dump();
  } else if (damage.how == "truncated") {
    bytes.resize(bytes.size() / 2);
  } else {
    for (std::size_t i = bytes.size() / 2; i < std::min(bytes.size(), bytes.size() / 2 + 8); ++i) bytes[i] ^= 0x5a;
  }
  std::ofstream(target, std::ios::binary | std::ios::trunc) << bytes;
  if (damage.how == "crashed") fs::remove_all(store / "done" / ("block_00000" + std::to_string(damage.block)));
}

// The store fuzz, the command's half (python/tests/test_store_damage.py continues each writer's stores with the
// other): every file of a dense and a sparse store flipped, truncated and deleted in turn, each JSON file edited
// (every value of the root's, one of each other file's), and each block's values crashed. Verifying vouches only
// for blocks that read as the pristine store's, and calls the store complete only if every part does (the matrix,
// the settings, the source and target arrays, the mesh); resuming computes every block without a marker again,
// and resuming with verify leaves the store complete and right; or each stops with an error naming a file every
// block depends on.
TEST(ZarrStore, EveryDamagedFileIsRepairedOrReportedNeverMarkedDone) {
  // In memory where Linux offers it: the test copies a store some 300 times, which takes a second there and far
  // longer on a loaded disk, where making a folder takes half a millisecond.
  const TemporaryFolder folder(fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path());
  for (const std::optional<double> cut : {std::optional<double>(), std::optional<double>(1.5)}) {
    const SmallMatrix matrix(cut);
    const fs::path pristine = folder.path / "pristine.zarr", store = folder.path / "store.zarr";
    fs::remove_all(pristine);
    matrix.write(pristine);
    std::set<std::string> everything;
    for (const auto& [part, files] : matrix.parts()) everything.insert(part);
    ASSERT_EQ(matrix.right_parts(pristine, pristine), everything);

    std::vector<Damage> cases;
    std::size_t other_files_edited = 0;
    for (const auto& entry : fs::recursive_directory_iterator(pristine)) {
      if (!entry.is_regular_file()) continue;
      const std::string file = entry.path().lexically_relative(pristine).string();
      for (const char* how : {"flipped", "truncated", "deleted"}) cases.push_back({file, how, ""});
      if (!file.ends_with(".json")) continue;
      const nlohmann::json document = nlohmann::json::parse(read_bytes(entry.path()));
      const nlohmann::json flat = document.flatten();
      std::vector<std::string> leaves;
      for (const auto& [leaf, value] : flat.items())  // empty objects and arrays flatten to null: left out
        if (document[nlohmann::json::json_pointer(leaf)].is_primitive()) leaves.push_back(leaf);
      // Every value of the root's; one of each other file's, a different key from file to file.
      if (file != "zarr.json" && !leaves.empty()) leaves = {leaves[other_files_edited++ % leaves.size()]};
      for (const std::string& leaf : leaves) cases.push_back({file, "edited", leaf});
    }
    for (std::size_t block = 0; block < SmallMatrix::kBlocks; ++block)
      cases.push_back({matrix.block_files(block).back(), "crashed", "", block});
    ASSERT_GT(cases.size(), cut ? 150u : 80u);

    // Verification vouches only for what reads right.
    const auto check_vouched = [&](const std::string& context) {
      const exactgeo::cli::StoreStatus status = exactgeo::cli::read_store_status(store, true);
      const std::set<std::string> right = matrix.right_parts(store, pristine);
      for (std::size_t block : status.done)
        EXPECT_TRUE(right.contains("block " + std::to_string(block))) << context << ": block " << block;
      if (status.complete()) {
        EXPECT_EQ(right, everything) << context << ": complete, but not every part is right";
      }
      return status;
    };
    // Only the files every block depends on may stop the store from being used; the error names them.
    const auto check_refusal = [&](const exactgeo::Error& e, const std::string& file, const std::string& context) {
      EXPECT_TRUE(file == "zarr.json" || file == "distances/zarr.json") << context << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find((file == "zarr.json" ? store : store / file).string()), std::string::npos)
          << context << ": " << e.what();
    };

    for (const Damage& c : cases) {
      const std::string context = (cut ? "sparse " : "dense ") + c.file + " " + c.how + " " + c.leaf;
      // In the order a user would go: status --verify (which changes nothing), --resume, --resume --verify.
      fs::remove_all(store);
      fs::copy(pristine, store, fs::copy_options::recursive);
      damage(store, c);
      for (const std::string run : {"resume", "resume-verify"}) {
        try {
          if (run == "resume") check_vouched(context + ", status --verify");
          const std::vector<std::size_t> done_before = exactgeo::cli::read_store_status(store).done;
          matrix.write(store, true, run == "resume-verify");
          const exactgeo::cli::StoreStatus status = check_vouched(context + ", " + run);
          if (run == "resume-verify") {
            EXPECT_TRUE(status.complete()) << context << ", " << run;
            EXPECT_EQ(matrix.right_parts(store, pristine), everything) << context << ", " << run;
          }
          for (std::size_t block = 0; block < SmallMatrix::kBlocks; ++block) {
            if (!std::binary_search(done_before.begin(), done_before.end(), block)) {
              EXPECT_TRUE(std::binary_search(status.done.begin(), status.done.end(), block))
                  << context << ", " << run << ": block " << block << " not computed";
            }
          }
        } catch (const exactgeo::Error& e) {
          check_refusal(e, c.file, context + ", " + run);
        }
      }
    }
  }
}

}  // namespace
