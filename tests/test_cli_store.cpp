// The pieces behind `exactgeo matrix --out M.zarr --shard I/N` (the store component's own are in
// tests/test_store.cpp): shard and block-range syntax, the store writer's files (python/tests/test_cli_zarr.py checks
// that zarr-python and exactgeo.distributed read them), and what --verify and --resume make of every file of a store
// damaged in turn.
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
  EXPECT_EQ(exactgeo::store::shard_blocks({1, 3}, 10), (std::vector<std::size_t>{1, 4, 7}));
  EXPECT_EQ(exactgeo::store::shard_blocks({5, 6}, 4), std::vector<std::size_t>{});
  for (std::size_t count : {1, 2, 3, 7, 40}) {
    std::multiset<std::size_t> all;
    for (std::size_t index = 0; index < count; ++index)
      for (std::size_t block : exactgeo::store::shard_blocks({index, count}, 23)) {
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
  exactgeo::store::Sha256 rows_digest;
  rows_digest.update(std::span(reinterpret_cast<const unsigned char*>(last.data()), columns * sizeof(float)));
  EXPECT_EQ(marker["attributes"]["sha256"], rows_digest.hex_digest());
  const exactgeo::store::StoreStatus status = exactgeo::store::read_store_status(store);
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
    for (const exactgeo::cli::RowRange& range : writer->row_ranges(sources.size())) {
      if (max_distance) {  // a cut-off matrix's rows come as their finite entries
        exactgeo::MatrixOptions options;
        options.geodesic.max_distance = *max_distance;
        exactgeo::for_each_sparse_block(mesh, std::span(sources).subspan(range.first, range.end - range.first), options,
                                        [&](std::size_t first, const exactgeo::SparseDistances& block) {
                                          writer->write_sparse_rows(range.first + first, block);
                                        });
      } else {
        writer->write_rows(range.first,
                           std::span(rows).subspan(range.first * columns, (range.end - range.first) * columns));
      }
    }
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
  EXPECT_EQ(exactgeo::store::read_store_status(store).missing, std::vector<std::size_t>{1});
  matrix.write(store, /*resume=*/true);
  EXPECT_EQ(read_bytes(chunk), data);
  const exactgeo::store::StoreStatus status = exactgeo::store::read_store_status(store, /*verify=*/true);
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
      const exactgeo::store::StoreStatus status = exactgeo::store::read_store_status(store, true);
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
          const std::vector<std::size_t> done_before = exactgeo::store::read_store_status(store).done;
          matrix.write(store, true, run == "resume-verify");
          const exactgeo::store::StoreStatus status = check_vouched(context + ", " + run);
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
