#include "zarr_store.hpp"

#include <pthread.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <system_error>

#include "exactgeo/version.hpp"
#include "npy.hpp"
#include "progress.hpp"
#include "sha256.hpp"

namespace exactgeo::cli {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

constexpr int kZarrFormat = 3;

exactgeo::Error invalid(const std::string& message) {
  return exactgeo::Error(exactgeo::ErrorCode::invalid_argument, message);
}
exactgeo::Error io_error(const std::string& message) { return exactgeo::Error(exactgeo::ErrorCode::io_error, message); }

std::string block_name(std::size_t block) {
  char name[32];
  std::snprintf(name, sizeof name, "block_%06zu", block);
  return name;
}

// A hidden name beside `final` for building it: the process and a random number keep racing processes apart.
fs::path temporary_beside(const fs::path& final) {
  static std::mt19937_64 random{std::random_device{}()};
  char suffix[40];
  std::snprintf(suffix, sizeof suffix, ".%ld.%016llx.tmp", static_cast<long>(::getpid()),
                static_cast<unsigned long long>(random()));
  return final.parent_path() / ("." + final.filename().string() + suffix);
}

// The signals that end a run (SIGINT, SIGTERM, SIGHUP) held back for the life of this object: a signal handler
// cannot remove a folder tree (that takes calls that are not async-signal-safe), so one arriving while a folder
// is built waits until the building is over, and the builder removes the folder itself. The command has no
// other thread while it builds (the engine's threads are joined before rows are handed over), so no other
// thread takes the signal meanwhile.
class HeldInterrupts {
 public:
  HeldInterrupts() {
    ::sigemptyset(&held_);
    for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) ::sigaddset(&held_, signal_number);
    ::pthread_sigmask(SIG_BLOCK, &held_, &previous_);
  }
  ~HeldInterrupts() { ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr); }
  HeldInterrupts(const HeldInterrupts&) = delete;
  HeldInterrupts& operator=(const HeldInterrupts&) = delete;

  bool arrived() const {
    sigset_t pending;
    ::sigpending(&pending);
    for (int signal_number : {SIGINT, SIGTERM, SIGHUP})
      if (::sigismember(&pending, signal_number)) return true;
    return false;
  }
  // Lets the held signals in: the one that arrived is taken now, and its handler
  // (remove_unfinished_outputs_on_interrupt) ends the run the way the signal would have.
  void deliver() { ::pthread_sigmask(SIG_UNBLOCK, &held_, nullptr); }

 private:
  sigset_t held_{}, previous_{};
};

// Builds a folder at a hidden name beside `final`, then renames it into place, so that it appears whole.
// False if a folder was there first (the one built is then removed): rename(2) replaces an empty folder and
// fails on a full one. Nothing is left behind if building fails or an interrupt arrives meanwhile.
template <class Build>
bool build_folder_into_place(const fs::path& final, const Build& build) {
  const fs::path building = temporary_beside(final);
  std::error_code ignored;
  HeldInterrupts interrupts;
  try {
    fs::create_directories(building);
    build(building);
  } catch (...) {
    fs::remove_all(building, ignored);
    throw;
  }
  if (interrupts.arrived()) {
    fs::remove_all(building, ignored);
    interrupts.deliver();
    throw io_error("interrupted while writing '" + final.string() + "'");  // if the signal's handler returned
  }
  if (std::rename(building.c_str(), final.c_str()) == 0) return true;
  const int reason = errno;
  fs::remove_all(building, ignored);
  if (reason == EEXIST || reason == ENOTEMPTY) return false;
  throw io_error("cannot write '" + final.string() + "': " + std::strerror(reason));
}

