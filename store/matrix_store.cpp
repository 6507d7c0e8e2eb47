// The store's settings, its creation and opening, and the writing of its blocks; reading them back and verifying
// them is in store_status.cpp.
#include "matrix_store.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <system_error>

#include "exactgeo/version.hpp"
#include "little_endian.hpp"
#include "sha256.hpp"
#include "store_files.hpp"

namespace exactgeo::store {
namespace {

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

// The arrays every block shares, into the store at `path`: written straight into a store being built, or in a
// store in use (`in_use`) each built beside its place and renamed into it, so that one replaced while other
// writers read it appears whole. (A store being built is renamed into place whole already; building a folder
// inside another would leave the outer one behind on an interrupt.)
void write_shared_arrays(const fs::path& path, const StoreSettings& settings, const MeshArrays& mesh, bool in_use) {
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
  array(path / "mesh" / "vertices", {mesh.positions.size() / 3, 3}, "float64", 0.0, {"vertex", "xyz"},
        little_endian_bytes(mesh.positions));
  array(path / "mesh" / "faces", {mesh.triangles.size() / 3, 3}, "uint32", 0, {"face", "corner"},
        little_endian_bytes(mesh.triangles));
}

// The whole store, built beside `path` and renamed into place, unless another process put one there first: of
// processes racing here, one store wins.
void create_store(const fs::path& path, const StoreSettings& settings, const MeshArrays& mesh) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  build_folder_into_place(path, Existing::kept, [&](const fs::path& building) {
    const Json attributes = {{"exactgeo", settings_json(settings)}};
    write_json_whole(building / "zarr.json", group_metadata(attributes));
    if (settings.max_distance) {
      write_group(building / "csr");
    } else {
      fs::create_directories(building / "distances" / "c");
      const std::vector<std::size_t> shape = {settings.sources.size(), settings.columns};
      const std::vector<std::size_t> chunks = {settings.block_rows, std::max<std::size_t>(1, settings.columns)};
      write_json_whole(building / "distances" / "zarr.json",
                       array_metadata(shape, chunks, settings.dtype, "NaN", {"source", "target"}));
    }
    write_shared_arrays(building, settings, mesh, /*in_use=*/false);
    write_group(building / "done");
  });
}

// A block whose data is about to be replaced is not done until its new marker: its old one goes first, so
// that a run stopped in between leaves the block missing, never marked done over other data.
void remove_marker(const fs::path& path, std::size_t block) {
  const fs::path marker = path / "done" / block_name(block);
  std::error_code error;
  fs::remove_all(marker, error);
  if (error) throw io_error("cannot remove '" + marker.string() + "': " + error.message());
}

// done/block_NNNNNN: a group whose attributes are the block's record; its metadata file, renamed into place after
// the block's data is written, is the marker.
void write_marker(const fs::path& path, const BlockRecord& block, std::optional<std::size_t> nnz,
                  const std::string& sha256) {
  Json record = {{"block", block.block},
                 {"rows", {block.first_row, block.end_row}},
                 {"max_distance", block.max_distance ? Json(*block.max_distance) : Json()}};
  if (nnz) record["nnz"] = *nnz;
  record["sha256"] = sha256;
  record["seconds"] = block.seconds;
  const fs::path marker = path / "done" / block_name(block.block);
  fs::create_directories(marker);
  write_json_whole(marker / "zarr.json", group_metadata(record));
}

}  // namespace

std::vector<std::size_t> shard_blocks(const Shard& shard, std::size_t blocks) {
  std::vector<std::size_t> mine;
  for (std::size_t block = shard.index; block < blocks; block += shard.count) mine.push_back(block);
  return mine;
}

std::size_t default_block_rows(std::size_t rows, std::size_t columns, std::size_t item_bytes) {
  const std::size_t budget = (std::size_t{32} << 20) / std::max<std::size_t>(1, columns * item_bytes);
  return std::max<std::size_t>(1, std::min({(rows + 31) / 32, budget, std::size_t{4096}}));
}

std::string block_name(std::size_t block) {
  char name[32];
  std::snprintf(name, sizeof name, "block_%06zu", block);
  return name;
}

std::string mesh_sha256(const MeshArrays& mesh) {
  Sha256 digest;
  digest.update("exactgeo-mesh/1");
  const std::vector<std::int64_t> counts = {static_cast<std::int64_t>(mesh.positions.size() / 3),
                                            static_cast<std::int64_t>(mesh.triangles.size() / 3), mesh.weld ? 1 : 0};
  digest.update(little_endian_bytes(counts));
  digest.update(little_endian_bytes(mesh.positions));
  digest.update(little_endian_bytes(mesh.triangles));
  return digest.hex_digest();
}

BlockShape StoreSettings::block_shape() const {
  return {.rows = sources.size(),
          .columns = columns,
          .block_rows = block_rows,
          .dtype = dtype,
          .max_distance = max_distance ? Json(*max_distance) : Json()};
}

