#include "zarr_store.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <system_error>

#include "little_endian.hpp"

namespace exactgeo::cli {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Writes a shard's blocks as their rows arrive: each block's data, then its marker (store::write_*_block).
class StoreWriter final : public MatrixWriter {
 public:
  StoreWriter(store::OpenStore open, const StoreRequest& request)
      : store_(std::move(open)),
        shard_(request.shard),
        quiet_(request.quiet),
        verify_(request.resume && request.verify),
        started_(std::chrono::steady_clock::now()) {
    if (!quiet_) {
      for (const store::DamagedArray& array : store_.rewritten)
        std::fprintf(stderr, "exactgeo: %s; written again\n", array.reason.c_str());
      for (const store::CorruptBlock& block : store_.failed)
        std::fprintf(stderr, "exactgeo: block %zu failed verification: %s\n", block.block, block.reason.c_str());
    }
    const std::vector<std::size_t>& done = store_.done;
    for (std::size_t block : store::shard_blocks(shard_, store_.shape.blocks())) {
      if (request.resume && std::binary_search(done.begin(), done.end(), block))
        ++reused_;
      else
        todo_.push_back(block);
    }
  }

  std::vector<RowRange> row_ranges(std::size_t rows) const override {
    std::vector<RowRange> ranges;
    for (std::size_t block : todo_)
      ranges.push_back({store_.shape.first(block), std::min(rows, store_.shape.end(block))});
    return ranges;
  }

  void write_rows(std::size_t first_row, std::span<const double> rows) override {
    if (store_.settings.max_distance)  // the command gives a cut-off matrix's rows as their finite entries
      throw exactgeo::Error(exactgeo::ErrorCode::internal, "dense rows for a sparse store");
    if (pending_.empty()) pending_first_ = first_row;
    pending_.insert(pending_.end(), rows.begin(), rows.end());
    const std::size_t block = pending_first_ / store_.shape.block_rows;
    const std::size_t end = store_.shape.end(block);
    if (pending_.size() < (end - pending_first_) * store_.shape.columns) return;
    write_dense(block, end);
    pending_.clear();
  }
  // A sparse store's blocks are CSR pieces, row pointers from 0 in each; a dense store takes the rows whole.
  void write_sparse_rows(std::size_t first_row, const exactgeo::SparseDistances& rows) override {
    if (!store_.settings.max_distance) return MatrixWriter::write_sparse_rows(first_row, rows);
    if (pending_sparse_.rows() == 0) pending_first_ = first_row;
    exactgeo::append_rows(pending_sparse_, rows);
    const std::size_t block = pending_first_ / store_.shape.block_rows;
    const std::size_t end = store_.shape.end(block);
    if (pending_first_ + pending_sparse_.rows() < end) return;
    write_sparse(block, end);
    pending_sparse_ = {};
  }

  void finish() override {
    if (!pending_.empty() || pending_sparse_.rows() > 0)
      throw exactgeo::Error(exactgeo::ErrorCode::internal, "a block was left unfinished");
    if (quiet_) return;
    const std::size_t blocks = store_.shape.blocks();
    const std::size_t done = store::done_blocks(store_.path, blocks).size();
    const std::string failed =
        verify_ ? " (" + std::to_string(store_.failed.size()) + " of them failed verification)" : "";
    std::fprintf(stderr,
                 "exactgeo: %s shard %zu/%zu: %zu blocks computed%s, %zu reused (done before%s), of %zu; "
                 "the store has %zu of %zu blocks done\n",
                 store_.path.c_str(), shard_.index, shard_.count, computed_, failed.c_str(), reused_,
                 verify_ ? ", verified" : "", computed_ + reused_, done, blocks);
  }

 private:
  store::BlockRecord record_of(std::size_t block, std::size_t end) const {
    return {.block = block,
            .first_row = store_.shape.first(block),
            .end_row = end,
            .max_distance = store_.settings.max_distance,
            .seconds = seconds_since(started_)};
  }
  void block_written() {
    ++computed_;
    started_ = std::chrono::steady_clock::now();
  }

  void write_dense(std::size_t block, std::size_t end) {
    // The last block's chunk is padded with the fill value to a whole chunk, as Zarr stores it.
    const std::size_t chunk_values = store_.shape.block_rows * store_.shape.columns;
    std::vector<unsigned char> bytes;
    if (store_.shape.dtype == "float32") {
      std::vector<float> chunk(chunk_values, std::numeric_limits<float>::quiet_NaN());
      std::transform(pending_.begin(), pending_.end(), chunk.begin(), [](double d) { return static_cast<float>(d); });
      bytes = store::little_endian_bytes(chunk);
    } else {
      std::vector<double> chunk(chunk_values, std::numeric_limits<double>::quiet_NaN());
      std::copy(pending_.begin(), pending_.end(), chunk.begin());
      bytes = store::little_endian_bytes(chunk);
    }
    store::write_dense_block(store_.path, record_of(block, end), bytes,
                             store_.shape.columns * store_.shape.item_bytes());
    block_written();
  }

  void write_sparse(std::size_t block, std::size_t end) {
    const std::vector<unsigned char> data_bytes =
        store_.shape.dtype == "float32"
            ? store::little_endian_bytes(std::vector<float>(pending_sparse_.data.begin(), pending_sparse_.data.end()))
            : store::little_endian_bytes(pending_sparse_.data);
    store::write_sparse_block(store_.path, record_of(block, end), store_.shape.dtype, data_bytes,
                              pending_sparse_.indices, pending_sparse_.indptr);
    block_written();
  }

  store::OpenStore store_;
  Shard shard_;
  bool quiet_;
  bool verify_;  // the done blocks were read back, and those not matching their marker computed again
  std::vector<std::size_t> todo_;
  std::size_t reused_ = 0, computed_ = 0;
  // The block being received, from row pending_first_: its rows (dense), or its compressed sparse rows.
  std::vector<double> pending_;
  exactgeo::CompressedSparseRows pending_sparse_;
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

std::unique_ptr<MatrixWriter> open_matrix_store(const std::string& path, const MatrixAxes& axes,
                                                const StoreRequest& request) {
  const exactgeo::Mesh& mesh = *request.mesh;
  const store::MeshArrays mesh_arrays{mesh.positions(), mesh.triangles(), request.weld};
  store::OpenRequest open{.settings = {.mesh_sha256 = store::mesh_sha256(mesh_arrays),
                                       .vertex_count = mesh.vertex_count(),
                                       .face_count = mesh.face_count(),
                                       .weld = request.weld,
                                       .sources = {axes.sources.begin(), axes.sources.end()},
                                       .targets = std::nullopt,
                                       .columns = axes.columns,
                                       .dtype = request.dtype,
                                       .max_distance = request.max_distance,
                                       .block_rows = request.block_rows},
                          .mesh = mesh_arrays,
                          .replace = false,
                          .verify = request.resume && request.verify,
                          .verified = request.shard,
                          .start_over = "remove this one to start over (nothing was changed)"};
  if (!axes.targets.empty()) open.settings.targets.emplace(axes.targets.begin(), axes.targets.end());
  return std::make_unique<StoreWriter>(store::open_store(path, open), request);
}

}  // namespace exactgeo::cli
