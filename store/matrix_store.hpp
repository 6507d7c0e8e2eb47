// The distance matrix store: the only code that knows its layout, which docs/distributed.md ("The store")
// specifies and tests/test_store.cpp and python/tests/test_store_layout.py check. The command's `matrix --out
// M.zarr` (cli/formats/zarr_store.cpp) and Python's exactgeo.distributed (through exactgeo._core) both call it,
// so that a store begun by one is continued by the other. A Zarr format 3 store:
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
// Verifying reads a done block back and compares it with the sha256 its marker recorded. Errors are
// exactgeo::Error naming the file or what differs: invalid_argument for a store that is not the one asked
// for, io_error for a file that cannot be written.
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

namespace exactgeo::store {

inline constexpr std::string_view kStoreFormat = "exactgeo-distance-matrix/1";

// The I-th of N interleaved sets of blocks: blocks B with B % N == I.
struct Shard {
  std::size_t index = 0;
  std::size_t count = 1;
};
std::vector<std::size_t> shard_blocks(const Shard& shard, std::size_t blocks);

// The block rule for a new store when none is asked for: at most 32 MiB a chunk, at most 4096 rows, some 32
// blocks or more when there are enough rows.
std::size_t default_block_rows(std::size_t rows, std::size_t columns, std::size_t item_bytes);

// "block_NNNNNN": the name of block B's marker and sparse pieces.
std::string block_name(std::size_t block);

// The mesh as given: positions (x, y, z per vertex, float64) and triangles (three corners per face, uint32).
struct MeshArrays {
  std::span<const double> positions;
  std::span<const std::uint32_t> triangles;
  bool weld = false;  // the mesh welds duplicate positions (a setting of the mesh, part of its hash)
};
// sha256 of the mesh: "exactgeo-mesh/1", the vertex and face counts and welding as int64, then the positions as
// float64 and the triangles as uint32, all little-endian (exactgeo.distributed.mesh_hash).
std::string mesh_sha256(const MeshArrays& mesh);

// The shape of a store's blocks, from the settings it records: block B is rows [first(B), end(B)).
struct BlockShape {
  std::size_t rows = 0, columns = 0, block_rows = 1;
  std::string dtype;
  nlohmann::ordered_json max_distance;  // null: the dense layout; a marker records the one its block was computed with

