// exactgeo._core's store functions: the distance matrix store of store/matrix_store.hpp (its layout, block rule,
// markers, mesh hash and verification), which exactgeo.distributed calls so that it keeps only the scheduling.
// Settings cross as the JSON text of the store's "exactgeo" attribute; arrays as numpy arrays the package has
// already converted (exact dtype, C order). The GIL is released while files are written or read back.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "exactgeo/error.hpp"
#include "marshalling.hpp"
#include "matrix_store.hpp"
#include "registration.hpp"

using namespace nb::literals;

namespace exactgeo::python {

namespace {

using PointerArray = nb::ndarray<const std::int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
// Values of the store's dtype (float32 or float64, little-endian), taken as the bytes they are.
using ValueArray = nb::ndarray<nb::c_contig, nb::device::cpu>;

std::span<const unsigned char> value_bytes(const ValueArray& values, const char* name) {
  if (values.dtype().code != static_cast<std::uint8_t>(nb::dlpack::dtype_code::Float) ||
      (values.dtype().bits != 32 && values.dtype().bits != 64))
    throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument, std::string(name) + " must be float32 or float64");
  return std::span(static_cast<const unsigned char*>(values.data()), values.nbytes());
}

exactgeo::store::MeshArrays mesh_arrays(const PointArray& vertices, const TriangleArray& faces, bool weld) {
  return {span_of(vertices), span_of(faces), weld};
}

std::vector<std::pair<std::size_t, std::string>> corrupt_pairs(
    const std::vector<exactgeo::store::CorruptBlock>& blocks) {
  std::vector<std::pair<std::size_t, std::string>> pairs;
  for (const auto& block : blocks) pairs.emplace_back(block.block, block.reason);
  return pairs;
}

std::vector<std::string> reasons(const std::vector<exactgeo::store::DamagedArray>& arrays) {
  std::vector<std::string> found;
  for (const auto& array : arrays) found.push_back(array.reason);
  return found;
}

}  // namespace

