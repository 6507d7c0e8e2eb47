// Distance matrices as Zarr stores (format v3), the layout exactgeo.distributed writes (see
// python/exactgeo/distributed.py and docs/distributed.md), so that a store started by `matrix --shard` jobs
// is continued by distance_matrix_to_zarr(..., resume=True) and the other way round:
//
//   STORE/zarr.json                 root group; attribute "exactgeo": what the matrix is (settings_json)
//   STORE/distances/c/B/0           block B's rows, uncompressed (dense layout)
//   STORE/csr/block_NNNNNN/         block B's rows as CSR pieces data, indices, indptr (sparse layout)
//   STORE/source, target, mesh/     the rows' and columns' vertices, the mesh's vertices and faces
//   STORE/done/block_NNNNNN/        block B's marker: a group whose zarr.json is renamed into place last
//
// Block B is rows [B * block_rows, (B + 1) * block_rows). Every file appears whole (written beside its place,
// then renamed), so processes computing different blocks share a store without locks, and a block counts as
// done only through its marker, written after its data: a block written again loses its marker first, and
// its chunk or pieces are replaced, never kept, so a marker vouches only for the data its own attempt wrote.
// Verifying reads a done block back and compares it with the sha256 its marker recorded.
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "outputs.hpp"

namespace exactgeo::cli {

inline constexpr std::string_view kStoreFormat = "exactgeo-distance-matrix/1";

// The I-th of N interleaved sets of blocks: blocks B with B % N == I.
struct Shard {
  std::size_t index = 0;
  std::size_t count = 1;
};
// "I/N" with 0 <= I < N; throws std::invalid_argument saying what is wrong otherwise.
Shard parse_shard(std::string_view text);
std::vector<std::size_t> shard_blocks(const Shard& shard, std::size_t blocks);

// Sorted block numbers as compact ranges: "0-2, 5, 7-9" ("none" for no block).
std::string block_ranges(std::span<const std::size_t> blocks);

// What a store holds: the "exactgeo" attribute of its root group, field for field.
struct StoreSettings {
  std::string mesh_sha256;
  std::size_t vertex_count = 0, face_count = 0;
  bool weld = false;
  std::vector<std::uint32_t> sources;
  std::optional<std::vector<std::uint32_t>> targets;  // none: every vertex, in order
  std::size_t columns = 0;
  std::string dtype = "float32";  // "float32" or "float64"
  std::optional<double> max_distance;  // set: the sparse layout
  std::size_t block_rows = 0;
  std::size_t blocks() const { return (sources.size() + block_rows - 1) / block_rows; }
};
nlohmann::ordered_json settings_json(const StoreSettings& settings);

// sha256 of the mesh's input as exactgeo.distributed.mesh_hash computes it: counts and welding, then vertices
// as float64 and faces as uint32, little-endian.
std::string mesh_sha256(const exactgeo::Mesh& mesh, bool weld);

// Python's default: at most 32 MiB a chunk, at most 4096 rows, some 32 blocks or more when there are enough rows.
std::size_t default_block_rows(std::size_t rows, std::size_t columns, std::size_t item_bytes);

// The metadata of a Zarr v3 array stored uncompressed (codecs: bytes, little-endian), as zarr-python 3 writes it.
nlohmann::ordered_json array_metadata(std::span<const std::size_t> shape, std::span<const std::size_t> chunk_shape,
                                      std::string_view data_type, const nlohmann::ordered_json& fill_value,
                                      const std::vector<std::string>& dimension_names);

// Why `stored` (a store's "exactgeo" attribute) does not answer the request `wanted`, one phrase per
// difference, as distributed.py's _differences words them; empty if it does.
std::vector<std::string> store_differences(const nlohmann::ordered_json& stored, const nlohmann::ordered_json& wanted,
                                           bool explicit_block_rows);

// A block marked done whose data on disk is not what its marker recorded, and why (naming the file at fault).
struct CorruptBlock {
  std::size_t block;
  std::string reason;
};

// An array every block shares (source, target, mesh) that does not hold what the store's settings record, and why
// (naming the file).
struct DamagedArray {
  std::string array;
  std::string reason;
};

// A store's settings and its done blocks, for --status. With `verify`, each done block's data is read back and
// hashed as its marker's sha256 was (exactgeo.distributed.store_status(verify=True) does the same): those that
// differ are corrupt, and missing; and the arrays every block shares (source, target, mesh/) are checked against
// the settings. Throws exactgeo::Error naming the file if `path` is not an exactgeo store, or (verifying) if its
// distances array is not stored as the command writes it.
struct StoreStatus {
  nlohmann::ordered_json settings;
  std::vector<std::size_t> done, missing;  // missing: corrupt blocks included
  std::vector<CorruptBlock> corrupt;
  std::vector<DamagedArray> damaged;  // with verify
  bool complete() const { return missing.empty() && damaged.empty(); }
};
StoreStatus read_store_status(const std::filesystem::path& path, bool verify = false);

// What the matrix command asks of a store besides the matrix's axes.
struct StoreRequest {
  const exactgeo::Mesh* mesh = nullptr;
  bool weld = false;
  std::optional<double> max_distance;
  std::string dtype = "float32";
  std::size_t block_rows = 0;  // 0: the store's, or the default for a new one
  Shard shard;
  bool resume = false;  // skip the shard's blocks already marked done
  bool verify = false;  // with resume: read those blocks back first, and compute again any not matching its marker;
                        // write the shared arrays again if they do not hold what the settings record
  bool quiet = false;   // no summary line
};

// Opens the store at `path` (creating it if there is none: built in a hidden folder beside it and renamed
// into place, so that shards starting together make one store) for the request's shard; the writer takes
// the shard's rows block by block. Throws exactgeo::Error naming what differs if the store was made for
// another matrix, and leaves a path holding anything else unchanged.
std::unique_ptr<MatrixWriter> open_matrix_store(const std::string& path, const MatrixAxes& axes,
                                                const StoreRequest& request);

}  // namespace exactgeo::cli