Json settings_json(const StoreSettings& settings) {
  const BlockShape shape = settings.block_shape();
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
      {"max_distance", shape.max_distance},
      {"layout", shape.sparse() ? "sparse" : "dense"},
      {"block_rows", settings.block_rows},
      {"blocks", shape.blocks()},
      {"zarr_format", kZarrFormat},
  };
}

std::vector<std::string> store_differences(const Json& stored, const Json& wanted, bool explicit_block_rows) {
  std::vector<std::string> found;
  const auto differs = [&](const char* key) { return stored.value(key, Json()) != wanted[key]; };
  if (differs("mesh_sha256") || differs("vertex_count") || differs("face_count") || differs("weld_duplicate_positions"))
    found.push_back("another mesh (the store's: " + describe_mesh(stored) + "; this one: " + describe_mesh(wanted) +
                    ")");
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

std::optional<Stored> read_stored(const fs::path& path) {
  std::error_code error;
  if (!fs::exists(path, error)) return std::nullopt;
  if (!fs::is_directory(path, error))
    throw invalid_store("'" + path.string() + "' exists and is not a folder: choose another store");
  if (fs::is_empty(path, error)) return std::nullopt;
  std::optional<Json> attributes;
  int zarr_format = kZarrFormat;
  if (const std::optional<Json> root = read_json(path / "zarr.json")) {
    if (root->value("zarr_format", Json()) != kZarrFormat || root->value("node_type", Json()) != "group")
      throw invalid_store("'" + (path / "zarr.json").string() + "' is not the metadata of a Zarr format 3 group");
    attributes = root->value("attributes", Json::object());
  } else if (fs::is_regular_file(path / ".zgroup", error)) {
    zarr_format = 2;
    attributes = read_json(path / ".zattrs").value_or(Json::object());
  } else {
    throw invalid_store("'" + path.string() +
                        "' exists and is not a Zarr store: choose another store (nothing was changed)");
  }
  const Json settings = attributes->is_object() ? attributes->value("exactgeo", Json()) : Json();
  if (!settings.is_object() || settings.value("format", "") != kStoreFormat)
    throw invalid_store("'" + path.string() + "' is a Zarr " + (zarr_format == kZarrFormat ? "" : "format 2 ") +
                        "store but not an exactgeo distance matrix: choose another store (nothing was changed)");
  // Every count is checked against the others, so that an edited block count cannot hide blocks.
  const auto count = [](const Json& value) { return value.is_number_unsigned(); };
  const auto indices = [&count](const Json& value) {
    return value.is_array() && std::all_of(value.begin(), value.end(), count);
  };
  const Json shape = settings.value("shape", Json()), dtype = settings.value("dtype", Json());
  const Json block_rows = settings.value("block_rows", Json()), blocks = settings.value("blocks", Json());
  const Json sources = settings.value("sources", Json()), targets = settings.value("targets", Json());
  const fs::path metadata = path / (zarr_format == kZarrFormat ? "zarr.json" : ".zattrs");
  if (!shape.is_array() || shape.size() != 2 || !count(shape[0]) || !count(shape[1]) || !count(block_rows) ||
      block_rows == 0 || !count(blocks) || (dtype != "float32" && dtype != "float64") ||
      !settings.contains("max_distance") || !indices(sources) || !(targets.is_null() || indices(targets)) ||
      !count(settings.value("vertex_count", Json())) || !count(settings.value("face_count", Json())) ||
      !settings.value("weld_duplicate_positions", Json()).is_boolean() ||
      !settings.value("mesh_sha256", Json()).is_string())
    throw invalid_store("'" + metadata.string() +
                        "': its exactgeo attribute has no valid shape, dtype, max_distance, blocks, "
                        "block_rows, sources, targets and mesh");
  const BlockShape block_shape{.rows = shape[0].get<std::size_t>(),
                               .columns = shape[1].get<std::size_t>(),
                               .block_rows = block_rows.get<std::size_t>(),
                               .dtype = dtype.get<std::string>(),
                               .max_distance = settings["max_distance"]};
  const Json layout = settings.value("layout", Json());
  if (!layout.is_string() || layout.get<std::string>() != (block_shape.sparse() ? "sparse" : "dense"))
    throw invalid_store("'" + metadata.string() + "': its exactgeo attribute's layout " + layout.dump() +
                        " does not go with its max_distance " + block_shape.max_distance.dump());
  const Json columns = targets.is_null() ? settings.value("vertex_count", Json()) : Json(targets.size());
  if (sources.size() != block_shape.rows || columns != block_shape.columns)
    throw invalid_store("'" + metadata.string() + "': its exactgeo attribute's shape " + shape.dump() +
                        " is not its sources by its targets (or vertices)");
  if (blocks != block_shape.blocks())
    throw invalid_store("'" + metadata.string() + "': its exactgeo attribute has " + blocks.dump() + " blocks, but " +
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
    if (fs::is_regular_file(entry->path() / "zarr.json", missing) ||
        fs::is_regular_file(entry->path() / ".zgroup", missing))
      done.push_back(block);
  }
  std::sort(done.begin(), done.end());
  return done;
}

OpenStore open_store(const fs::path& store, const OpenRequest& request) {
  const fs::path path = fs::absolute(store);
  StoreSettings settings = request.settings;
  const bool explicit_block_rows = settings.block_rows != 0;
  std::optional<Stored> stored = read_stored(path);
  if (stored && stored->zarr_format != kZarrFormat)
    throw invalid_store("'" + path.string() + "' is a Zarr format " + std::to_string(stored->zarr_format) +
                        " store (zarr-python 2 made it): exactgeo writes format 3 only; choose another store "
                        "(nothing was changed)");
  if (stored && request.replace) {
    fs::remove_all(path);
    stored.reset();
  }
  if (!explicit_block_rows)
    settings.block_rows =
        default_block_rows(settings.sources.size(), settings.columns, settings.block_shape().item_bytes());
  if (!stored) {
    create_store(path, settings, request.mesh);
    stored = read_stored(path);  // this one, or the one another writer made first
  }
  if (!stored) throw io_error("'" + path.string() + "' was removed while it was made");
  if (!explicit_block_rows) settings.block_rows = stored->shape.block_rows;
  const std::vector<std::string> differences =
      store_differences(stored->settings, settings_json(settings), explicit_block_rows);
  if (!differences.empty()) {
    std::string message = "the store '" + path.string() + "' was made for ";
    for (std::size_t i = 0; i < differences.size(); ++i) message += (i ? "; " : "") + differences[i];
    throw invalid_store(message + ". Use another store, or " + std::string(request.start_over));
  }
  if (!settings.max_distance)
    if (const std::string problem = distances_problem(path, stored->shape); !problem.empty())
      throw invalid_store("cannot write into '" + path.string() + "': " + problem + ": choose another store, or " +
                          std::string(request.start_over));
  OpenStore open{path, std::move(settings), stored->shape, done_blocks(path, stored->shape.blocks()), {}, {}};
  if (!request.verify) return open;
  // The request's settings are the store's (compared above), and its mesh the one they record.
  open.rewritten = damaged_shared_arrays(path, stored->settings);
  if (!open.rewritten.empty()) write_shared_arrays(path, open.settings, request.mesh, /*in_use=*/true);
  const std::vector<std::size_t> verified = shard_blocks(request.verified, open.shape.blocks());
  std::vector<std::size_t> intact;
  for (std::size_t block : open.done) {
    std::string problem = std::binary_search(verified.begin(), verified.end(), block)
                              ? block_problem(path, open.shape, block)
                              : std::string();
    if (problem.empty()) {
      intact.push_back(block);
      continue;
    }
    remove_marker(path, block);  // computed again
    open.failed.push_back({block, std::move(problem)});
  }
  open.done = std::move(intact);
  return open;
}

void remove_unfinished_pieces(const fs::path& path) {
  std::error_code error;
  for (fs::directory_iterator entry(path / "csr", error), end; !error && entry != end; entry.increment(error)) {
    const std::string name = entry->path().filename().string();
    std::error_code ignored;
    if (name.starts_with(".block_") && name.ends_with(".tmp")) fs::remove_all(entry->path(), ignored);
  }
}

void write_dense_block(const fs::path& path, const BlockRecord& record, std::span<const unsigned char> chunk,
                       std::size_t row_bytes) {
  remove_marker(path, record.block);
  Sha256 digest;
  digest.update(chunk.first((record.end_row - record.first_row) * row_bytes));  // without the last chunk's padding
  const fs::path chunk_path = path / "distances" / "c" / std::to_string(record.block) / "0";
  fs::create_directories(chunk_path.parent_path());
  write_whole(chunk_path, chunk);
  write_marker(path, record, std::nullopt, digest.hex_digest());
}

void write_sparse_block(const fs::path& path, const BlockRecord& record, std::string_view dtype,
                        std::span<const unsigned char> data, std::span<const std::uint32_t> indices,
                        std::span<const std::int64_t> indptr) {
  remove_marker(path, record.block);
  const std::vector<unsigned char> index_bytes = little_endian_bytes(indices);
  const std::vector<unsigned char> pointer_bytes = little_endian_bytes(indptr);
  Sha256 digest;
  for (const std::span<const unsigned char> bytes :
       {data, std::span<const unsigned char>(index_bytes), std::span<const unsigned char>(pointer_bytes)})
    digest.update(bytes);
  const std::size_t nnz = indices.size();
  // Pieces already there (an earlier attempt whose marker was never written, or was removed because they did not
  // match it) are replaced: the marker that follows vouches for these bytes only.
  build_folder_into_place(path / "csr" / block_name(record.block), Existing::replaced, [&](const fs::path& building) {
    write_group(building);
    write_array(building / "data", std::vector<std::size_t>{nnz}, dtype, 0.0, {"data"}, data);
    write_array(building / "indices", std::vector<std::size_t>{nnz}, "uint32", 0, {"indices"}, index_bytes);
    write_array(building / "indptr", std::vector<std::size_t>{indptr.size()}, "int64", 0, {"indptr"}, pointer_bytes);
  });
  write_marker(path, record, nnz, digest.hex_digest());
}

}  // namespace exactgeo::store
