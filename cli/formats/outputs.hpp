// What the commands write: files chosen by extension from one table per kind of result (values per vertex
// or per target, paths, samples, matrices), the JSON statistics and the aligned text summaries. A new
// format is one writer and one table line.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "exactgeo/exactgeo.hpp"

namespace exactgeo::cli {

// One output format: the lower-case ending that selects it (".npy", or ".ascii.ply" before ".ply") and the
// function that writes it.
template <class Writer>
struct Format {
  std::string_view extension;
  Writer write;
};

// "-" as an output: standard output, in the table's ".csv" format (tables without one do not accept it).
inline constexpr std::string_view kStdout = "-";

// Whether `path` ends with `extension`, whatever the case: every output format is chosen by its ending.
bool has_extension(const std::string& path, std::string_view extension);

// The first format of the table whose ending `path` has (so a longer ending goes before a shorter one it
// ends with); "-" finds ".csv".
template <class Writer>
const Format<Writer>* find_format(std::span<const Format<Writer>> formats, const std::string& path) {
  for (const Format<Writer>& format : formats)
    if (path == kStdout ? format.extension == ".csv" : has_extension(path, format.extension)) return &format;
  return nullptr;
}

// "FILE.{txt,csv}" for the help text and "must be .txt or .csv" for messages, from the table.
template <class Writer>
std::pair<std::string, std::string> format_names(std::span<const Format<Writer>> formats) {
  std::string braces, sentence;
  for (std::size_t i = 0; i < formats.size(); ++i) {
    braces += (i ? "," : "") + std::string(formats[i].extension.substr(1));
    sentence += (i == 0 ? "" : i + 1 == formats.size() ? " or " : ", ") + std::string(formats[i].extension);
  }
  const bool to_stdout = find_format(formats, std::string(kStdout)) != nullptr;
  return {"FILE.{" + braces + "}" + (to_stdout ? "|-" : ""), sentence + (to_stdout ? " (or - for CSV on stdout)" : "")};
}

// Where an output's bytes go. Through a symbolic link, to the file it names (the link stays, as a shell's >
// leaves it). A special file (a FIFO, a terminal, /dev/null) is written into directly: a file renamed over it
// would replace it rather than feed it, and it cannot hold a result half-written anyway.
struct OutputTarget {
  std::filesystem::path path;
  bool special;
};
OutputTarget output_target(const std::string& path);

// The error of a file that cannot be written or read, its message naming the file.
exactgeo::Error io_error(const std::string& message);
// The error of a value that the mesh or a store cannot take (exit code 2), its message naming the value.
exactgeo::Error invalid_argument(const std::string& message);

// An output file that appears only when complete: written to a temporary file beside its destination
// (output_target) and renamed over it by commit(). A run that fails or is interrupted leaves an existing file
// as it was, and never a truncated file that would load as a result. Every failure is an io_error naming the
// file. The path "-" is standard output, and a special file is written directly (commit() flushes it).
class OutputFile {
 public:
  explicit OutputFile(std::string path);
  ~OutputFile();  // uncommitted: removes the temporary file
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  std::FILE* stream();  // the file being written, opened on first use
  // For writers that open the file themselves (the .npz archive): write here, then commit().
  const std::string& writing_path() const { return writing_; }
  void commit();