  bool sparse() const { return !max_distance.is_null(); }
  std::size_t item_bytes() const { return dtype == "float32" ? 4 : 8; }
  std::size_t blocks() const { return (rows + block_rows - 1) / block_rows; }
  std::size_t first(std::size_t block) const { return block * block_rows; }
  std::size_t end(std::size_t block) const { return std::min(rows, (block + 1) * block_rows); }
};

// What a store holds: the "exactgeo" attribute of its root group, field for field.
struct StoreSettings {
  std::string mesh_sha256;
  std::size_t vertex_count = 0, face_count = 0;
  bool weld = false;
  std::vector<std::uint32_t> sources;
  std::optional<std::vector<std::uint32_t>> targets;  // none: every vertex, in order
  std::size_t columns = 0;
  std::string dtype = "float32";       // "float32" or "float64"
  std::optional<double> max_distance;  // set: the sparse layout
  std::size_t block_rows = 0;
  BlockShape block_shape() const;  // the one read_stored reads back from the store these settings make
};
nlohmann::ordered_json settings_json(const StoreSettings& settings);

// Why `stored` (a store's "exactgeo" attribute) does not answer the request `wanted`, one phrase per difference
// ("another mesh (the store's: ...; this one: ...)"); empty if it does. block_rows counts only if
// `explicit_block_rows`.
std::vector<std::string> store_differences(const nlohmann::ordered_json& stored, const nlohmann::ordered_json& wanted,
                                           bool explicit_block_rows);

// What a folder holds: an exactgeo store's settings (checked for their types and against each other, so that an
// edited block count cannot hide blocks), its blocks' shape and its Zarr format (2: made by zarr-python 2, read
// for its status only).
struct Stored {
  nlohmann::ordered_json settings;
  BlockShape shape;
  int zarr_format = 3;
};
// Nothing if `path` is absent or an empty folder; throws invalid_argument naming it if it holds anything else
// than an exactgeo store.
std::optional<Stored> read_stored(const std::filesystem::path& path);

// The blocks whose marker is there, in order.
std::vector<std::size_t> done_blocks(const std::filesystem::path& path, std::size_t blocks);

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

// A store's settings and its done blocks. With `verify`, each done block's data is read back and hashed as its
// marker's sha256 was: those that differ are corrupt, and missing; and the arrays every block shares (source,
// target, mesh/) are checked against the settings. Throws invalid_argument naming the file if `path` is not an
// exactgeo store, or (verifying) if its distances array is not stored as blocks are written.
struct StoreStatus {
  nlohmann::ordered_json settings;
  int zarr_format = 3;
  std::vector<std::size_t> done, missing;  // missing: corrupt blocks included
  std::vector<CorruptBlock> corrupt;
  std::vector<DamagedArray> damaged;  // with verify
  bool complete() const { return missing.empty() && damaged.empty(); }
};
StoreStatus read_store_status(const std::filesystem::path& path, bool verify = false);

// Why done block `block`'s data is not what its marker recorded (naming the file at fault); empty if it is.
std::string block_problem(const std::filesystem::path& path, const BlockShape& shape, std::size_t block);

// Why the dense array is not the one blocks are written into and read back from (its shape, chunks and dtype, NaN
// where no block was written, uncompressed), naming the file; empty if it is.
std::string distances_problem(const std::filesystem::path& path, const BlockShape& shape);

// The arrays every block shares that do not hold what `settings` (read_stored's) record, and why: `source` and
// `target` the settings' sources and targets (every vertex without targets), mesh/ the mesh whose sha256 they record.
std::vector<DamagedArray> damaged_shared_arrays(const std::filesystem::path& path,
                                                const nlohmann::ordered_json& settings);

// What a writer asks of a store.
struct OpenRequest {
  StoreSettings settings;  // block_rows 0: the store's, or default_block_rows for a new one
  MeshArrays mesh;         // the mesh the settings' hash is of
  bool replace = false;    // an exactgeo store at the path is replaced by a new one; otherwise it is joined, if it
                           // was made for the same matrix
  bool verify = false;     // the done blocks of `verified` are read back, and those not matching their marker lose
                           // it; the shared arrays are written again if they do not hold what the settings record
  Shard verified;
  std::string_view start_over;  // how the caller's user starts over, ending the message that names what differs
};
// A store open for writing blocks into.
struct OpenStore {
  std::filesystem::path path;  // absolute
  StoreSettings settings;      // block_rows resolved
  BlockShape shape;
  std::vector<std::size_t> done;        // marked done (and, verifying, intact)
  std::vector<CorruptBlock> failed;     // verifying: done blocks that were not intact, now missing
  std::vector<DamagedArray> rewritten;  // verifying: shared arrays written again
};
// Creates the store at `path` if there is none (built in a hidden folder beside it and renamed into place, so that
// processes starting together make one store), or opens the one there. Throws invalid_argument naming what
// differs if it was made for another matrix, or if it is in Zarr format 2 or its distances are stored compressed;
// a path holding anything but an exactgeo store is left unchanged.
OpenStore open_store(const std::filesystem::path& path, const OpenRequest& request);

// Removes the hidden folders that sparse blocks' attempts killed before their rename left (csr/.block_*.tmp).
// Only for a writer alone on the store: another one's block being built is such a folder too.
void remove_unfinished_pieces(const std::filesystem::path& path);

// A block's rows, as the marker records them.
struct BlockRecord {
  std::size_t block = 0;
  std::size_t first_row = 0, end_row = 0;
  std::optional<double> max_distance;
  double seconds = 0;  // spent computing and writing it
};
// Dense block: its chunk (block_rows rows of `row_bytes` each, the rows past end_row - first_row the fill value),
// then its marker. The old marker goes first, so that a block being written again is missing until its new one.
void write_dense_block(const std::filesystem::path& path, const BlockRecord& record,
                       std::span<const unsigned char> chunk, std::size_t row_bytes);
// Sparse block: its pieces (row pointers from 0; values of the store's dtype, as little-endian bytes) built in a
// hidden folder and renamed into csr/block_NNNNNN, replacing pieces there; then its marker.
void write_sparse_block(const std::filesystem::path& path, const BlockRecord& record, std::string_view dtype,
                        std::span<const unsigned char> data, std::span<const std::uint32_t> indices,
                        std::span<const std::int64_t> indptr);

// The mesh the store holds (mesh/vertices, mesh/faces) as little-endian bytes, checked against the hash its
// settings record; throws invalid_argument naming the folder otherwise.
struct StoredMesh {
  std::vector<double> positions;
  std::vector<std::uint32_t> triangles;
  bool weld = false;
};
StoredMesh read_stored_mesh(const std::filesystem::path& path);

// The CSR pieces of sparse block `block`, as written; throws invalid_argument naming the file that cannot be read.
struct SparsePieces {
  std::vector<unsigned char> data;  // values of the store's dtype, little-endian
  std::vector<std::uint32_t> indices;
  std::vector<std::int64_t> indptr;
};
SparsePieces read_sparse_block(const std::filesystem::path& path, const BlockShape& shape, std::size_t block);

}  // namespace exactgeo::store