// The file appears whole or not at all, and its bytes are on disk before it does: a marker renamed into place
// after it cannot outlive it in a crash.
void write_whole(const fs::path& path, std::span<const unsigned char> bytes) {
  OutputFile output(path.string());
  std::FILE* file = output.stream();
  if (!bytes.empty()) std::fwrite(bytes.data(), 1, bytes.size(), file);
  if (std::fflush(file) != 0 || ::fsync(::fileno(file)) != 0)
    throw io_error("error writing '" + path.string() + "': " + std::strerror(errno));
  output.commit();
}

void write_json_whole(const fs::path& path, const Json& json) {
  const std::string text = json_text(json);
  write_whole(path, std::span(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

Json group_metadata(const Json& attributes) {
  return Json{{"attributes", attributes}, {"zarr_format", kZarrFormat}, {"node_type", "group"}};
}

void write_group(const fs::path& folder, const Json& attributes = Json::object()) {
  fs::create_directories(folder);
  write_json_whole(folder / "zarr.json", group_metadata(attributes));
}

// A small array stored as one chunk (the whole array), as distributed.py's _array_of writes it.
void write_array(const fs::path& folder, std::span<const std::size_t> shape, std::string_view data_type,
                 const Json& fill_value, const std::vector<std::string>& dimension_names,
                 std::span<const unsigned char> bytes) {
  std::vector<std::size_t> chunk_shape(shape.begin(), shape.end());
  for (std::size_t& size : chunk_shape) size = std::max<std::size_t>(1, size);
  fs::create_directories(folder);
  if (!bytes.empty()) {
    fs::path chunk = folder / "c";  // chunk (0, ..., 0): c/0 for one dimension, c/0/0 for two
    for (std::size_t d = 1; d < shape.size(); ++d) chunk /= "0";
    fs::create_directories(chunk);
    write_whole(chunk / "0", bytes);
  }
  write_json_whole(folder / "zarr.json", array_metadata(shape, chunk_shape, data_type, fill_value, dimension_names));
}

std::optional<Json> read_json(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return std::nullopt;
  Json json = Json::parse(file, nullptr, false);
  if (json.is_discarded()) throw invalid("'" + path.string() + "' is not valid JSON");
  return json;
}

// What a folder holds: nothing (absent or empty), or an exactgeo store's settings and its Zarr format.
struct Stored {
  Json settings;
  int zarr_format;
};

std::optional<Stored> read_stored(const fs::path& path) {
  std::error_code error;
  if (!fs::exists(path, error)) return std::nullopt;
  if (!fs::is_directory(path, error))
    throw invalid("'" + path.string() + "' exists and is not a folder: choose another store");
  if (fs::is_empty(path, error)) return std::nullopt;
  std::optional<Json> attributes;
  int zarr_format = kZarrFormat;
  if (const std::optional<Json> root = read_json(path / "zarr.json")) {
    attributes = root->value("attributes", Json::object());
  } else if (fs::is_regular_file(path / ".zgroup", error)) {
    zarr_format = 2;
    attributes = read_json(path / ".zattrs").value_or(Json::object());
  } else {
    throw invalid("'" + path.string() + "' exists and is not a Zarr store: choose another store (nothing was changed)");
  }
  const Json settings = attributes->value("exactgeo", Json());
  if (!settings.is_object() || settings.value("format", "") != kStoreFormat)
    throw invalid("'" + path.string() + "' is a Zarr store but not an exactgeo distance matrix: choose another "
                  "store (nothing was changed)");
  const auto count = [&settings](const char* key) { return settings.value(key, Json()).is_number_unsigned(); };
  if (!count("blocks") || !count("block_rows") || settings["block_rows"] == 0)
    throw invalid("'" + path.string() + "': its exactgeo attribute has no valid blocks and block_rows");
  return Stored{settings, zarr_format};
}

std::vector<std::size_t> done_blocks(const fs::path& path, std::size_t blocks) {
  std::vector<std::size_t> done;
  std::error_code error;
  for (fs::directory_iterator entry(path / "done", error), end; !error && entry != end; entry.increment(error)) {
    const std::string name = entry->path().filename().string();
    std::size_t block = 0;
    const char* digits = name.data() + std::min<std::size_t>(name.size(), 6);
    const auto [stop, failure] = std::from_chars(digits, name.data() + name.size(), block);
    if (!name.starts_with("block_") || failure != std::errc() || stop != name.data() + name.size() || block >= blocks)
      continue;
    std::error_code missing;
    if (fs::is_regular_file(entry->path() / "zarr.json", missing) || fs::is_regular_file(entry->path() / ".zgroup", missing))
      done.push_back(block);
  }
  std::sort(done.begin(), done.end());
  return done;
}

std::string describe(const Json& values, const std::string& noun) {
  if (values.is_null()) return "every vertex as " + noun;
  std::string head;
  for (std::size_t i = 0; i < std::min<std::size_t>(values.size(), 5); ++i) head += (i ? ", " : "") + values[i].dump();
  if (values.size() > 5) head += ", ...";
  return std::to_string(values.size()) + " " + noun + " [" + head + "]";
}

std::string describe_mesh(const Json& settings) {
  return settings.value("vertex_count", Json()).dump() + " vertices, " + settings.value("face_count", Json()).dump() +
         " faces, sha256 " + settings.value("mesh_sha256", std::string()).substr(0, 12) + "...";
}

// A store's dense array must be the one this writer would make: same shape, chunks and dtype, uncompressed.
void check_distances_array(const fs::path& path, const StoreSettings& settings) {
  const fs::path metadata_path = path / "distances" / "zarr.json";
  const std::optional<Json> metadata = read_json(metadata_path);
  if (!metadata) throw invalid("'" + path.string() + "' has no distances array (" + metadata_path.string() + ")");
  const std::vector<std::size_t> shape = {settings.sources.size(), settings.columns};
  const std::vector<std::size_t> chunks = {settings.block_rows, std::max<std::size_t>(1, settings.columns)};
  const Json expected = array_metadata(shape, chunks, settings.dtype, "NaN", {"source", "target"});
  for (const char* key : {"shape", "data_type", "chunk_grid", "chunk_key_encoding", "codecs"}) {
    const Json found = metadata->value(key, Json());
    if (found == expected[key]) continue;
    std::string what = "its " + std::string(key) + " is " + found.dump() + ", not " + expected[key].dump();
    if (std::string(key) == "codecs") {
      std::string names;
      for (const Json& codec : found.is_array() ? found : Json::array())
        names += (names.empty() ? "" : ", ") + codec.value("name", std::string("?"));
      what = "its chunks are stored with codecs [" + names +
             "]; the command writes uncompressed chunks only (codecs [bytes], little-endian)";
    }
    throw invalid("cannot write into '" + metadata_path.parent_path().string() + "': " + what +
                  ". Continue this store with exactgeo.distributed, or choose another store (nothing was changed)");
  }
}

// The whole store, built beside `path` and renamed into place. False if another process put a store there
// first: of processes racing here, one store wins.
bool create_store(const fs::path& path, const StoreSettings& settings, const exactgeo::Mesh& mesh) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  return build_folder_into_place(path, [&](const fs::path& building) {
    const Json attributes = {{"exactgeo", settings_json(settings)}};
    write_json_whole(building / "zarr.json", group_metadata(attributes));
    const std::size_t rows = settings.sources.size();
    if (settings.max_distance) {
      write_group(building / "csr");
    } else {
      fs::create_directories(building / "distances" / "c");
      const std::vector<std::size_t> shape = {rows, settings.columns};
      const std::vector<std::size_t> chunks = {settings.block_rows, std::max<std::size_t>(1, settings.columns)};
      write_json_whole(building / "distances" / "zarr.json",
                       array_metadata(shape, chunks, settings.dtype, "NaN", {"source", "target"}));
    }
    const std::vector<std::int64_t> sources(settings.sources.begin(), settings.sources.end());
    std::vector<std::int64_t> targets(settings.columns);
    for (std::size_t c = 0; c < targets.size(); ++c)
      targets[c] = settings.targets ? (*settings.targets)[c] : std::int64_t(c);
    write_array(building / "source", std::vector<std::size_t>{rows}, "int64", 0, {"source"},
                little_endian_bytes(sources));
    write_array(building / "target", std::vector<std::size_t>{settings.columns}, "int64", 0, {"target"},
                little_endian_bytes(targets));
    write_group(building / "mesh");
    write_array(building / "mesh" / "vertices", std::vector<std::size_t>{mesh.vertex_count(), 3}, "float64", 0.0,
                {"vertex", "xyz"}, little_endian_bytes(mesh.positions()));
    write_array(building / "mesh" / "faces", std::vector<std::size_t>{mesh.face_count(), 3}, "uint32", 0,
                {"face", "corner"}, little_endian_bytes(mesh.triangles()));
    write_group(building / "done");
  });
}

// Writes a shard's blocks as their rows arrive: each block's data, then its marker.
class StoreWriter final : public MatrixWriter {
 public:
  StoreWriter(fs::path path, StoreSettings settings, const StoreRequest& request)
      : path_(std::move(path)), settings_(std::move(settings)), shard_(request.shard), quiet_(request.quiet),
        started_(std::chrono::steady_clock::now()) {
    const std::vector<std::size_t> done = done_blocks(path_, settings_.blocks());
    for (std::size_t block : shard_blocks(shard_, settings_.blocks())) {
      if (request.resume && std::binary_search(done.begin(), done.end(), block))
        ++reused_;
      else
        todo_.push_back(block);
    }
  }

  std::vector<RowRange> row_ranges(std::size_t rows) const override {
    std::vector<RowRange> ranges;
    for (std::size_t block : todo_)
      ranges.push_back({block * settings_.block_rows, std::min(rows, (block + 1) * settings_.block_rows)});
    return ranges;
  }

  void write_rows(std::size_t first_row, std::span<const double> rows) override {
    if (pending_.empty()) pending_first_ = first_row;
    pending_.insert(pending_.end(), rows.begin(), rows.end());
    const std::size_t block = pending_first_ / settings_.block_rows;
    const std::size_t end = std::min(settings_.sources.size(), (block + 1) * settings_.block_rows);
    if (pending_.size() < (end - pending_first_) * settings_.columns) return;
    write_block(block, end);
    pending_.clear();
  }

  void finish() override {
    if (!pending_.empty()) throw exactgeo::Error(exactgeo::ErrorCode::internal, "a block was left unfinished");
    if (quiet_) return;
    const std::size_t done = done_blocks(path_, settings_.blocks()).size();
    std::fprintf(stderr, "exactgeo: %s shard %zu/%zu: %zu blocks computed, %zu reused (done before), of %zu; the "
                 "store has %zu of %zu blocks done\n", path_.c_str(), shard_.index, shard_.count, computed_, reused_,
                 computed_ + reused_, done, settings_.blocks());
  }

 private:
  void write_block(std::size_t block, std::size_t end) {
    const std::size_t first = block * settings_.block_rows;
    Json record = {{"block", block}, {"rows", {first, end}}};
    Sha256 digest;
    if (settings_.max_distance)
      record["nnz"] = write_csr(block, digest);
    else
      write_chunk(block, digest);
    record["sha256"] = digest.hex_digest();
    record["seconds"] = seconds_since(started_);
    const fs::path marker = path_ / "done" / block_name(block);
    fs::create_directories(marker);
    write_json_whole(marker / "zarr.json", group_metadata(record));
    ++computed_;
    started_ = std::chrono::steady_clock::now();
  }

  // Block `block` is chunk (block, 0) of distances; the last one is padded with the fill value to a whole chunk.
  void write_chunk(std::size_t block, Sha256& digest) {
    const std::size_t values = pending_.size(), chunk_values = settings_.block_rows * settings_.columns;
    std::vector<unsigned char> bytes;
    if (settings_.dtype == "float32") {
      std::vector<float> chunk(chunk_values, std::numeric_limits<float>::quiet_NaN());
      std::transform(pending_.begin(), pending_.end(), chunk.begin(), [](double d) { return static_cast<float>(d); });
      bytes = little_endian_bytes(chunk);
    } else {
      std::vector<double> chunk(chunk_values, std::numeric_limits<double>::quiet_NaN());
      std::copy(pending_.begin(), pending_.end(), chunk.begin());
      bytes = little_endian_bytes(chunk);
    }
    digest.update(std::span(bytes).first(bytes.size() / chunk_values * values));
    const fs::path chunk_path = path_ / "distances" / "c" / std::to_string(block) / "0";
    fs::create_directories(chunk_path.parent_path());
    write_whole(chunk_path, bytes);
  }

  // The block's finite entries as CSR pieces (row pointers from 0), written in a hidden folder renamed into
  // csr/block_NNNNNN whole. Returns the entry count.
  std::size_t write_csr(std::size_t block, Sha256& digest) {
    std::vector<double> data;
    std::vector<std::uint32_t> indices;
    std::vector<std::int64_t> indptr = {0};
    for (std::size_t row = 0; row < pending_.size() / settings_.columns; ++row) {
      for (std::size_t column = 0; column < settings_.columns; ++column) {
        const double d = pending_[row * settings_.columns + column];
        if (std::isinf(d)) continue;
        data.push_back(d);
        indices.push_back(static_cast<std::uint32_t>(column));
      }
      indptr.push_back(static_cast<std::int64_t>(data.size()));
    }
    const std::vector<unsigned char> data_bytes =
        settings_.dtype == "float32" ? little_endian_bytes(std::vector<float>(data.begin(), data.end()))
                                     : little_endian_bytes(data);
    const std::vector<unsigned char> index_bytes = little_endian_bytes(indices);
    const std::vector<unsigned char> pointer_bytes = little_endian_bytes(indptr);
    for (const auto* bytes : {&data_bytes, &index_bytes, &pointer_bytes}) digest.update(*bytes);
    // If another attempt at this block put its pieces there first, they are the same rows, complete (blocks
    // are deterministic): kept.
    build_folder_into_place(path_ / "csr" / block_name(block), [&](const fs::path& building) {
      write_group(building);
      write_array(building / "data", std::vector<std::size_t>{data.size()}, settings_.dtype, 0.0, {"data"}, data_bytes);
      write_array(building / "indices", std::vector<std::size_t>{indices.size()}, "uint32", 0, {"indices"},
                  index_bytes);
      write_array(building / "indptr", std::vector<std::size_t>{indptr.size()}, "int64", 0, {"indptr"},
                  pointer_bytes);
    });
    return data.size();
  }

  fs::path path_;
  StoreSettings settings_;
  Shard shard_;
  bool quiet_;
  std::vector<std::size_t> todo_;
  std::size_t reused_ = 0, computed_ = 0;
  std::vector<double> pending_;  // the rows of the block being received
  std::size_t pending_first_ = 0;
  std::chrono::steady_clock::time_point started_;  // of the block being received
};

}  // namespace

Shard parse_shard(std::string_view text) {
  const std::size_t slash = text.find('/');
  Shard shard;
  const auto whole = [](std::string_view digits, std::size_t& value) {
    const auto [end, failure] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    return !digits.empty() && failure == std::errc() && end == digits.data() + digits.size();
  };
  if (slash == std::string_view::npos || !whole(text.substr(0, slash), shard.index) ||
      !whole(text.substr(slash + 1), shard.count))
    throw std::invalid_argument("'" + std::string(text) + "' is not a shard I/N (two whole numbers, as 0/4)");
  if (shard.count == 0) throw std::invalid_argument("'" + std::string(text) + "': N, the number of shards, is 0");
  if (shard.index >= shard.count)
    throw std::invalid_argument("'" + std::string(text) + "': shards are numbered 0 to N-1, so I must be below " +
                                std::to_string(shard.count));
  return shard;
}

std::vector<std::size_t> shard_blocks(const Shard& shard, std::size_t blocks) {
  std::vector<std::size_t> mine;
  for (std::size_t block = shard.index; block < blocks; block += shard.count) mine.push_back(block);
  return mine;
}

std::string block_ranges(std::span<const std::size_t> blocks) {
  std::string text;
  for (std::size_t i = 0; i < blocks.size();) {
    std::size_t last = i;
    while (last + 1 < blocks.size() && blocks[last + 1] == blocks[last] + 1) ++last;
    text += (text.empty() ? "" : ", ") + std::to_string(blocks[i]);
    if (last > i) text += "-" + std::to_string(blocks[last]);
    i = last + 1;
  }
  return text.empty() ? "none" : text;
}

Json settings_json(const StoreSettings& settings) {
  return Json{
      {"format", std::string(kStoreFormat)},
      {"version", exactgeo::kVersion},
      {"mesh_sha256", settings.mesh_sha256},
      {"vertex_count", settings.vertex_count},
      {"face_count", settings.face_count},
      {"weld_duplicate_positions", settings.weld},
      {"sources", settings.sources},
      {"targets", settings.targets ? Json(*settings.targets) : Json()},
      {"shape", {settings.sources.size(), settings.columns}},
      {"dtype", settings.dtype},
      {"max_distance", settings.max_distance ? Json(*settings.max_distance) : Json()},
      {"layout", settings.max_distance ? "sparse" : "dense"},
      {"block_rows", settings.block_rows},
      {"blocks", settings.blocks()},
      {"zarr_format", kZarrFormat},
  };
}

std::string mesh_sha256(const exactgeo::Mesh& mesh, bool weld) {
  Sha256 digest;
  digest.update("exactgeo-mesh/1");
  const std::vector<std::int64_t> counts = {static_cast<std::int64_t>(mesh.vertex_count()),
                                            static_cast<std::int64_t>(mesh.face_count()), weld ? 1 : 0};
  digest.update(little_endian_bytes(counts));
  digest.update(little_endian_bytes(mesh.positions()));
  digest.update(little_endian_bytes(mesh.triangles()));
  return digest.hex_digest();
}

std::size_t default_block_rows(std::size_t rows, std::size_t columns, std::size_t item_bytes) {
  const std::size_t budget = (std::size_t{32} << 20) / std::max<std::size_t>(1, columns * item_bytes);
  return std::max<std::size_t>(1, std::min({(rows + 31) / 32, budget, std::size_t{4096}}));
}

Json array_metadata(std::span<const std::size_t> shape, std::span<const std::size_t> chunk_shape,
                    std::string_view data_type, const Json& fill_value, const std::vector<std::string>& dimension_names) {
  return Json{
      {"shape", std::vector<std::size_t>(shape.begin(), shape.end())},
      {"data_type", std::string(data_type)},
      {"chunk_grid",
       {{"name", "regular"}, {"configuration", {{"chunk_shape", std::vector<std::size_t>(chunk_shape.begin(), chunk_shape.end())}}}}},
      {"chunk_key_encoding", {{"name", "default"}, {"configuration", {{"separator", "/"}}}}},
      {"fill_value", fill_value},
      {"codecs", Json::array({{{"name", "bytes"}, {"configuration", {{"endian", "little"}}}}})},
      {"attributes", Json::object()},
      {"dimension_names", dimension_names},
      {"zarr_format", kZarrFormat},
      {"node_type", "array"},
      {"storage_transformers", Json::array()},
  };
}

std::vector<std::string> store_differences(const Json& stored, const Json& wanted, bool explicit_block_rows) {
  std::vector<std::string> found;
  const auto differs = [&](const char* key) { return stored.value(key, Json()) != wanted[key]; };
  if (differs("mesh_sha256"))
    found.push_back("another mesh (the store's: " + describe_mesh(stored) + "; this one: " + describe_mesh(wanted) + ")");
  for (const auto& [key, noun] : {std::pair{"sources", "sources"}, std::pair{"targets", "targets"}})
    if (differs(key))
      found.push_back(std::string("other ") + noun + " (the store's: " + describe(stored.value(key, Json()), noun) +
                      "; these: " + describe(wanted[key], noun) + ")");
  std::vector<const char*> keys = {"dtype", "max_distance", "zarr_format"};
  if (explicit_block_rows) keys.push_back("block_rows");
  for (const char* key : keys)
    if (differs(key))
      found.push_back(std::string("another ") + key + " (the store's: " + stored.value(key, Json()).dump() +
                      "; this run's: " + wanted[key].dump() + ")");
  return found;
}

StoreStatus read_store_status(const fs::path& path) {
  const std::optional<Stored> stored = read_stored(path);
  if (!stored) throw invalid("'" + path.string() + "' holds no exactgeo distance matrix store");
  const std::size_t blocks = stored->settings["blocks"].get<std::size_t>();
  StoreStatus status{stored->settings, done_blocks(path, blocks), {}};
  for (std::size_t block = 0; block < blocks; ++block)
    if (!std::binary_search(status.done.begin(), status.done.end(), block)) status.missing.push_back(block);
  return status;
}

std::unique_ptr<MatrixWriter> open_matrix_store(const std::string& path_text, const MatrixAxes& axes,
                                                const StoreRequest& request) {
  const fs::path path = fs::absolute(path_text);
  const exactgeo::Mesh& mesh = *request.mesh;
  StoreSettings settings{.mesh_sha256 = mesh_sha256(mesh, request.weld),
                         .vertex_count = mesh.vertex_count(),
                         .face_count = mesh.face_count(),
                         .weld = request.weld,
                         .sources = {axes.sources.begin(), axes.sources.end()},
                         .targets = std::nullopt,
                         .columns = axes.columns,
                         .dtype = request.dtype,
                         .max_distance = request.max_distance,
                         .block_rows = request.block_rows};
  if (!axes.targets.empty()) settings.targets.emplace(axes.targets.begin(), axes.targets.end());
  const bool explicit_block_rows = request.block_rows != 0;
  if (!explicit_block_rows)
    settings.block_rows = default_block_rows(settings.sources.size(), settings.columns, request.dtype == "float32" ? 4 : 8);
  std::optional<Stored> stored = read_stored(path);
  if (!stored && !create_store(path, settings, mesh)) stored = read_stored(path);  // another shard's, just made
  if (stored) {
    if (stored->zarr_format != kZarrFormat)
      throw invalid("'" + path.string() + "' is a Zarr format " + std::to_string(stored->zarr_format) +
                    " store (zarr-python 2 made it); the command writes format 3 only: continue it with "
                    "exactgeo.distributed, or choose another store (nothing was changed)");
    if (!explicit_block_rows) settings.block_rows = stored->settings["block_rows"].get<std::size_t>();
    const std::vector<std::string> differences =
        store_differences(stored->settings, settings_json(settings), explicit_block_rows);
    if (!differences.empty()) {
      std::string message = "the store '" + path.string() + "' was made for ";
      for (std::size_t i = 0; i < differences.size(); ++i) message += (i ? "; " : "") + differences[i];
      throw invalid(message + ". Use another store, or remove this one to start over (nothing was changed)");
    }
    if (!settings.max_distance) check_distances_array(path, settings);
  }
  return std::make_unique<StoreWriter>(path, std::move(settings), request);
}

}  // namespace exactgeo::cli