void register_store(nb::module_& m) {
  namespace store = exactgeo::store;

  m.def(
      "store_mesh_sha256",
      [](const PointArray& vertices, const TriangleArray& faces, bool weld) {
        return store::mesh_sha256(mesh_arrays(vertices, faces, weld));
      },
      "vertices"_a.noconvert(), "faces"_a.noconvert(), "weld"_a,
      "sha256 (hex) of a mesh as the store records it: counts and welding, vertices as float64, faces as uint32.");

  m.def("store_default_block_rows", &store::default_block_rows, "rows"_a, "columns"_a, "item_bytes"_a,
        "Rows per block for a new store: at most 32 MiB a chunk, at most 4096 rows, some 32 blocks or more.");

  m.def(
      "store_settings",
      [](const std::string& path) -> std::optional<std::pair<std::string, int>> {
        const std::optional<store::Stored> stored = store::read_stored(path);
        if (!stored) return std::nullopt;
        return std::pair(stored->settings.dump(), stored->zarr_format);
      },
      "path"_a,
      "The store's settings (its \"exactgeo\" attribute, as JSON text) and Zarr format; None if there is no store.");

  m.def(
      "store_open",
      [](const std::string& path, const PointArray& vertices, const TriangleArray& faces, bool weld,
         const IndexArray& sources, std::optional<IndexArray> targets, const std::string& dtype,
         std::optional<double> max_distance, std::size_t block_rows, bool replace, bool verify) {
        const store::MeshArrays mesh = mesh_arrays(vertices, faces, weld);
        store::OpenRequest request{.settings = {.mesh_sha256 = store::mesh_sha256(mesh),
                                                .vertex_count = vertices.shape(0),
                                                .face_count = faces.shape(0),
                                                .weld = weld,
                                                .sources = {sources.data(), sources.data() + sources.size()},
                                                .targets = std::nullopt,
                                                .columns = targets ? targets->size() : vertices.shape(0),
                                                .dtype = dtype,
                                                .max_distance = max_distance,
                                                .block_rows = block_rows},
                                   .mesh = mesh,
                                   .replace = replace,
                                   .verify = verify,
                                   .verified = {},
                                   .start_over = "resume=False to replace this one."};
        if (targets) request.settings.targets.emplace(targets->data(), targets->data() + targets->size());
        store::OpenStore open;
        {
          nb::gil_scoped_release released;
          open = store::open_store(path, request);
        }
        return std::tuple(store::settings_json(open.settings).dump(), open.done, corrupt_pairs(open.failed),
                          reasons(open.rewritten));
      },
      "path"_a, "vertices"_a.noconvert(), "faces"_a.noconvert(), "weld"_a, "sources"_a.noconvert(),
      "targets"_a.noconvert().none(), "dtype"_a, "max_distance"_a.none(), "block_rows"_a, "replace"_a, "verify"_a,
      "Creates or opens the store for this matrix (block_rows 0: the store's or the default); returns its "
      "settings (JSON text), its done blocks and, verifying, the blocks and shared arrays that were not intact.");

  m.def(
      "store_remove_unfinished_pieces", [](const std::string& path) { store::remove_unfinished_pieces(path); },
      "path"_a, "Removes the hidden folders of sparse blocks whose writers died before renaming them into place.");

  m.def(
      "store_write_dense_block",
      [](const std::string& path, std::size_t block, std::size_t first_row, std::size_t end_row,
         const ValueArray& chunk, double seconds) {
        const std::span<const unsigned char> bytes = value_bytes(chunk, "chunk");
        if (chunk.ndim() != 2)
          throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument, "chunk must have two dimensions");
        const std::size_t row_bytes = chunk.shape(1) * chunk.itemsize();
        nb::gil_scoped_release released;
        store::write_dense_block(path, {block, first_row, end_row, std::nullopt, seconds}, bytes, row_bytes);
      },
      "path"_a, "block"_a, "first_row"_a, "end_row"_a, "chunk"_a.noconvert(), "seconds"_a,
      "Writes dense block `block` (its whole chunk, little-endian, rows past end_row - first_row the fill value), "
      "then its marker.");

  m.def(
      "store_write_sparse_block",
      [](const std::string& path, std::size_t block, std::size_t first_row, std::size_t end_row, double max_distance,
         const ValueArray& data, const IndexArray& indices, const PointerArray& indptr, double seconds) {
        const std::span<const unsigned char> bytes = value_bytes(data, "data");
        const char* dtype = data.itemsize() == 4 ? "float32" : "float64";
        nb::gil_scoped_release released;
        store::write_sparse_block(path, {block, first_row, end_row, max_distance, seconds}, dtype, bytes,
                                  span_of(indices), span_of(indptr));
      },
      "path"_a, "block"_a, "first_row"_a, "end_row"_a, "max_distance"_a, "data"_a.noconvert(), "indices"_a.noconvert(),
      "indptr"_a.noconvert(), "seconds"_a,
      "Writes sparse block `block` as CSR pieces (row pointers from 0), then its marker.");

  m.def(
      "store_status",
      [](const std::string& path, bool verify) {
        store::StoreStatus status;
        {
          nb::gil_scoped_release released;
          status = store::read_store_status(path, verify);
        }
        return std::tuple(status.settings.dump(), status.zarr_format, status.done, status.missing,
                          corrupt_pairs(status.corrupt), reasons(status.damaged));
      },
      "path"_a, "verify"_a,
      "(settings as JSON text, Zarr format, done, missing, corrupt (block, reason) pairs, damaged reasons).");

  m.def(
      "store_read_mesh",
      [](const std::string& path) {
        store::StoredMesh mesh = store::read_stored_mesh(path);
        const std::size_t vertices = mesh.positions.size() / 3, faces = mesh.triangles.size() / 3;
        auto* positions = new std::vector<double>(std::move(mesh.positions));
        auto* triangles = new std::vector<std::uint32_t>(std::move(mesh.triangles));
        nb::capsule position_owner(positions, [](void* p) noexcept { delete static_cast<std::vector<double>*>(p); });
        nb::capsule triangle_owner(triangles,
                                   [](void* p) noexcept { delete static_cast<std::vector<std::uint32_t>*>(p); });
        return std::tuple(nb::ndarray<nb::numpy, double>(positions->data(), {vertices, 3}, position_owner),
                          nb::ndarray<nb::numpy, std::uint32_t>(triangles->data(), {faces, 3}, triangle_owner),
                          mesh.weld);
      },
      "path"_a, "The mesh the store holds (vertices, faces, weld), checked against the hash its settings record.");

  m.def(
      "store_read_sparse_block",
      [](const std::string& path, std::size_t block) {
        const std::optional<store::Stored> stored = store::read_stored(path);
        if (!stored)
          throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument,
                                "'" + path + "' holds no exactgeo distance matrix store");
        store::SparsePieces pieces = store::read_sparse_block(path, stored->shape, block);
        return std::tuple(nb::bytes(pieces.data.data(), pieces.data.size()),
                          nb::bytes(pieces.indices.data(), pieces.indices.size() * sizeof(std::uint32_t)),
                          nb::bytes(pieces.indptr.data(), pieces.indptr.size() * sizeof(std::int64_t)));
      },
      "path"_a, "block"_a,
      "Sparse block `block`'s pieces data, indices and indptr, as the little-endian bytes written.");
}

}  // namespace exactgeo::python
