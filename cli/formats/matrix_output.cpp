// Distance matrices, written block by block as the rows arrive, so memory stays at a block of rows where the
// format allows it.
#include <cmath>
#include <array>
#include <memory>

#include "npy.hpp"
#include "outputs.hpp"
#include "zarr_store.hpp"

namespace exactgeo::cli {

void MatrixWriter::write_sparse_rows(std::size_t first_row, const exactgeo::SparseDistances& block) {
  std::vector<double> rows(block.rows * block.columns, HUGE_VAL);
  for (std::size_t k = 0; k < block.distance.size(); ++k)
    rows[block.row[k] * block.columns + block.column[k]] = block.distance[k];
  write_rows(first_row, rows);
}

namespace {

// A matrix written through a stream: the file appears when finish() commits it.
class FileMatrixWriter : public MatrixWriter {
 public:
  explicit FileMatrixWriter(const std::string& path) : output_(path), file_(output_.stream()) {}
  void finish() override { output_.commit(); }

 protected:
  OutputFile output_;
  std::FILE* file_;
};

// Dense float64, inf beyond the cut-off: the header, then the rows as they come. The matrix alone: NumPy
// refuses headers with keys of its own, so the sources and targets are the caller's (or use .npz).
class NpyMatrixWriter final : public FileMatrixWriter {
 public:
  NpyMatrixWriter(const std::string& path, const MatrixAxes& axes) : FileMatrixWriter(path) {
    const std::string header = npy_header("<f8", std::vector<std::size_t>{axes.sources.size(), axes.columns});
    std::fwrite(header.data(), 1, header.size(), file_);
  }
  void write_rows(std::size_t, std::span<const double> rows) override {
    const std::vector<unsigned char> bytes = little_endian_bytes(rows);
    std::fwrite(bytes.data(), 1, bytes.size(), file_);
  }
};

// source,vertex,distance for the finite entries (source: the row, an index into the sources); with targets
// source,target,distance (target: an index into the targets).
class CsvMatrixWriter final : public FileMatrixWriter {
 public:
  CsvMatrixWriter(const std::string& path, const MatrixAxes& axes) : FileMatrixWriter(path), columns_(axes.columns) {
    std::fputs(axes.targets.empty() ? "source,vertex,distance\n" : "source,target,distance\n", file_);
  }
  void write_rows(std::size_t first_row, std::span<const double> rows) override {
    write_sparse_rows(first_row, exactgeo::finite_entries(rows, columns_));
  }
  void write_sparse_rows(std::size_t first_row, const exactgeo::SparseDistances& block) override {
    for (std::size_t k = 0; k < block.distance.size(); ++k)
      std::fprintf(file_, "%zu,%zu,%.17g\n", first_row + block.row[k], std::size_t{block.column[k]}, block.distance[k]);
  }

 private:
  std::size_t columns_;
};

// scipy.sparse CSR of the finite entries, for scipy.sparse.load_npz, with the source vertex of each row
// (`sources`, int64) and, with targets, the target vertex of each column (`targets`), which load_npz
// leaves aside and numpy.load reads. A zip member's size comes before its data, so the entries and their
// columns grow in temporary files, and the archive is written at the end: memory stays at a block of rows
// (and one offset per row).
class NpzMatrixWriter final : public MatrixWriter {
 public:
  NpzMatrixWriter(const std::string& path, const MatrixAxes& axes)
      : output_(path), rows_(axes.sources.size()), columns_(axes.columns),
        sources_(axes.sources.begin(), axes.sources.end()), targets_(axes.targets.begin(), axes.targets.end()) {}
  void write_rows(std::size_t first_row, std::span<const double> rows) override {
    write_sparse_rows(first_row, exactgeo::finite_entries(rows, columns_));
  }
  void write_sparse_rows(std::size_t, const exactgeo::SparseDistances& block) override {
    exactgeo::append_row_pointers(indptr_, block);
    const std::vector<std::int32_t> indices(block.column.begin(), block.column.end());
    data_.append(little_endian_bytes(block.distance), block.distance.size());
    indices_.append(little_endian_bytes(indices), indices.size());
  }
  void finish() override {
    const std::vector<std::int64_t> shape = {static_cast<std::int64_t>(rows_), static_cast<std::int64_t>(columns_)};
    std::vector<NpzMember> members = {
        {"indices", "", {}, {}, indices_.finish()},
        {"indptr", "<i8", {indptr_.size()}, little_endian_bytes(indptr_)},
        {"format", "|S3", {}, {'c', 's', 'r'}},
        {"shape", "<i8", {2}, little_endian_bytes(shape)},
        {"data", "", {}, {}, data_.finish()},
        {"sources", "<i8", {sources_.size()}, little_endian_bytes(sources_)},
    };
    if (!targets_.empty()) members.push_back({"targets", "<i8", {targets_.size()}, little_endian_bytes(targets_)});
    write_npz(output_.writing_path(), members);
    output_.commit();
  }

 private:
  OutputFile output_;
  std::size_t rows_, columns_;
  std::vector<std::int64_t> sources_, targets_;
  GrowingNpy data_{"<f8"};
  GrowingNpy indices_{"<i4"};
  std::vector<std::int64_t> indptr_ = {0};
};

std::unique_ptr<MatrixWriter> make_npy(const std::string& path, const MatrixAxes& axes, const StoreRequest&) {
  return std::make_unique<NpyMatrixWriter>(path, axes);
}
std::unique_ptr<MatrixWriter> make_npz(const std::string& path, const MatrixAxes& axes, const StoreRequest&) {
  return std::make_unique<NpzMatrixWriter>(path, axes);
}
std::unique_ptr<MatrixWriter> make_csv(const std::string& path, const MatrixAxes& axes, const StoreRequest&) {
  return std::make_unique<CsvMatrixWriter>(path, axes);
}

constexpr std::array<Format<MatrixWriterFactory>, 4> kMatrixFormatTable = {{
    {".npy", make_npy},
    {".npz", make_npz},
    {".csv", make_csv},
    {".zarr", open_matrix_store},  // a folder, shared by the shards of a job array
}};

}  // namespace

const std::span<const Format<MatrixWriterFactory>> kMatrixFormats = kMatrixFormatTable;

}  // namespace exactgeo::cli
