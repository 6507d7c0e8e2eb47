// Reading a store back: its status, the verification of its blocks and shared arrays against what their markers
// and its settings record, and the mesh and sparse pieces it holds.
#include <algorithm>
#include <array>
#include <bit>
#include <numeric>
#include <type_traits>

#include "little_endian.hpp"
#include "matrix_store.hpp"
#include "sha256.hpp"
#include "store_files.hpp"

namespace exactgeo::store {
namespace {

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

// The pieces of sparse block `block` as write_sparse_block wrote them, into `pieces`; why they cannot be read
// (naming the file), or nothing.
std::string read_pieces(const fs::path& path, const BlockShape& shape, std::size_t block,
                        std::array<WholeArray, 3>& pieces) {
  const std::array<std::pair<const char*, std::string>, 3> names = {
      {{"data", shape.dtype}, {"indices", "uint32"}, {"indptr", "int64"}}};
  for (std::size_t i = 0; i < names.size(); ++i)
    if (std::string problem =
            read_whole_array(path / "csr" / block_name(block) / names[i].first, names[i].second, 1, pieces[i]);
        !problem.empty())
      return problem;
  return {};
}

// The values whose little-endian bytes are `bytes`.
template <typename T>
std::vector<T> values_of(const std::vector<unsigned char>& bytes) {
  using Bits = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
  std::vector<T> values(bytes.size() / sizeof(T));
  for (std::size_t i = 0; i < values.size(); ++i) {
    Bits bits = 0;
    for (std::size_t byte = 0; byte < sizeof(T); ++byte) bits |= Bits{bytes[i * sizeof(T) + byte]} << (8 * byte);
    values[i] = std::bit_cast<T>(bits);
  }
  return values;
}

}  // namespace

std::string distances_problem(const fs::path& path, const BlockShape& shape) {
  const std::vector<std::size_t> size = {shape.rows, shape.columns};
  const std::vector<std::size_t> chunks = {shape.block_rows, std::max<std::size_t>(1, shape.columns)};
  const fs::path metadata_path = path / "distances" / "zarr.json";
  Json metadata;
  if (std::string problem = read_json_into(metadata_path, metadata); !problem.empty()) return problem;
  return array_problem(metadata_path, metadata, array_metadata(size, chunks, shape.dtype, "NaN", {"source", "target"}));
}

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
  if (shape.sparse()) {
    std::array<WholeArray, 3> pieces;
    if (std::string problem = read_pieces(path, shape, block, pieces); !problem.empty()) return problem;
    for (const WholeArray& piece : pieces) digest.update(piece.bytes);
  } else if (std::string problem = hash_chunk(path, shape, block, digest); !problem.empty()) {
    return problem;
  }
  if (digest.hex_digest() == record["sha256"].get<std::string>()) return {};
  if (shape.sparse())
    return "the pieces in '" + (path / "csr" / block_name(block)).string() + "' do not hash to the sha256 in '" +
           marker.string() + "'";
  return "'" + (path / "distances" / "c" / std::to_string(block) / "0").string() +
         "' does not hash to the sha256 in '" + marker.string() + "'";
}

std::vector<DamagedArray> damaged_shared_arrays(const fs::path& path, const Json& settings) {
  std::vector<DamagedArray> damaged;
  const std::size_t vertex_count = settings["vertex_count"].get<std::size_t>();
  std::vector<std::int64_t> targets(vertex_count);
  std::iota(targets.begin(), targets.end(), 0);
  if (!settings["targets"].is_null()) targets = settings["targets"].get<std::vector<std::int64_t>>();
  const std::vector<std::int64_t> sources = settings["sources"].get<std::vector<std::int64_t>>();
  for (const auto& [name, expected] :
       {std::pair<std::string, const std::vector<std::int64_t>&>{"source", sources}, {"target", targets}}) {
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
  if (problem.empty() && (vertices.shape != std::vector<std::size_t>{vertex_count, 3} ||
                          faces.shape != std::vector<std::size_t>{face_count, 3} ||
                          mesh_digest(vertex_count, face_count, settings["weld_duplicate_positions"].get<bool>(),
                                      vertices.bytes, faces.bytes) != settings["mesh_sha256"].get<std::string>()))
    problem = "'" + (path / "mesh").string() + "' does not hold the mesh whose sha256 its store's zarr.json records";
  if (!problem.empty()) damaged.push_back({"mesh", std::move(problem)});
  return damaged;
}

StoreStatus read_store_status(const fs::path& store, bool verify) {
  const fs::path path = fs::absolute(store);
  const std::optional<Stored> stored = read_stored(path);
  if (!stored) throw invalid_store("'" + path.string() + "' holds no exactgeo distance matrix store");
  StoreStatus status{stored->settings, stored->zarr_format, done_blocks(path, stored->shape.blocks()), {}, {}, {}};
  if (verify) {
    if (stored->zarr_format != kZarrFormat)
      throw invalid_store("'" + path.string() + "' is a Zarr format " + std::to_string(stored->zarr_format) +
                          " store: exactgeo verifies format 3 stores only");
    if (!stored->shape.sparse())
      if (const std::string problem = distances_problem(path, stored->shape); !problem.empty())
        throw invalid_store("cannot verify '" + path.string() + "': " + problem);
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

StoredMesh read_stored_mesh(const fs::path& store) {
  const fs::path path = fs::absolute(store);
  const std::optional<Stored> stored = read_stored(path);
  if (!stored) throw invalid_store("'" + path.string() + "' holds no exactgeo distance matrix store");
  WholeArray vertices, faces;
  std::string problem = read_whole_array(path / "mesh" / "vertices", "float64", 2, vertices);
  if (problem.empty()) problem = read_whole_array(path / "mesh" / "faces", "uint32", 2, faces);
  const Json& settings = stored->settings;
  const bool weld = settings["weld_duplicate_positions"].get<bool>();
  if (problem.empty() && (vertices.shape.at(1) != 3 || faces.shape.at(1) != 3 ||
                          mesh_digest(vertices.shape[0], faces.shape[0], weld, vertices.bytes, faces.bytes) !=
                              settings["mesh_sha256"].get<std::string>()))
    problem = "its sha256 is not the one its store's zarr.json records";
  if (!problem.empty())
    throw invalid_store("the mesh stored in '" + (path / "mesh").string() + "' cannot be read: " + problem);
  return {values_of<double>(vertices.bytes), values_of<std::uint32_t>(faces.bytes), weld};
}

SparsePieces read_sparse_block(const fs::path& path, const BlockShape& shape, std::size_t block) {
  std::array<WholeArray, 3> pieces;
  if (std::string problem = read_pieces(path, shape, block, pieces); !problem.empty()) throw invalid_store(problem);
  return {std::move(pieces[0].bytes), values_of<std::uint32_t>(pieces[1].bytes),
          values_of<std::int64_t>(pieces[2].bytes)};
}

}  // namespace exactgeo::store
