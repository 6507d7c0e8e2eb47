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
#include <numeric>
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

// mesh_sha256 of a mesh given as its counts and its positions (float64) and triangles (uint32) as little-endian
// bytes, as a store keeps them.
std::string mesh_digest(std::size_t vertex_count, std::size_t face_count, bool weld,
                        std::span<const unsigned char> position_bytes, std::span<const unsigned char> triangle_bytes) {
  Sha256 digest;
  digest.update("exactgeo-mesh/1");
  const std::vector<std::int64_t> counts = {static_cast<std::int64_t>(vertex_count),
                                            static_cast<std::int64_t>(face_count), weld ? 1 : 0};
  digest.update(little_endian_bytes(counts));
  digest.update(position_bytes);
  digest.update(triangle_bytes);
  return digest.hex_digest();
}

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

// What build_folder_into_place does with a folder already at `final`.
enum class Existing {
  kept,      // left as it is (another process's store, made first)
  replaced,  // moved aside and removed: leftover pieces are never trusted
};

// Builds a folder at a hidden name beside `final`, then renames it into place, so that it appears whole.
// rename(2) replaces an empty folder and fails on a full one: a folder there first is kept (the one built is
// removed, and the result is false) or replaced, as `existing` says. Nothing is left behind if building fails
// or an interrupt arrives meanwhile, and interrupts wait while a folder is replaced, so that none lands
// between moving the old one aside and renaming the new one in.
template <class Build>
bool build_folder_into_place(const fs::path& final, Existing existing, const Build& build) {
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
  while (std::rename(building.c_str(), final.c_str()) != 0) {
    int reason = errno;
    const bool occupied = reason == EEXIST || reason == ENOTEMPTY;
    if (occupied && existing == Existing::replaced) {
      // Another attempt at the same block may move it aside first (ENOENT): then the rename is tried again.
      const fs::path aside = temporary_beside(final);
      if (std::rename(final.c_str(), aside.c_str()) == 0 || errno == ENOENT) {
        fs::remove_all(aside, ignored);
        continue;
      }
      reason = errno;
    }
    fs::remove_all(building, ignored);
    if (occupied && existing == Existing::kept) return false;
    throw io_error("cannot write '" + final.string() + "': " + std::strerror(reason));
  }
  return true;
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

// The JSON object in `path`, or nothing if there is no such file; throws exactgeo::Error naming the file if it
// holds anything else (a file cut short or overwritten).
std::optional<Json> read_json(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return std::nullopt;
  Json json = Json::parse(file, nullptr, false);
  if (json.is_discarded()) throw invalid_argument("'" + path.string() + "' is not valid JSON");
  if (!json.is_object()) throw invalid_argument("'" + path.string() + "' holds " + json.dump() + ", not a JSON object");
  return json;
}

// The shape of a store's blocks, from the settings it records: what reading a block back needs.
struct BlockShape {
  std::size_t rows = 0, columns = 0, block_rows = 1;
  std::string dtype;
  Json max_distance;  // null: the dense layout; a marker records the one its block was computed with

  bool sparse() const { return !max_distance.is_null(); }
  std::size_t item_bytes() const { return dtype == "float32" ? 4 : 8; }
  std::size_t blocks() const { return (rows + block_rows - 1) / block_rows; }
  std::size_t first(std::size_t block) const { return block * block_rows; }
  std::size_t end(std::size_t block) const { return std::min(rows, (block + 1) * block_rows); }
};

// What a folder holds: nothing (absent or empty), or an exactgeo store's settings, its blocks' shape and its
// Zarr format.
struct Stored {
  Json settings;
  BlockShape shape;
  int zarr_format;
};

std::optional<Stored> read_stored(const fs::path& path) {
  std::error_code error;
  if (!fs::exists(path, error)) return std::nullopt;
  if (!fs::is_directory(path, error))
    throw invalid_argument("'" + path.string() + "' exists and is not a folder: choose another store");
  if (fs::is_empty(path, error)) return std::nullopt;
  std::optional<Json> attributes;
  int zarr_format = kZarrFormat;
  if (const std::optional<Json> root = read_json(path / "zarr.json")) {
    if (root->value("zarr_format", Json()) != kZarrFormat || root->value("node_type", Json()) != "group")
      throw invalid_argument("'" + (path / "zarr.json").string() + "' is not the metadata of a Zarr format 3 group");
    attributes = root->value("attributes", Json::object());
  } else if (fs::is_regular_file(path / ".zgroup", error)) {
    zarr_format = 2;
    attributes = read_json(path / ".zattrs").value_or(Json::object());
  } else {
    throw invalid_argument("'" + path.string() +
                           "' exists and is not a Zarr store: choose another store (nothing was changed)");
  }
  const Json settings = attributes->is_object() ? attributes->value("exactgeo", Json()) : Json();
  if (!settings.is_object() || settings.value("format", "") != kStoreFormat)
    throw invalid_argument("'" + path.string() +
                           "' is a Zarr store but not an exactgeo distance matrix: choose another "
                           "store (nothing was changed)");
  // Every count is checked against the others, so that an edited block count cannot hide blocks.
  const auto count = [](const Json& value) { return value.is_number_unsigned(); };
  const auto indices = [&count](const Json& value) {
    return value.is_array() && std::all_of(value.begin(), value.end(), count);
  };
  const Json shape = settings.value("shape", Json()), dtype = settings.value("dtype", Json());
  const Json block_rows = settings.value("block_rows", Json()), blocks = settings.value("blocks", Json());
  const Json sources = settings.value("sources", Json()), targets = settings.value("targets", Json());
  if (!shape.is_array() || shape.size() != 2 || !count(shape[0]) || !count(shape[1]) || !count(block_rows) ||
      block_rows == 0 || !count(blocks) || (dtype != "float32" && dtype != "float64") ||
      !settings.contains("max_distance") || !indices(sources) || !(targets.is_null() || indices(targets)) ||
      !count(settings.value("vertex_count", Json())) || !count(settings.value("face_count", Json())) ||
      !settings.value("weld_duplicate_positions", Json()).is_boolean() ||
      !settings.value("mesh_sha256", Json()).is_string())
    throw invalid_argument("'" + path.string() +
                           "': its exactgeo attribute has no valid shape, dtype, max_distance, blocks, "
                           "block_rows, sources, targets and mesh");
  const BlockShape block_shape{.rows = shape[0].get<std::size_t>(),
                               .columns = shape[1].get<std::size_t>(),
                               .block_rows = block_rows.get<std::size_t>(),
                               .dtype = dtype.get<std::string>(),
                               .max_distance = settings["max_distance"]};
  const Json layout = settings.value("layout", Json());
  if (!layout.is_string() || layout.get<std::string>() != (block_shape.sparse() ? "sparse" : "dense"))
    throw invalid_argument("'" + path.string() + "': its exactgeo attribute's layout " + layout.dump() +
                           " does not go with its max_distance " + block_shape.max_distance.dump());
  const Json columns = targets.is_null() ? settings.value("vertex_count", Json()) : Json(targets.size());
  if (sources.size() != block_shape.rows || columns != block_shape.columns)
    throw invalid_argument("'" + path.string() + "': its exactgeo attribute's shape " + shape.dump() +
                           " is not its sources by its targets (or vertices)");
  if (blocks != block_shape.blocks())
    throw invalid_argument("'" + path.string() + "': its exactgeo attribute has " + blocks.dump() + " blocks, but " +
                           shape[0].dump() + " rows in blocks of " + block_rows.dump() + " make " +
                           std::to_string(block_shape.blocks()));
  return Stored{settings, block_shape, zarr_format};
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

// Reads the JSON object in `path` into `json`; returns why it cannot (naming the file), or nothing.
std::string read_json_into(const fs::path& path, Json& json) {
  try {
    const std::optional<Json> read = read_json(path);
    if (!read) return "'" + path.string() + "' is missing";
    json = *read;
  } catch (const exactgeo::Error& e) {
    return e.what();
  }
  return {};
}

// Why the array whose metadata is `metadata` (read from `metadata_path`) does not store its chunks as
// `expected` says (an array of that shape and data type, its chunks, chunk keys and fill value, in uncompressed
// little-endian bytes: the layout blocks are written and read back in); empty if it does.
std::string array_problem(const fs::path& metadata_path, const Json& metadata, const Json& expected) {
  for (const char* key :
       {"zarr_format", "node_type", "shape", "data_type", "chunk_grid", "chunk_key_encoding", "fill_value", "codecs"}) {
    const Json found = metadata.value(key, Json());
    if (found == expected[key]) continue;
    if (std::string(key) != "codecs")
      return "'" + metadata_path.string() + "': its " + key + " is " + found.dump() + ", not " + expected[key].dump();
    std::string names;
    for (const Json& codec : found.is_array() ? found : Json::array())
      names += (names.empty() ? "" : ", ") + (codec.is_object() ? codec.value("name", std::string("?")) : "?");
    return "'" + metadata_path.parent_path().string() + "': its chunks are stored with codecs [" + names +
           "]; the command writes and reads uncompressed chunks only (codecs [bytes], little-endian)";
  }
  return {};
}

// A store's dense array must be the one this writer would make: same shape, chunks and dtype, uncompressed.
std::string distances_problem(const fs::path& path, const BlockShape& shape) {
  const std::vector<std::size_t> size = {shape.rows, shape.columns};
  const std::vector<std::size_t> chunks = {shape.block_rows, std::max<std::size_t>(1, shape.columns)};
  const fs::path metadata_path = path / "distances" / "zarr.json";
  Json metadata;
  if (std::string problem = read_json_into(metadata_path, metadata); !problem.empty()) return problem;
  return array_problem(metadata_path, metadata, array_metadata(size, chunks, shape.dtype, "NaN", {"source", "target"}));
}

// The bytes of a whole file, or nothing if it cannot be read.
std::optional<std::vector<unsigned char>> read_file(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return std::nullopt;
  std::vector<unsigned char> bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  if (file.bad()) return std::nullopt;
  return bytes;
}

// Hashes dense block `block` as its writer did: the rows of its chunk, without the padding of the last one.
std::string hash_chunk(const fs::path& path, const BlockShape& shape, std::size_t block, Sha256& digest) {
  const fs::path chunk = path / "distances" / "c" / std::to_string(block) / "0";
  const std::optional<std::vector<unsigned char>> bytes = read_file(chunk);
  if (!bytes) return "'" + chunk.string() + "' is missing";
  const std::size_t row_bytes = shape.columns * shape.item_bytes();
  if (bytes->size() != shape.block_rows * row_bytes)
    return "'" + chunk.string() + "' has " + std::to_string(bytes->size()) + " bytes, not " +
           std::to_string(shape.block_rows * row_bytes);
  digest.update(std::span(*bytes).first((shape.end(block) - shape.first(block)) * row_bytes));
  return {};
}

// An array stored whole in one chunk, as write_array writes it (the pieces of a sparse block, the axes, the mesh).
struct WholeArray {
  std::vector<std::size_t> shape;
  std::vector<unsigned char> bytes;  // little-endian
};

// Reads the array in `folder` whose data type is `data_type` and whose shape has `rank` sizes, whatever they are,
// into `array`; returns why it cannot be read as write_array would have written an array of that shape (naming
// the file), or nothing. Zarr leaves out a chunk holding the fill value alone (0): an absent chunk reads as zeros.
std::string read_whole_array(const fs::path& folder, std::string_view data_type, std::size_t rank, WholeArray& array) {
  const fs::path metadata_path = folder / "zarr.json";
  Json metadata;
  if (std::string problem = read_json_into(metadata_path, metadata); !problem.empty()) return problem;
  const Json shape = metadata.value("shape", Json());
  if (!shape.is_array() || shape.size() != rank ||
      !std::all_of(shape.begin(), shape.end(), [](const Json& size) { return size.is_number_unsigned(); }))
    return "'" + metadata_path.string() + "': its shape is " + shape.dump() + ", not " + std::to_string(rank) +
           " sizes";
  array.shape = shape.get<std::vector<std::size_t>>();
  std::vector<std::size_t> chunks = array.shape;
  for (std::size_t& size : chunks) size = std::max<std::size_t>(1, size);
  const Json layout = array_metadata(array.shape, chunks, data_type, 0, {});
  if (std::string problem = array_problem(metadata_path, metadata, layout); !problem.empty()) return problem;
  std::size_t expected = data_type == "float32" || data_type == "uint32" ? 4 : 8;
  for (std::size_t size : array.shape) expected *= size;
  fs::path chunk = folder / "c";  // chunk (0, ..., 0)
  for (std::size_t d = 0; d < rank; ++d) chunk /= "0";
  std::error_code error;
  if (!fs::exists(chunk, error) && !error) {
    array.bytes.assign(expected, 0);
    return {};
  }
  std::optional<std::vector<unsigned char>> bytes = read_file(chunk);
  if (!bytes) return "'" + chunk.string() + "' cannot be read";
  if (bytes->size() != expected)
    return "'" + chunk.string() + "' has " + std::to_string(bytes->size()) + " bytes, not " + std::to_string(expected);
  array.bytes = std::move(*bytes);
  return {};
}

// Hashes sparse block `block` as its writer did: the values of its pieces data, indices and indptr.
std::string hash_pieces(const fs::path& path, const BlockShape& shape, std::size_t block, Sha256& digest) {
  for (const auto& [name, data_type] : {std::pair<std::string, std::string>{"data", shape.dtype},
                                        {"indices", "uint32"}, {"indptr", "int64"}}) {
    WholeArray piece;
    if (std::string problem = read_whole_array(path / "csr" / block_name(block) / name, data_type, 1, piece);
        !problem.empty())
      return problem;
    digest.update(piece.bytes);
  }
  return {};
}

// Why done block `block`'s data on disk is not what its marker recorded (naming the file at fault); empty if it
// is. The bytes hashed are those exactgeo.distributed's _block_intact hashes, so both agree on every store.
std::string block_problem(const fs::path& path, const BlockShape& shape, std::size_t block) {
  const fs::path marker = path / "done" / block_name(block) / "zarr.json";
  Json group;
  if (std::string problem = read_json_into(marker, group); !problem.empty()) return problem;
  const Json record = group.value("attributes", Json());
  const Json rows = {shape.first(block), shape.end(block)};
  if (!record.is_object() || !record.value("sha256", Json()).is_string() || record.value("rows", Json()) != rows)
    return "'" + marker.string() + "' does not record rows " + rows.dump() + " and their sha256";
  // No other file repeats the cut-off: a store whose settings claim another one is caught here.
  if (record.value("max_distance", Json("none recorded")) != shape.max_distance)
    return "'" + marker.string() + "' records max_distance " + record.value("max_distance", Json("none")).dump() +
           ", not the store's " + shape.max_distance.dump();
  Sha256 digest;
  const std::string problem =
      shape.sparse() ? hash_pieces(path, shape, block, digest) : hash_chunk(path, shape, block, digest);
  if (!problem.empty()) return problem;
  if (digest.hex_digest() == record["sha256"].get<std::string>()) return {};
  if (shape.sparse())
    return "the pieces in '" + (path / "csr" / block_name(block)).string() + "' do not hash to the sha256 in '" +
           marker.string() + "'";
  return "'" + (path / "distances" / "c" / std::to_string(block) / "0").string() +
         "' does not hash to the sha256 in '" + marker.string() + "'";
}

// The arrays every block shares that do not hold what the settings record, and why (naming the file): `source`
// and `target` the settings' sources and targets (every vertex without targets), mesh/vertices and mesh/faces the
// mesh whose sha256 they record. The settings are read_stored's, checked for their types.
std::vector<DamagedArray> damaged_shared_arrays(const fs::path& path, const Json& settings) {
  std::vector<DamagedArray> damaged;
  const std::size_t vertex_count = settings["vertex_count"].get<std::size_t>();
  std::vector<std::int64_t> targets(vertex_count);
  std::iota(targets.begin(), targets.end(), 0);
  if (!settings["targets"].is_null()) targets = settings["targets"].get<std::vector<std::int64_t>>();
  const std::vector<std::int64_t> sources = settings["sources"].get<std::vector<std::int64_t>>();
  for (const auto& [name, expected] : {std::pair<std::string, const std::vector<std::int64_t>&>{"source", sources},
                                       {"target", targets}}) {
    WholeArray array;
    std::string problem = read_whole_array(path / name, "int64", 1, array);
    if (problem.empty() && array.bytes != little_endian_bytes(expected))
      problem = "'" + (path / name).string() + "' does not hold the " + name + "s its store's zarr.json records";
    if (!problem.empty()) damaged.push_back({name, std::move(problem)});
  }
  WholeArray vertices, faces;
  Json group;
  std::string problem = read_json_into(path / "mesh" / "zarr.json", group);
  if (problem.empty() &&
      (group.value("zarr_format", Json()) != kZarrFormat || group.value("node_type", Json()) != "group"))
    problem = "'" + (path / "mesh" / "zarr.json").string() + "' is not the metadata of a Zarr format 3 group";
  if (problem.empty()) problem = read_whole_array(path / "mesh" / "vertices", "float64", 2, vertices);
  if (problem.empty()) problem = read_whole_array(path / "mesh" / "faces", "uint32", 2, faces);
  const std::size_t face_count = settings["face_count"].get<std::size_t>();
  if (problem.empty() &&
      (vertices.shape != std::vector<std::size_t>{vertex_count, 3} ||
       faces.shape != std::vector<std::size_t>{face_count, 3} ||
       mesh_digest(vertex_count, face_count, settings["weld_duplicate_positions"].get<bool>(), vertices.bytes,
                   faces.bytes) != settings["mesh_sha256"].get<std::string>()))
    problem = "'" + (path / "mesh").string() + "' does not hold the mesh whose sha256 its store's zarr.json records";
  if (!problem.empty()) damaged.push_back({"mesh", std::move(problem)});
  return damaged;
}

// The arrays every block shares, into the store at `path`: written straight into a store being built, or in a
// store in use (`in_use`) each built beside its place and renamed into it, so that one replaced while other shards
// read it appears whole. (A store being built is renamed into place whole already; building a folder inside
// another would leave the outer one behind on an interrupt.)
void write_shared_arrays(const fs::path& path, const StoreSettings& settings, const exactgeo::Mesh& mesh,
                         bool in_use) {
  const auto array = [in_use](const fs::path& folder, std::vector<std::size_t> shape, std::string_view data_type,
                              const Json& fill_value, const std::vector<std::string>& dimension_names,
                              std::span<const unsigned char> bytes) {
    const auto write = [&](const fs::path& into) {
      write_array(into, shape, data_type, fill_value, dimension_names, bytes);
    };
    if (in_use)
      build_folder_into_place(folder, Existing::replaced, write);
    else
      write(folder);
  };
  const std::vector<std::int64_t> sources(settings.sources.begin(), settings.sources.end());
  std::vector<std::int64_t> targets(settings.columns);
  for (std::size_t c = 0; c < targets.size(); ++c)
    targets[c] = settings.targets ? (*settings.targets)[c] : std::int64_t(c);
  array(path / "source", {sources.size()}, "int64", 0, {"source"}, little_endian_bytes(sources));
  array(path / "target", {settings.columns}, "int64", 0, {"target"}, little_endian_bytes(targets));
  write_group(path / "mesh");
  array(path / "mesh" / "vertices", {mesh.vertex_count(), 3}, "float64", 0.0, {"vertex", "xyz"},
        little_endian_bytes(mesh.positions()));
  array(path / "mesh" / "faces", {mesh.face_count(), 3}, "uint32", 0, {"face", "corner"},
        little_endian_bytes(mesh.triangles()));
}

// The whole store, built beside `path` and renamed into place, unless another process put one there first: of
// processes racing here, one store wins.
void create_store(const fs::path& path, const StoreSettings& settings, const exactgeo::Mesh& mesh) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  build_folder_into_place(path, Existing::kept, [&](const fs::path& building) {
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
    write_shared_arrays(building, settings, mesh, /*in_use=*/false);
    write_group(building / "done");
  });
}

// Writes a shard's blocks as their rows arrive: each block's data, then its marker.
class StoreWriter final : public MatrixWriter {
 public:
  StoreWriter(fs::path path, StoreSettings settings, const BlockShape& shape, const StoreRequest& request)
      : path_(std::move(path)), settings_(std::move(settings)), shard_(request.shard), quiet_(request.quiet),
        verify_(request.resume && request.verify), started_(std::chrono::steady_clock::now()) {
    // The request's settings are the store's (open_matrix_store compared them), and its mesh the one they record.
    const std::vector<DamagedArray> damaged =
        verify_ ? damaged_shared_arrays(path_, settings_json(settings_)) : std::vector<DamagedArray>();
    for (const DamagedArray& array : damaged)
      if (!quiet_) std::fprintf(stderr, "exactgeo: %s; written again\n", array.reason.c_str());
    if (!damaged.empty()) write_shared_arrays(path_, settings_, *request.mesh, /*in_use=*/true);
    const std::vector<std::size_t> done = done_blocks(path_, settings_.blocks());
    for (std::size_t block : shard_blocks(shard_, settings_.blocks())) {
      if (!request.resume || !std::binary_search(done.begin(), done.end(), block)) {
        todo_.push_back(block);
        continue;
      }
      const std::string problem = verify_ ? block_problem(path_, shape, block) : std::string();
      if (problem.empty()) {
        ++reused_;
        continue;
      }
      if (!quiet_) std::fprintf(stderr, "exactgeo: block %zu failed verification: %s\n", block, problem.c_str());
      remove_marker(block);
      todo_.push_back(block);
      ++failed_;
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
    const std::string failed = verify_ ? " (" + std::to_string(failed_) + " of them failed verification)" : "";
    std::fprintf(stderr, "exactgeo: %s shard %zu/%zu: %zu blocks computed%s, %zu reused (done before%s), of %zu; "
                 "the store has %zu of %zu blocks done\n", path_.c_str(), shard_.index, shard_.count, computed_,
                 failed.c_str(), reused_, verify_ ? ", verified" : "", computed_ + reused_, done, settings_.blocks());
  }

 private:
  // A block whose data is about to be replaced is not done until its new marker: its old one goes first, so
  // that a run stopped in between leaves the block missing, never marked done over other data.
  void remove_marker(std::size_t block) {
    const fs::path marker = path_ / "done" / block_name(block);
    std::error_code error;
    fs::remove_all(marker, error);
    if (error) throw io_error("cannot remove '" + marker.string() + "': " + error.message());
  }

  void write_block(std::size_t block, std::size_t end) {
    remove_marker(block);
    const std::size_t first = block * settings_.block_rows;
    Json record = {{"block", block},
                   {"rows", {first, end}},
                   {"max_distance", settings_.max_distance ? Json(*settings_.max_distance) : Json()}};
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
    // Pieces already there (an earlier attempt whose marker was never written, or was removed because they
    // did not match it) are replaced: the marker that follows vouches for these bytes only.
    build_folder_into_place(path_ / "csr" / block_name(block), Existing::replaced, [&](const fs::path& building) {
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
  bool verify_;  // the done blocks were read back, and those not matching their marker computed again
  std::vector<std::size_t> todo_;
  std::size_t reused_ = 0, computed_ = 0, failed_ = 0;
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
  return mesh_digest(mesh.vertex_count(), mesh.face_count(), weld, little_endian_bytes(mesh.positions()),
                     little_endian_bytes(mesh.triangles()));
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
  if (differs("mesh_sha256") || differs("vertex_count") || differs("face_count") || differs("weld_duplicate_positions"))
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

StoreStatus read_store_status(const fs::path& store, bool verify) {
  const fs::path path = fs::absolute(store);
  const std::optional<Stored> stored = read_stored(path);
  if (!stored) throw invalid_argument("'" + path.string() + "' holds no exactgeo distance matrix store");
  StoreStatus status{stored->settings, done_blocks(path, stored->shape.blocks()), {}, {}, {}};
  if (verify) {
    if (stored->zarr_format != kZarrFormat)
      throw invalid_argument("'" + path.string() + "' is a Zarr format " + std::to_string(stored->zarr_format) +
                             " store: the command verifies format 3 stores only");
    if (!stored->shape.sparse())
      if (const std::string problem = distances_problem(path, stored->shape); !problem.empty())
        throw invalid_argument("cannot verify '" + path.string() + "': " + problem);
    std::vector<std::size_t> intact;
    for (std::size_t block : status.done) {
      std::string problem = block_problem(path, stored->shape, block);
      if (problem.empty())
        intact.push_back(block);
      else
        status.corrupt.push_back({block, std::move(problem)});
    }
    status.done = std::move(intact);
    status.damaged = damaged_shared_arrays(path, stored->settings);
  }
  for (std::size_t block = 0; block < stored->shape.blocks(); ++block)
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
  if (!stored) {
    create_store(path, settings, mesh);
    stored = read_stored(path);  // this one, or the one another shard made first
  }
  if (!stored) throw io_error("'" + path.string() + "' was removed while it was made");
  if (stored->zarr_format != kZarrFormat)
    throw invalid_argument("'" + path.string() + "' is a Zarr format " + std::to_string(stored->zarr_format) +
                           " store (zarr-python 2 made it); the command writes format 3 only: continue it with "
                           "exactgeo.distributed, or choose another store (nothing was changed)");
  if (!explicit_block_rows) settings.block_rows = stored->shape.block_rows;
  const std::vector<std::string> differences =
      store_differences(stored->settings, settings_json(settings), explicit_block_rows);
  if (!differences.empty()) {
    std::string message = "the store '" + path.string() + "' was made for ";
    for (std::size_t i = 0; i < differences.size(); ++i) message += (i ? "; " : "") + differences[i];
    throw invalid_argument(message + ". Use another store, or remove this one to start over (nothing was changed)");
  }
  if (!settings.max_distance)
    if (const std::string problem = distances_problem(path, stored->shape); !problem.empty())
      throw invalid_argument(
          "cannot write into '" + path.string() + "': " + problem +
          ". Continue this store with exactgeo.distributed, or choose another store (nothing was changed)");
  return std::make_unique<StoreWriter>(path, std::move(settings), stored->shape, request);
}

}  // namespace exactgeo::cli