 private:
  std::string path_;         // as given, for messages
  std::string writing_;      // the temporary file, or the special file itself
  std::string destination_;  // what the temporary file is renamed to; empty when written directly
  std::FILE* stream_ = nullptr;
  bool committed_ = false;
};

// On SIGINT, SIGTERM or SIGHUP, removes the temporary files of unfinished outputs before the process ends
// as the signal would end it: an interrupted run leaves neither a partial result nor litter.
void remove_unfinished_outputs_on_interrupt();

// Lets `write` fill `path` through an OutputFile.
void write_file(const std::string& path, const std::function<void(std::FILE*)>& write);

// Values per vertex, per target or per query point; with labels, each row also gives the nearest source (-1
// where none).
struct Values {
  std::span<const double> distances;
  std::span<const std::uint32_t> labels;  // empty: no label column
  const char* row_name;                   // "vertex", "target" or "point": the first CSV column
  const exactgeo::Mesh* mesh;             // the mesh the values belong to (.ply), or null for targets and points
};
using ValuesWriter = void (*)(std::FILE*, const Values&);
extern const std::span<const Format<ValuesWriter>> kVertexValueFormats;  // .txt .csv .npy .ascii.ply .ply .vtk
extern const std::span<const Format<ValuesWriter>> kTargetValueFormats;  // .txt .csv .npy
void write_values(const std::string& path, std::span<const Format<ValuesWriter>> formats, const Values& values);

using PathWriter = void (*)(std::FILE*, const exactgeo::GeodesicPath&);
extern const std::span<const Format<PathWriter>> kPathFormats;  // .csv .obj .json

using SamplesWriter = void (*)(std::FILE*, const exactgeo::Sampling&);
extern const std::span<const Format<SamplesWriter>> kSamplesFormats;  // .txt .csv .npy

// Points in space located on the surface: per point, the surface point, where it lies and how far it was.
struct LocatedPoints {
  std::span<const exactgeo::SurfacePoint> points;
  std::span<const std::array<double, 3>> positions;
  std::span<const double> distances;
};
using LocatedWriter = void (*)(std::FILE*, const LocatedPoints&);
extern const std::span<const Format<LocatedWriter>> kLocatedFormats;  // .txt .csv

// Rows [first, end) of a matrix.
struct RowRange {
  std::size_t first, end;
};

// A distance matrix arriving in blocks of whole rows (sources x vertices), written as it comes.
class MatrixWriter {
 public:
  virtual ~MatrixWriter() = default;
  // The rows it wants, in order: every row for a file; a store's shard (less the blocks done, when resuming).
  virtual std::vector<RowRange> row_ranges(std::size_t rows) const { return {{0, rows}}; }
  virtual void write_rows(std::size_t first_row, std::span<const double> rows) = 0;
  // Rows [first_row, first_row + block.rows) of a cut-off matrix, as their finite entries
  // (exactgeo::for_each_sparse_block): by default written as the dense rows they stand for.
  virtual void write_sparse_rows(std::size_t first_row, const exactgeo::SparseDistances& block);
  // Completes the file; until then it is not a valid result.
  virtual void finish() = 0;
};
// What the rows and columns are: the source vertex of each row, and the target vertex of each column (empty:
// the columns are every vertex, in order).
struct MatrixAxes {
  std::span<const std::uint32_t> sources;
  std::span<const std::uint32_t> targets;
  std::size_t columns;
};
struct StoreRequest;  // what a .zarr store needs besides (zarr_store.hpp); files leave it aside
using MatrixWriterFactory = std::unique_ptr<MatrixWriter> (*)(const std::string& path, const MatrixAxes& axes,
                                                              const StoreRequest& store);
extern const std::span<const Format<MatrixWriterFactory>> kMatrixFormats;  // .npy .npz .csv .zarr

// %.17g round-trips every double; unreachable is written "inf" on every platform.
void print_distance(std::FILE* file, double distance);
std::string format_distance(double distance);
std::string format_number(const char* format, double value);
// The nearest-source label as written: -1 for kNoSource.
long long label_value(std::uint32_t label);

// Name-value rows, names aligned: the text summaries.
using Rows = std::vector<std::pair<std::string, std::string>>;
void print_table(const Rows& rows);

// The text of a JSON output, indented. JSON holds text only: a string that is not UTF-8 (a file name in
// another encoding) gets U+FFFD in place of its invalid bytes, and a warning on stderr says so.
std::string json_text(const nlohmann::ordered_json& json);
void write_json(const std::string& path, const nlohmann::ordered_json& json);

// Whether two output arguments reach the same file, however spelled (./x, a link, a hard link): written
// one after the other, the second would replace the first without a word.
bool same_output(const std::string& first, const std::string& second);

}  // namespace exactgeo::cli
