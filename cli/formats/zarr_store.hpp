// `matrix --out M.zarr`: the command's side of the distance matrix store, whose layout store/matrix_store.hpp
// alone knows (docs/distributed.md). Here: the shard syntax, and the MatrixWriter that opens a store for the
// request's shard and hands each block's rows to the store as they arrive, with the summary line on stderr.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "matrix_store.hpp"
#include "outputs.hpp"

namespace exactgeo::cli {

using store::Shard;

// "I/N" with 0 <= I < N; throws std::invalid_argument saying what is wrong otherwise.
Shard parse_shard(std::string_view text);

// Sorted block numbers as compact ranges: "0-2, 5, 7-9" ("none" for no block).
std::string block_ranges(std::span<const std::size_t> blocks);

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

// Opens the store at `path` (store::open_store: creating it if there is none) for the request's shard; the writer
// takes the shard's rows block by block. Throws exactgeo::Error naming what differs if the store was made for
// another matrix, and leaves a path holding anything else unchanged.
std::unique_ptr<MatrixWriter> open_matrix_store(const std::string& path, const MatrixAxes& axes,
                                                const StoreRequest& request);

}  // namespace exactgeo::cli
